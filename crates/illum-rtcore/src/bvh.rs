//! The bounding volume hierarchy, built on the host and flattened into the storage buffers the
//! generated traversal walks (bvh_traversal.rs, `shaders/bvh.wgsl`). One builder ([`Hierarchy`])
//! serves every primitive put under a BVH: a scene's mesh triangles past the literal limit
//! (mesh_traversal.rs), and its small analytic objects past theirs (analytic_bvh.rs). A scene with neither has
//! none: its objects stay literals in the generated traversal (traversal.rs).
//!
//! Build: top-down, each node split where the surface area heuristic (SAH) is least among
//! `BINS` equal bins of its primitives' centroids on each axis (binned SAH, Wald 2007): the cost
//! of a split is `TRAVERSAL_COST + (A_left N_left + A_right N_right) / A_node` in units of one
//! ray-primitive test, and a node becomes a leaf when no split costs less than testing its N
//! primitives, or when it has at most `MIN_SPLIT` primitives. Depth is capped at `MAX_DEPTH`, the
//! size of the shader's stack.
//!
//! Layout, for a CPU Vulkan driver such as lavapipe: each lane of a SIMD group runs its own
//! loop and every buffer read is a scalar load per lane, so the layout minimises loads per step:
//! a node is 32 bytes (two vec4s: bounds and two u32s), children are visited one node per step
//! with the near child first (by the ray's sign on the split axis, no second box test), and the
//! first child is stored right after its parent (depth-first order), so only the second child's
//! index is stored. On a GPU, where a warp's lanes load a node together, a wide BVH (4 or 8
//! children tested per load, Ylitie et al. 2017) would suit better; on lavapipe it would make
//! each lane test boxes it does not need.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// Centroid bins per axis.
const BINS: usize = 16;
/// The cost of visiting a node, relative to one ray-primitive test.
const TRAVERSAL_COST: f32 = 1.0;
/// Nodes with at most this many primitives are leaves.
const MIN_SPLIT: usize = 2;
/// The deepest node; the shader's stack holds `MAX_DEPTH` entries (BVH_STACK in bvh.wgsl).
pub const MAX_DEPTH: usize = 32;

/// One node as `struct BvhNode` in bvh.wgsl: its bounds, and `a`, `b`: for a leaf, the first
/// of its primitives and `count << 2` (count >= 1); for an inner node, the index of its second
/// child (the first is the next node) and the split axis (0, 1, 2) in `b`, whose count is 0.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct BvhNode {
    pub lo: [f32; 3],
    pub a: u32,
    pub hi: [f32; 3],
    pub b: u32,
}

/// One triangle as `struct MeshTriangle` in bvh.wgsl: its corners (front: counter-clockwise,
/// normal (b - a) x (c - a)), the index of its material, the index in the scene of the
/// mesh object it belongs to (for object-ID images; the shaders do not read it), and `order`,
/// its index among the scene's triangles before the BVH reorders them (set by
/// [`MeshForm::of`](crate::mesh_traversal::MeshForm::of)): where its shading normals are
/// (mesh_shading.rs).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct MeshTriangle {
    pub a: [f32; 3],
    pub material: u32,
    pub b: [f32; 3],
    pub object: u32,
    pub c: [f32; 3],
    pub order: u32,
}

impl MeshTriangle {
    pub fn new([a, b, c]: [Vec3; 3], material: u32, object: u32) -> Self {
        MeshTriangle { a: a.to_array(), material, b: b.to_array(), object, c: c.to_array(), order: 0 }
    }

    fn corners(&self) -> [Vec3; 3] {
        [self.a, self.b, self.c].map(Vec3::from_array)
    }
}

/// The hierarchy: nodes (the root first) and the triangles in leaf order.
#[derive(Clone, PartialEq)]
pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    pub triangles: Vec<MeshTriangle>,
}

impl std::fmt::Debug for Bvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bvh")
            .field("nodes", &self.nodes.len())
            .field("triangles", &self.triangles.len())
            .finish()
    }
}

#[derive(Clone, Copy)]
struct Aabb {
    lo: Vec3,
    hi: Vec3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb { lo: Vec3::INFINITY, hi: Vec3::NEG_INFINITY };

    fn grow(self, p: Vec3) -> Aabb {
        Aabb { lo: self.lo.min(p), hi: self.hi.max(p) }
    }

    fn join(self, o: Aabb) -> Aabb {
        Aabb { lo: self.lo.min(o.lo), hi: self.hi.max(o.hi) }
    }

