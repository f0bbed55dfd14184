//! A minimal conditional-compilation and import pass for WGSL, which has
//! neither.
//!
//! Lines `#if NAME`, `#if !NAME`, `#if A || B`, `#else` and `#endif`
//! (nestable) keep or drop the lines between them according to the set of
//! enabled names. This is how the shader is specialised per scene: code for
//! a feature the scene does not use never reaches the compiler.
//!
//! A line `#import <path>` (a WGSL file's path from the repository's root)
//! says the file needs that one; an import inside a dropped branch is not
//! taken, so a file can need another for one feature only. The shader
//! table (`shader_source`) follows the imports.
//!
//! Not naga_oil (Bevy's `#import` and `#ifdef` composer): it mangles and
//! rewrites each imported module, so an error would no longer point at its
//! file and line, which marbre's shader messages and `--dev` rely on, and
//! these files are small enough to concatenate.

use std::collections::BTreeSet;

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PreprocessError {
    #[error("{file}:{line}: `{directive}` without a matching `#if`")]
    Unmatched {
        file: String,
        line: usize,
        directive: String,
    },
    #[error("{file}: `#if` opened at line {line} is never closed")]
    Unclosed { file: String, line: usize },
    #[error("{file}:{line}: `#import {name}` names no WGSL file marbre has")]
    UnknownImport {
        file: String,
        line: usize,
        name: String,
    },
    #[error("{file} imports itself, through {}", chain.join(" → "))]
    ImportCycle { file: String, chain: Vec<String> },
}

/// A file's text after [`preprocess`], and the files it imports.
#[derive(Debug, PartialEq)]
pub struct Preprocessed {
    /// The kept lines; dropped and `#import` lines left empty, so that each
    /// line keeps its number.
    pub text: String,
    /// Each import taken: the path named and the line naming it, in order.
    pub imports: Vec<(String, usize)>,
}

/// Filters `source` (named `file` in errors), keeping what `enabled` selects,
/// and lists the imports of the kept lines.
pub fn preprocess(
    source: &str,
    file: &str,
    enabled: &BTreeSet<&str>,
) -> Result<Preprocessed, PreprocessError> {
    // Each open #if: (line it opened at, whether its current branch is kept).
    let mut stack: Vec<(usize, bool)> = Vec::new();
    let mut out = String::with_capacity(source.len());
    let mut imports = Vec::new();
    for (index, line) in source.lines().enumerate() {
        let number = index + 1;
        let trimmed = line.trim();
        let parent_kept = stack.iter().all(|&(_, kept)| kept);
        if let Some(cond) = trimmed.strip_prefix("#if ") {
            let value = cond.split("||").any(|term| {
                let term = term.trim();
                match term.strip_prefix('!') {
                    Some(name) => !enabled.contains(name.trim()),
                    None => enabled.contains(term),
                }
            });
            stack.push((number, value));
        } else if trimmed == "#else" || trimmed == "#endif" {
            let Some(top) = stack.last_mut() else {
                return Err(PreprocessError::Unmatched {
                    file: file.into(),
                    line: number,
                    directive: trimmed.into(),
                });
            };
            if trimmed == "#else" {
                top.1 = !top.1;
            } else {
                stack.pop();
            }
        } else if let Some(name) = trimmed.strip_prefix("#import ") {
            if parent_kept {
                imports.push((name.trim().to_owned(), number));
            }
        } else if parent_kept {
            out.push_str(line);
        }
        // Keep line numbers aligned with the source for compiler messages.
        out.push('\n');
    }
    if let Some(&(line, _)) = stack.last() {
        return Err(PreprocessError::Unclosed {
            file: file.into(),
            line,
        });
    }
    Ok(Preprocessed { text: out, imports })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(src: &str, names: &[&str]) -> String {
        let enabled = names.iter().copied().collect();
        preprocess(src, "t.wgsl", &enabled)
            .unwrap()
            .text
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ")
    }

    #[test]
    fn an_or_keeps_the_block_if_any_name_is_enabled() {
        let src = "#if A || B\nx\n#endif\n#if !A || C\ny\n#endif";
        assert_eq!(run(src, &["B"]), "x y");
        assert_eq!(run(src, &["A"]), "x");
        assert_eq!(run(src, &[]), "y");
    }

    #[test]
    fn keeps_and_drops_branches() {
        let src = "a\n#if X\nb\n#else\nc\n#endif\nd\n";
        assert_eq!(run(src, &["X"]), "a b d");
        assert_eq!(run(src, &[]), "a c d");
    }

    #[test]
    fn nests_and_negates() {
        let src = "#if X\n#if !Y\nxy\n#endif\nx\n#endif\n";
        assert_eq!(run(src, &["X"]), "xy x");
        assert_eq!(run(src, &["X", "Y"]), "x");
        assert_eq!(run(src, &["Y"]), "");
    }

    #[test]
    fn takes_the_imports_of_kept_lines_and_keeps_line_numbers() {
        let src =
            "#import a.wgsl\n#if X\n#import b.wgsl\n#else\n#import c.wgsl\n#endif\nfn f() {}\n";
        let enabled = ["X"].into_iter().collect();
        let out = preprocess(src, "t.wgsl", &enabled).unwrap();
        assert_eq!(
            out.imports,
            vec![("a.wgsl".to_owned(), 1), ("b.wgsl".to_owned(), 3)]
        );
        assert_eq!(out.text.lines().nth(6), Some("fn f() {}"));
        assert!(!out.text.contains('#'), "a directive reached the WGSL");
        let none = preprocess(src, "t.wgsl", &BTreeSet::new()).unwrap();
        assert_eq!(
            none.imports,
            vec![("a.wgsl".to_owned(), 1), ("c.wgsl".to_owned(), 5)]
        );
    }

    #[test]
    fn reports_unbalanced_directives() {
        let none = BTreeSet::new();
        assert!(matches!(
            preprocess("#endif\n", "f", &none),
            Err(PreprocessError::Unmatched { line: 1, .. })
        ));
        assert!(matches!(
            preprocess("a\n#if X\n", "f", &none),
            Err(PreprocessError::Unclosed { line: 2, .. })
        ));
    }
}
