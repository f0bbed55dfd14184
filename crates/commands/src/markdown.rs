//! Text put into a Markdown page (the gallery `marbre tx --gallery`
//! writes) so that a reader parses back exactly that text (issue 47).
//!
//! A gallery's titles, file names and TX sources come from its
//! `gallery.ron`, whoever wrote it: a title holding `](` or a newline, a
//! file name holding `)` or a space, or a source holding a run of
//! backticks would otherwise end its heading, its image link or its code
//! block early and turn the rest into the page's own markup. Each kind of
//! place has its one function here; the page is built from them alone.
//! The rules are CommonMark's (a backslash escapes any ASCII
//! punctuation; a link destination in `<…>`; a code fence longer than any
//! run of backticks inside), and the tests read the page back with
//! pulldown-cmark, a CommonMark parser, rather than with these rules.

/// The characters that can start or end inline markup (emphasis, code,
/// links, images, HTML, entities, tables, strikethrough, a heading's
/// closing `#`s) or escape another: each is escaped where it stands in
/// inline text. Other punctuation (a title's `§2.3, (a)` and `-`) reads as
/// itself there and stays as written, so the page's source stays legible.
const INLINE_MARKUP: &[char] = &[
    '\\', '`', '*', '_', '[', ']', '<', '>', '!', '#', '&', '|', '~',
];

/// `text` as inline text on one line (a heading, an image's alt text):
/// each character of [`INLINE_MARKUP`] escaped, and line breaks and other
/// control characters made spaces, since a heading or a link text cannot
/// span lines.
pub fn inline(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_control() {
            out.push(' ');
        } else {
            if INLINE_MARKUP.contains(&c) {
                out.push('\\');
            }
            out.push(c);
        }
    }
    out
}

/// `target` as a link's destination: inside `<…>`, where spaces and
/// parentheses are plain, with `<`, `>` and `\` escaped, and a line break
/// (which ends a destination) percent-encoded as URLs write it.
pub fn link_target(target: &str) -> String {
    let mut out = String::from("<");
    for c in target.chars() {
        match c {
            '<' | '>' | '\\' => {
                out.push('\\');
                out.push(c);
            }
            c if c.is_control() => out.push_str(&format!("%{:02X}", u32::from(c))),
            c => out.push(c),
        }
    }
    out.push('>');
    out
}

/// `code` as a fenced code block: the fence one backtick longer than the
/// longest run of backticks in it (three at least), so no line of the
/// code closes it.
pub fn code_block(code: &str) -> String {
    let longest = code.split(|c| c != '`').map(str::len).max().unwrap_or(0);
    let fence = "`".repeat((longest + 1).max(3));
    format!("{fence}\n{code}\n{fence}\n")
}

#[cfg(test)]
mod tests {
    use super::*;
    use pulldown_cmark::{Event, Parser, Tag, TagEnd};

    /// Names and sources a gallery's author might give, hostile or not.
    const HOSTILE: [&str; 8] = [
        "plain",
        "a](evil.png) ![b",
        "# not a heading\n## nor this",
        "`code` and ``` fences",
        "<script>alert(1)</script>",
        "back\\slash *star* _under_ [x]: y",
        "tab\there\rreturn",
        "é ü ✓",
    ];

    /// The text of every `Text` and `Code` event between `start` and its
    /// end, of the first element `start` matches.
    fn text_of(page: &str, start: impl Fn(&Tag) -> bool, end: TagEnd) -> String {
        let mut inside = false;
        let mut text = String::new();
        for event in Parser::new(page) {
            match event {
                Event::Start(tag) if !inside && start(&tag) => inside = true,
                Event::End(e) if inside && e == end => return text,
                Event::Text(t) | Event::Code(t) if inside => text.push_str(&t),
                _ => {}
            }
        }
        panic!("no such element in:\n{page}")
    }

    #[test]
    fn a_heading_reads_back_as_its_text_on_one_line() {
        for title in HOSTILE {
            let page = format!("## {}\n\nafter\n", inline(title));
            let read = text_of(
                &page,
                |t| matches!(t, Tag::Heading { .. }),
                TagEnd::Heading(pulldown_cmark::HeadingLevel::H2),
            );
            let expected: String = title
                .chars()
                .map(|c| if c.is_control() { ' ' } else { c })
                .collect();
            assert_eq!(read.trim(), expected.trim(), "page:\n{page}");
            let headings = Parser::new(&page)
                .filter(|e| matches!(e, Event::Start(Tag::Heading { .. })))
                .count();
            assert_eq!(headings, 1, "the title made a heading of its own:\n{page}");
        }
    }

    #[test]
    fn an_image_reads_back_with_its_alt_text_and_destination() {
        for (title, file) in HOSTILE.iter().zip(HOSTILE.iter().rev()) {
            let page = format!("![{}]({})\n", inline(title), link_target(file));
            let mut images = Parser::new(&page).filter_map(|e| match e {
                Event::Start(Tag::Image { dest_url, .. }) => Some(dest_url.to_string()),
                _ => None,
            });
            let dest = images
                .next()
                .unwrap_or_else(|| panic!("no image in:\n{page}"));
            assert!(images.next().is_none(), "two images in:\n{page}");
            let expected: String = file
                .chars()
                .map(|c| {
                    if c.is_control() {
                        format!("%{:02X}", u32::from(c))
                    } else {
                        c.to_string()
                    }
                })
                .collect();
            assert_eq!(dest, expected, "page:\n{page}");
            let alt = text_of(&page, |t| matches!(t, Tag::Image { .. }), TagEnd::Image);
            let title_on_one_line: String = title
                .chars()
                .map(|c| if c.is_control() { ' ' } else { c })
                .collect();
            assert_eq!(alt, title_on_one_line, "page:\n{page}");
        }
    }

    #[test]
    fn a_code_block_reads_back_as_its_code() {
        for code in HOSTILE.iter().chain(&["```\nafter a fence\n````", "`"]) {
            let page = format!("{}\nafter\n", code_block(code));
            let read = text_of(&page, |t| matches!(t, Tag::CodeBlock(_)), TagEnd::CodeBlock);
            assert_eq!(read, format!("{code}\n"), "page:\n{page}");
        }
    }
}
