//! A bounding volume hierarchy over triangles, built on the CPU with the
//! binned surface area heuristic and flattened into the 32-byte nodes that
//! `crates/core/src/accel/traverse.wgsl` walks.
//!
//! # Layout
//!
//! `nodes[0]` is the root. A node with `count > 0` is a leaf holding the
//! triangles `a .. a + count` of the *reordered* triangle list (see
//! [`Bvh::permutation`]). A node with `count == 0` is interior: its two
//! children are `nodes[a]` (left) and `nodes[a + 1]` (right), always side by
//! side so one index names both, and `a ≥ 1`. Children come after their
//! parent, each pair's subtrees depth-first after it.
//!
//! The one exception is the hierarchy of no triangles: a single node with
//! `count == 0`, `a == 0` and the empty box ([`BvhNode::EMPTY`]). Traversal
//! tests the root's box before anything else and the empty box rejects
//! every ray, so that node's "children" are never read; both traversals
//! also stop at a root of `count == 0` and `a == 0` outright, so a zeroed
//! placeholder buffer (a point box whose children would be itself) cannot
//! send them round in circles.
//!
//! # Build
//!
//! Top-down, one node at a time: triangle boxes' centres are sorted into
//! [`SAH_BINS`] bins along each axis, and the split between bins of least
//! SAH cost wins (Wald, "On fast Construction of SAH-based Bounding Volume
//! Hierarchies", 2007). A node of at most [`MAX_LEAF_TRIANGLES`] becomes a
//! leaf where that is cheaper than its best split. Where the bins cannot
//! split (every centre the same, or NaN) the node splits by count.
//!
//! Depth is bounded by [`MAX_DEPTH`], the traversal stack's size: a node
//! whose depth plus the levels a balanced split would still need reaches the
//! bound splits at its median instead, which halves it exactly.
//!
//! Triangles with a NaN or infinite coordinate get the empty box. Where
//! there are some among finite ones, the root's right child holds them all,
//! in leaves whose boxes are empty: the permutation still covers every
//! triangle, but no ray reaches them and no box grows because of them.

use super::aabb::Aabb;
use bytemuck::{Pod, Zeroable};
use glam::{Vec3, Vec3A};
use std::time::Duration;
use web_time::Instant;

/// Triangles per leaf, at most.
pub const MAX_LEAF_TRIANGLES: usize = 4;
/// Bins per axis for the SAH.
pub const SAH_BINS: usize = 16;
/// The deepest a node may be (the root is at depth 0): a leaf at depth d
/// leaves at most d entries on the traversal stack, so `BVH_STACK_SIZE` in
/// `crates/core/src/accel/traverse.wgsl` must be at least this.
pub const MAX_DEPTH: usize = 64;
/// SAH cost of visiting an interior node (testing its two children's boxes)
/// relative to one triangle test. On the GPU the two box tests cost a bit
/// less than one watertight triangle test, and a leaf's triangles are
/// tested in a loop whose length every lane of a SIMD group waits on, so the
/// two are priced the same.
pub const TRAVERSAL_COST: f32 = 1.0;
/// SAH cost of one ray–triangle test.
pub const TRIANGLE_COST: f32 = 1.0;

/// One flattened node, as `struct BvhNode` in `crates/core/src/accel/traverse.wgsl` (32 bytes:
/// `vec3f` min, `u32`, `vec3f` max, `u32`). See the module documentation for
/// what `a` and `count` mean.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct BvhNode {
    pub min: [f32; 3],
    /// Leaf: the first triangle. Interior: the left child (right is a + 1).
    pub a: u32,
    pub max: [f32; 3],
    /// Leaf: how many triangles (> 0). Interior: 0.
    pub count: u32,
}

/// How far the corners of the empty box lie: finite (WGSL lets compilers
/// assume no infinities) but far beyond any scene, and inverted (min > max)
/// so the slab test rejects it along any axis the ray moves along.
pub const EMPTY_BOX_EXTENT: f32 = 1.0e20;

