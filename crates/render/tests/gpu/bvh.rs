//! The triangle-mesh BVH (`marbre_core::accel`, `crates/core/src/accel/traverse.wgsl`):
//!
//! * on the CPU, closest hits through the BVH equal brute force over every
//!   triangle, and every node bounds what is under it;
//! * rays aimed exactly at shared edges and vertices of a tessellated plane
//!   and sphere, from near and far and at grazing angles, never slip
//!   through, on the CPU and on the GPU, where a naive Möller–Trumbore test
//!   lets some through;
//! * the GPU's traversal agrees with the CPU's, triangle for triangle.

use glam::Vec3;
use marbre_core::accel::bvh::{MAX_DEPTH, MAX_LEAF_TRIANGLES};
use marbre_core::accel::shapes::{IndexedMesh, bumpy_sphere, grid_plane, uv_sphere};
use marbre_core::accel::{Bvh, BvhNode, MeshHit, TriangleHit, TriangleVerts, intersect};
use marbre_render::gpu::GpuContext;
use marbre_render::gpu::harness::bvh::{BvhHarness, Ray};
use marbre_render::gpu::testing::gpu_or_skip;
use proptest::prelude::*;
use std::collections::HashMap;

/// xorshift64*, so the tests need no random crate and repeat exactly.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40;
        bits as f32 / (1u64 << 24) as f32
    }

    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next()
    }

    fn index(&mut self, n: usize) -> usize {
        ((self.next() * n as f32) as usize).min(n - 1)
    }

    fn unit_vector(&mut self) -> Vec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f32::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    fn point_in_cube(&mut self, half: f32) -> Vec3 {
        Vec3::new(
            self.range(-half, half),
            self.range(-half, half),
            self.range(-half, half),
        )
    }
}

const T_MAX: f32 = 1.0e30;
const RAYS: usize = 10_000;

/// Triangles of random size and orientation scattered through [-1, 1]³.
fn soup(n: usize, rng: &mut Rng) -> Vec<[Vec3; 3]> {
    (0..n)
        .map(|_| {
            let c = rng.point_in_cube(1.0);
            let size = rng.range(0.05, 0.3);
            [0; 3].map(|_| c + rng.unit_vector() * size)
        })
        .collect()
}

fn sphere() -> IndexedMesh {
    uv_sphere(Vec3::ZERO, 1.0, 24, 48)
}

/// Rays from all over [-1.2, 1.2]³ in every direction.
fn rays_through_cube(n: usize, rng: &mut Rng) -> Vec<Ray> {
    (0..n)
        .map(|_| Ray {
            origin: rng.point_in_cube(1.2),
            direction: rng.unit_vector(),
            t_max: T_MAX,
        })
        .collect()
}

/// Rays at a unit sphere: from outside towards points near it (some miss),
/// and from inside (all hit), with unnormalised directions too.
fn rays_at_sphere(n: usize, rng: &mut Rng) -> Vec<Ray> {
    (0..n)
        .map(|k| {
            let origin = if k % 4 == 0 {
                rng.unit_vector() * rng.range(0.0, 0.9)
            } else {
                rng.unit_vector() * rng.range(1.1, 4.0)
            };
            let target = rng.unit_vector() * rng.range(0.0, 1.3);
            Ray {
                origin,
                direction: (target - origin) * rng.range(0.5, 3.0),
                t_max: T_MAX,
            }
        })
        .collect()
}

/// The closest hit over every triangle, in input order, and its index.
fn brute_force(tris: &[[Vec3; 3]], ray: &Ray) -> Option<(u32, TriangleHit)> {
    let mut best: Option<(u32, TriangleHit)> = None;
    for (i, tri) in tris.iter().enumerate() {
        let t_max = best.map_or(ray.t_max, |(_, h)| h.t);
        if let Some(h) = intersect(ray.origin, ray.direction, *tri, t_max) {
            best = Some((i as u32, h));
        }
    }
    best
}

struct Mesh {
    /// Input order.
    triangles: Vec<[Vec3; 3]>,
    bvh: Bvh,
    /// BVH order.
    ordered: Vec<[Vec3; 3]>,
}

impl Mesh {
    fn new(triangles: Vec<[Vec3; 3]>) -> Self {
        let bvh = Bvh::build(&triangles);
        let ordered = bvh.reorder(&triangles);
        Mesh {
            triangles,
            bvh,
            ordered,
        }
    }

