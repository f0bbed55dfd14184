//! The input of `marbre noise`: one point `x,y,z` a line (commas, spaces
//! or tabs between the numbers), blank lines and `#` comments skipped.
//! Read here, beside the noise it feeds, so that the command and its fuzz
//! target share the reader.

use glam::DVec3;
use std::io::{self, BufRead};

/// The longest line read: a point is three numbers, and a longer line
/// (a comment, or `/dev/zero`, which is one endless line) is skipped
/// without being held, so that memory stays bounded whatever the input.
pub const MAX_LINE_BYTES: usize = 64 * 1024;

/// Why a line is not a point.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BadPoint {
    #[error("`{0}` is not a number (a line is x,y,z)")]
    NotANumber(String),
    #[error("expected 3 numbers x,y,z, found {0}")]
    Count(usize),
    #[error("coordinates must be finite")]
    NotFinite,
    #[error("longer than {} KiB (a line is x,y,z)", MAX_LINE_BYTES / 1024)]
    TooLong,
}

/// A line of the input that is neither blank nor a comment.
#[derive(Debug, Clone, PartialEq)]
pub struct PointLine {
    /// Its 1-based number in the input.
    pub number: usize,
    /// Its point, in double precision, or why it has none.
    pub point: Result<DVec3, BadPoint>,
}

/// Each line of `input` that is neither blank nor a comment, with its
/// point or why it has none, so that one bad line costs only itself. Bytes
/// that are not UTF-8 read as U+FFFD, so such a line is reported as not a
/// number instead of ending the input. A line is read as it arrives (a
/// pipe's points come out before the pipe ends), no more than
/// [`MAX_LINE_BYTES`] of it is held, and a longer one is reported as soon
/// as it passes that (`/dev/zero` gives its one error at once, then is
/// skipped). An error reading `input` is the last item.
pub fn read_points(input: impl BufRead) -> impl Iterator<Item = io::Result<PointLine>> {
    let mut lines = Lines {
        input,
        line: Vec::new(),
        in_long_line: false,
    };
    let mut number = 0;
    let mut failed = false;
    std::iter::from_fn(move || {
        while !failed {
            match lines.next_line() {
                Err(e) => {
                    // A reader that failed may fail again forever (a folder
                    // as stdin): stop at the first error.
                    failed = true;
                    return Some(Err(e));
                }
                Ok(None) => return None,
                Ok(Some(whole)) => {
                    number += 1;
                    let text = String::from_utf8_lossy(&lines.line);
                    let point = if whole {
                        parse_line(&text)
                    } else {
                        too_long(&text)
                    };
                    if let Some(point) = point {
                        return Some(Ok(PointLine { number, point }));
                    }
                }
            }
        }
        None
    })
}

/// The lines of an input, each held up to [`MAX_LINE_BYTES`].
struct Lines<R> {
    input: R,
    /// The line last read, or the start of one cut short.
    line: Vec<u8>,
    /// Whether the line last read was cut short, its rest still to skip.
    in_long_line: bool,
}

