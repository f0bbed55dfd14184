//! The BVH collapsed to four children a node, for the CPU: a ray tests
//! the four boxes at once in SIMD lanes (`Vec4`), as Embree and pbrt's CPU
//! renderers do, instead of two at a time with a step down the tree per
//! pair. Built from the binary [`Bvh`] the GPU walks (each node takes the
//! children of its largest interior child until it has four), so the
//! triangles, their order and the leaves are the same; the slab and
//! triangle tests are the binary walk's (`traverse.rs`), lane by lane, so
//! a ray meets the same triangles at the same distances. Only which of two
//! triangles at exactly the same distance is reported may differ (the
//! visiting order is the wide nodes'). The CPU kernel's traversal.

use super::bvh::{Bvh, BvhNode};
use super::traverse::{MeshHit, SLAB_INFLATE, SLAB_PAD, SLAB_PARALLEL};
use super::triangle::WatertightRay;
use glam::{Vec3, Vec4};
use std::mem::MaybeUninit;

/// Four children's boxes in lanes, and what each child is.
#[derive(Debug, Clone, Copy)]
pub struct WideNode {
    /// `lo[axis]` and `hi[axis]`: the four boxes' lower and upper planes.
    lo: [Vec4; 3],
    hi: [Vec4; 3],
    /// A leaf's first triangle, or an interior child's node index.
    first: [u32; 4],
    /// A leaf's triangles; 0 for an interior child or an empty slot
    /// (whose box is the inverted empty box, which no ray enters).
    count: [u32; 4],
}

/// A BVH of [`WideNode`]s; the root is `nodes[0]`.
#[derive(Debug, Clone, Default)]
pub struct WideBvh {
    nodes: Vec<WideNode>,
}

/// The most children a node holds.
const WIDTH: usize = 4;
/// Entries a walk's stack can hold: three pushed per level of at most
/// [`super::bvh::MAX_DEPTH`] binary levels, with room to spare.
const STACK: usize = 3 * super::bvh::MAX_DEPTH + WIDTH;

impl WideBvh {
    /// The wide form of `bvh` (which must be non-empty to hold nodes).
    pub fn build(bvh: &Bvh) -> Self {
        let mut out = WideBvh { nodes: Vec::new() };
        let root = bvh.nodes[0];
        if bvh.nodes.is_empty() || (root.count == 0 && root.a == 0) {
            return out;
        }
        out.collapse(bvh, &[root]);
        out
    }

    /// Appends the wide node holding `children` (binary nodes) and,
    /// depth first, the nodes below it; returns its index.
    fn collapse(&mut self, bvh: &Bvh, children: &[BvhNode]) -> u32 {
        let mut slots: Vec<BvhNode> = children.to_vec();
        // Open the interior child of largest surface until there are four.
        while slots.len() < WIDTH {
            let open = slots
                .iter()
                .enumerate()
                .filter(|(_, n)| !n.is_leaf())
                .max_by(|(_, a), (_, b)| a.bounds().area().total_cmp(&b.bounds().area()))
                .map(|(i, _)| i);
            let Some(i) = open else { break };
            let n = slots.remove(i);
            slots.insert(i, bvh.nodes[n.a as usize + 1]);
            slots.insert(i, bvh.nodes[n.a as usize]);
        }
        let index = self.nodes.len();
        let empty = BvhNode::EMPTY;
        let mut node = WideNode {
            lo: [Vec4::ZERO; 3],
            hi: [Vec4::ZERO; 3],
            first: [0; WIDTH],
            count: [0; WIDTH],
        };
        for lane in 0..WIDTH {
            let n = slots.get(lane).unwrap_or(&empty);
            for axis in 0..3 {
                node.lo[axis][lane] = n.min[axis];
                node.hi[axis][lane] = n.max[axis];
            }
            node.count[lane] = n.count;
        }
        self.nodes.push(node);
        for (lane, n) in slots.iter().enumerate() {
            self.nodes[index].first[lane] = if n.is_leaf() {
                n.a
            } else {
                self.collapse(bvh, &[bvh.nodes[n.a as usize], bvh.nodes[n.a as usize + 1]])
            };
        }
        index as u32
    }

