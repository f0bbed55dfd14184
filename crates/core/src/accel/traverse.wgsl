// Triangle meshes: the watertight ray-triangle test (Woop, Benthin and
// Wald, "Watertight Ray/Triangle Intersection", JCGT 2013) and the walk of
// the BVH built by bvh.rs. traverse.rs is its CPU twin: `SlabRay` and
// `slab_ray_new`, `_entry`, `_intersect`, `_occluded` are its `SlabRay`
// and its methods (the WGSL ray also holds the watertight test's shear).
//
// The including program declares, at bindings of its choosing:
//
//   var<storage, read> bvh_nodes: array<BvhNode>;
//   var<storage, read> mesh_triangles: array<TriangleVerts>;
//
// and `const NO_HIT: f32` (intersect.wgsl). Triangles are in the BVH's order
// (Bvh::reorder); a hit's `triangle` indexes mesh_triangles.
//
// Nodes: a node with count > 0 is a leaf of the triangles a .. a + count; a
// node with count == 0 is interior, its children bvh_nodes[a] and
// bvh_nodes[a + 1]. The root is bvh_nodes[0]; its box is tested first, and
// the mesh of no triangles is one node whose box (inverted, min > max)
// rejects every ray. A root of count 0 and a 0 (that node, or a zeroed
// placeholder buffer, whose "children" would be itself) is never walked.
// Leaves are at most 63 deep, so BVH_STACK_SIZE entries always suffice
// (accel::bvh::MAX_DEPTH).
//
// Shaped for lanes in lock step (llvmpipe runs every branch under a mask):
// nodes and triangles are read from the storage arrays in place, the ray's
// constants are computed once, and bool operators are the non-short-circuit
// `&`, `|`, so the tests are straight-line code. On lavapipe (Mesa 22.3) the
// reads bound the speed, not the arithmetic: a storage read whose index
// differs between lanes becomes a loop over the 8 lanes, one scalar load per
// component and lane, each inserted into the vector through memory. A step
// down the tree reads 14 components (two child boxes, then the next node's
// a and count), a triangle 9.

#import crates/core/src/geometry/sphere.wgsl

struct BvhNode {
    min: vec3f,
    a: u32,       // leaf: first triangle; interior: left child (right is a + 1)
    max: vec3f,
    count: u32,   // leaf: triangles (> 0); interior: 0
}

// One triangle's corners; w is unused.
struct TriangleVerts {
    v0: vec4f,
    v1: vec4f,
    v2: vec4f,
}

// The closest hit: t along the ray's direction (not necessarily unit), the
// triangle's index in mesh_triangles, and the barycentric weights of v1 and
// v2 (v0's is 1 - b1 - b2). No hit: t = NO_HIT, triangle = NO_TRIANGLE.
struct MeshHit {
    t: f32,
    triangle: u32,
    b1: f32,
    b2: f32,
}

const NO_TRIANGLE: u32 = 0xffffffffu;
const BVH_STACK_SIZE: u32 = 64u;
// A direction component at most 2^-40 of the largest counts as zero: that
// axis does not cull (conservative), and 1/d stays finite, since WGSL lets
// compilers assume there are no infinities or NaNs (no 0 * inf).
const SLAB_PARALLEL: f32 = 9.094947e-13;
const SLAB_PAD: f32 = 1.0e30;
// 1 + 16 ulp(1): stretches the exit distance beyond the rounding of
// (bound - origin) * (1/d) on both sides (Ize, "Robust BVH Ray Traversal",
// JCGT 2013: 1 + 2 gamma_3 for correctly rounded division; a GPU's may be
// 2.5 ulp), so a ray through a face, an edge or a flat box is never culled.
const SLAB_INFLATE: f32 = 1.0000019;
const BOX_MISS: f32 = 3.4e38;

// What the tests need of a ray, computed once per traversal.
struct SlabRay {
    o: vec3f,
    inv: vec3f,           // 1/d, 0 on parallel axes
    pad: vec3f,           // SLAB_PAD on parallel axes, else 0
    negative: vec3<bool>, // the slab is entered by its max plane
    // Woop et al.'s transform as a matrix: (v - o) * shear is the vertex in
    // the frame where the ray runs along +z (x - Sx z, y - Sy z, Sz z after
    // permuting the axes so that z is d's largest). A matrix instead of
    // indexing by kx, ky, kz keeps the per-triangle work free of dynamic
    // indices; the zero entries add exact zeros, so the numbers are the
    // paper's.
    shear: mat3x3f,
}

