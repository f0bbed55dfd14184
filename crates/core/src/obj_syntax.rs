//! Where an OBJ or MTL file goes wrong: `tobj` reports what is wrong but not
//! where, so a failed load is followed by this line-by-line check, which
//! finds the first statement a reader cannot take. It knows only the
//! statements marbre reads; others are skipped as `tobj` skips them.

/// The 1-based number and text of the first line of an OBJ file that `tobj`
/// would refuse: numbers that do not parse, faces with fewer than three
/// corners, or indices that point at no vertex.
pub fn first_bad_obj_line(text: &str) -> Option<(usize, String)> {
    let count = |key: &str| {
        text.lines()
            .filter(|l| statement(l).next() == Some(key))
            .count() as i64
    };
    let (vertices, texcoords, normals) = (count("v"), count("vt"), count("vn"));
    text.lines().enumerate().find_map(|(i, line)| {
        let mut words = statement(line);
        let ok = match words.next() {
            Some("v") | Some("vn") => floats(words).is_some_and(|n| n >= 3),
            Some("vt") => floats(words).is_some_and(|n| n >= 1),
            Some("f") => {
                let corners: Vec<&str> = words.collect();
                corners.len() >= 3
                    && corners
                        .iter()
                        .all(|c| corner_ok(c, [vertices, texcoords, normals]))
            }
            _ => true,
        };
        (!ok).then(|| (i + 1, line.trim().to_owned()))
    })
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

/// Whether a face corner `v`, `v/t`, `v//n` or `v/t/n` names existing
/// elements (negative indices count back from the end, as OBJ allows).
fn corner_ok(corner: &str, counts: [i64; 3]) -> bool {
    let parts: Vec<&str> = corner.split('/').collect();
    if parts.is_empty() || parts.len() > 3 {
        return false;
    }
    parts.iter().zip(counts).enumerate().all(|(k, (p, count))| {
        if p.is_empty() {
            // Only the texture slot of `v//n` may be empty.
            return k == 1 && parts.len() == 3;
        }
        match p.parse::<i64>() {
            Ok(i) if i > 0 => i <= count,
            Ok(i) if i < 0 => -i <= count,
            _ => false,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_bad_statement_is_found() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n";
        assert_eq!(first_bad_obj_line(obj), Some((5, "f 1 2 4".into())));
        assert_eq!(first_bad_obj_line("v 0 0 0\nv 1 zero 0\n").unwrap().0, 2);
        assert_eq!(
            first_bad_obj_line("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n")
                .unwrap()
                .0,
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
}