impl BvhNode {
    /// The whole hierarchy of an empty mesh: no ray hits it.
    pub const EMPTY: BvhNode = BvhNode {
        min: [EMPTY_BOX_EXTENT; 3],
        a: 0,
        max: [-EMPTY_BOX_EXTENT; 3],
        count: 0,
    };

    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    /// The node's box as the builder saw it (the empty box for
    /// [`EMPTY_BOX_EXTENT`] corners).
    pub fn bounds(&self) -> Aabb {
        if self.min[0] > self.max[0] {
            return Aabb::EMPTY;
        }
        Aabb {
            min: Vec3A::from_array(self.min),
            max: Vec3A::from_array(self.max),
        }
    }

    fn new(bounds: &Aabb, a: u32, count: u32) -> Self {
        if bounds.is_empty() {
            return BvhNode {
                a,
                count,
                ..Self::EMPTY
            };
        }
        BvhNode {
            min: bounds.min.to_array(),
            a,
            max: bounds.max.to_array(),
            count,
        }
    }
}

/// What the build made, for reports.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BvhStats {
    pub triangles: usize,
    pub nodes: usize,
    pub leaves: usize,
    /// The deepest leaf's depth (the root is at depth 0).
    pub max_depth: usize,
    /// The tree's SAH cost: the expected cost of a random ray that hits the
    /// root's box, in triangle tests, with [`TRAVERSAL_COST`] per interior
    /// node and [`TRIANGLE_COST`] per triangle, each weighted by its box's
    /// area over the root's.
    pub sah_cost: f32,
    pub build_time: Duration,
}

/// The flattened hierarchy and the order it put the triangles in.
#[derive(Debug, Clone)]
pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    /// `permutation[i]` is the index, in the builder's input, of the i-th
    /// triangle in the order the leaves use: reorder per-triangle data with
    /// [`Bvh::reorder`] before uploading it.
    pub permutation: Vec<u32>,
    pub stats: BvhStats,
}

impl Bvh {
    /// Builds the hierarchy of `triangles`.
    pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
        Self::build_with_depth_bound(triangles, MAX_DEPTH)
    }

    /// [`Bvh::build`] with leaves no deeper than `max_depth - 1`.
    fn build_with_depth_bound(triangles: &[[Vec3; 3]], max_depth: usize) -> Bvh {
        let start = Instant::now();
        let mut prims: Vec<PrimRef> = triangles
            .iter()
            .enumerate()
            .map(|(i, tri)| PrimRef {
                bounds: Aabb::of_triangle(tri),
                index: i as u32,
            })
            .collect();
        let mut nodes = Vec::with_capacity(2 * prims.len().max(1) + 2);
        nodes.push(BvhNode::EMPTY);
        // Non-finite triangles go to a subtree of their own under the root,
        // whose empty boxes no ray enters: they are never tested.
        let finite = partition(&mut prims, |p| !p.bounds.is_empty());
        if finite > 0 && finite < prims.len() {
            nodes.extend([BvhNode::zeroed(); 2]);
            let (good, bad) = prims.split_at_mut(finite);
            build_node(&mut nodes, 1, good, 0, 1, max_depth);
            build_node(&mut nodes, 2, bad, finite, 1, max_depth);
            nodes[0] = BvhNode::new(&nodes[1].bounds(), 1, 0);
        } else if !prims.is_empty() {
            build_node(&mut nodes, 0, &mut prims, 0, 0, max_depth);
        }
        let build_time = start.elapsed();
        let permutation = prims.iter().map(|p| p.index).collect();
        let mut stats = tree_stats(&nodes);
        stats.triangles = triangles.len();
        stats.build_time = build_time;
        Bvh {
            nodes,
            permutation,
            stats,
        }
    }

    /// Per-triangle data in the order the leaves use.
    pub fn reorder<T: Clone>(&self, per_triangle: &[T]) -> Vec<T> {
        self.permutation
            .iter()
            .map(|&i| per_triangle[i as usize].clone())
            .collect()
    }
}

