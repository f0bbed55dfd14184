//! Paths tidied by their text alone, for what the user reads: a preset in
//! `bad/` naming `../envmaps/x.exr` resolves to `envmaps/x.exr`, not
//! `bad/../envmaps/x.exr`.
//!
//! Lexical: `a/link/..` becomes `a` even where `link` is a symbolic link
//! to another folder (the file system would go to the link's parent), the
//! rule presets already follow when they save paths relative to their
//! folder.

use std::path::{Component, Path, PathBuf};

/// `path` without `.` components and with each `..` cancelling the folder
/// before it; a `..` with nothing to cancel stays in a relative path and is
/// dropped at the root of an absolute one. An empty result is `.`.
pub fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => match out.components().next_back() {
                Some(Component::Normal(_)) => {
                    out.pop();
                }
                Some(Component::RootDir | Component::Prefix(_)) => {}
                Some(Component::ParentDir | Component::CurDir) | None => out.push(".."),
            },
            other => out.push(other),
        }
    }
    if out.as_os_str().is_empty() {
        out.push(".");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dots_are_resolved_by_the_text() {
        for (path, expected) in [
            ("bad/../envmaps/x.exr", "envmaps/x.exr"),
            ("./presets/./a.ron", "presets/a.ron"),
            ("a/b/../../c", "c"),
            ("../envmaps/x.exr", "../envmaps/x.exr"),
            ("a/../../x", "../x"),
            ("../../x", "../../x"),
            ("/srv/presets/../envmaps/x.exr", "/srv/envmaps/x.exr"),
            ("/../x", "/x"),
            ("a/..", "."),
            ("envmaps/x.exr", "envmaps/x.exr"),
        ] {
            assert_eq!(normalize(Path::new(path)), Path::new(expected), "{path}");
        }
    }
}
