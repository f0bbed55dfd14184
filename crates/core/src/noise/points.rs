//! The input of `marbre noise`: one point `x,y,z` a line (commas, spaces
//! or tabs between the numbers), blank lines and `#` comments skipped.
//! Read here, beside the noise it feeds, so that the command and its fuzz
//! target share the reader.

use glam::DVec3;
use std::io::{self, BufRead};

/// Why a line is not a point.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BadPoint {
    #[error("`{0}` is not a number (a line is x,y,z)")]
    NotANumber(String),
    #[error("expected 3 numbers x,y,z, found {0}")]
    Count(usize),
    #[error("coordinates must be finite")]
    NotFinite,
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
/// number instead of ending the input. An error reading `input` is the
/// last item.
pub fn read_points(input: impl BufRead) -> impl Iterator<Item = io::Result<PointLine>> {
    let mut lines = input.split(b'\n').enumerate();
    let mut failed = false;
    std::iter::from_fn(move || {
        while !failed {
            let (i, bytes) = lines.next()?;
            match bytes {
                Err(e) => {
                    // A reader that failed may fail again forever (a folder
                    // as stdin): stop at the first error.
                    failed = true;
                    return Some(Err(e));
                }
                Ok(bytes) => {
                    if let Some(point) = parse_line(&String::from_utf8_lossy(&bytes)) {
                        return Some(Ok(PointLine {
                            number: i + 1,
                            point,
                        }));
                    }
                }
            }
        }
        None
    })
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
