//! Axis-aligned boxes for the BVH builder (SIMD `Vec3A`).

use glam::{Vec3, Vec3A};

/// A box; the empty box has min = +∞ and max = −∞, so it grows to whatever
/// is added to it and adds nothing to a union.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub min: Vec3A,
    pub max: Vec3A,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3A::INFINITY,
        max: Vec3A::NEG_INFINITY,
    };

    /// The box of a triangle; empty when any coordinate is NaN or infinite,
    /// so such a triangle never widens a node and no ray is sent its way.
    pub fn of_triangle(tri: &[Vec3; 3]) -> Aabb {
        if !tri.iter().all(|v| v.is_finite()) {
            return Aabb::EMPTY;
        }
        let [a, b, c] = tri.map(Vec3A::from);
        Aabb {
            min: a.min(b).min(c),
            max: a.max(b).max(c),
        }
    }

    pub fn is_empty(&self) -> bool {
        !(self.min.cmple(self.max).all())
    }

    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    pub fn grow(&mut self, p: Vec3A) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// The centre; NaN for the empty box.
    pub fn center(&self) -> Vec3A {
        (self.min + self.max) * 0.5
    }

    /// Surface area; 0 for the empty box.
    pub fn area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.max - self.min;
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// Whether `inner` lies inside (the empty box lies inside any box).
    pub fn contains(&self, inner: &Aabb) -> bool {
        inner.is_empty() || (self.min.cmple(inner.min).all() && inner.max.cmple(self.max).all())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_non_finite_triangle_has_the_empty_box() {
        let tri = [Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::ONE];
        let b = Aabb::of_triangle(&tri);
        assert!(b.is_empty());
        assert_eq!(b.area(), 0.0);
        let unit = Aabb::of_triangle(&[Vec3::ZERO, Vec3::X, Vec3::ONE]);
        assert_eq!(unit.union(&b), unit);
        assert!(unit.contains(&b));
    }

    #[test]
    fn area_of_a_box() {
        let b = Aabb::of_triangle(&[Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO]);
        assert_eq!(b.area(), 2.0 * (2.0 + 6.0 + 3.0));
    }
}
