//! Many analytic objects under a BVH. A scene's analytic objects (spheres, quads, boxes) are
//! literals in its generated traversal, one straight-line test each, up to [`LITERAL_OBJECTS`]
//! of those that may go under a hierarchy; past that those go under one hierarchy (bvh.rs's
//! builder, walked by bvh_traversal.rs's generated loop) read from group 1, whose leaf test
//! dispatches on each record's kind among only the kinds the hierarchy holds.
//!
//! What may go under it ([`UnderHierarchy`]): every non-emitting analytic object but the large
//! ones. Emitters stay literals: the lights are sampled by their index among the last objects,
//! and an emitter wins a tie with the surface it is set into by a test of its own. A large
//! object (on its longest axis, more than a quarter of the longest axis of all the analytic
//! objects' bounds: a floor, a wall) stays a literal too: in a leaf its box would swell the
//! leaf's and every ancestor's to the scene's, so that every ray would walk down to it, while as
//! a literal tested before the walk its hit (most rays meet the floor) bounds the walk.
//!
//! The objects under the hierarchy are the first of the scene's order, in leaf order, so that
//! a leaf's range of primitives is a range of object indices: the walk reports a hit's object
//! index with no lookup, and object_at builds the record of any of them from its record here.
//!
//! The walk reads the nodes and the records from uniform buffers, declared in the generated
//! traversal with the scene's sizes: on lavapipe a storage-buffer read at a per-lane index is
//! one bounds-checked scalar load per lane, and the same walk over storage buffers ran 2 to 4
//! times slower at 200 spheres (no faster than the literal list), while uniform buffers made it
//! 2 to 4 times faster than the list (docs/performance-geometry.md, "Many spheres, quads and boxes"). A
//! uniform binding holds 64 KiB on every device WebGPU allows (wgpu's default limit), which
//! bounds the objects under the hierarchy at [`MAX_BVH_OBJECTS`].

use std::collections::BTreeSet;
use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use illum_scene::{Scene, SceneError};

use crate::bvh::{BvhNode, Hierarchy};
use crate::object::{GpuObject, ObjectRecord, ShapeKind};

/// Up to this many objects that may go under the hierarchy ([`UnderHierarchy`]) are literals;
/// past it, a BVH. The crossover measured on lavapipe, time to the first image and throughput
/// both, is in docs/performance-geometry.md ("Many spheres, quads and boxes"): a literal list's compile
/// time grows with its length, and a BVH walk costs a loop and per-lane buffer reads that a few
/// literals do not.
pub const LITERAL_OBJECTS: usize = 16;

/// The most objects the hierarchy holds: its nodes (at most 2n - 1 of 32 bytes) and its records
/// (64 bytes each, [`BvhObject`]) each fit a 64 KiB uniform binding. A scene with more is refused
/// ([`check_count`]): as literals its traversal would take minutes to compile.
pub const MAX_BVH_OBJECTS: usize = 1024;

/// The hierarchy over the analytic objects: its nodes (the root first) and the objects, objects
/// 0 to `objects.len() - 1` of the scene's order.
#[derive(Clone, Debug, PartialEq)]
pub struct AnalyticBvh {
    pub nodes: Vec<BvhNode>,
    pub objects: Vec<GpuObject>,
}

/// One object as `struct BvhObject` in bvh.wgsl: its [`ObjectRecord`]'s four vectors (the last
/// one's w, 0 for every kind, left out) and `tag`, its kind's code in the low 4 bits and its
/// material above them. No emitter is under the hierarchy, so the record's emitter flag is 0.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct BvhObject {
    pub a: [f32; 4],
    pub b: [f32; 4],
    pub c: [f32; 4],
    pub d: [f32; 3],
    pub tag: u32,
}

/// The bits of [`BvhObject::tag`] that hold the kind's code.
const KIND_BITS: u32 = 4;

impl BvhObject {
    pub fn of(record: &ObjectRecord) -> Self {
        assert!(record.kind < 1 << KIND_BITS && record.material < 1 << (32 - KIND_BITS));
        let [dx, dy, dz, _] = record.d;
        BvhObject {
            a: record.a,
            b: record.b,
            c: record.c,
            d: [dx, dy, dz],
            tag: record.kind | record.material << KIND_BITS,
        }
    }
}

impl AnalyticBvh {
    /// The records as the uniform buffer holds them, in leaf order.
    pub fn records(&self) -> Vec<BvhObject> {
        self.objects.iter().map(|o| BvhObject::of(&o.record())).collect()
    }