#[derive(Clone, Copy)]
struct PrimRef {
    bounds: Aabb,
    index: u32,
}

/// The levels of balanced splits `n` triangles need before every leaf holds
/// at most [`MAX_LEAF_TRIANGLES`].
fn balanced_levels(n: usize) -> usize {
    n.div_ceil(MAX_LEAF_TRIANGLES)
        .next_power_of_two()
        .trailing_zeros() as usize
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Aabb,
    count: u32,
}

const EMPTY_BIN: Bin = Bin {
    bounds: Aabb::EMPTY,
    count: 0,
};

/// Maps centres to bins along each axis. The same arithmetic sorts
/// triangles into bins and then partitions them, so both agree exactly;
/// a NaN centre (empty box) goes to bin 0 (Rust's `as` saturates).
struct Binning {
    origin: Vec3A,
    scale: Vec3A,
}

impl Binning {
    fn new(centers: &Aabb) -> Self {
        let extent = centers.max - centers.min;
        let scale = Vec3A::from_array(extent.to_array().map(|e| {
            if e > 0.0 && e.is_finite() {
                SAH_BINS as f32 / e
            } else {
                0.0
            }
        }));
        Binning {
            origin: centers.min,
            scale,
        }
    }

    #[inline]
    fn bins(&self, bounds: &Aabb) -> [usize; 3] {
        let k = (bounds.center() - self.origin) * self.scale;
        k.to_array().map(|x| (x as usize).min(SAH_BINS - 1))
    }
}

enum Split {
    /// Left: the triangles whose bin along `axis` is at most `last_left`.
    Sah { axis: usize, last_left: usize },
    /// Half the triangles by centre along `axis` (or in the order they are
    /// when no axis separates them).
    Median { axis: Option<usize> },
}

fn build_node(
    nodes: &mut Vec<BvhNode>,
    at: usize,
    prims: &mut [PrimRef],
    first: usize,
    depth: usize,
    max_depth: usize,
) {
    let n = prims.len();
    let mut bounds = Aabb::EMPTY;
    let mut centers = Aabb::EMPTY;
    for p in prims.iter() {
        bounds = bounds.union(&p.bounds);
        if !p.bounds.is_empty() {
            centers.grow(p.bounds.center());
        }
    }
    let leaf = BvhNode::new(&bounds, first as u32, n as u32);
    let split = if n == 1 {
        None
    } else if depth + balanced_levels(n) >= max_depth - 1 || bounds.area() == 0.0 {
        (n > MAX_LEAF_TRIANGLES).then(|| median(&centers))
    } else {
        match best_sah_split(prims, &bounds, &centers) {
            Some((cost, split)) if n > MAX_LEAF_TRIANGLES || cost < TRIANGLE_COST * n as f32 => {
                Some(split)
            }
            Some(_) => None,
            None => (n > MAX_LEAF_TRIANGLES).then(|| median(&centers)),
        }
    };
    let Some(split) = split else {
        nodes[at] = leaf;
        return;
    };
    let mid = match split {
        Split::Sah { axis, last_left } => {
            let binning = Binning::new(&centers);
            partition(prims, |p| binning.bins(&p.bounds)[axis] <= last_left)
        }
        Split::Median { axis } => {
            let mid = n / 2;
            if let Some(axis) = axis {
                prims.select_nth_unstable_by(mid, |a, b| {
                    a.bounds.center()[axis].total_cmp(&b.bounds.center()[axis])
                });
            }
            mid
        }
    };
    debug_assert!(0 < mid && mid < n);
    let left = nodes.len();
    nodes.push(BvhNode::zeroed());
    nodes.push(BvhNode::zeroed());
    nodes[at] = BvhNode::new(&bounds, left as u32, 0);
    let (lo, hi) = prims.split_at_mut(mid);
    build_node(nodes, left, lo, first, depth + 1, max_depth);
    build_node(nodes, left + 1, hi, first + mid, depth + 1, max_depth);
}