    fn cpu(&self, ray: &Ray) -> Option<MeshHit> {
        self.bvh
            .intersect(&self.ordered, ray.origin, ray.direction, ray.t_max)
    }

    fn harness(&self, ctx: &GpuContext) -> BvhHarness {
        let verts: Vec<TriangleVerts> = self.ordered.iter().map(TriangleVerts::new).collect();
        BvhHarness::new(ctx, &self.bvh.nodes, &verts).unwrap()
    }
}

/// BVH closest hits against brute force: the same distance to the bit (the
/// same triangle test runs on the same triangle), the same triangle unless
/// two are hit at exactly that distance, and any-hit queries that see the
/// hit exactly when t_max lies beyond it.
fn check_against_brute_force(name: &str, mesh: &Mesh, rays: &[Ray], min_hits: usize) {
    let mut hits = 0;
    for ray in rays {
        let bvh = mesh.cpu(ray);
        let brute = brute_force(&mesh.triangles, ray);
        match (bvh, brute) {
            (None, None) => {}
            (Some(h), Some((i, b))) => {
                hits += 1;
                let original = mesh.bvh.permutation[h.triangle as usize];
                assert_eq!(h.t, b.t, "{name}: {ray:?}");
                if original == i {
                    assert_eq!((h.b1, h.b2), (b.b1, b.b2), "{name}: {ray:?}");
                } else {
                    let tie = intersect(
                        ray.origin,
                        ray.direction,
                        mesh.triangles[original as usize],
                        T_MAX,
                    );
                    assert_eq!(tie.map(|t| t.t), Some(b.t), "{name}: {ray:?}");
                }
                let (o, d) = (ray.origin, ray.direction);
                assert!(!mesh.bvh.occluded(&mesh.ordered, o, d, h.t), "{name}");
                assert!(
                    mesh.bvh.occluded(&mesh.ordered, o, d, h.t.next_up()),
                    "{name}"
                );
            }
            (bvh, brute) => panic!("{name}: BVH {bvh:?}, brute force {brute:?} for {ray:?}"),
        }
        if bvh.is_none() {
            assert!(
                !mesh
                    .bvh
                    .occluded(&mesh.ordered, ray.origin, ray.direction, T_MAX)
            );
        }
    }
    println!("{name}: {hits} of {} rays hit", rays.len());
    assert!(
        hits >= min_hits,
        "{name}: too few hits ({hits}) to mean much"
    );
}

#[test]
fn bvh_closest_hits_equal_brute_force() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let soup = Mesh::new(soup(2000, &mut rng));
    check_against_brute_force("soup", &soup, &rays_through_cube(RAYS, &mut rng), RAYS / 4);
    let sphere = Mesh::new(sphere().triangles());
    check_against_brute_force("sphere", &sphere, &rays_at_sphere(RAYS, &mut rng), RAYS / 2);
}

/// The box of a triangle, computed here independently of the builder.
fn triangle_box(tri: &[Vec3; 3]) -> (Vec3, Vec3) {
    (
        tri[0].min(tri[1]).min(tri[2]),
        tri[0].max(tri[1]).max(tri[2]),
    )
}

fn inside(inner: (Vec3, Vec3), node: &BvhNode) -> bool {
    let (lo, hi) = (Vec3::from_array(node.min), Vec3::from_array(node.max));
    lo.cmple(inner.0).all() && inner.1.cmple(hi).all()
}