    /// The closest hit with t in (0, `t_max`) among `triangles` (in the
    /// BVH's order), as [`Bvh::intersect`] finds it.
    #[inline]
    pub fn intersect(
        &self,
        triangles: &[[Vec3; 3]],
        origin: Vec3,
        direction: Vec3,
        t_max: f32,
    ) -> Option<MeshHit> {
        let mut closest = None;
        self.walk(origin, direction, t_max, |i, ray, t_far| {
            let h = ray.intersect(&triangles[i as usize], t_far)?;
            closest = Some(MeshHit {
                t: h.t,
                triangle: i,
                b1: h.b1,
                b2: h.b2,
            });
            Some(Visit::Shorten(h.t))
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
        self.walk(origin, direction, t_max, |i, ray, t_far| {
            ray.intersect(&triangles[i as usize], t_far)?;
            hit = true;
            Some(Visit::Stop)
        });
        hit
    }

    /// Visits the leaves the ray enters, nearest box first, handing each
    /// triangle to `test` with the current far bound.
    #[inline]
    fn walk(
        &self,
        origin: Vec3,
        direction: Vec3,
        t_max: f32,
        mut test: impl FnMut(u32, &WatertightRay, f32) -> Option<Visit>,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let Some(tri_ray) = WatertightRay::new(origin, direction) else {
            return;
        };
        let slab = WideRay::new(origin, direction);
        let mut t_far = t_max;
        // Entries: (first, count): a leaf's triangles, or with count 0 a
        // node; each with the distance its box was entered at.
        // Left uninitialised: zeroing its 2 KiB was 5 % of the CPU
        // kernel's time. Only entries below `sp` are read, and each was
        // written when it was pushed.
        let mut stack = [const { MaybeUninit::<Entry>::uninit() }; STACK];
        stack[0].write((0, 0, 0.0));
        let mut sp = 1;
        // SAFETY (each `assume_init_read`): `i < sp`, and every entry below
        // `sp` was written by a push or by the insertion that moved it.
        let read = |stack: &[MaybeUninit<Entry>], i: usize| unsafe { stack[i].assume_init_read() };
        while sp > 0 {
            sp -= 1;
            let (first, count, enter) = read(&stack, sp);
            if enter > t_far * SLAB_INFLATE {
                continue;
            }
            if count > 0 {
                for i in first..first + count {
                    match test(i, &tri_ray, t_far) {
                        None => {}
                        Some(Visit::Shorten(t)) => t_far = t,
                        Some(Visit::Stop) => return,
                    }
                }
                continue;
            }
            let node = &self.nodes[first as usize];
            let (entered, hits) = slab.enter(node, t_far);
            // Push the farthest first, so the nearest is popped next: the
            // entered boxes sorted by insertion (at most four).
            let base = sp;
            let mut bits = hits;
            while bits != 0 {
                let lane = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let entry = (node.first[lane], node.count[lane], entered[lane]);
                let mut at = sp;
                while at > base && read(&stack, at - 1).2 < entry.2 {
                    stack[at].write(read(&stack, at - 1));
                    at -= 1;
                }
                stack[at].write(entry);
                sp += 1;
            }
        }
    }
}

enum Visit {
    Shorten(f32),
    Stop,
}

/// A stack entry: a leaf's first triangle and count, or a node's index
/// and 0; and the distance at which the ray entered its box.
type Entry = (u32, u32, f32);

/// The slab test's per-ray constants, splat into lanes, with the planes a
/// ray enters and leaves each slab by chosen once (by the direction's
/// sign) rather than per box.
struct WideRay {
    origin: [Vec4; 3],
    inv: [Vec4; 3],
    pad: [Vec4; 3],
    /// Per axis: whether the ray enters by the max plane (d < 0).
    negative: [bool; 3],
}

impl WideRay {
    #[inline]
    fn new(origin: Vec3, direction: Vec3) -> Self {
        let largest = direction.abs().max_element();
        let parallel = direction.abs().cmple(Vec3::splat(SLAB_PARALLEL * largest));
        let inv = Vec3::select(parallel, Vec3::ZERO, direction.recip());
        let pad = Vec3::select(parallel, Vec3::splat(SLAB_PAD), Vec3::ZERO);
        Self {
            origin: [0, 1, 2].map(|k| Vec4::splat(origin[k])),
            inv: [0, 1, 2].map(|k| Vec4::splat(inv[k])),
            pad: [0, 1, 2].map(|k| Vec4::splat(pad[k])),
            negative: [0, 1, 2].map(|k| direction[k] < 0.0),
        }
    }

    /// Where the ray enters each of the node's four boxes (clamped to 0),
    /// and a bit per box it enters before `t_far`: `SlabRay::entry`'s
    /// arithmetic in each lane.
    #[inline]
    fn enter(&self, node: &WideNode, t_far: f32) -> ([f32; 4], u32) {
        let mut t_near = Vec4::splat(f32::MIN);
        let mut t_exit = Vec4::splat(f32::MAX);
        for k in 0..3 {
            let (near, far) = if self.negative[k] {
                (node.hi[k], node.lo[k])
            } else {
                (node.lo[k], node.hi[k])
            };
            t_near = t_near.max((near - self.origin[k]) * self.inv[k] - self.pad[k]);
            t_exit = t_exit.min((far - self.origin[k]) * self.inv[k] + self.pad[k]);
        }
        let enter = t_near.max(Vec4::ZERO);
        let exit = t_exit.min(Vec4::splat(t_far)) * SLAB_INFLATE;
        (enter.to_array(), enter.cmple(exit).bitmask())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::shapes::{bumpy_sphere, grid_plane};

    /// A fixed spread of rays: from points around and inside the meshes,
    /// towards points on a sphere (an LCG, so the test is the same run to
    /// run), some along the axes and the grid's plane.
    fn rays() -> Vec<(Vec3, Vec3)> {
        let mut state = 7u32;
        let mut next = move || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / 16_777_216.0 * 2.0 - 1.0
        };
        let mut out: Vec<(Vec3, Vec3)> = (0..4000)
            .map(|_| {
                let o = Vec3::new(next(), next(), next()) * 3.0;
                let target = Vec3::new(next(), next(), next()) * 0.8;
                (o, target - o)
            })
            .collect();
        for axis in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
            out.push((-2.5 * axis + Vec3::new(0.01, 0.02, 0.03), axis));
        }
        out.push((Vec3::new(-3.0, 0.0, 0.1), Vec3::X));
        out
    }

    /// The wide walk finds what the binary walk finds: the same closest
    /// distance (to the bit) and the same occlusion, for every ray and
    /// every far bound, on meshes of 1 to 20 000 triangles.
    #[test]
    fn the_wide_walk_finds_the_binary_walks_hits() {
        let meshes = [
            vec![[
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ]],
            grid_plane(8, 1.0).triangles(),
            bumpy_sphere(20_000).triangles(),
        ];
        for triangles in meshes {
            let bvh = Bvh::build(&triangles);
            let ordered = bvh.reorder(&triangles);
            let wide = WideBvh::build(&bvh);
            let mut hits = 0;
            for (o, d) in rays() {
                for t_max in [f32::MAX, 2.5] {
                    let binary = bvh.intersect(&ordered, o, d, t_max);
                    let found = wide.intersect(&ordered, o, d, t_max);
                    assert_eq!(binary.map(|h| h.t), found.map(|h| h.t), "{o} {d} {t_max}");
                    assert_eq!(
                        bvh.occluded(&ordered, o, d, t_max),
                        wide.occluded(&ordered, o, d, t_max)
                    );
                    hits += usize::from(found.is_some());
                }
            }
            assert!(hits > 100, "{} triangles: {hits} hits", triangles.len());
        }
    }

    /// An empty mesh has no wide node, and nothing is hit.
    #[test]
    fn the_empty_mesh_is_never_hit() {
        let bvh = Bvh::build(&[]);
        let wide = WideBvh::build(&bvh);
        assert!(wide.nodes.is_empty());
        assert_eq!(wide.intersect(&[], Vec3::ZERO, Vec3::X, f32::MAX), None);
        assert!(!wide.occluded(&[], Vec3::ZERO, Vec3::X, f32::MAX));
    }
}