/// Split by count along the widest axis of the centres, if any.
fn median(centers: &Aabb) -> Split {
    let extent = (centers.max - centers.min).to_array();
    let axis = (0..3)
        .filter(|&k| extent[k] > 0.0)
        .max_by(|&a, &b| extent[a].total_cmp(&extent[b]));
    Split::Median { axis }
}

/// The cheapest split between bins, with its SAH cost relative to the
/// node's area: `TRAVERSAL_COST + TRIANGLE_COST (A_l n_l + A_r n_r) / A`.
/// `None` when no bin boundary has triangles on both sides.
fn best_sah_split(prims: &[PrimRef], bounds: &Aabb, centers: &Aabb) -> Option<(f32, Split)> {
    let binning = Binning::new(centers);
    let mut bins = [[EMPTY_BIN; SAH_BINS]; 3];
    for p in prims {
        let k = binning.bins(&p.bounds);
        for axis in 0..3 {
            let bin = &mut bins[axis][k[axis]];
            bin.bounds = bin.bounds.union(&p.bounds);
            bin.count += 1;
        }
    }
    let mut best: Option<(f32, usize, usize)> = None;
    for (axis, bins) in bins.iter().enumerate() {
        // right_cost[i]: area × count of the bins after i.
        let mut right_cost = [0.0f32; SAH_BINS];
        let mut right_count = [0u32; SAH_BINS];
        let mut acc = Aabb::EMPTY;
        let mut count = 0;
        for i in (1..SAH_BINS).rev() {
            acc = acc.union(&bins[i].bounds);
            count += bins[i].count;
            right_cost[i - 1] = acc.area() * count as f32;
            right_count[i - 1] = count;
        }
        let mut acc = Aabb::EMPTY;
        let mut count = 0;
        for i in 0..SAH_BINS - 1 {
            acc = acc.union(&bins[i].bounds);
            count += bins[i].count;
            if count == 0 || right_count[i] == 0 {
                continue;
            }
            let cost = acc.area() * count as f32 + right_cost[i];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, i));
            }
        }
    }
    let (cost, axis, last_left) = best?;
    let relative = TRAVERSAL_COST + TRIANGLE_COST * cost / bounds.area();
    Some((relative, Split::Sah { axis, last_left }))
}

/// Moves the triangles for which `left` holds to the front; returns how many.
fn partition(prims: &mut [PrimRef], left: impl Fn(&PrimRef) -> bool) -> usize {
    let (mut i, mut j) = (0, prims.len());
    while i < j {
        if left(&prims[i]) {
            i += 1;
        } else {
            j -= 1;
            prims.swap(i, j);
        }
    }
    i
}