/// The tree's shape: every node reached once from the root, interior
/// nodes' children inside their box, leaves of 1 to 4 triangles inside
/// theirs, the leaves' ranges covering the triangles once, the permutation
/// a permutation, depth within the stack, and the stats telling the truth.
fn check_structure(name: &str, triangles: &[[Vec3; 3]]) {
    let bvh = Bvh::build(triangles);
    let ordered = bvh.reorder(triangles);
    let n = triangles.len();
    let mut sorted = bvh.permutation.clone();
    sorted.sort_unstable();
    assert!(
        sorted.iter().copied().eq(0..n as u32),
        "{name}: permutation"
    );
    let mut reached = vec![0u32; bvh.nodes.len()];
    let mut covered = vec![0u32; n];
    let (mut leaves, mut max_depth) = (0, 0);
    let mut stack = vec![(0usize, 0usize)];
    while let Some((i, depth)) = stack.pop() {
        reached[i] += 1;
        let node = &bvh.nodes[i];
        let finite = |t: &&[Vec3; 3]| t.iter().all(|v| v.is_finite());
        if node.count > 0 {
            leaves += 1;
            max_depth = max_depth.max(depth);
            assert!(node.count as usize <= MAX_LEAF_TRIANGLES, "{name}");
            let range = node.a as usize..(node.a + node.count) as usize;
            let leaf = &ordered[range.clone()];
            if leaf.iter().all(|t| finite(&t)) {
                for t in leaf {
                    assert!(inside(triangle_box(t), node), "{name}: leaf {i}");
                }
            } else {
                // Non-finite triangles sit apart, in leaves of empty boxes.
                assert!(!leaf.iter().any(|t| finite(&t)), "{name}: leaf {i}");
                assert!(node.min[0] > node.max[0], "{name}: leaf {i}");
            }
            for c in &mut covered[range] {
                *c += 1;
            }
        } else {
            let a = node.a as usize;
            assert!(a >= 1 && a + 1 < bvh.nodes.len(), "{name}: node {i}");
            for child in [a, a + 1] {
                let c = &bvh.nodes[child];
                if c.min[0] <= c.max[0] {
                    let b = (Vec3::from_array(c.min), Vec3::from_array(c.max));
                    assert!(inside(b, node), "{name}: child {child} of {i}");
                }
                stack.push((child, depth + 1));
            }
        }
    }
    assert!(reached.iter().all(|&r| r == 1), "{name}: reachability");
    assert!(covered.iter().all(|&c| c == 1), "{name}: leaf ranges");
    assert!(max_depth < MAX_DEPTH, "{name}: depth {max_depth}");
    let s = bvh.stats;
    assert_eq!(
        (s.triangles, s.nodes, s.leaves, s.max_depth),
        (n, bvh.nodes.len(), leaves, max_depth),
        "{name}"
    );
    assert_eq!(s.nodes, 2 * s.leaves - 1, "{name}");
    println!("{name}: {s:?}");
}

#[test]
fn bvh_nodes_bound_their_children_and_triangles() {
    let mut rng = Rng(42);
    check_structure("soup", &soup(3000, &mut rng));
    check_structure("sphere", &sphere().triangles());
    check_structure("bumpy sphere", &bumpy_sphere(20_000).triangles());
    check_structure("plane", &grid_plane(40, 1.0).triangles());
    let same = [Vec3::ZERO, Vec3::X, Vec3::Y];
    check_structure("one", &[same]);
    check_structure("identical", &vec![same; 777]);
    let mut with_nan = soup(500, &mut rng);
    for (k, t) in with_nan.iter_mut().enumerate().filter(|(k, _)| k % 3 == 0) {
        t[k % 3].y = f32::NAN;
    }
    check_structure("with NaN", &with_nan);
}

#[test]
fn degenerate_meshes_build_and_answer() {
    let mut rng = Rng(7);
    let rays = rays_through_cube(2000, &mut rng);
    // No triangles: one node, nothing hit.
    let empty = Mesh::new(Vec::new());
    assert_eq!(empty.bvh.nodes, vec![BvhNode::EMPTY]);
    assert!(rays.iter().all(|r| empty.cpu(r).is_none()));
    // A zeroed node (a point box at the origin, its own child) neither.
    let zeroed = Bvh {
        nodes: vec![BvhNode {
            min: [0.0; 3],
            a: 0,
            max: [0.0; 3],
            count: 0,
        }],
        permutation: Vec::new(),
        stats: Default::default(),
    };
    for r in &rays {
        assert!(zeroed.intersect(&[], r.origin, -r.origin, T_MAX).is_none());
        assert!(!zeroed.occluded(&[], r.origin, -r.origin, T_MAX));
    }
    // One triangle, and many identical ones: as brute force.
    let big = [
        Vec3::new(-2.0, -1.0, 0.0),
        Vec3::new(2.0, -1.0, 0.3),
        Vec3::Y,
    ];
    check_against_brute_force("one triangle", &Mesh::new(vec![big]), &rays, 50);
    check_against_brute_force("identical", &Mesh::new(vec![big; 100]), &rays, 50);
    // NaN and infinite corners: never hit, and the rest found as before.
    let mut tris = soup(1000, &mut rng);
    let finite = Mesh::new(tris.clone());
    for (k, t) in tris.iter_mut().enumerate().filter(|(k, _)| k % 4 == 0) {
        *t = [Vec3::NAN, Vec3::splat(f32::INFINITY), t[2]];
        if k % 8 == 0 {
            t[2] = Vec3::NAN;
        }
    }
    let broken = Mesh::new(tris.clone());
    for ray in &rays {
        let hit = broken.cpu(ray);
        if let Some(h) = hit {
            let original = broken.bvh.permutation[h.triangle as usize];
            assert!(!original.is_multiple_of(4), "a NaN triangle was hit");
        }
        let expected = finite
            .cpu(ray)
            .filter(|h| !finite.bvh.permutation[h.triangle as usize].is_multiple_of(4));
        if expected.is_some() {
            assert_eq!(hit.map(|h| h.t), expected.map(|h| h.t));
        }
    }
    let all_nan = Mesh::new(vec![[Vec3::NAN; 3]; 50]);
    assert!(rays.iter().all(|r| all_nan.cpu(r).is_none()));
}

