//! Many spheres under a BVH. A scene's spheres are literals in its generated traversal, one
//! straight-line test each, up to [`LITERAL_SPHERES`] of them; past that they go under one
//! hierarchy (bvh.rs's builder, walked by bvh_traversal.rs's generated loop) read from group 1,
//! and the traversal keeps as literals only the other objects: quads and boxes (in the shipped
//! scenes the floor, walls and lights: few and large, hit by most rays) and emitters.
//!
//! The spheres under the hierarchy are the first objects of the scene's order, in leaf order,
//! so that a leaf's range of primitives is a range of object indices: the walk reports a hit's
//! object index with no lookup, and object_at builds the record of any of them from its sphere.
//!
//! The walk reads the nodes and the spheres from uniform buffers, declared in the generated
//! traversal with the scene's sizes: on lavapipe a storage-buffer read at a
//! per-lane index is one bounds-checked scalar load per lane, and the same walk over storage
//! buffers ran 2 to 4 times slower at 200 spheres (no faster than the literal list), while
//! uniform buffers made it 2 to 4 times faster than the list (docs/performance.md, "Many
//! spheres"). A uniform binding holds 64 KiB on every device WebGPU allows (wgpu's default
//! limit), which bounds the spheres under the hierarchy at [`MAX_BVH_SPHERES`].

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use illum_scene::{Scene, SceneError};

use crate::bvh::{BvhNode, Hierarchy};
use crate::object::{GpuObject, GpuShape, ObjectRecord};

/// Up to this many non-emitting spheres are literals; past it, a BVH. The crossover measured on
/// lavapipe, time to the first image and throughput both, is in docs/performance.md ("Many
/// spheres"): a literal list's compile time grows with its length, and a BVH walk costs a loop
/// and per-lane buffer reads that a few literals do not.
pub const LITERAL_SPHERES: usize = 16;

/// The most spheres the hierarchy holds: its nodes (at most 2n - 1 of 32 bytes) and its spheres
/// (32 bytes each) each fit a 64 KiB uniform binding. A scene with more is refused
/// ([`check_count`]): as literals its traversal would take minutes to compile.
pub const MAX_BVH_SPHERES: usize = 1024;

/// The spheres' hierarchy: its nodes (the root first) and the records of the spheres, objects
/// 0 to `records.len() - 1`.
#[derive(Clone, Debug, PartialEq)]
pub struct SphereBvh {
    pub nodes: Vec<BvhNode>,
    pub records: Vec<ObjectRecord>,
}

/// One sphere as `struct BvhSphere` in bvh.wgsl: (centre, radius) and material.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct BvhSphere {
    pub sphere: [f32; 4],
    pub material: u32,
    pub padding: [u32; 3],
}

impl SphereBvh {
    /// The spheres as the uniform buffer holds them, in leaf order.
    pub fn spheres(&self) -> Vec<BvhSphere> {
        self.records
            .iter()
            .map(|r| BvhSphere { sphere: r.a, material: r.material, padding: [0; 3] })
            .collect()
    }
}

/// The uniform buffers the walk reads, declared with this scene's sizes (group 1: the nodes at
/// binding 2, the spheres at 3), and their reads: `sphere_node(i)`, `sphere_at(i)` (centre,
/// radius) and `sphere_object(i)`, the record [`GpuObject::record`] makes of sphere i.
pub(crate) fn declarations(bvh: &SphereBvh) -> String {
    format!(
        "@group(1) @binding(2) var<uniform> sphere_nodes: array<BvhNode, {}>;
@group(1) @binding(3) var<uniform> spheres: array<BvhSphere, {}>;

fn sphere_node(i: u32) -> BvhNode {{
    return sphere_nodes[i];
}}

fn sphere_at(i: u32) -> vec4<f32> {{
    return spheres[i].sphere;
}}

fn sphere_object(i: u32) -> Object {{
    let s = spheres[i];
    let zero = vec4<f32>(0.0);
    return Object(KIND_SPHERE, s.material, 0u, 0u, s.sphere, zero, zero, zero);
}}

",
        bvh.nodes.len(),
        bvh.records.len()
    )
}

fn is_bvh_sphere(object: &GpuObject) -> bool {
    !object.emitter && matches!(object.shape, GpuShape::Sphere { .. })
}

fn bvh_sphere_count<'a>(objects: impl IntoIterator<Item = &'a GpuObject>) -> usize {
    objects.into_iter().filter(|o| is_bvh_sphere(o)).count()
}

/// Whether the objects (in the scene's order) put their spheres under a BVH.
pub fn spheres_under_bvh<'a>(objects: impl IntoIterator<Item = &'a GpuObject>) -> bool {
    bvh_sphere_count(objects) > LITERAL_SPHERES
}

