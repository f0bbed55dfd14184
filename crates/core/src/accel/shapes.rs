//! Indexed triangle meshes made procedurally, for the tests and the
//! benchmark: a tessellated plane, a UV sphere, and a displaced sphere.
//! Neighbouring triangles share vertex indices, so shared edges have
//! bit-identical end points, as a loaded mesh's do.

use crate::noise::{self, FractalParams, HashKind, NoiseKind, NoiseSettings};
use glam::Vec3;
use std::f32::consts::PI;

#[derive(Debug, Clone, Default, PartialEq)]
pub struct IndexedMesh {
    pub positions: Vec<Vec3>,
    pub indices: Vec<[u32; 3]>,
}

impl IndexedMesh {
    /// One `[v0, v1, v2]` per triangle.
    pub fn triangles(&self) -> Vec<[Vec3; 3]> {
        self.indices
            .iter()
            .map(|t| t.map(|i| self.positions[i as usize]))
            .collect()
    }
}

/// The square [-half, half]² in the plane y = 0, cut into `n × n` quads of
/// two triangles each (split along the quad's diagonal from (x0, z0) to
/// (x1, z1)), facing +y.
pub fn grid_plane(n: u32, half: f32) -> IndexedMesh {
    let n = n.max(1);
    let mut mesh = IndexedMesh::default();
    for j in 0..=n {
        for i in 0..=n {
            let s = |k: u32| -half + 2.0 * half * k as f32 / n as f32;
            mesh.positions.push(Vec3::new(s(i), 0.0, s(j)));
        }
    }
    let at = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            mesh.indices.push([a, c, b]);
            mesh.indices.push([a, d, c]);
        }
    }
    mesh
}

/// A UV sphere: `rings` bands from pole to pole, `segments` around the y
/// axis; the pole bands are fans of triangles. Closed: every edge is shared
/// by two triangles.
pub fn uv_sphere(center: Vec3, radius: f32, rings: u32, segments: u32) -> IndexedMesh {
    displaced_sphere(center, radius, rings, segments, |_| 0.0)
}

/// A UV sphere whose radius at each vertex is `radius · (1 + bump(unit
/// direction))`.
pub fn displaced_sphere(
    center: Vec3,
    radius: f32,
    rings: u32,
    segments: u32,
    bump: impl Fn(Vec3) -> f32,
) -> IndexedMesh {
    let (rings, segments) = (rings.max(2), segments.max(3));
    let mut mesh = IndexedMesh::default();
    let mut vertex = |dir: Vec3| {
        mesh.positions
            .push(center + dir * radius * (1.0 + bump(dir)));
    };
    vertex(Vec3::Y);
    for r in 1..rings {
        let theta = PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = 2.0 * PI * s as f32 / segments as f32;
            let (st, ct) = theta.sin_cos();
            let (sp, cp) = phi.sin_cos();
            vertex(Vec3::new(st * cp, ct, st * sp));
        }
    }
    vertex(Vec3::NEG_Y);
    let south = (mesh.positions.len() - 1) as u32;
    let ring = |r: u32, s: u32| 1 + (r - 1) * segments + s % segments;
    for s in 0..segments {
        mesh.indices.push([0, ring(1, s + 1), ring(1, s)]);
        mesh.indices
            .push([south, ring(rings - 1, s), ring(rings - 1, s + 1)]);
    }
    for r in 1..rings - 1 {
        for s in 0..segments {
            let (a, b) = (ring(r, s), ring(r, s + 1));
            let (c, d) = (ring(r + 1, s + 1), ring(r + 1, s));
            mesh.indices.push([a, b, c]);
            mesh.indices.push([a, c, d]);
        }
    }
    mesh
}

/// A unit sphere of at least (and about) `triangles` triangles whose radius
/// varies by fBm (±15 %): the benchmark's heavy mesh. Its triangles vary in
/// size and orientation, unlike a plain sphere's.
pub fn bumpy_sphere(triangles: usize) -> IndexedMesh {
    // 2 · segments · (rings − 1) triangles, with segments = 2 · rings: the
    // fewest rings that make at least `triangles`.
    let rings = (((1.0 + (1.0 + triangles as f64).sqrt()) / 2.0).ceil() as u32).max(2);
    let settings = NoiseSettings {
        kind: NoiseKind::Gradient,
        hash: HashKind::Pcg,
        fractal: FractalParams {
            octaves: 6.0,
            frequency: 3.0,
            amplitude: 0.15,
            persistence: 0.5,
            lacunarity: 2.0,
            distortion: 0.0,
            progression: Default::default(),
        },
        evolution: None,
    };
    displaced_sphere(Vec3::ZERO, 1.0, rings, 2 * rings, |d| {
        noise::fbm(d, &settings)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// How many triangles use each undirected edge.
    fn edge_uses(mesh: &IndexedMesh) -> HashMap<(u32, u32), u32> {
        let mut uses = HashMap::new();
        for t in &mesh.indices {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        uses
    }

    #[test]
    fn the_sphere_is_closed_and_faces_out() {
        let mesh = uv_sphere(Vec3::ONE, 2.0, 7, 9);
        assert_eq!(mesh.indices.len(), 2 * 9 + 2 * 9 * 5);
        assert!(edge_uses(&mesh).values().all(|&u| u == 2));
        for t in mesh.triangles() {
            let n = (t[1] - t[0]).cross(t[2] - t[0]);
            let c = (t[0] + t[1] + t[2]) / 3.0 - Vec3::ONE;
            assert!(n.dot(c) > 0.0, "{t:?}");
        }
    }

    #[test]
    fn the_plane_faces_up_and_its_inner_edges_are_shared() {
        let mesh = grid_plane(4, 1.0);
        assert_eq!(mesh.indices.len(), 32);
        let uses = edge_uses(&mesh);
        assert_eq!(uses.values().filter(|&&u| u == 1).count(), 16);
        assert!(uses.values().all(|&u| u <= 2));
        for t in mesh.triangles() {
            assert!((t[1] - t[0]).cross(t[2] - t[0]).y > 0.0);
        }
    }

    #[test]
    fn the_bumpy_sphere_has_about_the_triangles_asked_for() {
        // One ring more adds 8 (rings − 1) ≈ 4 √n triangles.
        for asked in [2_000, 50_000] {
            let n = bumpy_sphere(asked).indices.len() as f64;
            let asked = asked as f64;
            assert!(n >= asked && n < asked + 4.0 * asked.sqrt() + 8.0, "{n}");
        }
    }
}