// ---- watertightness ---------------------------------------------------

/// The edges two triangles share (as vertex index pairs) and the vertices
/// in them.
fn shared_edges(mesh: &IndexedMesh) -> Vec<(u32, u32)> {
    let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &mesh.indices {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut edges: Vec<_> = uses.into_iter().filter(|&(_, u)| u == 2).collect();
    edges.sort_unstable();
    edges.into_iter().map(|(e, _)| e).collect()
}

/// A ray aimed at a point of a mesh, and how far away it starts.
struct AimedRay {
    ray: Ray,
    distance: f32,
}

/// Rays aimed exactly at shared vertices (even k) and at points of shared
/// edges (odd k; the point rounded to f32 as a renderer's would be), from
/// `approach(rng, target)`: a unit vector pointing from the target to the
/// ray's origin, which lies 0.5 to 1000 units away (log-uniform).
fn aimed_rays(
    mesh: &IndexedMesh,
    eligible: impl Fn(Vec3) -> bool,
    n: usize,
    rng: &mut Rng,
    approach: impl Fn(&mut Rng, Vec3) -> Vec3,
) -> Vec<AimedRay> {
    let edges: Vec<_> = shared_edges(mesh)
        .into_iter()
        .filter(|&(a, b)| {
            eligible(mesh.positions[a as usize]) && eligible(mesh.positions[b as usize])
        })
        .collect();
    let mut vertices: Vec<u32> = edges.iter().flat_map(|&(a, b)| [a, b]).collect();
    vertices.sort_unstable();
    vertices.dedup();
    (0..n)
        .map(|k| {
            let target = if k % 2 == 0 {
                mesh.positions[vertices[rng.index(vertices.len())] as usize]
            } else {
                let (a, b) = edges[rng.index(edges.len())];
                let (a, b) = (mesh.positions[a as usize], mesh.positions[b as usize]);
                a + (b - a) * rng.range(0.01, 0.99)
            };
            let distance = 0.5 * 2000f32.powf(rng.next());
            let origin = target + approach(rng, target) * distance;
            AimedRay {
                ray: Ray {
                    origin,
                    direction: (target - origin).normalize(),
                    t_max: T_MAX,
                },
                distance,
            }
        })
        .collect()
}

/// The plane y = 0 ([-1, 1]², 16 × 16 quads), at points within 0.75 of its
/// centre (so a grazing ray's rounding cannot carry it off the edge), from
/// above: a third grazing (0.06° to 2°), the rest up to the zenith.
fn plane_rays(n: usize, rng: &mut Rng) -> (IndexedMesh, Vec<AimedRay>) {
    let plane = grid_plane(16, 1.0);
    let eligible = |p: Vec3| p.x.abs() <= 0.75 && p.z.abs() <= 0.75;
    let rays = aimed_rays(&plane, eligible, n, rng, |rng, _| {
        let elevation = if rng.next() < 1.0 / 3.0 {
            1.0e-3 * 35f32.powf(rng.next())
        } else {
            rng.range(0.035, std::f32::consts::FRAC_PI_2)
        };
        let azimuth = rng.range(0.0, std::f32::consts::TAU);
        Vec3::new(
            elevation.cos() * azimuth.cos(),
            elevation.sin(),
            elevation.cos() * azimuth.sin(),
        )
    });
    (plane, rays)
}

/// The unit UV sphere (24 rings, 48 segments), anywhere including the
/// poles, from outside: the approach makes at least 0.2 with the sphere's
/// normal there, so it also does with every face around the point (faces
/// lean at most 7.5°), and the first hit is the point itself.
fn sphere_rays(n: usize, rng: &mut Rng) -> (IndexedMesh, Vec<AimedRay>) {
    let sphere = sphere();
    let rays = aimed_rays(
        &sphere,
        |_| true,
        n,
        rng,
        |rng, target| {
            let normal = target.normalize();
            loop {
                let u = rng.unit_vector();
                if u.dot(normal) >= 0.2 {
                    return u;
                }
            }
        },
    );
    (sphere, rays)
}

/// Naive Möller–Trumbore (1997): each triangle's barycentrics from its own
/// first vertex and edges, so neighbours round a shared edge differently.
fn moller_trumbore(o: Vec3, d: Vec3, [v0, v1, v2]: [Vec3; 3]) -> Option<f32> {
    let (e1, e2) = (v1 - v0, v2 - v0);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0).then_some(t)
}

