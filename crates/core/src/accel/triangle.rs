//! Watertight ray–triangle intersection: Woop, Benthin and Wald,
//! "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013.
//!
//! Why this test rather than Möller–Trumbore: a mesh's neighbouring
//! triangles share edges and vertices, and a ray through a shared edge must
//! hit at least one of them. Möller–Trumbore computes each triangle's
//! barycentrics from its own first vertex and edge vectors, so the two
//! triangles round the shared edge differently and a ray can slip through
//! the crack between them (visible as speckles of background on a mesh).
//! Woop et al. instead move the ray to the origin and shear space so that
//! the ray runs along +z; each vertex is transformed on its own (a shared
//! vertex lands on the same 2D point for every triangle that holds it), and
//! each edge test is a 2D cross product of two transformed vertices, which
//! gives exactly the negated value when the neighbour evaluates the same
//! edge in the opposite direction. So a shared edge is seen the same way by
//! both triangles, and since a zero edge function counts as inside, a ray
//! through it is never lost.

use glam::{Mat3A, Vec3, Vec3A};

/// Where a ray meets a triangle: the distance along the (not necessarily
/// unit) direction, and the barycentric weights of `v1` and `v2` (the
/// weight of `v0` is `1 - b1 - b2`), so the point is
/// `v0 + b1 (v1 - v0) + b2 (v2 - v0)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// The per-ray part of the test, computed once for a ray and reused for
/// every triangle (a BVH traversal tests many).
#[derive(Debug, Clone, Copy)]
pub struct WatertightRay {
    origin: Vec3A,
    /// The paper's transform as a matrix (as accel/traverse.wgsl holds
    /// it): rows `e_kx − Sx e_kz`, `e_ky − Sy e_kz` and `Sz e_kz`, where kz
    /// is the axis along which |d| is largest and kx, ky the other two,
    /// swapped when d[kz] < 0 to keep the triangles' winding; Sx, Sy, Sz
    /// are d[kx]/d[kz], d[ky]/d[kz] and 1/d[kz]. Each row has at most two
    /// non-zero entries and the others add exact zeros, so the products
    /// are the paper's `a[kx] − Sx a[kz]`… to the bit, with no indexing
    /// by axis per triangle (the CPU kernel's hottest loop).
    shear: Mat3A,
}

impl WatertightRay {
    /// `None` for a zero or non-finite direction, which meets nothing.
    #[inline]
    pub fn new(origin: Vec3, direction: Vec3) -> Option<Self> {
        let a = direction.abs();
        if !direction.is_finite() || a.max_element() == 0.0 {
            return None;
        }
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if direction[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let (sx, sy, sz) = (
            direction[kx] / direction[kz],
            direction[ky] / direction[kz],
            1.0 / direction[kz],
        );
        let unit = |k: usize| Vec3A::from(Vec3::AXES[k]);
        let rows = [
            unit(kx) - sx * unit(kz),
            unit(ky) - sy * unit(kz),
            sz * unit(kz),
        ];
        Some(Self {
            origin: origin.into(),
            shear: Mat3A::from_cols(rows[0], rows[1], rows[2]).transpose(),
        })
    }

    /// The vertex relative to the origin, sheared and scaled so that the
    /// ray becomes the +z axis: (x, y) in the plane across the ray, z the
    /// distance along it.
    #[inline]
    fn transform(&self, v: Vec3) -> (f32, f32, f32) {
        let t = self.shear * (Vec3A::from(v) - self.origin);
        (t.x, t.y, t.z)
    }

    /// The closest-hit test against one triangle, with `t` in (0, `t_max`).
    #[inline]
    pub fn intersect(&self, tri: &[Vec3; 3], t_max: f32) -> Option<TriangleHit> {
        let (ax, ay, az) = self.transform(tri[0]);
        let (bx, by, bz) = self.transform(tri[1]);
        let (cx, cy, cz) = self.transform(tri[2]);
        // Edge functions: u is the weight of v0 (the edge v1 → v2), v of v1,
        // w of v2. Each is a cross product of two transformed vertices.
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        // A zero may be a product pair that rounded to the same float
        // rather than a ray truly on the edge. Each product of two f32 is
        // exact in f64 (48 significant bits ≤ 53), so the f64 difference has
        // the exact sign: the paper's fallback, which settles which side of
        // the edge the ray passes.
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let f = f64::from;
            u = (f(cx) * f(by) - f(cy) * f(bx)) as f32;
            v = (f(ax) * f(cy) - f(ay) * f(cx)) as f32;
            w = (f(bx) * f(ay) - f(by) * f(ax)) as f32;
        }
        // Both sides: inside when the three agree in sign (zero counts as
        // either, so a ray exactly on an edge meets both of its triangles).
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        // All three zero: the triangle is seen edge-on (or is degenerate).
        if det == 0.0 {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = (u * az + v * bz + w * cz) * inv_det;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        Some(TriangleHit {
            t,
            b1: v * inv_det,
            b2: w * inv_det,
        })
    }
}

/// The watertight test of the ray `o + t d` against a triangle, for `t` in
/// (0, `t_max`). See the module documentation for why it is watertight.
pub fn intersect(o: Vec3, d: Vec3, tri: [Vec3; 3], t_max: f32) -> Option<TriangleHit> {
    WatertightRay::new(o, d)?.intersect(&tri, t_max)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRI: [Vec3; 3] = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];

    #[test]
    fn hits_inside_with_the_barycentrics_of_v1_and_v2() {
        for d in [Vec3::NEG_Z, Vec3::Z] {
            let o = Vec3::new(0.25, 0.5, -2.0 * d.z);
            let hit = intersect(o, d, TRI, f32::INFINITY).unwrap();
            assert!((hit.t - 2.0).abs() < 1e-6, "{hit:?}");
            assert!((hit.b1 - 0.25).abs() < 1e-6 && (hit.b2 - 0.5).abs() < 1e-6);
        }
    }

    #[test]
    fn misses_outside_behind_and_beyond_t_max() {
        let d = Vec3::NEG_Z;
        assert!(intersect(Vec3::new(0.6, 0.6, 1.0), d, TRI, 10.0).is_none());
        assert!(intersect(Vec3::new(0.2, 0.2, -1.0), d, TRI, 10.0).is_none());
        assert!(intersect(Vec3::new(0.2, 0.2, 1.0), d, TRI, 1.0).is_none());
        assert!(intersect(Vec3::new(0.2, 0.2, 1.0), d, TRI, 1.001).is_some());
        assert!(intersect(Vec3::new(0.2, 0.2, 1.0), Vec3::ZERO, TRI, 10.0).is_none());
    }

    #[test]
    fn an_edge_on_triangle_is_missed() {
        let o = Vec3::new(-1.0, 0.5, 0.0);
        assert!(intersect(o, Vec3::X, TRI, 10.0).is_none());
    }

    #[test]
    fn a_ray_through_a_vertex_or_an_edge_hits() {
        for target in [TRI[0], TRI[1], TRI[2], Vec3::new(0.5, 0.5, 0.0)] {
            let o = target + Vec3::new(0.0, 0.0, 3.0);
            let hit = intersect(o, Vec3::NEG_Z, TRI, 10.0);
            assert_eq!(hit.map(|h| h.t), Some(3.0), "{target}");
        }
    }

    #[test]
    fn scaling_the_direction_scales_t() {
        let o = Vec3::new(0.2, 0.3, 5.0);
        let hit = intersect(o, Vec3::new(0.0, 0.0, -4.0), TRI, 10.0).unwrap();
        assert!((hit.t - 1.25).abs() < 1e-6);
    }
}