/// Refuses more non-emitting spheres among `objects` (`scene`'s, in any order) than
/// [`MAX_BVH_SPHERES`], by count, limit and remedy.
pub fn check_count(scene: &Scene, objects: &[GpuObject]) -> Result<(), SceneError> {
    let count = bvh_sphere_count(objects);
    if count <= MAX_BVH_SPHERES {
        return Ok(());
    }
    Err(SceneError::invalid(
        &scene.source,
        "objects (spheres)",
        format!("{count} non-emitting spheres"),
        format!(
            "the GPU ray tracers hold at most {MAX_BVH_SPHERES} (the most whose hierarchy fits a 64 KiB \
             uniform binding); remove spheres, or model some of them as one triangle mesh"
        ),
    ))
}

/// With more non-emitting spheres than [`LITERAL_SPHERES`] among `ordered` (the scene's order:
/// non-emitters, then emitters, each with its index in the scene), moves them to the front in
/// the leaf order of a hierarchy built over them, and returns the hierarchy. The rest keep
/// their order, so emitters stay last.
pub fn arrange<T>(ordered: &mut Vec<(T, GpuObject)>) -> Option<Arc<SphereBvh>> {
    if !spheres_under_bvh(ordered.iter().map(|(_, o)| o)) {
        return None;
    }
    let (spheres, rest): (Vec<_>, Vec<_>) =
        std::mem::take(ordered).into_iter().partition(|(_, o)| is_bvh_sphere(o));
    let hierarchy = Hierarchy::build(spheres.iter().map(|(_, o)| match o.shape {
        GpuShape::Sphere { center, radius } => {
            [center - glam::Vec3::splat(radius), center + glam::Vec3::splat(radius)]
        }
        _ => unreachable!("only spheres are partitioned out"),
    }));
    let mut slots: Vec<Option<(T, GpuObject)>> = spheres.into_iter().map(Some).collect();
    ordered.extend(hierarchy.order.iter().map(|&i| slots[i].take().expect("the order is a permutation")));
    let records = ordered.iter().map(|(_, o)| o.record()).collect();
    ordered.extend(rest);
    Some(Arc::new(SphereBvh { nodes: hierarchy.nodes, records }))
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn sphere(x: f32, emitter: bool) -> GpuObject {
        GpuObject {
            shape: GpuShape::Sphere { center: Vec3::new(x, 0.0, 0.0), radius: 0.25 },
            material: 0,
            emitter,
        }
    }

    fn quad() -> GpuObject {
        GpuObject {
            shape: GpuShape::Quad { corner: Vec3::ZERO, edge_u: Vec3::X, edge_v: Vec3::Z },
            material: 1,
            emitter: false,
        }
    }

    /// A few spheres stay literals in place; more move first, in leaf order, past the most the
    /// GPU ray tracers take too (check_count refuses those by name, so none fall back to a
    /// literal list that would take minutes to compile).
    #[test]
    fn a_few_spheres_stay_in_place_and_more_move_first_in_leaf_order() {
        let objects = |n: usize| {
            let mut o: Vec<(usize, GpuObject)> = vec![(0, quad())];
            o.extend((0..n).map(|i| (i + 1, sphere(((i * 7) % n) as f32, false))));
            o.push((n + 1, sphere(0.0, true)));
            o
        };
        let mut few = objects(LITERAL_SPHERES);
        let before = few.clone();
        assert!(arrange(&mut few).is_none());
        assert_eq!(few, before);

        for n in [LITERAL_SPHERES + 1, MAX_BVH_SPHERES + 1] {
            check_arranged(n, objects(n));
        }
    }

    fn check_arranged(n: usize, mut many: Vec<(usize, GpuObject)>) {
        let bvh = arrange(&mut many).expect("a BVH past the limit");
        // The spheres first (each once), then the quad, then the emitter: the same objects.
        let mut indices: Vec<usize> = many[..n].iter().map(|(i, _)| *i).collect();
        indices.sort_unstable();
        assert_eq!(indices, (1..=n).collect::<Vec<_>>());
        assert_eq!(many[n], (0, quad()));
        assert_eq!(many[n + 1].0, n + 1);
        assert_eq!(bvh.records, many[..n].iter().map(|(_, o)| o.record()).collect::<Vec<_>>());
        // Every leaf's range holds spheres inside its bounds.
        for node in bvh.nodes.iter().filter(|node| node.b >> 2 > 0) {
            for record in &bvh.records[node.a as usize..(node.a + (node.b >> 2)) as usize] {
                for axis in 0..3 {
                    let (c, r) = (record.a[axis], record.a[3]);
                    assert!(node.lo[axis] <= c - r && c + r <= node.hi[axis]);
                }
            }
        }
    }
}
