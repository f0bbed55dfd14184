//! Text from a file, as a message shows it.

/// `text` from an input file (a TX word, an OBJ statement, a file name) as
/// a message shows it: its control characters
/// escaped (ESC as `\u{1b}`), so that a text cannot drive the terminal or
/// the log that prints the message; everything else, accents included, as
/// written.
pub fn shown(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped_and_accents_kept() {
        assert_eq!(shown("UNI \u{1b}[2JX é"), "UNI \\u{1b}[2JX é");
        assert_eq!(shown("a\tb\r"), "a\\tb\\r");
    }
}