/// Node and leaf counts, depth and SAH cost of a flattened tree.
fn tree_stats(nodes: &[BvhNode]) -> BvhStats {
    let root_area = nodes[0].bounds().area();
    let relative = |node: &BvhNode| {
        if root_area > 0.0 {
            node.bounds().area() / root_area
        } else {
            1.0
        }
    };
    let mut stats = BvhStats {
        nodes: nodes.len(),
        ..Default::default()
    };
    if nodes[0] == BvhNode::EMPTY {
        stats.leaves = 1;
        return stats;
    }
    let mut sah = 0.0f64;
    let mut stack = vec![(0usize, 0usize)];
    while let Some((i, depth)) = stack.pop() {
        let node = &nodes[i];
        if node.is_leaf() {
            stats.leaves += 1;
            stats.max_depth = stats.max_depth.max(depth);
            sah += f64::from(TRIANGLE_COST * node.count as f32 * relative(node));
        } else {
            sah += f64::from(TRAVERSAL_COST * relative(node));
            let a = node.a as usize;
            stack.push((a, depth + 1));
            stack.push((a + 1, depth + 1));
        }
    }
    stats.sah_cost = sah as f32;
    stats
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(c: Vec3) -> [Vec3; 3] {
        [c, c + Vec3::X * 0.1, c + Vec3::Y * 0.1]
    }

    #[test]
    fn the_node_is_32_bytes() {
        assert_eq!(std::mem::size_of::<BvhNode>(), 32);
    }

    #[test]
    fn balanced_levels_of_a_few_counts() {
        assert_eq!(balanced_levels(1), 0);
        assert_eq!(balanced_levels(4), 0);
        assert_eq!(balanced_levels(5), 1);
        assert_eq!(balanced_levels(8), 1);
        assert_eq!(balanced_levels(9), 2);
        assert_eq!(balanced_levels(1 << 20), 18);
    }

    #[test]
    fn no_triangles_make_one_empty_node() {
        let bvh = Bvh::build(&[]);
        assert_eq!(bvh.nodes, vec![BvhNode::EMPTY]);
        assert!(bvh.permutation.is_empty());
        assert_eq!((bvh.stats.nodes, bvh.stats.leaves), (1, 1));
    }

    #[test]
    fn one_triangle_is_one_leaf() {
        let bvh = Bvh::build(&[tri(Vec3::ZERO)]);
        assert_eq!(bvh.nodes.len(), 1);
        assert_eq!((bvh.nodes[0].a, bvh.nodes[0].count), (0, 1));
        assert_eq!(bvh.nodes[0].min, [0.0; 3]);
        assert_eq!(bvh.nodes[0].max, [0.1, 0.1, 0.0]);
        assert_eq!(bvh.permutation, vec![0]);
    }

    #[test]
    fn identical_centroids_split_by_count() {
        let tris = vec![tri(Vec3::ONE); 1000];
        let bvh = Bvh::build(&tris);
        assert!(bvh.nodes.iter().all(|n| n.count <= 4));
        assert_eq!(bvh.stats.leaves, 256);
        assert_eq!(bvh.stats.max_depth, 8);
        let mut seen = bvh.permutation.clone();
        seen.sort();
        assert_eq!(seen, (0..1000).collect::<Vec<_>>());
    }

    #[test]
    fn nan_triangles_are_kept_but_widen_no_box() {
        let mut tris: Vec<_> = (0..50).map(|i| tri(Vec3::X * i as f32)).collect();
        for i in 0..50 {
            let mut t = tri(Vec3::Y * i as f32);
            t[i % 3].x = if i % 2 == 0 { f32::NAN } else { f32::INFINITY };
            tris.push(t);
        }
        let bvh = Bvh::build(&tris);
        assert_eq!(bvh.permutation.len(), 100);
        assert_eq!(bvh.nodes[0].min, [0.0; 3]);
        assert_eq!(bvh.nodes[0].max, [49.1, 0.1, 0.0]);
        let all_nan: Vec<_> = (0..20).map(|_| [Vec3::NAN; 3]).collect();
        let bvh = Bvh::build(&all_nan);
        assert_eq!(bvh.permutation.len(), 20);
        assert!(bvh.nodes.iter().all(|n| n.bounds().is_empty()));
    }

    #[test]
    fn the_depth_bound_holds() {
        // 4000 scattered triangles: the SAH alone goes deeper than 13.
        let mut x = 1u32;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x as f32 / u32::MAX as f32
        };
        let tris: Vec<_> = (0..4000)
            .map(|_| tri(Vec3::new(next(), next(), next()) * 10.0))
            .collect();
        assert!(Bvh::build(&tris).stats.max_depth > 13);
        for bound in [12, 14] {
            let bvh = Bvh::build_with_depth_bound(&tris, bound);
            assert!(bvh.stats.max_depth < bound, "{:?}", bvh.stats);
            assert!(bvh.nodes.iter().all(|n| n.count <= 4));
        }
    }
}
