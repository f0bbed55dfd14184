//! Where an OBJ or MTL file goes wrong: `tobj` reports what is wrong but not
//! where, so a failed load is followed by this line-by-line check, which
//! finds the first statement a reader cannot take. It knows only the
//! statements marbre reads; others are skipped as `tobj` skips them.

/// A statement a reader cannot take, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct BadStatement {
    /// Its 1-based line.
    pub line: usize,
    pub statement: String,
    /// What is wrong, in words a user can act on.
    pub why: String,
}

/// The first line of an OBJ file that `tobj` would refuse, and why: numbers that do not parse, a vertex with other than three
/// coordinates (four with a non-zero w, or six with a colour), a texture
/// coordinate without two, a face with fewer than three corners, or an
/// index that points at no element declared on an earlier line.
///
/// Indices count only what earlier lines declared, as the OBJ format
/// defines them and as `tobj` resolves negative ones: counted over the
/// whole file instead, `f 1/-1 2/-1 3/-1` before the file's first `vt`
/// passed, `tobj` (4.0.5) turned -1 into `usize::MAX` and multiplied it
/// (an overflow, or in a release build "face texcoord index out of
/// bounds" with no line).
pub fn first_bad_obj_line(text: &str) -> Option<BadStatement> {
    // Positions, texture coordinates and normals declared so far.
    let mut declared = [0u64; 3];
    text.lines().enumerate().find_map(|(i, line)| {
        let mut words = statement(line);
        let (verdict, declares) = match words.next() {
            Some("v") => (
                check(
                    vertex_ok(words),
                    "a vertex takes x y z, then nothing, a w other than 0, or an r g b colour",
                ),
                Some(0),
            ),
            // tobj reads two numbers and fails on fewer.
            Some("vt") => (
                check(
                    floats(words).is_some_and(|n| n >= 2),
                    "a texture coordinate takes two numbers, u v",
                ),
                Some(1),
            ),
            Some("vn") => (
                check(
                    floats(words).is_some_and(|n| n >= 3),
                    "a normal takes three numbers, x y z",
                ),
                Some(2),
            ),
            Some("f") => {
                let corners: Vec<&str> = words.collect();
                let verdict = if corners.len() < 3 {
                    Err("a face takes three corners or more".to_owned())
                } else {
                    corners.iter().try_for_each(|c| corner_ok(c, declared))
                };
                (verdict, None)
            }
            _ => (Ok(()), None),
        };
        if let Some(kind) = declares {
            declared[kind] += 1;
        }
        verdict.err().map(|why| BadStatement {
            line: i + 1,
            statement: line.trim().to_owned(),
            why,
        })
    })
}

/// `Ok` if `ok`, else `why`.
fn check(ok: bool, why: &str) -> Result<(), String> {
    if ok { Ok(()) } else { Err(why.to_owned()) }
}

/// The first line of an MTL file `tobj` would refuse: a colour without
/// three numbers, a scalar that is not a number, a map without a file.
pub fn first_bad_mtl_line(text: &str) -> Option<(usize, String)> {
    text.lines().enumerate().find_map(|(i, line)| {
        let mut words = statement(line);
        let ok = match words.next() {
            // tobj reads the first three numbers and panics on fewer.
            Some("Ka" | "Kd" | "Ks" | "Ke") => floats(words).is_some_and(|n| n >= 3),
            Some("Ns" | "Ni" | "d" | "Tr") => floats(words).is_some_and(|n| n >= 1),
            Some("newmtl") => words.next().is_some(),
            Some(key) if key.starts_with("map_") || key == "bump" => words.next().is_some(),
            _ => true,
        };
        (!ok).then(|| (i + 1, line.trim().to_owned()))
    })
}

/// The words of a line before any `#` comment.
fn statement(line: &str) -> std::str::SplitWhitespace<'_> {
    line.split('#').next().unwrap_or("").split_whitespace()
}

/// How many words there are, if every one is a number.
fn floats<'a>(words: impl Iterator<Item = &'a str>) -> Option<usize> {
    let mut n = 0;
    for w in words {
        w.parse::<f32>().ok()?;
        n += 1;
    }
    Some(n)
}

/// Whether a `v` statement's words are what `tobj` takes: x y z, then
/// nothing, a w it divides them by (not zero), or an r g b colour.
fn vertex_ok<'a>(words: impl Iterator<Item = &'a str>) -> bool {
    let mut values = Vec::new();
    for w in words {
        match w.parse::<f32>() {
            Ok(v) => values.push(v),
            Err(_) => return false,
        }
    }
    match values.len() {
        3 | 6 => true,
        4 => values[3] != 0.0,
        _ => false,
    }
}

