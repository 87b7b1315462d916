//! The scene's objects as both ray tracers' traversals see them ([`Geometry`]): in the order the
//! shaders store them, with what shadow rays can be aimed at, and the meshes' and analytic objects' forms
//! (literals or a BVH). `traversal.rs` generates the WGSL from it.

use std::sync::Arc;

use illum_scene::{Scene, Shape};

use crate::analytic_bvh::{self, AnalyticBvh};
use crate::bvh::{Bvh, MeshTriangle};
use crate::mesh_traversal::MeshForm;
use crate::object::{GpuObject, ObjectRecord, ordered_objects};

/// What a traversal is generated from: the scene's objects in the order the shaders store them,
/// and what shadow rays can be aimed at.
#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    /// The scene's name, for the generated module's comments.
    pub scene: String,
    /// Non-emitters first, then emitters ([`ordered_objects`]); with objects under a BVH, those
    /// first of all, in its leaf order ([`analytic_bvh::arrange`]).
    pub objects: Vec<GpuObject>,
    /// Each object's name, in the same order.
    pub names: Vec<String>,
    /// Each object's index in the scene's objects, in the same order.
    pub scene_index: Vec<usize>,
    /// The index of the first emitter in `objects`.
    pub first_emitter: u32,
    /// The corners of every emitting quad: every point a shadow ray toward an area light (or a
    /// point light standing for one) can end at lies in their convex hulls.
    pub light_corners: Vec<[f32; 3]>,
    /// Whether a shadow ray can leave in any direction: a directional light, or an emitter that
    /// is not a quad. Then every object may block a light.
    pub unbounded_lights: bool,
    /// The triangles of every mesh object, as literals or under a BVH (mesh_traversal.rs);
    /// `None` for a scene without a mesh, whose traversal has no mesh code.
    pub meshes: Option<MeshForm>,
    /// The hierarchy over the analytic objects 0 to n - 1, for a scene with more than
    /// [`analytic_bvh::LITERAL_OBJECTS`] that may go under one; `None` when all are literals.
    pub analytic: Option<Arc<AnalyticBvh>>,
}

impl Geometry {
    pub fn new(scene: &Scene) -> Self {
        let (mut ordered, first_emitter) = ordered_objects(scene);
        let analytic = analytic_bvh::arrange(&mut ordered);
        let mut light_corners = Vec::new();
        let mut unbounded_lights = scene.directional_light.is_some();
        for (index, object) in &ordered {
            if !object.emitter {
                continue;
            }
            match scene.objects[*index].shape {
                Shape::Quad(q) => {
                    let (p, u, v) = (q.corner, q.edge_u, q.edge_v);
                    light_corners.extend([p, p + u, p + v, p + u + v].map(|c| c.to_array()));
                }
                _ => unbounded_lights = true,
            }
        }
        let triangles: Vec<MeshTriangle> = scene
            .objects
            .iter()
            .enumerate()
            .filter_map(|(index, o)| match &o.shape {
                Shape::Mesh(mesh) => Some(
                    (0..mesh.triangles.len())
                        .map(move |i| MeshTriangle::new(mesh.triangle(i), o.material as u32, index as u32)),
                ),
                _ => None,
            })
            .flatten()
            .collect();
        Self {
            meshes: (!triangles.is_empty()).then(|| MeshForm::of(triangles)),
            scene: scene.name.clone(),
            names: ordered.iter().map(|(i, _)| scene.objects[*i].name.clone()).collect(),
            scene_index: ordered.iter().map(|(i, _)| *i).collect(),
            objects: ordered.into_iter().map(|(_, object)| object).collect(),
            analytic,
            first_emitter,
            light_corners,
            unbounded_lights,
        }
    }

    /// The BVH over the mesh triangles, for a scene with more of them than the traversal writes
    /// as literals.
    pub fn mesh_bvh(&self) -> Option<&Bvh> {
        match &self.meshes {
            Some(MeshForm::Bvh(bvh)) => Some(bvh),
            _ => None,
        }
    }

    /// The objects as the shaders' storage buffers hold them.
    pub fn object_records(&self) -> Vec<ObjectRecord> {
        self.objects.iter().map(GpuObject::record).collect()
    }
}