    /// The kinds of shape under the hierarchy: the kinds its leaf test dispatches on.
    pub fn kinds(&self) -> BTreeSet<ShapeKind> {
        self.objects.iter().map(|o| o.shape.kind()).collect()
    }
}

/// The uniform buffers the walk reads, declared with this scene's sizes (group 1: the nodes at
/// binding 2, the records at 3), and their reads: `analytic_node(i)`, `analytic_record(i)` and
/// `analytic_object(i)`, the record [`GpuObject::record`] makes of object i.
pub(crate) fn declarations(bvh: &AnalyticBvh) -> String {
    format!(
        "@group(1) @binding(2) var<uniform> analytic_nodes: array<BvhNode, {}>;
@group(1) @binding(3) var<uniform> analytic_records: array<BvhObject, {}>;

fn analytic_node(i: u32) -> BvhNode {{
    return analytic_nodes[i];
}}

fn analytic_record(i: u32) -> BvhObject {{
    return analytic_records[i];
}}

fn analytic_object(i: u32) -> Object {{
    let r = analytic_records[i];
    return Object(r.tag & {mask}u, r.tag >> {KIND_BITS}u, 0u, 0u, r.a, r.b, r.c, vec4<f32>(r.d, 0.0));
}}

",
        bvh.nodes.len(),
        bvh.objects.len(),
        mask = (1u32 << KIND_BITS) - 1,
    )
}

/// The longest axis of a box.
fn longest(bounds: [Vec3; 2]) -> f32 {
    (bounds[1] - bounds[0]).max_element()
}

/// Which of a scene's analytic objects may go under the hierarchy: the non-emitters no
/// longer, on their longest axis, than a quarter of the longest axis of all of them together
/// (the module's comment says why).
#[derive(Clone, Copy, Debug)]
pub struct UnderHierarchy {
    /// A quarter of the longest axis of the analytic objects' bounds.
    large: f32,
}

impl UnderHierarchy {
    /// The rule for `objects`, a scene's analytic objects in any order.
    pub fn of<'a>(objects: impl IntoIterator<Item = &'a GpuObject>) -> Self {
        let all = objects
            .into_iter()
            .map(|o| o.shape.bounds())
            .fold([Vec3::INFINITY, Vec3::NEG_INFINITY], |a, b| [a[0].min(b[0]), a[1].max(b[1])]);
        UnderHierarchy { large: 0.25 * longest(all).max(0.0) }
    }

    pub fn holds(self, object: &GpuObject) -> bool {
        !object.emitter && longest(object.shape.bounds()) <= self.large
    }
}

fn count_under(objects: &[GpuObject]) -> usize {
    let under = UnderHierarchy::of(objects);
    objects.iter().filter(|o| under.holds(o)).count()
}

/// Refuses more objects that go under the hierarchy among `objects` (`scene`'s analytic
/// objects, in any order) than [`MAX_BVH_OBJECTS`], by count, limit and remedy.
pub fn check_count(scene: &Scene, objects: &[GpuObject]) -> Result<(), SceneError> {
    let count = count_under(objects);
    if count <= MAX_BVH_OBJECTS {
        return Ok(());
    }
    Err(SceneError::invalid(
        &scene.source,
        "objects",
        format!("{count} non-emitting spheres, quads and boxes"),
        format!(
            "the GPU ray tracers hold at most {MAX_BVH_OBJECTS} (the most whose hierarchy fits a 64 KiB \
             uniform binding; emitters and objects longer than a quarter of the scene are not counted); \
             remove some, or model some of them as one triangle mesh"
        ),
    ))
}

