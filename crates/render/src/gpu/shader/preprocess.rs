//! A minimal conditional-compilation pass for WGSL, which has none.
//!
//! Lines `#if NAME`, `#if !NAME`, `#if A || B`, `#else` and `#endif`
//! (nestable) keep or drop
//! the lines between them according to the set of enabled names. This is how
//! the shader is specialised per scene: code for a feature the scene does not
//! use never reaches the compiler.

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
}

/// Filters `source` (named `file` in errors), keeping what `enabled` selects.
pub fn preprocess(
    source: &str,
    file: &str,
    enabled: &BTreeSet<&str>,
) -> Result<String, PreprocessError> {
    // Each open #if: (line it opened at, whether its current branch is kept).
    let mut stack: Vec<(usize, bool)> = Vec::new();
    let mut out = String::with_capacity(source.len());
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
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(src: &str, names: &[&str]) -> String {
        let enabled = names.iter().copied().collect();
        preprocess(src, "t.wgsl", &enabled)
            .unwrap()
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
