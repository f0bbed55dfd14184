//! TX tokens: words (keywords and file names) and numbers, each with the
//! line and column (1-based, in characters) where it starts, for messages.

use crate::shown::shown;

/// What a token is.
#[derive(Debug, Clone, PartialEq)]
pub enum Tok {
    /// A keyword or a file name: any run of non-blank characters that is
    /// not a number.
    Word(String),
    Number(f32),
}

#[derive(Debug, Clone, PartialEq)]
pub struct Token {
    pub tok: Tok,
    pub line: usize,
    pub column: usize,
}

impl Token {
    /// How a message quotes it: `keyword `QUAD``, `number `0.5``.
    pub fn describe(&self) -> String {
        match &self.tok {
            Tok::Word(w) => format!("`{}`", shown(w)),
            Tok::Number(n) => format!("number `{n}`"),
        }
    }
}

/// Splits `text` at blanks. A run is a number if Rust reads it as a
/// finite f32 and it starts like one (a digit, a sign or a point), so
/// that `inf` and `NaN` stay words (and are refused where numbers belong).
///
/// Columns are counted as the line is scanned (each character's place
/// comes with it), not from the line's start for each token: a preset's
/// text is one line, and counting from its start made a long one quadratic.
pub fn tokenize(text: &str) -> Vec<Token> {
    let mut out = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let mut chars = line.char_indices().enumerate().peekable();
        while let Some(&(before, (start, c))) = chars.peek() {
            if c.is_whitespace() {
                chars.next();
                continue;
            }
            let mut end = start;
            while let Some(&(_, (i, c))) = chars.peek() {
                if c.is_whitespace() {
                    break;
                }
                end = i + c.len_utf8();
                chars.next();
            }
            let word = &line[start..end];
            let numeric_start = word.starts_with(|c: char| c.is_ascii_digit() || "+-.".contains(c));
            let tok = match word.parse::<f32>() {
                Ok(n) if numeric_start && n.is_finite() => Tok::Number(n),
                _ => Tok::Word(word.to_owned()),
            };
            out.push(Token {
                tok,
                line: index + 1,
                column: before + 1,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_and_numbers_carry_their_line_and_column() {
        let t = tokenize("TX QUAD\n  UNI CD 0.8 -1 .5 FTX\n\tIMAGE a.ppm 1e400");
        let at: Vec<(Tok, usize, usize)> =
            t.into_iter().map(|t| (t.tok, t.line, t.column)).collect();
        let w = |s: &str| Tok::Word(s.into());
        assert_eq!(
            at,
            vec![
                (w("TX"), 1, 1),
                (w("QUAD"), 1, 4),
                (w("UNI"), 2, 3),
                (w("CD"), 2, 7),
                (Tok::Number(0.8), 2, 10),
                (Tok::Number(-1.0), 2, 14),
                (Tok::Number(0.5), 2, 17),
                (w("FTX"), 2, 20),
                (w("IMAGE"), 3, 2),
                (w("a.ppm"), 3, 8),
                // Overflows f32: not a number, so refused where one belongs.
                (w("1e400"), 3, 14),
            ]
        );
    }

    /// A preset's text is one line: 200,000 tokens on it tokenize with
    /// their columns in characters (`é` is two bytes, one column).
    #[test]
    fn a_long_line_keeps_its_columns_in_characters() {
        let pairs = 100_000;
        let text = format!("{}FTX", "é 0.5 ".repeat(pairs));
        let t = tokenize(&text);
        assert_eq!(t.len(), 2 * pairs + 1);
        for (k, pair) in t.chunks_exact(2).enumerate() {
            // "é 0.5 " is six characters: the word at 6k + 1, the number at 6k + 3.
            assert_eq!(
                (&pair[0].tok, pair[0].line, pair[0].column),
                (&Tok::Word("é".into()), 1, 6 * k + 1)
            );
            assert_eq!(
                (&pair[1].tok, pair[1].line, pair[1].column),
                (&Tok::Number(0.5), 1, 6 * k + 3)
            );
        }
        let last = t.last().unwrap();
        assert_eq!(
            (&last.tok, last.line, last.column),
            (&Tok::Word("FTX".into()), 1, 6 * pairs + 1)
        );
    }

    #[test]
    fn control_characters_are_escaped_in_messages_and_accents_kept() {
        let t = tokenize("\x1b[2J\u{9b}31m éèô\x07");
        let shown: Vec<String> = t.iter().map(Token::describe).collect();
        assert_eq!(shown, ["`\\u{1b}[2J\\u{9b}31m`", "`éèô\\u{7}`"]);
        assert!(shown.iter().all(|s| !s.chars().any(char::is_control)));
    }
}