    /// Half the surface area (the SAH needs only ratios); 0 when empty.
    fn half_area(self) -> f32 {
        let e = (self.hi - self.lo).max(Vec3::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }
}

/// The hierarchy's shape over any primitives, from their bounds alone: the nodes, whose leaves
/// index `order`, and `order`, the primitives' indices in leaf order. Every primitive kind the
/// traversal puts under a BVH (mesh triangles, analytic objects) is built by this one builder.
#[derive(Clone, Debug, PartialEq)]
pub struct Hierarchy {
    pub nodes: Vec<BvhNode>,
    pub order: Vec<usize>,
}

impl Hierarchy {
    /// Builds the hierarchy over primitives with these bounds (`[lo, hi]` each, at least one).
    pub fn build(bounds: impl IntoIterator<Item = [Vec3; 2]>) -> Hierarchy {
        let bounds: Vec<Aabb> = bounds.into_iter().map(|[lo, hi]| Aabb { lo, hi }).collect();
        assert!(!bounds.is_empty(), "a BVH needs at least one primitive");
        let centroids = bounds.iter().map(|b| 0.5 * (b.lo + b.hi)).collect();
        let count = bounds.len();
        let mut builder = Builder { order: (0..count).collect(), bounds, centroids, nodes: Vec::new() };
        builder.node(0, count, 0);
        Hierarchy { nodes: builder.nodes, order: builder.order }
    }
}

struct Builder {
    /// The primitives' indices, partitioned in place as nodes are split.
    order: Vec<usize>,
    bounds: Vec<Aabb>,
    centroids: Vec<Vec3>,
    nodes: Vec<BvhNode>,
}

impl Bvh {
    /// Builds the hierarchy over `triangles` (at least one).
    pub fn build(triangles: Vec<MeshTriangle>) -> Bvh {
        assert!(!triangles.is_empty(), "a BVH needs at least one triangle");
        let hierarchy = Hierarchy::build(triangles.iter().map(|t| {
            let b = t.corners().into_iter().fold(Aabb::EMPTY, Aabb::grow);
            [b.lo, b.hi]
        }));
        let triangles = hierarchy.order.iter().map(|&i| triangles[i]).collect();
        Bvh { nodes: hierarchy.nodes, triangles }
    }
}

impl Builder {
    /// Builds the node of primitives `first..first + count` at `depth`; returns its index.
    fn node(&mut self, first: usize, count: usize, depth: usize) -> usize {
        let range = first..first + count;
        let bounds = self.bounds[range.clone()].iter().fold(Aabb::EMPTY, |a, &b| a.join(b));
        let index = self.nodes.len();
        self.nodes.push(BvhNode { lo: bounds.lo.to_array(), a: 0, hi: bounds.hi.to_array(), b: 0 });
        let split = if count <= MIN_SPLIT || depth + 1 >= MAX_DEPTH {
            None
        } else {
            self.best_split(first, count, bounds)
        };
        let Some((axis, left_count)) = split else {
            self.nodes[index].a = first as u32;
            self.nodes[index].b = (count as u32) << 2;
            return index;
        };
        self.node(first, left_count, depth + 1);
        let second = self.node(first + left_count, count - left_count, depth + 1);
        self.nodes[index].a = second as u32;
        self.nodes[index].b = axis as u32;
        index
    }

