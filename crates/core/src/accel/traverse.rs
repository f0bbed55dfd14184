//! Closest-hit and any-hit traversal of a [`Bvh`] on the CPU: the same
//! algorithm as `crates/core/src/accel/traverse.wgsl` (stack of [`MAX_DEPTH`] entries, near
//! child first, the same slab test), so the GPU's results can be held to it.

use super::bvh::{Bvh, BvhNode, MAX_DEPTH};
use super::triangle::WatertightRay;
use glam::{BVec3A, Vec3, Vec3A};

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/accel/traverse.wgsl");

/// The closest hit of a ray with a mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshHit {
    pub t: f32,
    /// The triangle's index in the reordered list (the BVH's order);
    /// `bvh.permutation[triangle]` is its index in the builder's input.
    pub triangle: u32,
    /// Barycentric weights of the triangle's `v1` and `v2`.
    pub b1: f32,
    pub b2: f32,
}

/// A direction component at most this times the largest one counts as
/// zero for the slab test, which then does not cull along that axis at all
/// (`SLAB_PARALLEL` in accel/traverse.wgsl). Keeps 1/d finite and bounded (|1/d| ≤
/// 2^40 / max|d|), so no 0·∞ = NaN or ∞ ever appears, which WGSL does not
/// promise to handle; not culling is conservative, so no hit is lost.
pub const SLAB_PARALLEL: f32 = 1.0 / (1u64 << 40) as f32;
// The empty box's corners times the largest 1/d of a unit direction stay
// finite (and far from overflow) in the slab test.
const _: () = assert!(super::bvh::EMPTY_BOX_EXTENT / SLAB_PARALLEL < 1e36);
/// Added to either side of a parallel axis's slab interval.
pub(super) const SLAB_PAD: f32 = 1.0e30;
/// The exit distance is stretched by this before it is compared with the
/// entry. Ize ("Robust BVH Ray Traversal", JCGT 2013) and pbrt show that
/// 1 + 2γ₃ covers the rounding of (bound − origin) · (1/d) on both sides,
/// so a ray through a box's face or edge, or a flat box, is never culled;
/// this is 1 + 16 ε (≈ 1 + 1.9e−6), more than enough for a GPU's 2.5-ulp
/// division (`SLAB_INFLATE` in accel/traverse.wgsl).
pub const SLAB_INFLATE: f32 = 1.0 + 16.0 * f32::EPSILON;

/// A ray prepared for slab tests: its origin, a finite inverse direction
/// (0 on parallel axes), the padding of parallel axes, and which side of
/// each slab it enters by.
#[derive(Debug, Clone, Copy)]
pub struct SlabRay {
    origin: Vec3A,
    inv: Vec3A,
    pad: Vec3A,
    /// Which slabs the ray enters by their max plane (d < 0).
    negative: BVec3A,
}

impl SlabRay {
    #[inline]
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        let largest = direction.abs().max_element();
        let parallel = direction.abs().cmple(Vec3::splat(SLAB_PARALLEL * largest));
        SlabRay {
            origin: origin.into(),
            inv: Vec3::select(parallel, Vec3::ZERO, direction.recip()).into(),
            pad: Vec3::select(parallel, Vec3::splat(SLAB_PAD), Vec3::ZERO).into(),
            negative: Vec3A::from(direction).cmplt(Vec3A::ZERO),
        }
    }

    /// Where the ray enters the node's box, if it does before `t_far`
    /// (entry clamped to 0). The near and far planes are picked by the
    /// direction's sign rather than by min/max of the two distances, so an
    /// inverted box (the empty one) is rejected. In SIMD lanes (`Vec3A`):
    /// the same operations per axis as the shader's.
    #[inline]
    pub fn entry(&self, node: &BvhNode, t_far: f32) -> Option<f32> {
        let (lo, hi) = (Vec3A::from_array(node.min), Vec3A::from_array(node.max));
        let near = Vec3A::select(self.negative, hi, lo);
        let far = Vec3A::select(self.negative, lo, hi);
        let t_near = (near - self.origin) * self.inv - self.pad;
        let t_far_axes = (far - self.origin) * self.inv + self.pad;
        let enter = t_near.max_element().max(0.0);
        let exit = t_far_axes.min_element().min(t_far) * SLAB_INFLATE;
        (enter <= exit).then_some(enter)
    }
}

impl Bvh {
    /// The closest hit with t in (0, `t_max`) among `triangles`, which must
    /// be in the BVH's order ([`Bvh::reorder`]).
    #[inline]
    pub fn intersect(
        &self,
        triangles: &[[Vec3; 3]],
        origin: Vec3,
        direction: Vec3,
        t_max: f32,
    ) -> Option<MeshHit> {
        let mut closest: Option<MeshHit> = None;
        self.walk(origin, direction, t_max, |i, tri_ray, t_far| {
            if let Some(h) = tri_ray.intersect(&triangles[i as usize], t_far) {
                closest = Some(MeshHit {
                    t: h.t,
                    triangle: i,
                    b1: h.b1,
                    b2: h.b2,
                });
                return Visit::Shorten(h.t);
            }
            Visit::Continue
        });
        closest
    }