fn mesh_unit(k: u32) -> vec3f {
    return vec3f(select(0.0, 1.0, k == 0u), select(0.0, 1.0, k == 1u), select(0.0, 1.0, k == 2u));
}

fn slab_ray_new(o: vec3f, d: vec3f) -> SlabRay {
    let a = abs(d);
    let kz = select(select(2u, 1u, a.y >= a.z), 0u, a.x >= a.y && a.x >= a.z);
    let flip = d[kz] < 0.0;
    // kx, ky: the next two axes, swapped when d[kz] < 0 (keeps the winding).
    let kx = select((kz + 1u) % 3u, (kz + 2u) % 3u, flip);
    let ky = select((kz + 2u) % 3u, (kz + 1u) % 3u, flip);
    // (A zero direction, whose dz is 0, is turned away by the callers.)
    let dz = select(d[kz], 1.0, d[kz] == 0.0);
    let sx = d[kx] / dz;
    let sy = d[ky] / dz;
    let sz = 1.0 / dz;
    let ez = mesh_unit(kz);
    var r: SlabRay;
    r.o = o;
    r.shear = mat3x3f(mesh_unit(kx) - sx * ez, mesh_unit(ky) - sy * ez, sz * ez);
    let largest = max(max(a.x, a.y), a.z);
    let parallel = a <= vec3f(SLAB_PARALLEL * largest);
    r.inv = select(1.0 / select(d, vec3f(1.0), parallel), vec3f(0.0), parallel);
    r.pad = select(vec3f(0.0), vec3f(SLAB_PAD), parallel);
    r.negative = d < vec3f(0.0);
    return r;
}

// The edge function of the edge p -> q in the sheared plane: the 2D cross
// product, written as its difference with the reversed edge's. Without
// contraction into fused multiply-adds that is exactly twice the paper's
// value. With it (WGSL lets compilers fuse a * b - c * d), the paper's form
// would give a neighbour's reversed edge a value that is not exactly the
// negation, and a ray could slip between them; this form is antisymmetric
// whatever is fused: mesh_edge(q, p) == -mesh_edge(p, q).
fn mesh_edge(p: vec2f, q: vec2f) -> f32 {
    return (q.x * p.y - q.y * p.x) - (p.x * q.y - p.y * q.x);
}

// (t, b1, b2) of the ray's hit with triangle `index` for t in (0, t_max),
// or t = NO_HIT.
//
// Watertight up to one caveat: the paper recomputes an edge function that
// rounds to exactly 0 in double precision, which WGSL lacks. Here a zero
// counts as inside for both triangles of its edge, so a ray through an
// edge or vertex still hits at least one of them; what is lost is only the
// arbitration between them (both may report the hit), and a triangle whose
// three edge functions all underflow to zero (vertices within ~1e-19 of the
// ray) is missed. A fused multiply-add's different rounding can, in
// principle, also flip the sign of an edge function within an ulp of zero;
// each edge is still seen the same way by both of its triangles.
fn mesh_triangle(r: SlabRay, index: u32, t_max: f32) -> vec3f {
    let a = (mesh_triangles[index].v0.xyz - r.o) * r.shear;
    let b = (mesh_triangles[index].v1.xyz - r.o) * r.shear;
    let c = (mesh_triangles[index].v2.xyz - r.o) * r.shear;
    let u = mesh_edge(b.xy, c.xy); // weight of v0
    let v = mesh_edge(c.xy, a.xy); // weight of v1
    let w = mesh_edge(a.xy, b.xy); // weight of v2
    let mixed = (u < 0.0 | v < 0.0 | w < 0.0) & (u > 0.0 | v > 0.0 | w > 0.0);
    let det = u + v + w;
    let inv_det = 1.0 / select(det, 1.0, det == 0.0);
    let t = (u * a.z + v * b.z + w * c.z) * inv_det;
    let hit = !mixed & det != 0.0 & t > 0.0 & t < t_max;
    return select(vec3f(NO_HIT, 0.0, 0.0), vec3f(t, v * inv_det, w * inv_det), hit);
}

// Whether the ray may meet anything at all: a non-zero direction, a root
// that is not the empty hierarchy (count 0, a 0), and the root's box.
fn mesh_worth_walking(r: SlabRay, d: vec3f, t_far: f32) -> bool {
    let empty = bvh_nodes[0].count == 0u & bvh_nodes[0].a == 0u;
    return !(empty | all(d == vec3f(0.0))) & slab_ray_entry(r, 0u, t_far) < BOX_MISS;
}

