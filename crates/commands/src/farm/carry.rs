//! What a scheduler's files can carry, checked before anything of a job
//! is written: a value the plan, a script or a manifest could not hold as
//! it is (a newline that would start a new `#SBATCH` line or a shell
//! command, a byte that is not text) is refused, naming its option.
//! Everything else is carried exactly: shell words by
//! [`super::shell::quoted`], JSON by serde.

use super::shown_path;
use anyhow::{Result, bail};
use std::path::Path;

/// `path`'s text, refused if the job's files could not carry it: bytes
/// that are not UTF-8 (the plan and the manifests hold paths as text) or
/// a control character (a scheduler's line or log would misread it).
/// `what` names it, as "--preset".
pub fn path_text<'a>(what: &str, path: &'a Path) -> Result<&'a str> {
    let Some(text) = path.to_str() else {
        bail!(
            "{what} {}: the path is not UTF-8 text, which a job's plan and scripts hold; \
             rename it",
            shown_path(path)
        );
    };
    if let Some(c) = text.chars().find(|c| c.is_control()) {
        bail!(
            "{what} {}: a job's path cannot hold the control character {c:?} (a script or a \
             scheduler would misread it); rename it",
            shown_path(path)
        );
    }
    Ok(text)
}

/// Refuses a job folder whose path an `#SBATCH --output` line cannot
/// carry: sbatch reads that line itself, splitting it at spaces and taking
/// quotes and backslashes as its own, and `%` is its pattern sign.
pub fn slurm_folder(dir: &Path) -> Result<()> {
    let text = path_text("the job's folder (-o)", dir)?;
    if let Some(c) = text
        .chars()
        .find(|c| c.is_whitespace() || matches!(c, '%' | '\'' | '"' | '\\'))
    {
        bail!(
            "{text}: a Slurm job's folder cannot hold {c:?} (its #SBATCH --output line would \
             misread it); choose another folder"
        );
    }
    Ok(())
}

/// Refuses a value of a Slurm flag (`option`, as "--partition") that an
/// `#SBATCH --option=value` line cannot carry: a control character (a
/// newline would start a line of the script), a space (sbatch splits the
/// line there), a quote or a backslash (which sbatch takes as its own), or
/// `#`.
pub fn slurm_value(option: &str, value: &str) -> Result<()> {
    if value.is_empty() {
        bail!("{option} is empty: give a value or leave it out");
    }
    if let Some(c) = value
        .chars()
        .find(|c| c.is_control() || c.is_whitespace() || matches!(c, '\'' | '"' | '\\' | '#'))
    {
        bail!(
            "{option} {value:?}: an #SBATCH line cannot carry {c:?} (sbatch would misread the \
             line); give the value without it"
        );
    }
    Ok(())
}

/// Refuses a container image reference with a control character or a
/// space, which no image name holds (the manifest would carry it, and the
/// cluster refuse it only once the job runs).
pub fn image(image: &str) -> Result<()> {
    if image.is_empty() {
        bail!("--image is empty: give the image that holds marbre");
    }
    if let Some(c) = image.chars().find(|c| c.is_control() || c.is_whitespace()) {
        bail!("--image {image:?}: an image reference cannot hold {c:?}");
    }
    Ok(())
}

/// Refuses a persistent volume claim's name that is not what Kubernetes
/// names objects by (a DNS subdomain: at most 253 lower-case letters,
/// digits, `-` and `.`, a letter or digit at each end).
pub fn claim(claim: &str) -> Result<()> {
    let alphanumeric = |c: char| c.is_ascii_lowercase() || c.is_ascii_digit();
    let valid = (1..=253).contains(&claim.len())
        && claim
            .chars()
            .all(|c| alphanumeric(c) || matches!(c, '-' | '.'))
        && claim.starts_with(alphanumeric)
        && claim.ends_with(alphanumeric);
    if !valid {
        bail!(
            "--claim {claim:?} is not a claim's name: Kubernetes names it with 1 to 253 \
             lower-case letters, digits, `-` and `.`, beginning and ending with a letter or a \
             digit"
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;

    #[test]
    fn slurm_folders_and_values_that_sbatch_would_misread_are_refused() {
        let e = slurm_folder(Path::new("/jobs/it's")).unwrap_err();
        assert!(e.to_string().contains("cannot hold '\\''"), "{e}");
        assert!(slurm_folder(Path::new("/jobs/50%")).is_err());
        assert!(slurm_folder(Path::new("/jobs/a b")).is_err());
        slurm_folder(Path::new("/jobs/a$(b);`c`")).unwrap();
        for bad in [
            "gpu\ntouch x",
            "gpu x",
            "a\"b",
            "a'b",
            "a\\b",
            "a#b",
            "a\u{1b}",
            "",
        ] {
            let e = slurm_value("--gres", bad).unwrap_err().to_string();
            assert!(e.starts_with("--gres"), "{e}");
        }
        slurm_value("--gres", "gpu:a100:2,shard:1").unwrap();
        slurm_value("--time", "1-00:30:00").unwrap();
    }

    /// A path that is not text, or holds a control character, is refused
    /// and shown escaped.
    #[test]
    fn paths_that_are_not_text_are_refused() {
        let e = path_text("--mount", Path::new(OsStr::from_bytes(b"/a\xffb")))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("--mount /a\u{fffd}b: the path is not UTF-8"),
            "{e}"
        );
        let e = path_text("--preset", Path::new("/a\n\u{1b}[2Jb"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--preset /a\\n\\u{1b}[2Jb: "), "{e}");
        assert_eq!(
            path_text("--preset", Path::new("/a'\"$b")).unwrap(),
            "/a'\"$b"
        );
    }

    #[test]
    fn kubernetes_names_are_checked() {
        claim("renders").unwrap();
        claim("a.b-c9").unwrap();
        for bad in [
            "",
            "Renders",
            "-a",
            "a-",
            "a\"b",
            "a b",
            "a\nb",
            &"a".repeat(254),
        ] {
            assert!(claim(bad).is_err(), "{bad}");
        }
        image("registry.example:5000/marbre@sha256:00").unwrap();
        image("weird'\"$(x)`y`;").unwrap();
        assert!(image("a\nb").is_err() && image("a b").is_err() && image("").is_err());
    }
}