/// A hit, near the point aimed at (the first surface on the way).
fn check_aimed_hit(name: &str, aimed: &AimedRay, t: Option<f32>) -> bool {
    let Some(t) = t else {
        return false;
    };
    let error = (t - aimed.distance).abs() / aimed.distance;
    assert!(
        error < 1e-3,
        "{name}: hit at {t}, aimed {} away",
        aimed.distance
    );
    true
}

const AIMED_RAYS: usize = 2000;

/// Zero misses on the CPU, by brute force over the triangle test and
/// through the BVH, where Möller–Trumbore misses some of the same rays (or
/// only hits what lies behind the point aimed at).
#[test]
fn rays_at_shared_edges_and_vertices_never_slip_through_on_the_cpu() {
    let mut rng = Rng(0xfeed_beef);
    for (name, (mesh, rays)) in [
        ("plane", plane_rays(AIMED_RAYS, &mut rng)),
        ("sphere", sphere_rays(AIMED_RAYS, &mut rng)),
    ] {
        let tris = mesh.triangles();
        let bvh_mesh = Mesh::new(tris.clone());
        let mut naive_misses = 0;
        for aimed in &rays {
            let ray = &aimed.ray;
            let brute = brute_force(&tris, ray).map(|(_, h)| h.t);
            assert!(
                check_aimed_hit(name, aimed, brute),
                "{name}: the triangle test let {ray:?} through"
            );
            let through_bvh = bvh_mesh.cpu(ray).map(|h| h.t);
            assert!(
                check_aimed_hit(name, aimed, through_bvh),
                "{name}: the BVH let {ray:?} through"
            );
            // Through the crack, a ray may still hit the sphere's far side.
            let naive = tris.iter().any(|t| {
                moller_trumbore(ray.origin, ray.direction, *t)
                    .is_some_and(|t| (t - aimed.distance).abs() < 1e-3 * aimed.distance)
            });
            naive_misses += usize::from(!naive);
        }
        println!(
            "{name}: 0 of {} rays missed; naive Möller–Trumbore missed {naive_misses}",
            rays.len()
        );
        assert!(
            naive_misses > 0,
            "{name}: the rays are too easy to show anything"
        );
    }
}

#[test]
fn rays_at_shared_edges_and_vertices_never_slip_through_on_the_gpu() {
    let Some(ctx) = gpu_or_skip("rays_at_shared_edges_and_vertices_never_slip_through_on_the_gpu")
    else {
        return;
    };
    let mut rng = Rng(0xfeed_beef);
    for (name, (mesh, rays)) in [
        ("plane", plane_rays(AIMED_RAYS, &mut rng)),
        ("sphere", sphere_rays(AIMED_RAYS, &mut rng)),
    ] {
        let mesh = Mesh::new(mesh.triangles());
        let harness = mesh.harness(&ctx);
        let plain: Vec<Ray> = rays.iter().map(|a| a.ray).collect();
        let hits = harness.closest(&ctx, &plain).unwrap();
        let occluded = harness.occluded(&ctx, &plain).unwrap();
        let mut misses = Vec::new();
        for ((aimed, hit), occluded) in rays.iter().zip(&hits).zip(&occluded) {
            if !check_aimed_hit(name, aimed, hit.map(|h| h.t)) || !occluded {
                misses.push(aimed.ray);
            }
        }
        println!(
            "{name}: {} of {} rays missed on {}",
            misses.len(),
            rays.len(),
            ctx.describe()
        );
        assert!(misses.is_empty(), "{name}: slipped through: {misses:?}");
    }
}