impl<R: BufRead> Lines<R> {
    /// Reads the next line into `line` (without its `\n`): `Some(true)`
    /// for a whole line, `Some(false)` for one longer than
    /// [`MAX_LINE_BYTES`], returned as soon as that much of it is read
    /// (with that start, which tells a comment from a number; leading
    /// ASCII whitespace does not count), `None` at the end of the input.
    fn next_line(&mut self) -> io::Result<Option<bool>> {
        if self.in_long_line {
            self.skip_line()?;
            self.in_long_line = false;
        }
        self.line.clear();
        let mut any = false;
        loop {
            let buffer = match self.input.fill_buf() {
                Ok(buffer) => buffer,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if buffer.is_empty() {
                return Ok(any.then_some(true));
            }
            any = true;
            let (part, ends) = match buffer.iter().position(|&b| b == b'\n') {
                Some(end) => (&buffer[..end], true),
                None => (buffer, false),
            };
            let room = MAX_LINE_BYTES - self.line.len();
            if part.len() <= room {
                self.line.extend_from_slice(part);
                let used = part.len() + usize::from(ends);
                self.input.consume(used);
                if ends {
                    return Ok(Some(true));
                }
                continue;
            }
            let blank = self.line.iter().all(u8::is_ascii_whitespace);
            let spaces = part.iter().take_while(|b| b.is_ascii_whitespace()).count();
            if blank && (spaces > 0 || !self.line.is_empty()) {
                // Longer than the cap, but only whitespace so far, which
                // a point's parse trims anyway: dropped, and read on.
                self.line.clear();
                let whole_part = spaces == part.len();
                self.input.consume(spaces + usize::from(whole_part && ends));
                if whole_part && ends {
                    return Ok(Some(true));
                }
                continue;
            }
            // Longer than the cap: its start kept, its rest skipped by the
            // next read.
            self.line.extend_from_slice(&part[..room]);
            self.input.consume(room);
            self.in_long_line = true;
            return Ok(Some(false));
        }
    }

    /// Consumes the input up to and including the next `\n`.
    fn skip_line(&mut self) -> io::Result<()> {
        loop {
            let buffer = match self.input.fill_buf() {
                Ok(buffer) => buffer,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if buffer.is_empty() {
                return Ok(());
            }
            let (used, ends) = match buffer.iter().position(|&b| b == b'\n') {
                Some(end) => (end + 1, true),
                None => (buffer.len(), false),
            };
            self.input.consume(used);
            if ends {
                return Ok(());
            }
        }
    }
}

/// What a line longer than [`MAX_LINE_BYTES`] is, from its start: blank
/// or a comment like any other, else too long to be a point.
fn too_long(start: &str) -> Option<Result<DVec3, BadPoint>> {
    let t = start.trim_start();
    if t.is_empty() || t.starts_with('#') {
        None
    } else {
        Some(Err(BadPoint::TooLong))
    }
}

/// A line's point; `None` for a blank line or a comment.
fn parse_line(line: &str) -> Option<Result<DVec3, BadPoint>> {
    let t = line.trim();
    if t.is_empty() || t.starts_with('#') {
        return None;
    }
    let values = t
        .split([',', ' ', '\t'])
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().map_err(|_| BadPoint::NotANumber(s.to_owned())))
        .collect::<Result<Vec<f64>, _>>();
    Some(values.and_then(|values| match values[..] {
        [x, y, z] if [x, y, z].iter().all(|c| c.is_finite()) => Ok(DVec3::new(x, y, z)),
        [_, _, _] => Err(BadPoint::NotFinite),
        _ => Err(BadPoint::Count(values.len())),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_line_gives_its_point_or_why_not_by_its_number() {
        let input = b"# x,y,z\n1,2,3\n\n 4 5\t6 \r\n1,2\nx,2,3\n1,inf,3\n\xff,0,0\n7,8,9";
        let lines: Vec<PointLine> = read_points(&input[..]).map(Result::unwrap).collect();
        let at = |number, point| PointLine { number, point };
        assert_eq!(
            lines,
            vec![
                at(2, Ok(DVec3::new(1.0, 2.0, 3.0))),
                at(4, Ok(DVec3::new(4.0, 5.0, 6.0))),
                at(5, Err(BadPoint::Count(2))),
                at(6, Err(BadPoint::NotANumber("x".into()))),
                at(7, Err(BadPoint::NotFinite)),
                at(8, Err(BadPoint::NotANumber("\u{fffd}".into()))),
                at(9, Ok(DVec3::new(7.0, 8.0, 9.0))),
            ]
        );
    }

    /// A line longer than the cap is one error by its number, however it
    /// arrives (here in reads of 7 bytes and whole), and the lines after
    /// it keep their numbers; a long comment and a long run of whitespace
    /// are what they are at any length.
    #[test]
    fn a_line_over_the_cap_is_too_long_and_the_next_lines_go_on() {
        let over = MAX_LINE_BYTES + 10;
        let input = [
            "1,2,3\n".to_owned(),
            "7".repeat(over) + "\n",
            "#".to_owned() + &"x".repeat(over) + "\n",
            " ".repeat(over) + "\n",
            " ".repeat(over) + "4,5,6\n",
            "8,8,8".to_owned(),
        ]
        .concat();
        let expected = vec![
            PointLine {
                number: 1,
                point: Ok(DVec3::new(1.0, 2.0, 3.0)),
            },
            PointLine {
                number: 2,
                point: Err(BadPoint::TooLong),
            },
            PointLine {
                number: 5,
                point: Ok(DVec3::new(4.0, 5.0, 6.0)),
            },
            PointLine {
                number: 6,
                point: Ok(DVec3::splat(8.0)),
            },
        ];
        let whole: Vec<_> = read_points(input.as_bytes()).map(Result::unwrap).collect();
        assert_eq!(whole, expected);
        let in_small_reads = io::BufReader::with_capacity(7, input.as_bytes());
        let small: Vec<_> = read_points(in_small_reads).map(Result::unwrap).collect();
        assert_eq!(small, expected);
        assert_eq!(
            BadPoint::TooLong.to_string(),
            "longer than 64 KiB (a line is x,y,z)"
        );
    }

    /// An endless line (`/dev/zero`, a stream that never sends `\n`) is
    /// reported once its first [`MAX_LINE_BYTES`] are read, not held
    /// until it ends: the reader here fails the test's way once far more
    /// than that is read.
    #[test]
    fn an_endless_line_is_reported_without_reading_it_all() {
        struct Endless(usize);
        impl io::Read for Endless {
            fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
                if self.0 > 64 << 20 {
                    return Err(io::Error::other("read 64 MiB of one line"));
                }
                buf.fill(b'7');
                self.0 += buf.len();
                Ok(buf.len())
            }
        }
        let mut endless = Endless(0);
        let first = read_points(io::BufReader::new(&mut endless)).next();
        let first = first.unwrap().unwrap();
        assert_eq!(first.number, 1);
        assert_eq!(first.point, Err(BadPoint::TooLong));
        assert!(endless.0 <= 2 * MAX_LINE_BYTES, "read {} bytes", endless.0);
    }

    /// A reader that fails: its error is the last item, however often it
    /// would fail again.
    #[test]
    fn a_read_error_ends_the_points() {
        struct Broken;
        impl io::Read for Broken {
            fn read(&mut self, _: &mut [u8]) -> io::Result<usize> {
                Err(io::Error::other("broken"))
            }
        }
        let items: Vec<_> = read_points(io::BufReader::new(Broken)).collect();
        assert_eq!(items.len(), 1);
        assert_eq!(items[0].as_ref().unwrap_err().to_string(), "broken");
    }
}
