//! `marbre_core::noise::improved_noise` against points computed by Ken Perlin's own
//! 2002 Java reference (`tests/data/perlin/ImprovedNoise.java`, run under
//! OpenJDK 17; see `tests/data/perlin/README.md`).

// 3.14 is Perlin's published test coordinate, not an approximation of π.
#![allow(clippy::approx_constant)]

use marbre_core::noise::improved_noise;

const REFERENCE: &str = include_str!("../data/perlin/reference_points.txt");

fn reference_points() -> Vec<[f64; 4]> {
    REFERENCE
        .lines()
        .filter(|l| !l.trim().is_empty())
        .enumerate()
        .map(|(i, line)| {
            let v: Vec<f64> = line
                .split_whitespace()
                .map(|t| {
                    t.parse::<f64>()
                        .unwrap_or_else(|e| panic!("line {}: bad number {t:?}: {e}", i + 1))
                })
                .collect();
            assert_eq!(
                v.len(),
                4,
                "line {}: expected `x y z value`: {line:?}",
                i + 1
            );
            [v[0], v[1], v[2], v[3]]
        })
        .collect()
}

#[test]
fn fixture_has_80_points_16_of_them_far_out() {
    let points = reference_points();
    assert_eq!(points.len(), 80);
    let far = points
        .iter()
        .filter(|p| p[..3].iter().any(|c| c.abs() > 1000.0));
    assert!(far.count() >= 8, "the far points reach |c| > 1000");
}

#[test]
fn matches_java_reference_at_every_point() {
    let mut failures = Vec::new();
    for [x, y, z, expected] in reference_points() {
        let got = improved_noise(x, y, z);
        // Written so that a NaN counts as a failure.
        let matches = (got - expected).abs() <= 1e-12;
        if !matches {
            failures.push(format!(
                "noise({x}, {y}, {z}) = {got:.17}, Java reference {expected:.17} (diff {:e})",
                got - expected
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} points differ:\n{}",
        failures.len(),
        reference_points().len(),
        failures.join("\n")
    );
}

#[test]
fn published_value_at_3_14_42_7() {
    let v = improved_noise(3.14, 42.0, 7.0);
    assert!(
        (v - 0.136919958784).abs() < 1e-9,
        "noise(3.14, 42, 7) = {v}"
    );
}

#[test]
fn fixture_contains_published_point() {
    let pts = reference_points();
    let p = pts
        .iter()
        .find(|p| p[0] == 3.14 && p[1] == 42.0 && p[2] == 7.0)
        .expect("fixture lacks (3.14, 42, 7)");
    assert!((p[3] - 0.136919958784).abs() < 1e-9);
}