// ---- GPU against CPU ----------------------------------------------------

/// The GPU's closest hits against the CPU traversal's: hit or miss alike,
/// t within 1e-5 (relative), the same triangle unless the CPU sees the
/// GPU's within 1e-5 of its own distance, barycentrics within 1e-4; and
/// any-hit queries alike.
fn check_parity(ctx: &GpuContext, name: &str, mesh: &Mesh, rays: &[Ray], min_hits: usize) {
    let harness = mesh.harness(ctx);
    let gpu = harness.closest(ctx, rays).unwrap();
    let occluded = harness.occluded(ctx, rays).unwrap();
    let (mut hits, mut ties) = (0, 0);
    for ((ray, g), occ) in rays.iter().zip(&gpu).zip(&occluded) {
        let c = mesh.cpu(ray);
        assert_eq!(*occ, c.is_some(), "{name}: occluded for {ray:?}");
        let (g, c) = match (g, c) {
            (None, None) => continue,
            (Some(g), Some(c)) => (g, c),
            _ => panic!("{name}: GPU {g:?}, CPU {c:?} for {ray:?}"),
        };
        hits += 1;
        let close = |a: f32, b: f32| (a - b).abs() <= 1e-5 * b.abs().max(1e-3);
        assert!(close(g.t, c.t), "{name}: GPU {g:?}, CPU {c:?} for {ray:?}");
        if g.triangle == c.triangle {
            assert!(
                (g.b1 - c.b1).abs() < 1e-4 && (g.b2 - c.b2).abs() < 1e-4,
                "{name}: GPU {g:?}, CPU {c:?}"
            );
        } else {
            ties += 1;
            let tri = mesh.ordered[g.triangle as usize];
            let other = intersect(ray.origin, ray.direction, tri, T_MAX);
            assert!(
                other.is_some_and(|h| close(h.t, c.t)),
                "{name}: GPU {g:?}, CPU {c:?} ({other:?}) for {ray:?}"
            );
        }
    }
    println!(
        "{name}: {hits} of {} rays hit; {ties} ties between triangles",
        rays.len()
    );
    assert!(hits >= min_hits, "{name}: too few hits ({hits})");
}

#[test]
fn gpu_traversal_matches_the_cpu() {
    let Some(ctx) = gpu_or_skip("gpu_traversal_matches_the_cpu") else {
        return;
    };
    let mut rng = Rng(0x5eed);
    let soup = Mesh::new(soup(3000, &mut rng));
    check_parity(
        &ctx,
        "soup",
        &soup,
        &rays_through_cube(RAYS, &mut rng),
        RAYS / 4,
    );
    let sphere = Mesh::new(sphere().triangles());
    check_parity(
        &ctx,
        "sphere",
        &sphere,
        &rays_at_sphere(RAYS, &mut rng),
        RAYS / 2,
    );
    let bumpy = Mesh::new(bumpy_sphere(50_000).triangles());
    check_parity(
        &ctx,
        "bumpy sphere",
        &bumpy,
        &rays_at_sphere(RAYS, &mut rng),
        RAYS / 2,
    );
}

