//! Shared by `chi2` and `sampling_stability`: a seeded
//! random source with the shader's resolution, parametrisations of the
//! sphere by the unit square (with their Jacobians), and tensor
//! Gauss–Legendre quadrature over a grid of cells in such a domain.

use glam::{DMat3, DVec2, DVec3, Vec3};
use std::f64::consts::PI;

/// PCG32 (O'Neill 2014) with a fixed seed, so every run draws the same
/// numbers; `uniform` has `rand()`'s resolution (multiples of 2^-24 in
/// [0, 1 − 2^-24]), as the trace pass draws them.
pub struct Pcg(u64);

impl Pcg {
    pub fn new(seed: u64) -> Self {
        let mut rng = Pcg(0);
        rng.next();
        rng.0 = rng.0.wrapping_add(seed);
        rng.next();
        rng
    }

    fn next(&mut self) -> u32 {
        let old = self.0;
        self.0 = old
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32)
    }

    pub fn uniform(&mut self) -> f32 {
        (self.next() >> 8) as f32 * (1.0 / 16_777_216.0)
    }
}

/// A map from the unit square onto (part of) the sphere of directions.
pub trait Domain {
    fn direction(&self, p: DVec2) -> DVec3;
    /// The point of the square that maps to `d`; `None` outside the domain.
    fn point(&self, d: DVec3) -> Option<DVec2>;
    /// dω / (da db) at `p`.
    fn jacobian(&self, p: DVec2) -> f64;
}

/// The lab's lat-long parametrisation by the map's texel uv `t` (row 0 at
/// the top), for a map turned by `rotation_degrees`: θ = π (1 − t.y) from
/// straight down, φ = 2π t.x − π; dω = 2π² sin(π t.y) dt. Cells aligned
/// with the map's texels hold a constant env-sampling density.
pub struct LatLong {
    pub rotation_degrees: f64,
}

impl LatLong {
    fn turn(d: DVec3, degrees: f64) -> DVec3 {
        let (s, c) = (-degrees.to_radians()).sin_cos();
        DVec3::new(c * d.x + s * d.z, d.y, -s * d.x + c * d.z)
    }
}

impl Domain for LatLong {
    fn direction(&self, p: DVec2) -> DVec3 {
        let (u, v) = (p.x, 1.0 - p.y);
        let phi = 2.0 * PI * u - PI;
        let theta = PI * v;
        let lookup = DVec3::new(
            theta.sin() * phi.sin(),
            -theta.cos(),
            theta.sin() * phi.cos(),
        );
        Self::turn(lookup, -self.rotation_degrees)
    }

    fn point(&self, d: DVec3) -> Option<DVec2> {
        let l = Self::turn(d.normalize(), self.rotation_degrees);
        let u = (l.x.atan2(l.z) + PI) / (2.0 * PI);
        let v = (-l.y).clamp(-1.0, 1.0).acos() / PI;
        Some(DVec2::new(u.rem_euclid(1.0), 1.0 - v))
    }

    fn jacobian(&self, p: DVec2) -> f64 {
        2.0 * PI * PI * (PI * p.y).sin()
    }
}

/// The hemisphere above `frame.z_axis` in spherical coordinates (θ from
/// the normal, φ about it), each warped to crowd the grid around a lobe
/// centred at (θc, φc) about `width` radians wide: x ↦ c + s tan(α(x)),
/// α linear from atan(−c/s) to atan((1 − c)/s), so a narrow GGX lobe spans
/// many cells and a wide one an almost even grid. The horizon is the
/// domain's edge, never inside a cell, so the density is smooth in every
/// cell and the quadrature converges fast.
pub struct Hemisphere {
    frame: DMat3,
    theta: Warp,
    phi: Warp,
    phi_centre: f64,
}

#[derive(Clone, Copy)]
struct Warp {
    c: f64,
    s: f64,
    a0: f64,
    a1: f64,
}

impl Warp {
    fn new(c: f64, s: f64) -> Self {
        Self {
            c,
            s,
            a0: (-c / s).atan(),
            a1: ((1.0 - c) / s).atan(),
        }
    }
    fn forward(&self, x: f64) -> f64 {
        (self.c + self.s * (self.a0 + (self.a1 - self.a0) * x).tan()).clamp(0.0, 1.0)
    }
    fn inverse(&self, y: f64) -> f64 {
        (((y - self.c) / self.s).atan() - self.a0) / (self.a1 - self.a0)
    }
    fn derivative(&self, x: f64) -> f64 {
        let a = self.a0 + (self.a1 - self.a0) * x;
        self.s * (self.a1 - self.a0) / (a.cos() * a.cos())
    }
}

