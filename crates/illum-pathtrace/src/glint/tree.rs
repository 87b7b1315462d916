//! A bounding-volume hierarchy over the glint's bodies: the solve follows each chain many
//! thousands of times, and without it a scene of n objects costs n ray tests per segment.

use glam::DVec3;

/// A node of the bodies' hierarchy: its box, and either two children (`count == 0`: `first` is
/// the left child's index, the right one follows it) or the bodies `order[first..][..count]`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Node {
    pub(super) lo: DVec3,
    pub(super) hi: DVec3,
    pub(super) first: usize,
    pub(super) count: usize,
}

/// Bodies per leaf of the hierarchy.
const LEAF_BODIES: usize = 4;

/// Builds the hierarchy over the bodies `members` (indices into `boxes`, their lower and upper
/// corners) by median splits on the widest axis of the boxes' centres, and orders the bodies to
/// match it. Returns the nodes, the root first (none for no members), and the indices of the
/// bodies in the leaves' order.
pub(super) fn build_tree(boxes: &[(DVec3, DVec3)], members: Vec<usize>) -> (Vec<Node>, Vec<usize>) {
    let mut order = members;
    if order.is_empty() {
        return (Vec::new(), order);
    }
    let mut nodes = vec![Node { lo: DVec3::ZERO, hi: DVec3::ZERO, first: 0, count: 0 }];
    // (node, range of `order`)
    let mut work = vec![(0usize, 0usize, order.len())];
    while let Some((node, start, end)) = work.pop() {
        let (lo, hi) =
            order[start..end].iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &i| {
                (lo.min(boxes[i].0), hi.max(boxes[i].1))
            });
        if end - start <= LEAF_BODIES {
            nodes[node] = Node { lo, hi, first: start, count: end - start };
            continue;
        }
        let centre = |i: usize| 0.5 * (boxes[i].0 + boxes[i].1);
        let (clo, chi) =
            order[start..end].iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &i| {
                (lo.min(centre(i)), hi.max(centre(i)))
            });
        let extent = chi - clo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        order[start..end].sort_by(|&a, &b| centre(a)[axis].total_cmp(&centre(b)[axis]).then(a.cmp(&b)));
        let mid = (start + end) / 2;
        let left = nodes.len();
        nodes.push(Node { lo: DVec3::ZERO, hi: DVec3::ZERO, first: 0, count: 0 });
        nodes.push(Node { lo: DVec3::ZERO, hi: DVec3::ZERO, first: 0, count: 0 });
        nodes[node] = Node { lo, hi, first: left, count: 0 };
        work.push((left, start, mid));
        work.push((left + 1, mid, end));
    }
    (nodes, order)
}

/// Whether the ray o + t d (inv = 1 / d per axis) meets the box [lo, hi] at some t in [0, far].
pub(super) fn slab_hit(o: DVec3, inv: DVec3, lo: DVec3, hi: DVec3, far: f64) -> bool {
    let (mut near_t, mut far_t) = (0.0f64, far);
    for axis in 0..3 {
        let (a, b) = ((lo[axis] - o[axis]) * inv[axis], (hi[axis] - o[axis]) * inv[axis]);
        // A direction parallel to the slab: inside it, (-inf, inf), or outside it, no hit; a
        // product 0 x inf (the origin on the slab's plane) is NaN and counts as inside.
        let (a, b) =
            (if a.is_nan() { f64::NEG_INFINITY } else { a }, if b.is_nan() { f64::INFINITY } else { b });
        near_t = near_t.max(a.min(b));
        far_t = far_t.min(a.max(b));
    }
    near_t <= far_t
}