/// No triangles, one, and NaN ones, on the GPU: no hangs, no hits where
/// there is nothing to hit.
#[test]
fn gpu_traversal_of_degenerate_meshes() {
    let Some(ctx) = gpu_or_skip("gpu_traversal_of_degenerate_meshes") else {
        return;
    };
    let mut rng = Rng(99);
    let mut rays = rays_through_cube(1000, &mut rng);
    // Axis-aligned rays and a zero direction too.
    for d in [Vec3::X, Vec3::NEG_Y, Vec3::Z, Vec3::ZERO] {
        rays.push(Ray {
            origin: Vec3::new(0.1, 0.2, -3.0 * d.z),
            direction: d,
            t_max: T_MAX,
        });
    }
    let empty = Mesh::new(Vec::new());
    // Also a zeroed node, as a placeholder buffer holds: a point box at the
    // origin whose children would be itself. Rays through the origin too.
    let zeroed = [BvhNode {
        min: [0.0; 3],
        a: 0,
        max: [0.0; 3],
        count: 0,
    }];
    let mut through_origin = rays.clone();
    through_origin.extend(rays.iter().map(|r| Ray {
        direction: -r.origin,
        ..*r
    }));
    for nodes in [&empty.bvh.nodes[..], &zeroed] {
        let harness = BvhHarness::new(&ctx, nodes, &[]).unwrap();
        let hits = harness.closest(&ctx, &through_origin).unwrap();
        assert!(hits.iter().all(Option::is_none));
        let occluded = harness.occluded(&ctx, &through_origin).unwrap();
        assert!(!occluded.iter().any(|&o| o));
    }
    let big = [
        Vec3::new(-2.0, -1.0, 0.0),
        Vec3::new(2.0, -1.0, 0.3),
        Vec3::Y,
    ];
    check_parity(&ctx, "one triangle", &Mesh::new(vec![big]), &rays, 50);
    let mut tris = soup(1000, &mut rng);
    for t in tris.iter_mut().step_by(3) {
        t[1] = Vec3::NAN;
    }
    let broken = Mesh::new(tris);
    let hits = broken.harness(&ctx).closest(&ctx, &rays).unwrap();
    for (ray, hit) in rays.iter().zip(hits) {
        let cpu = broken.cpu(ray);
        assert_eq!(hit.map(|h| h.triangle), cpu.map(|h| h.triangle), "{ray:?}");
        if let Some(h) = hit {
            let original = broken.bvh.permutation[h.triangle as usize];
            assert!(!original.is_multiple_of(3), "a NaN triangle was hit");
        }
    }
}

// ---- edge-on (issue 6, case 11) ------------------------------------------

/// Rays that see the UV sphere edge-on along its shared edges: each lies in
/// the plane through a shared edge and the sphere's normal at the point it
/// is aimed at (a vertex of the edge, or a point of it), so the edge
/// projects onto the ray's own pixel and, in exact arithmetic, the ray runs
/// along the boundary between the two triangles for its whole length. It
/// comes from 11° to 90° above the tangent plane (faces lean at most 7.5°
/// from it, so the first hit is the point aimed at), from either way along
/// the edge, 0.5 to 1000 units away.
fn edge_on_sphere_rays(n: usize, rng: &mut Rng) -> (IndexedMesh, Vec<AimedRay>) {
    let sphere = sphere();
    let edges = shared_edges(&sphere);
    let rays = (0..n)
        .map(|k| {
            let (a, b) = edges[rng.index(edges.len())];
            let (a, b) = (sphere.positions[a as usize], sphere.positions[b as usize]);
            let target = if k % 2 == 0 {
                a
            } else {
                a + (b - a) * rng.range(0.01, 0.99)
            };
            let normal = target.normalize();
            let along = (b - a) - normal * (b - a).dot(normal);
            let along = along.normalize() * if rng.next() < 0.5 { 1.0 } else { -1.0 };
            let elevation = rng.range(0.2, std::f32::consts::FRAC_PI_2);
            let approach = normal * elevation.sin() + along * elevation.cos();
            let distance = 0.5 * 2000f32.powf(rng.next());
            let origin = target + approach * distance;
            AimedRay {
                ray: Ray {
                    origin,
                    direction: (target - origin).normalize(),
                    t_max: T_MAX,
                },
                distance,
            }
        })
        .collect();
    (sphere, rays)
}

