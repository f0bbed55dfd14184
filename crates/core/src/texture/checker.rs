//! Checkerboards: the point-sampled 2D and 3D boards, and a 2D board
//! box-filtered in closed form over a footprint, so that it does not alias
//! where cells get smaller than a pixel.

use glam::{Vec2, Vec3};

/// Where a 2D point falls in a board of cells: which child texture applies
/// there, and the point in the cell's own [0, 1)² space. Every cell is a
/// whole texture space for its child (the texture report's rule), which is
/// what nests checkers in checkers and lays one tile per cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// 0 for the first child, 1 for the second.
    pub select: f32,
    pub local: Vec2,
}

/// The odd cells (select 1) and even ones (select 0) of a board of cells of
/// `size` in u and v, whose odd rows are shifted by `phase` of a cell (0.5
/// lays the cells like bricks).
pub fn checker_2d(uv: Vec2, size: Vec2, phase: f32) -> Cell {
    let row = (uv.y / size.y).floor();
    let x = uv.x / size.x + phase * odd(row);
    let column = x.floor();
    Cell {
        select: odd(column + row),
        local: Vec2::new(x - column, uv.y / size.y - row),
    }
}

/// 1 in the odd cells, 0 in the even ones, of a 3D board of boxes.
pub fn checker_3d(p: Vec3, size: Vec3) -> f32 {
    let c = (p / size).floor();
    odd(c.x + c.y + c.z)
}

/// 1 for an odd integer, 0 for an even one (any sign).
pub fn odd(n: f32) -> f32 {
    n - 2.0 * (n * 0.5).floor()
}

/// The antiderivative of the 1D square wave that is 1 on [2k + 1, 2k + 2):
/// how much of [0, x] lies in odd cells.
fn odd_measure(x: f32) -> f32 {
    let half = (x * 0.5).floor();
    half + 2.0 * (x * 0.5 - half - 0.5).max(0.0)
}

/// Fraction of [x - w, x + w] that lies in odd cells (unit cells).
fn odd_fraction(x: f32, w: f32) -> f32 {
    if w <= 0.0 {
        return odd(x.floor());
    }
    (odd_measure(x + w) - odd_measure(x - w)) / (2.0 * w)
}

/// [`checker_2d`] averaged over the box `uv ± half_width` (in uv units),
/// in closed form (pbrt's filtered checkerboard): the board is the XOR of
/// two square waves, so the box average is sx + sy − 2·sx·sy with sx, sy
/// the odd fractions along each axis. The row shift of `phase` is taken at
/// the box's centre row, exact while the box spans one row.
pub fn filtered_checker_2d(uv: Vec2, size: Vec2, phase: f32, half_width: Vec2) -> f32 {
    let row = (uv.y / size.y).floor();
    let x = uv.x / size.x + phase * odd(row);
    let sx = odd_fraction(x, half_width.x / size.x);
    let sy = odd_fraction(uv.y / size.y, half_width.y / size.y);
    sx + sy - 2.0 * sx * sy
}

