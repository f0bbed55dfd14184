//! Cutouts: a regular polygon (or a disc) in the unit cell of uv space,
//! repeated every cell. With the opacity binding, its outside becomes holes.

use glam::Vec2;
use std::f32::consts::{PI, TAU};

/// 1 inside, 0 outside: the regular polygon of `sides` sides and
/// circumradius `radius`, centred in every unit cell of `uv`, one vertex on
/// the +u axis; with fewer than 3 sides, the disc of that radius.
pub fn cutout(uv: Vec2, sides: u32, radius: f32) -> f32 {
    let q = uv - uv.floor() - Vec2::splat(0.5);
    let r = q.length();
    if sides < 3 {
        return if r <= radius { 1.0 } else { 0.0 };
    }
    // Fold the angle into one sector, centred on its edge's normal: inside
    // when the projection on that normal is within the apothem.
    let sector = TAU / sides as f32;
    let angle = q.y.atan2(q.x);
    let folded = angle - sector * (angle / sector).floor() - 0.5 * sector;
    let apothem = radius * (PI / sides as f32).cos();
    if r * folded.cos() <= apothem {
        1.0
    } else {
        0.0
    }
}

/// The area of the polygon (or disc) that [`cutout`] draws.
pub fn cutout_area(sides: u32, radius: f32) -> f32 {
    if sides < 3 {
        PI * radius * radius
    } else {
        0.5 * sides as f32 * radius * radius * (TAU / sides as f32).sin()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::covered_fraction;

    /// The covered fraction of a cell, by a fine grid of samples, is the
    /// polygon's area.
    #[test]
    fn covered_fraction_is_the_polygon_area() {
        let n = 600;
        for (sides, radius) in [(0, 0.4), (3, 0.45), (4, 0.3), (6, 0.5), (7, 0.2)] {
            let fraction = covered_fraction(n, Vec2::new(3.0, -2.0), |uv| {
                cutout(uv, sides, radius) == 1.0
            });
            let area = cutout_area(sides, radius);
            assert!(
                (fraction - area).abs() < 2e-3,
                "{sides} sides, radius {radius}: {fraction} vs {area}"
            );
        }
    }

    #[test]
    fn square_has_its_vertices_on_the_axes() {
        // Circumradius 0.3: the vertex at (0.3, 0) is in, (0.3, 0.1) is out.
        let c = Vec2::splat(0.5);
        assert_eq!(cutout(c + Vec2::new(0.29, 0.0), 4, 0.3), 1.0);
        assert_eq!(cutout(c + Vec2::new(0.29, 0.1), 4, 0.3), 0.0);
        assert_eq!(cutout(c, 4, 0.3), 1.0);
    }
}
