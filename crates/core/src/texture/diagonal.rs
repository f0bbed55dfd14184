//! The diagonal: the texture report's example of a new texture (§2.1,
//! `MaTexture`), which colours a point by whether u < v.

use glam::Vec2;

/// 0 (the first child) where u < v, 1 (the second) elsewhere: the report's
/// `if (u < v) rouge else vert` as a blend factor.
pub fn diagonal(uv: Vec2) -> f32 {
    if uv.x < uv.y { 0.0 } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Above the diagonal u = v the first child, on and below it the
    /// second, as the report's `u < v` test reads.
    #[test]
    fn the_diagonal_splits_the_unit_square_at_u_equals_v() {
        assert_eq!(diagonal(Vec2::new(0.2, 0.7)), 0.0);
        assert_eq!(diagonal(Vec2::new(0.7, 0.2)), 1.0);
        assert_eq!(diagonal(Vec2::new(0.5, 0.5)), 1.0);
        // Half of the unit square each: a midpoint grid of 100 × 100 has
        // 4950 points strictly above the diagonal, 4950 below, 100 on it.
        let n = 100;
        let ones: f32 = (0..n * n)
            .map(|i| {
                let uv = Vec2::new((i % n) as f32, (i / n) as f32) / n as f32;
                diagonal(uv)
            })
            .sum();
        assert_eq!(ones, 5050.0);
    }
}