    /// Whether any triangle is hit with t in (0, `t_max`).
    #[inline]
    pub fn occluded(
        &self,
        triangles: &[[Vec3; 3]],
        origin: Vec3,
        direction: Vec3,
        t_max: f32,
    ) -> bool {
        let mut hit = false;
        self.walk(origin, direction, t_max, |i, tri_ray, t_far| {
            hit = tri_ray.intersect(&triangles[i as usize], t_far).is_some();
            if hit { Visit::Stop } else { Visit::Continue }
        });
        hit
    }

    /// Visits the triangles of every leaf the ray reaches, near child first,
    /// handing each to `test` with the current far bound.
    #[inline]
    fn walk(
        &self,
        origin: Vec3,
        direction: Vec3,
        t_max: f32,
        mut test: impl FnMut(u32, &WatertightRay, f32) -> Visit,
    ) {
        let Some(tri_ray) = WatertightRay::new(origin, direction) else {
            return;
        };
        let slab = SlabRay::new(origin, direction);
        let mut t_far = t_max;
        // The empty hierarchy (or a zeroed node) would be its own child.
        let root = &self.nodes[0];
        if (root.count == 0 && root.a == 0) || slab.entry(root, t_far).is_none() {
            return;
        }
        let mut stack = [0u32; MAX_DEPTH];
        let mut sp = 0;
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            let mut next = None;
            if n.is_leaf() {
                for i in n.a..n.a + n.count {
                    match test(i, &tri_ray, t_far) {
                        Visit::Continue => {}
                        Visit::Shorten(t) => t_far = t,
                        Visit::Stop => return,
                    }
                }
            } else {
                let (l, r) = (n.a as usize, n.a as usize + 1);
                let tl = slab.entry(&self.nodes[l], t_far);
                let tr = slab.entry(&self.nodes[r], t_far);
                next = match (tl, tr) {
                    (Some(a), Some(b)) => {
                        let (near, far) = if b < a { (r, l) } else { (l, r) };
                        stack[sp] = far as u32;
                        sp += 1;
                        Some(near)
                    }
                    (Some(_), None) => Some(l),
                    (None, Some(_)) => Some(r),
                    (None, None) => None,
                };
            }
            node = match next {
                Some(next) => next,
                None if sp == 0 => return,
                None => {
                    sp -= 1;
                    stack[sp] as usize
                }
            };
        }
    }
}

enum Visit {
    Continue,
    /// A hit at this distance: look no further.
    Shorten(f32),
    Stop,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(min: [f32; 3], max: [f32; 3]) -> BvhNode {
        BvhNode {
            min,
            a: 0,
            max,
            count: 1,
        }
    }

    #[test]
    fn axis_aligned_rays_on_a_face_of_a_box_enter_it() {
        let b = node([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
        // Along +x in the plane y = 1 (the max face) and y = 0 (the min).
        for y in [0.0, 1.0, 0.5] {
            let ray = SlabRay::new(Vec3::new(-1.0, y, 0.5), Vec3::X);
            assert_eq!(ray.entry(&b, 10.0), Some(1.0), "y = {y}");
        }
        // A parallel axis does not cull: conservative, and rare enough.
        let ray = SlabRay::new(Vec3::new(-1.0, 1.5, 0.5), Vec3::X);
        assert_eq!(ray.entry(&b, 10.0), Some(1.0));
        let ray = SlabRay::new(Vec3::new(-1.0, 1.5, 0.5), Vec3::new(1.0, 1e-3, 0.0));
        assert_eq!(ray.entry(&b, 10.0), None);
        // A flat box, hit across.
        let flat = node([0.0, 0.0, 0.0], [1.0, 0.0, 1.0]);
        let ray = SlabRay::new(Vec3::new(0.3, 2.0, 0.3), Vec3::NEG_Y);
        assert_eq!(ray.entry(&flat, 10.0), Some(2.0));
    }

    #[test]
    fn the_empty_box_rejects_every_ray() {
        for d in [Vec3::X, Vec3::NEG_Y, Vec3::new(1.0, -2.0, 0.5), Vec3::Z] {
            for o in [Vec3::ZERO, Vec3::splat(-1e6), Vec3::splat(1e6)] {
                let ray = SlabRay::new(o, d);
                assert_eq!(ray.entry(&BvhNode::EMPTY, f32::MAX), None);
            }
        }
    }

    #[test]
    fn a_box_behind_or_beyond_is_missed() {
        let b = node([0.0; 3], [1.0; 3]);
        let ray = SlabRay::new(Vec3::new(0.5, 0.5, 3.0), Vec3::Z);
        assert_eq!(ray.entry(&b, 10.0), None);
        let ray = SlabRay::new(Vec3::new(0.5, 0.5, 3.0), Vec3::NEG_Z);
        assert_eq!(ray.entry(&b, 1.9), None);
        assert_eq!(ray.entry(&b, 2.0), Some(2.0));
        let inside = SlabRay::new(Vec3::splat(0.5), Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(inside.entry(&b, 10.0), Some(0.0));
    }
}