impl Hemisphere {
    /// The hemisphere about `n`, crowded around `centre` (a direction above
    /// it) over `width` radians in θ and `azimuthal_width` radians across.
    pub fn new(n: DVec3, centre: DVec3, width: f64, azimuthal_width: f64) -> Self {
        let z = n.normalize();
        let x = z.any_orthonormal_vector();
        let frame = DMat3::from_cols(x, z.cross(x), z);
        let local = frame.transpose() * centre.normalize();
        let theta_c = local.z.clamp(-1.0, 1.0).acos() / (PI / 2.0);
        let sin_c = (1.0 - local.z * local.z).max(0.0).sqrt();
        let s_theta = (width / (PI / 2.0)).min(1.0);
        let s_phi = (azimuthal_width / (2.0 * PI * sin_c.max(1e-9))).min(1.0);
        Self {
            frame,
            theta: Warp::new(theta_c.min(1.0), s_theta),
            phi: Warp::new(0.5, s_phi),
            phi_centre: local.y.atan2(local.x),
        }
    }
}

impl Domain for Hemisphere {
    fn direction(&self, p: DVec2) -> DVec3 {
        let theta = PI / 2.0 * self.theta.forward(p.x);
        let phi = self.phi_centre - PI + 2.0 * PI * self.phi.forward(p.y);
        self.frame
            * DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            )
    }

    fn point(&self, d: DVec3) -> Option<DVec2> {
        let l = self.frame.transpose() * d.normalize();
        if l.z <= 0.0 {
            return None;
        }
        let theta = l.z.min(1.0).acos() / (PI / 2.0);
        let phi = (l.y.atan2(l.x) - self.phi_centre + PI).rem_euclid(2.0 * PI) / (2.0 * PI);
        Some(DVec2::new(self.theta.inverse(theta), self.phi.inverse(phi)))
    }

    fn jacobian(&self, p: DVec2) -> f64 {
        let theta = PI / 2.0 * self.theta.forward(p.x);
        theta.sin() * (PI / 2.0) * self.theta.derivative(p.x) * 2.0 * PI * self.phi.derivative(p.y)
    }
}

/// Five-point Gauss–Legendre nodes and weights on [-1, 1]. No node lies on
/// a cell's edge, so a density constant on each cell (the env map's) is
/// integrated exactly, and a smooth one to high order.
const GL_NODES: [f64; 5] = [
    -0.906_179_845_938_664,
    -0.538_469_310_105_683,
    0.0,
    0.538_469_310_105_683,
    0.906_179_845_938_664,
];
const GL_WEIGHTS: [f64; 5] = [
    0.236_926_885_056_189,
    0.478_628_670_499_366,
    0.568_888_888_888_889,
    0.478_628_670_499_366,
    0.236_926_885_056_189,
];

/// A grid of `res.0 × res.1` cells over a domain's unit square, cell
/// (i, j) covering a ∈ [i, i + 1) / res.0, b ∈ [j, j + 1) / res.1.
pub struct Grid<'a> {
    pub domain: &'a dyn Domain,
    pub res: (usize, usize),
}

impl Grid<'_> {
    /// The quadrature nodes' directions, cell by cell (25 per cell).
    pub fn nodes(&self) -> Vec<Vec3> {
        let mut out = Vec::with_capacity(self.res.0 * self.res.1 * 25);
        self.for_each_node(|_, p, _| out.push(self.domain.direction(p).as_vec3()));
        out
    }

    /// ∫ pdf dω over each cell, from the density at each of [`Grid::nodes`].
    pub fn integrate(&self, pdf_at_nodes: &[f32]) -> Vec<f64> {
        let mut cells = vec![0.0; self.res.0 * self.res.1];
        let mut k = 0;
        self.for_each_node(|cell, p, w| {
            cells[cell] += w * f64::from(pdf_at_nodes[k]) * self.domain.jacobian(p);
            k += 1;
        });
        cells
    }

    fn for_each_node(&self, mut f: impl FnMut(usize, DVec2, f64)) {
        let (ra, rb) = self.res;
        let (ha, hb) = (0.5 / ra as f64, 0.5 / rb as f64);
        for i in 0..ra {
            for j in 0..rb {
                let centre = DVec2::new((2 * i + 1) as f64 * ha, (2 * j + 1) as f64 * hb);
                for (x, wx) in GL_NODES.iter().zip(GL_WEIGHTS) {
                    for (y, wy) in GL_NODES.iter().zip(GL_WEIGHTS) {
                        let p = centre + DVec2::new(x * ha, y * hb);
                        f(i * rb + j, p, wx * wy * ha * hb);
                    }
                }
            }
        }
    }

    /// The cell `d` falls in, or `None` outside the domain.
    pub fn cell(&self, d: Vec3) -> Option<usize> {
        let p = self.domain.point(d.as_dvec3())?;
        let i = ((p.x * self.res.0 as f64) as usize).min(self.res.0 - 1);
        let j = ((p.y * self.res.1 as f64) as usize).min(self.res.1 - 1);
        Some(i * self.res.1 + j)
    }
}