/// [`checker_3d`] averaged over the box `p ± half_width` (per axis), in
/// closed form:
/// the board is the XOR of three square waves, and the XOR of independent
/// bits that are odd with probabilities s is odd with probability
/// (1 − Π(1 − 2s)) / 2 (for two axes, sx + sy − 2·sx·sy).
pub fn filtered_checker_3d(p: Vec3, size: Vec3, half_width: Vec3) -> f32 {
    let q = p / size;
    let w = half_width / size;
    let s = Vec3::new(
        odd_fraction(q.x, w.x),
        odd_fraction(q.y, w.y),
        odd_fraction(q.z, w.z),
    );
    0.5 * (1.0 - (1.0 - 2.0 * s.x) * (1.0 - 2.0 * s.y) * (1.0 - 2.0 * s.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 3D box average against a supersampled integral, and the point
    /// checker for a zero box.
    #[test]
    fn filtered_3d_checker_equals_the_supersampled_box_integral() {
        let size = Vec3::new(0.5, 0.7, 0.3);
        for (p, w) in [
            (Vec3::new(0.1, 0.2, 0.05), Vec3::splat(0.2)),
            (Vec3::new(-1.3, 0.9, 2.2), Vec3::new(0.45, 0.1, 0.3)),
            (Vec3::new(3.0, -0.35, 0.6), Vec3::new(0.05, 0.0, 0.2)),
        ] {
            let n = 40;
            let mut sum = 0.0;
            for k in 0..n * n * n {
                let f = Vec3::new(
                    (k % n) as f32 + 0.5,
                    ((k / n) % n) as f32 + 0.5,
                    (k / (n * n)) as f32 + 0.5,
                ) / n as f32;
                sum += checker_3d(p + (2.0 * f - 1.0) * w, size);
            }
            let box_mean = sum / (n * n * n) as f32;
            let filtered = filtered_checker_3d(p, size, w);
            assert!(
                (filtered - box_mean).abs() < 2e-2,
                "{p} ± {w}: {filtered} vs {box_mean}"
            );
        }
        let p = Vec3::new(0.3, 0.4, 0.1);
        assert_eq!(
            filtered_checker_3d(p, size, Vec3::ZERO),
            checker_3d(p, size)
        );
    }

    #[test]
    fn neighbouring_cells_alternate_in_2d_and_3d() {
        let size = Vec2::new(0.5, 2.0);
        for (i, j) in [(0_i32, 0_i32), (3, -2), (-5, 7)] {
            let centre = Vec2::new((i as f32 + 0.5) * size.x, (j as f32 + 0.5) * size.y);
            let here = checker_2d(centre, size, 0.0).select;
            assert_eq!(here, (i + j).rem_euclid(2) as f32);
            assert_eq!(
                here + checker_2d(centre + Vec2::X * size.x, size, 0.0).select,
                1.0
            );
            assert_eq!(
                here + checker_2d(centre + Vec2::Y * size.y, size, 0.0).select,
                1.0
            );
        }
        let p = Vec3::new(0.25, 0.25, 0.25);
        assert_eq!(checker_3d(p, Vec3::ONE), 0.0);
        for axis in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X] {
            assert_eq!(checker_3d(p + axis, Vec3::ONE), 1.0);
        }
    }

    /// Each cell maps onto [0, 1)² for its child: a 3×3 board nested in a
    /// 4×4 one has cells of 1/12.
    #[test]
    fn cells_are_whole_texture_spaces_for_their_children() {
        let outer = Vec2::splat(0.25);
        let uv = Vec2::new(0.3, 0.6);
        let cell = checker_2d(uv, outer, 0.0);
        assert!((cell.local - Vec2::new(0.2, 0.4)).length() < 1e-6);
        let inner = checker_2d(cell.local, Vec2::splat(1.0 / 3.0), 0.0);
        // Column 0, row 1 of the inner board.
        assert_eq!(inner.select, 1.0);
        assert!((inner.local - Vec2::new(0.6, 0.2)).length() < 1e-5);
    }

    #[test]
    fn phase_shifts_odd_rows_only() {
        let size = Vec2::ONE;
        // Row 0 is unshifted; in row 1 a phase of 1 swaps every cell.
        for x in [0.2_f32, 1.7, -3.4] {
            assert_eq!(
                checker_2d(Vec2::new(x, 0.5), size, 1.0).select,
                checker_2d(Vec2::new(x, 0.5), size, 0.0).select
            );
            assert_eq!(
                checker_2d(Vec2::new(x, 1.5), size, 1.0).select,
                1.0 - checker_2d(Vec2::new(x, 1.5), size, 0.0).select
            );
        }
        // A phase of 0.5 moves the odd rows' cell edges to the cells' middles.
        assert_ne!(
            checker_2d(Vec2::new(0.4, 1.5), size, 0.5).select,
            checker_2d(Vec2::new(0.6, 1.5), size, 0.5).select
        );
    }

    /// The closed form equals a brute-force average of point samples.
    #[test]
    fn filtered_checker_equals_the_supersampled_box_integral() {
        let size = Vec2::new(1.0, 0.5);
        // Fine enough that the midpoint rule's error at the cell edges stays
        // well under the tolerance.
        let n = 1600;
        for (centre, half) in [
            (Vec2::new(0.3, 0.1), Vec2::new(0.2, 0.05)),
            (Vec2::new(-1.7, 2.3), Vec2::new(0.9, 0.1)),
            (Vec2::new(5.05, -0.26), Vec2::new(0.04, 0.2)),
            (Vec2::new(0.5, 0.2), Vec2::new(3.3, 1.7)),
        ] {
            let mut sum = 0.0_f64;
            for i in 0..n {
                for j in 0..n {
                    let t = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    let q = centre - half + 2.0 * half * t;
                    sum += checker_2d(q, size, 0.0).select as f64;
                }
            }
            let brute = (sum / (n * n) as f64) as f32;
            let closed = filtered_checker_2d(centre, size, 0.0, half);
            assert!(
                (brute - closed).abs() < 1e-3,
                "{centre} ± {half}: {closed} vs supersampled {brute}"
            );
        }
    }

    #[test]
    fn filtered_checker_over_a_cell_pair_is_one_half() {
        let size = Vec2::new(0.7, 1.3);
        for centre in [Vec2::ZERO, Vec2::new(0.33, -2.1), Vec2::new(10.2, 4.4)] {
            let v = filtered_checker_2d(centre, size, 0.0, size);
            assert!((v - 0.5).abs() < 1e-5, "{centre}: {v}");
        }
        // With no footprint it is the point sample.
        let p = Vec2::new(0.2, 1.4);
        assert_eq!(
            filtered_checker_2d(p, size, 0.0, Vec2::ZERO),
            checker_2d(p, size, 0.0).select
        );
    }
}