/// Issue 6, case 11: 1,000 rays along shared edges of a closed tessellated
/// sphere, at its vertices and edges, all hit it where aimed, by brute
/// force and through the BVH on the CPU, and through accel/traverse.wgsl on the GPU
/// (closest and any hit). The naive Möller–Trumbore test's misses are
/// printed for contrast.
#[test]
fn a_sphere_seen_edge_on_along_its_shared_edges_has_no_cracks() {
    let mut rng = Rng(0xed9e_0011);
    let (mesh, rays) = edge_on_sphere_rays(1000, &mut rng);
    let tris = mesh.triangles();
    let bvh_mesh = Mesh::new(tris.clone());
    let mut naive_misses = 0;
    for aimed in &rays {
        let ray = &aimed.ray;
        let brute = brute_force(&tris, ray).map(|(_, h)| h.t);
        assert!(
            check_aimed_hit("edge-on", aimed, brute),
            "the triangle test let {ray:?} through"
        );
        let through_bvh = bvh_mesh.cpu(ray).map(|h| h.t);
        assert!(
            check_aimed_hit("edge-on", aimed, through_bvh),
            "the BVH let {ray:?} through"
        );
        let naive = tris.iter().any(|t| {
            moller_trumbore(ray.origin, ray.direction, *t)
                .is_some_and(|t| (t - aimed.distance).abs() < 1e-3 * aimed.distance)
        });
        naive_misses += usize::from(!naive);
    }
    println!(
        "edge-on: 0 of {} rays missed on the CPU; naive Möller–Trumbore missed {naive_misses}",
        rays.len()
    );
    assert!(naive_misses > 0, "the rays are too easy to show anything");
    let Some(ctx) = gpu_or_skip("a_sphere_seen_edge_on_along_its_shared_edges_has_no_cracks")
    else {
        return;
    };
    let harness = bvh_mesh.harness(&ctx);
    let plain: Vec<Ray> = rays.iter().map(|a| a.ray).collect();
    let hits = harness.closest(&ctx, &plain).unwrap();
    let occluded = harness.occluded(&ctx, &plain).unwrap();
    for ((aimed, hit), occluded) in rays.iter().zip(&hits).zip(&occluded) {
        let t = hit.map(|h| h.t);
        assert!(t.is_none_or(f32::is_finite), "{:?}", aimed.ray);
        assert!(
            check_aimed_hit("edge-on (GPU)", aimed, t) && *occluded,
            "the GPU let {:?} through",
            aimed.ray
        );
    }
}

// ---- property tests (issue 6) ----------------------------------------------

/// A vertex in [-2, 2]³ on a grid of 1/8, so that soups share vertices,
/// edges and planes exactly and hold ties and degenerate triangles.
fn grid_vertex() -> impl Strategy<Value = Vec3> {
    [-16i32..=16, -16i32..=16, -16i32..=16]
        .prop_map(|c| Vec3::from_array(c.map(|k| k as f32 / 8.0)))
}

/// Triangle soups of 1 to 120 triangles: random ones, some on the grid
/// (shared edges, duplicates), some with repeated vertices (zero area).
fn triangle_soup() -> impl Strategy<Value = Vec<[Vec3; 3]>> {
    let free = [-2.0f32..2.0, -2.0f32..2.0, -2.0f32..2.0].prop_map(Vec3::from_array);
    let vertex = prop_oneof![free, grid_vertex()];
    let triangle = prop_oneof![
        6 => [vertex.clone(), vertex.clone(), vertex.clone()],
        1 => (vertex.clone(), vertex).prop_map(|(a, b)| [a, b, a]),
    ];
    proptest::collection::vec(triangle, 1..120)
}

/// Rays from [-3, 3]³, half aimed at a soup's vertex (where neighbours
/// meet), half in any direction, of any length from 0.1 to 10.
fn ray_strategy() -> impl Strategy<Value = (Vec3, Vec3, bool, f32)> {
    (
        [-3.0f32..3.0, -3.0f32..3.0, -3.0f32..3.0].prop_map(Vec3::from_array),
        [-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0].prop_map(Vec3::from_array),
        any::<bool>(),
        0.1f32..10.0,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Closest hits through the BVH equal brute force (distance to the bit,
    /// the same triangle unless tied), any-hit queries agree, every
    /// triangle lies in exactly one leaf, and every node bounds its
    /// children and triangles.
    #[test]
    fn bvh_equals_brute_force_and_bounds_its_leaves(
        soup in triangle_soup(),
        rays in proptest::collection::vec(ray_strategy(), 64),
    ) {
        check_structure("proptest soup", &soup);
        let rays: Vec<Ray> = rays
            .iter()
            .enumerate()
            .map(|(k, &(origin, direction, aimed, length))| {
                let direction = if aimed {
                    soup[k % soup.len()][k % 3] - origin
                } else {
                    direction
                };
                Ray { origin, direction: direction * length, t_max: T_MAX }
            })
            .collect();
        check_against_brute_force("proptest soup", &Mesh::new(soup), &rays, 0);
    }
}