/// With more objects that may go under the hierarchy ([`UnderHierarchy`]) than
/// [`LITERAL_OBJECTS`] among `ordered` (the scene's order: non-emitters, then emitters, each
/// with its index in the scene), moves them to the front in the leaf order of a hierarchy built
/// over them, and returns the hierarchy. The rest keep their order, so emitters stay last.
pub fn arrange<T>(ordered: &mut Vec<(T, GpuObject)>) -> Option<Arc<AnalyticBvh>> {
    let under = UnderHierarchy::of(ordered.iter().map(|(_, o)| o));
    if ordered.iter().filter(|(_, o)| under.holds(o)).count() <= LITERAL_OBJECTS {
        return None;
    }
    let (objects, rest): (Vec<_>, Vec<_>) =
        std::mem::take(ordered).into_iter().partition(|(_, o)| under.holds(o));
    let hierarchy = Hierarchy::build(objects.iter().map(|(_, o)| o.shape.bounds()));
    let mut slots: Vec<Option<(T, GpuObject)>> = objects.into_iter().map(Some).collect();
    ordered.extend(hierarchy.order.iter().map(|&i| slots[i].take().expect("the order is a permutation")));
    let objects = ordered.iter().map(|(_, o)| *o).collect();
    ordered.extend(rest);
    Some(Arc::new(AnalyticBvh { nodes: hierarchy.nodes, objects }))
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::object::GpuShape;

    /// Small object `i` at x = `x`: a sphere, a quad, a rotated box or an axis-aligned box by
    /// `i % 4`, of material `i % 3`.
    fn small(i: usize, x: f32, emitter: bool) -> GpuObject {
        let c = Vec3::new(x, 0.0, 0.0);
        let shape = match i % 4 {
            0 => GpuShape::Sphere { center: c, radius: 0.25 },
            1 => GpuShape::Quad {
                corner: c,
                edge_u: Vec3::new(0.5, 0.0, 0.1),
                edge_v: Vec3::new(0.0, 0.4, 0.2),
            },
            2 => GpuShape::Box {
                local_min: Vec3::splat(-0.2),
                local_max: Vec3::splat(0.2),
                cos: 0.8,
                sin: 0.6,
                offset: c,
            },
            _ => GpuShape::Aabb { min: c - 0.2, max: c + 0.3 },
        };
        GpuObject { shape, material: (i % 3) as u32, emitter }
    }

    /// A floor under `n` of them: longer than a quarter of the scene.
    fn floor(n: usize) -> GpuObject {
        GpuObject {
            shape: GpuShape::Quad {
                corner: Vec3::new(-1.0, -1.0, -1.0),
                edge_u: Vec3::new(0.0, 0.0, 2.0),
                edge_v: Vec3::new(n as f32 + 2.0, 0.0, 0.0),
            },
            material: 1,
            emitter: false,
        }
    }

    /// The scene's order for `n` small objects of every kind: the floor, the objects, then two
    /// small emitters (a quad and a sphere), each with its index in the scene.
    fn objects(n: usize) -> Vec<(usize, GpuObject)> {
        let mut o: Vec<(usize, GpuObject)> = vec![(0, floor(n))];
        o.extend((0..n).map(|i| (i + 1, small(i, ((i * 7) % n) as f32, false))));
        o.push((n + 1, small(1, 3.0, true)));
        o.push((n + 2, small(0, 5.0, true)));
        o
    }

    /// A few objects stay literals in place; more move first, in leaf order, past the most the
    /// GPU ray tracers take too (check_count refuses those by name, so none fall back to a
    /// literal list that would take minutes to compile).
    #[test]
    fn a_few_objects_stay_in_place_and_more_move_first_in_leaf_order() {
        let mut few = objects(LITERAL_OBJECTS);
        let before = few.clone();
        assert!(arrange(&mut few).is_none());
        assert_eq!(few, before);

        for n in [LITERAL_OBJECTS + 1, MAX_BVH_OBJECTS + 1] {
            check_arranged(n, objects(n));
        }
    }

    fn check_arranged(n: usize, mut many: Vec<(usize, GpuObject)>) {
        let before = many.clone();
        let bvh = arrange(&mut many).expect("a BVH past the limit");
        // The small objects first (each once, with its own shape and material), then the floor,
        // then the emitters in their order: the same objects.
        let mut moved: Vec<(usize, GpuObject)> = many[..n].to_vec();
        moved.sort_by_key(|(i, _)| *i);
        assert_eq!(moved, before[1..=n]);
        assert_eq!(many[n..], [before[0], before[n + 1], before[n + 2]]);
        assert_eq!(bvh.objects, many[..n].iter().map(|(_, o)| *o).collect::<Vec<_>>());
        assert_eq!(bvh.kinds(), ShapeKind::ALL.into_iter().collect());
        // The records hold each object's record; the kind and material come back from the tag.
        for (record, object) in bvh.records().iter().zip(&bvh.objects) {
            let full = object.record();
            assert_eq!((record.tag & 15, record.tag >> 4), (full.kind, full.material));
            assert_eq!([record.a, record.b, record.c], [full.a, full.b, full.c]);
            assert_eq!([record.d[0], record.d[1], record.d[2], 0.0], full.d);
        }
        // Every leaf's range holds objects inside its bounds.
        for node in bvh.nodes.iter().filter(|node| node.b >> 2 > 0) {
            for object in &bvh.objects[node.a as usize..(node.a + (node.b >> 2)) as usize] {
                let [lo, hi] = object.shape.bounds();
                for axis in 0..3 {
                    assert!(node.lo[axis] <= lo[axis] && hi[axis] <= node.hi[axis]);
                }
            }
        }
    }
}