    /// The cheapest binned split of `first..first + count`, if it costs less than a leaf: its
    /// axis and the number of primitives on its left, which it has moved to the front.
    fn best_split(&mut self, first: usize, count: usize, bounds: Aabb) -> Option<(usize, usize)> {
        let range = first..first + count;
        let centre_bounds = self.centroids[range.clone()].iter().fold(Aabb::EMPTY, |a, &c| a.grow(c));
        let extent = centre_bounds.hi - centre_bounds.lo;
        let bin_of = |c: Vec3, axis: usize| {
            let k = ((c[axis] - centre_bounds.lo[axis]) / extent[axis] * BINS as f32) as usize;
            k.min(BINS - 1)
        };
        let mut best: Option<(f32, usize, usize)> = None;
        for axis in 0..3 {
            if extent[axis] <= 0.0 || extent[axis].is_nan() {
                continue;
            }
            let mut bins = [(Aabb::EMPTY, 0usize); BINS];
            for i in range.clone() {
                let bin = &mut bins[bin_of(self.centroids[i], axis)];
                *bin = (bin.0.join(self.bounds[i]), bin.1 + 1);
            }
            // Sweep from the right: the area and count right of each boundary.
            let mut right = [(0.0f32, 0usize); BINS];
            let (mut acc, mut n) = (Aabb::EMPTY, 0);
            for k in (1..BINS).rev() {
                acc = acc.join(bins[k].0);
                n += bins[k].1;
                right[k] = (acc.half_area(), n);
            }
            let (mut acc, mut n) = (Aabb::EMPTY, 0);
            for k in 1..BINS {
                acc = acc.join(bins[k - 1].0);
                n += bins[k - 1].1;
                let (right_area, right_n) = right[k];
                if n == 0 || right_n == 0 {
                    continue;
                }
                let cost = acc.half_area() * n as f32 + right_area * right_n as f32;
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, k));
                }
            }
        }
        let (cost, axis, boundary) = best?;
        let parent = bounds.half_area();
        let split_cost = TRAVERSAL_COST + if parent > 0.0 { cost / parent } else { count as f32 };
        if split_cost >= count as f32 {
            return None;
        }
        // Partition: primitives whose centroid's bin is left of the boundary first.
        let mut left = first;
        for i in range {
            if bin_of(self.centroids[i], axis) < boundary {
                self.order.swap(i, left);
                self.bounds.swap(i, left);
                self.centroids.swap(i, left);
                left += 1;
            }
        }
        Some((axis, left - first))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of n x n unit squares (two triangles each) in the plane z = x / 7.
    fn grid(n: usize) -> Vec<MeshTriangle> {
        let p = |i: usize, j: usize| Vec3::new(i as f32, j as f32, i as f32 / 7.0);
        let mut out = Vec::new();
        for i in 0..n {
            for j in 0..n {
                out.push(MeshTriangle::new([p(i, j), p(i + 1, j), p(i + 1, j + 1)], (i + j) as u32, 0));
                out.push(MeshTriangle::new([p(i, j), p(i + 1, j + 1), p(i, j + 1)], 7, 0));
            }
        }
        out
    }

    /// Every node's bounds hold its subtree; leaves partition the triangles; depth is capped.
    fn check(bvh: &Bvh, node: usize, depth: usize, covered: &mut Vec<bool>) {
        assert!(depth < MAX_DEPTH);
        let n = bvh.nodes[node];
        let inside = |p: [f32; 3]| (0..3).all(|a| n.lo[a] <= p[a] && p[a] <= n.hi[a]);
        let count = (n.b >> 2) as usize;
        if count > 0 {
            for t in &bvh.triangles[n.a as usize..n.a as usize + count] {
                assert!(inside(t.a) && inside(t.b) && inside(t.c));
            }
            for c in &mut covered[n.a as usize..n.a as usize + count] {
                assert!(!*c, "a triangle in two leaves");
                *c = true;
            }
            return;
        }
        for child in [node + 1, n.a as usize] {
            let c = bvh.nodes[child];
            assert!(inside(c.lo) && inside(c.hi), "child {child} of {node} pokes out");
            check(bvh, child, depth + 1, covered);
        }
    }

    #[test]
    fn the_hierarchy_holds_every_triangle_once_within_its_bounds() {
        for n in [1, 2, 5, 40] {
            let triangles = grid(n);
            let bvh = Bvh::build(triangles.clone());
            let mut covered = vec![false; bvh.triangles.len()];
            check(&bvh, 0, 0, &mut covered);
            assert!(covered.iter().all(|&c| c), "{n}");
            // The same triangles, reordered.
            let key = |t: &MeshTriangle| format!("{t:?}");
            let (mut a, mut b): (Vec<_>, Vec<_>) =
                (triangles.iter().map(key).collect(), bvh.triangles.iter().map(key).collect());
            a.sort();
            b.sort();
            assert_eq!(a, b);
        }
    }

    #[test]
    fn leaves_are_small_where_triangles_are_spread() {
        let bvh = Bvh::build(grid(40));
        let leaves: Vec<u32> = bvh.nodes.iter().filter(|n| n.b >> 2 > 0).map(|n| n.b >> 2).collect();
        let largest = leaves.iter().max().unwrap();
        assert!(*largest <= 8, "a leaf of {largest} triangles");
        assert!(leaves.len() > 3200 / 8, "{} leaves", leaves.len());
    }

    #[test]
    fn coincident_triangles_make_one_leaf() {
        let t = MeshTriangle::new([Vec3::ZERO, Vec3::X, Vec3::Y], 0, 0);
        let bvh = Bvh::build(vec![t; 100]);
        assert_eq!(bvh.nodes.len(), 1);
        assert_eq!(bvh.nodes[0].b >> 2, 100);
    }
}