// Where the ray enters node `index`'s box (clamped to 0), or BOX_MISS when
// it does not before t_far. Near and far planes are picked by the
// direction's sign, not by min/max of the two distances, so an inverted
// (empty) box is rejected.
fn slab_ray_entry(r: SlabRay, index: u32, t_far: f32) -> f32 {
    let lo = bvh_nodes[index].min;
    let hi = bvh_nodes[index].max;
    let t_near = (select(lo, hi, r.negative) - r.o) * r.inv - r.pad;
    let t_exit = (select(hi, lo, r.negative) - r.o) * r.inv + r.pad;
    let enter = max(max(max(t_near.x, t_near.y), t_near.z), 0.0);
    let exit = min(min(min(t_exit.x, t_exit.y), t_exit.z), t_far) * SLAB_INFLATE;
    return select(BOX_MISS, enter, enter <= exit);
}

// The closest hit with t in (0, t_max) (t_max above NO_HIT counts as
// NO_HIT), or t = NO_HIT and triangle = NO_TRIANGLE.
//
// "While-while" (Aila and Laine, "Understanding the Efficiency of Ray
// Traversal on GPUs", 2009): an inner loop walks interior nodes until the
// lane holds a leaf, then the leaf's triangles are tested. Lanes in lock
// step wait for each other at the end of each inner loop, so they test
// triangles together rather than each iteration paying, under a mask, for
// both a node step and a leaf.
fn slab_ray_intersect(o: vec3f, d: vec3f, t_max: f32) -> MeshHit {
    var hit = MeshHit(NO_HIT, NO_TRIANGLE, 0.0, 0.0);
    let r = slab_ray_new(o, d);
    var t_far = min(t_max, NO_HIT);
    if !mesh_worth_walking(r, d, t_far) {
        return hit;
    }
    var stack: array<u32, BVH_STACK_SIZE>;
    var sp = 0u;
    var node = 0u;
    loop {
        var a = bvh_nodes[node].a;
        var count = bvh_nodes[node].count;
        while count == 0u {
            let tl = slab_ray_entry(r, a, t_far);
            let tr = slab_ray_entry(r, a + 1u, t_far);
            // Near child first; the other waits on the stack. A missed
            // child's BOX_MISS sorts last.
            let right_first = tr < tl;
            if max(tl, tr) < BOX_MISS {
                stack[sp] = select(a + 1u, a, right_first);
                sp += 1u;
            }
            if min(tl, tr) < BOX_MISS {
                node = select(a, a + 1u, right_first);
            } else {
                if sp == 0u {
                    return hit;
                }
                sp -= 1u;
                node = stack[sp];
            }
            a = bvh_nodes[node].a;
            count = bvh_nodes[node].count;
        }
        for (var i = a; i < a + count; i++) {
            let h = mesh_triangle(r, i, t_far);
            if h.x < t_far {
                t_far = h.x;
                hit = MeshHit(h.x, i, h.y, h.z);
            }
        }
        if sp == 0u {
            return hit;
        }
        sp -= 1u;
        node = stack[sp];
    }
    return hit;
}

// Whether any triangle is hit with t in (0, t_max): for shadow rays. The
// same walk, stopping at the first hit. Near children first too: in a
// closed mesh the near side is where a hit is likeliest.
fn slab_ray_occluded(o: vec3f, d: vec3f, t_max: f32) -> bool {
    let r = slab_ray_new(o, d);
    let t_far = min(t_max, NO_HIT);
    if !mesh_worth_walking(r, d, t_far) {
        return false;
    }
    var stack: array<u32, BVH_STACK_SIZE>;
    var sp = 0u;
    var node = 0u;
    loop {
        var a = bvh_nodes[node].a;
        var count = bvh_nodes[node].count;
        while count == 0u {
            let tl = slab_ray_entry(r, a, t_far);
            let tr = slab_ray_entry(r, a + 1u, t_far);
            let right_first = tr < tl;
            if max(tl, tr) < BOX_MISS {
                stack[sp] = select(a + 1u, a, right_first);
                sp += 1u;
            }
            if min(tl, tr) < BOX_MISS {
                node = select(a, a + 1u, right_first);
            } else {
                if sp == 0u {
                    return false;
                }
                sp -= 1u;
                node = stack[sp];
            }
            a = bvh_nodes[node].a;
            count = bvh_nodes[node].count;
        }
        for (var i = a; i < a + count; i++) {
            if mesh_triangle(r, i, t_far).x < t_far {
                return true;
            }
        }
        if sp == 0u {
            return false;
        }
        sp -= 1u;
        node = stack[sp];
    }
    return false;
}