/// Whether a face corner `v`, `v/t`, `v//n` or `v/t/n` names elements
/// among the `declared` ones (negative indices count back from the last,
/// as OBJ allows); if not, why.
fn corner_ok(corner: &str, declared: [u64; 3]) -> Result<(), String> {
    const KINDS: [(&str, &str); 3] = [
        ("vertex", "vertices"),
        ("texture coordinate", "texture coordinates"),
        ("normal", "normals"),
    ];
    let malformed = || {
        format!(
            "corner `{corner}` is not v, v/t, v//n or v/t/n (whole numbers other than 0, \
             negative ones counting back)"
        )
    };
    let parts: Vec<&str> = corner.split('/').collect();
    if parts.len() > 3 {
        return Err(malformed());
    }
    for (k, (p, count)) in parts.iter().zip(declared).enumerate() {
        if p.is_empty() {
            // Only the texture slot of `v//n` may be empty.
            if k == 1 && parts.len() == 3 {
                continue;
            }
            return Err(malformed());
        }
        // 0 is no index; i64::MIN has no negation, hence unsigned_abs.
        let index = p
            .parse::<i64>()
            .ok()
            .filter(|&i| i != 0)
            .ok_or_else(malformed)?;
        if index.unsigned_abs() > count {
            let (one, many) = KINDS[k];
            return Err(format!(
                "corner `{corner}` names {one} {index}, but {count} {} declared above this line",
                if count == 1 {
                    one.to_owned() + " is"
                } else {
                    many.to_owned() + " are"
                }
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each refusal says what is wrong, in the user's terms.
    #[test]
    fn a_refused_statement_says_why() {
        let why = |text: &str| first_bad_obj_line(text).unwrap().why;
        assert_eq!(
            why("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 9\n"),
            "corner `9` names vertex 9, but 4 vertices are declared above this line"
        );
        assert_eq!(
            why("v 0 0 0\nvt 0 0\nf 1/2 1/1 1/1\n"),
            "corner `1/2` names texture coordinate 2, but 1 texture coordinate is declared \
             above this line"
        );
        assert!(why("v 0 0 0\nf 1 1\n").contains("three corners"));
        assert!(why("v 0 0 0\nf 1 1 x\n").contains("is not v, v/t"));
        assert!(why("v 0 0\n").contains("a vertex takes x y z"));
    }

    #[test]
    fn the_first_bad_statement_is_found() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n";
        assert_eq!(
            first_bad_obj_line(obj).map(|b| (b.line, b.statement)),
            Some((5, "f 1 2 4".into()))
        );
        assert_eq!(first_bad_obj_line("v 0 0 0\nv 1 zero 0\n").unwrap().line, 2);
        assert_eq!(
            first_bad_obj_line("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n")
                .unwrap()
                .line,
            4
        );
        assert_eq!(
            first_bad_obj_line("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -3\n"),
            None
        );
        assert_eq!(
            first_bad_obj_line("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n"),
            None
        );
        let mtl = "newmtl a\nKd 1 1 1\nKs 0.5 0.5\n";
        assert_eq!(first_bad_mtl_line(mtl), Some((3, "Ks 0.5 0.5".into())));
        assert_eq!(first_bad_mtl_line("newmtl a\nmap_Kd\n").unwrap().0, 2);
        assert_eq!(first_bad_mtl_line("newmtl a\nNs ten\n").unwrap().0, 2);
        assert_eq!(first_bad_mtl_line("newmtl a\nKa 0.6 0.1 0.1 # red\n"), None);
    }

    /// Indices point only at what earlier lines declared. The texture
    /// coordinates counted back from before the first `vt` are the input
    /// that overflowed `tobj` 4.0.5 (`vt * 2`, lib.rs:852).
    #[test]
    fn indices_point_only_at_elements_declared_before_the_face() {
        let triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        let bad = |obj: &str| first_bad_obj_line(obj).map(|b| b.line);
        assert_eq!(
            first_bad_obj_line(&format!("{triangle}f 1/-2 2/-2 3/-2\nvt 0 0\nvt 1 1\n"))
                .map(|b| (b.line, b.statement)),
            Some((4, "f 1/-2 2/-2 3/-2".into()))
        );
        assert_eq!(
            bad(&format!("{triangle}f 1//-1 2//-1 3//-1\nvn 0 0 1\n")),
            Some(4)
        );
        assert_eq!(bad("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n"), Some(3));
        assert_eq!(
            bad(&format!("{triangle}vt 0 0\nvt 1 1\nf 1/-2 2/-1 3/2\n")),
            None
        );
        // No negation of i64::MIN to overflow here either.
        assert_eq!(
            bad(&format!("{triangle}f 1 2 -9223372036854775808\n")),
            Some(4)
        );
        assert_eq!(bad(&format!("{triangle}f 0 1 2\n")), Some(4));
    }

    /// `v` takes three coordinates, then a non-zero w or an r g b colour;
    /// `vt` two numbers: anything else `tobj` refuses without a line.
    #[test]
    fn vertices_and_texture_coordinates_have_the_counts_tobj_reads() {
        let bad = |obj: &str| first_bad_obj_line(obj).map(|b| b.line);
        assert_eq!(bad("v 0 0 0 2\nv 0 0 0 1 0.5 0\n"), None);
        assert_eq!(bad("v 0 0 0\nv 0 0 0 0\n"), Some(2));
        assert_eq!(bad("v 0 0 0 1 1\n"), Some(1));
        assert_eq!(bad("v 0 0 0 1 1 1 1\n"), Some(1));
        assert_eq!(bad("vt 0.5 0.5 0\nvt 0.5\n"), Some(2));
    }
}
