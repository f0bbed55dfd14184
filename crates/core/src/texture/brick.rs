//! Bricks and tiles: cells separated by mortar. Bricks run in rows shifted
//! by a fraction of a brick; a tile fills its (unit) cell and rises from the
//! mortar along a bevel, which tilts the shading normal.

use super::checker::{Cell, odd};
use glam::Vec2;

/// Bricks of `size` (u, v) with mortar joints `mortar` wide (in uv units),
/// odd rows shifted by `row_offset` of a brick. `select` is 1 on a brick and
/// 0 in the mortar; `local` is the point in its brick's [0, 1)² space.
pub fn brick(uv: Vec2, size: Vec2, mortar: f32, row_offset: f32) -> Cell {
    let row = (uv.y / size.y).floor();
    let x = uv.x / size.x + row_offset * odd(row);
    let local = Vec2::new(x - x.floor(), uv.y / size.y - row);
    // Half a joint on each side of every brick, in uv units.
    let from_edge = local.min(Vec2::ONE - local) * size;
    let on_brick = from_edge.x >= 0.5 * mortar && from_edge.y >= 0.5 * mortar;
    Cell {
        select: if on_brick { 1.0 } else { 0.0 },
        local,
    }
}

/// The fraction of a wall that is mortar, for [`brick`]'s parameters.
pub fn brick_mortar_fraction(size: Vec2, mortar: f32) -> f32 {
    let brick = (size - Vec2::splat(mortar)).max(Vec2::ZERO);
    1.0 - brick.x * brick.y / (size.x * size.y)
}

/// A tile filling the unit cell `uv` ∈ [0, 1)² (lay it with a checker to
/// repeat it): mortar within `mortar_half_width` of the cell's edge, then a
/// bevel `bevel_width` wide over which the tile rises by `bevel_height`, then
/// the flat top.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TileSample {
    /// 1 on the tile (bevel included), 0 in the mortar.
    pub select: f32,
    /// The gradient of the tile's height over uv: zero on the top and in
    /// the mortar, pointing inwards on the bevel. Bump mapping turns it into
    /// a tilted normal.
    pub height_gradient: Vec2,
}

pub fn tile(uv: Vec2, mortar_half_width: f32, bevel_width: f32, bevel_height: f32) -> TileSample {
    let local = uv - uv.floor();
    // Distance to the nearest edge along each axis, and which way is inward.
    let inward = Vec2::new(
        if local.x < 0.5 { 1.0 } else { -1.0 },
        if local.y < 0.5 { 1.0 } else { -1.0 },
    );
    let from_edge = local.min(Vec2::ONE - local);
    let nearest = from_edge.x.min(from_edge.y);
    if nearest < mortar_half_width {
        return TileSample {
            select: 0.0,
            height_gradient: Vec2::ZERO,
        };
    }
    let on_bevel = nearest < mortar_half_width + bevel_width && bevel_width > 0.0;
    let height_gradient = if on_bevel {
        // The height rises along the axis of the nearest edge only.
        let slope = bevel_height / bevel_width;
        if from_edge.x <= from_edge.y {
            Vec2::new(slope * inward.x, 0.0)
        } else {
            Vec2::new(0.0, slope * inward.y)
        }
    } else {
        Vec2::ZERO
    };
    TileSample {
        select: 1.0,
        height_gradient,
    }
}

/// The height of [`tile`]'s profile: 0 in the mortar, rising linearly over
/// the bevel to 1 on the top (a step when `bevel_width` is 0). As a bump
/// texture it raises the tiles; as a colour blend it fades the tile in over
/// its bevel.
pub fn tile_height(uv: Vec2, mortar_half_width: f32, bevel_width: f32) -> f32 {
    let local = uv - uv.floor();
    let from_edge = local.min(Vec2::ONE - local);
    let rise = from_edge.x.min(from_edge.y) - mortar_half_width;
    if rise < 0.0 {
        0.0
    } else if rise >= bevel_width {
        1.0
    } else {
        rise / bevel_width
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::covered_fraction;

    #[test]
    fn brick_mortar_covers_its_share_of_the_wall() {
        let n = 800;
        for (size, mortar, offset) in [
            (Vec2::new(0.25, 0.1), 0.02, 0.5),
            (Vec2::new(0.1, 0.1), 0.01, 0.0),
            (Vec2::new(0.5, 0.2), 0.05, 0.25),
        ] {
            // A whole number of bricks in each direction: the unit square.
            let fraction = covered_fraction(n, Vec2::ZERO, |uv| {
                brick(uv, size, mortar, offset).select == 0.0
            });
            let expected = brick_mortar_fraction(size, mortar);
            assert!(
                (fraction - expected).abs() < 5e-3,
                "{size} {mortar}: {fraction} vs {expected}"
            );
        }
    }

    #[test]
    fn odd_rows_are_offset() {
        let size = Vec2::new(1.0, 1.0);
        let even = brick(Vec2::new(0.3, 0.5), size, 0.1, 0.5);
        let odd_row = brick(Vec2::new(0.3, 1.5), size, 0.1, 0.5);
        assert!((even.local.x - 0.3).abs() < 1e-6);
        assert!((odd_row.local.x - 0.8).abs() < 1e-6);
    }

    /// The height profile's slope on the bevel is the tile's height gradient
    /// for a bevel one unit high.
    #[test]
    fn tile_height_rises_over_the_bevel_with_the_tile_slope() {
        let (m, b) = (0.02, 0.05);
        assert_eq!(tile_height(Vec2::new(0.01, 0.5), m, b), 0.0);
        assert_eq!(tile_height(Vec2::splat(0.5), m, b), 1.0);
        let e = 1e-3;
        for uv in [
            Vec2::new(0.04, 0.5),
            Vec2::new(0.5, 0.95),
            Vec2::new(0.96, 0.3),
        ] {
            let numeric = Vec2::new(
                tile_height(uv + Vec2::X * e, m, b) - tile_height(uv - Vec2::X * e, m, b),
                tile_height(uv + Vec2::Y * e, m, b) - tile_height(uv - Vec2::Y * e, m, b),
            ) / (2.0 * e);
            let analytic = tile(uv, m, b, 1.0).height_gradient;
            assert!(
                (numeric - analytic).length() < 1e-2,
                "{uv}: {numeric} vs {analytic}"
            );
        }
        // No bevel: a step.
        assert_eq!(tile_height(Vec2::new(0.021, 0.5), m, 0.0), 1.0);
    }

    #[test]
    fn tile_mortar_bevel_and_top() {
        let (m, b, h) = (0.02, 0.05, 0.4);
        let n = 1000;
        let fraction = covered_fraction(n, Vec2::ZERO, |uv| tile(uv, m, b, h).select == 0.0);
        let expected = 1.0 - (1.0 - 2.0 * m) * (1.0 - 2.0 * m);
        assert!(
            (fraction - expected).abs() < 3e-3,
            "{fraction} vs {expected}"
        );
        // On the top the surface is flat; on the bevel it rises inwards.
        assert_eq!(tile(Vec2::splat(0.5), m, b, h).height_gradient, Vec2::ZERO);
        assert_eq!(
            tile(Vec2::new(0.04, 0.5), m, b, h).height_gradient,
            Vec2::new(h / b, 0.0)
        );
        assert_eq!(
            tile(Vec2::new(0.5, 0.97), m, b, h).height_gradient,
            Vec2::new(0.0, -h / b)
        );
        assert_eq!(
            tile(Vec2::new(0.01, 0.5), m, b, h).height_gradient,
            Vec2::ZERO
        );
    }
}
