//! The objects as every compute ray tracer stores them: each shape in the form its ray test
//! wants, and the 80-byte record the shaders read (`struct Object` in `shaders/geometry.wgsl`).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use illum_scene::{Scene, Shape};

use crate::spawn::spawn_error;

fn v4(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

/// The kinds of shape the shader tests rays against. Declared in the order of their names, so
/// that a set of kinds lists them as the generated code expects.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ShapeKind {
    /// A box without rotation, stored by its world bounds: the shader skips the frame change.
    Aabb,
    /// A box rotated about +Y.
    Box,
    Quad,
    Sphere,
    /// A mesh's triangle, under the scene's BVH (bvh.rs): its constant is generated into the
    /// traversal of a scene with a mesh only, so that other scenes' shaders stay as they were.
    Triangle,
}

impl ShapeKind {
    /// Every analytic kind (all but [`ShapeKind::Triangle`]), in the order of their names: the
    /// codes module's constants.
    pub const ALL: [ShapeKind; 4] = [ShapeKind::Aabb, ShapeKind::Box, ShapeKind::Quad, ShapeKind::Sphere];

    /// Its `KIND_*` value in the shaders (the `illum::rtcore::codes` module is generated from
    /// these).
    pub fn code(self) -> u32 {
        match self {
            ShapeKind::Box => 0,
            ShapeKind::Quad => 1,
            ShapeKind::Sphere => 2,
            ShapeKind::Aabb => 3,
            ShapeKind::Triangle => 4,
        }
    }

    /// Its name: "aabb", "box", "quad" or "sphere".
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Aabb => "aabb",
            ShapeKind::Box => "box",
            ShapeKind::Quad => "quad",
            ShapeKind::Sphere => "sphere",
            ShapeKind::Triangle => "triangle",
        }
    }

    /// The name of its `KIND_*` constant.
    pub fn wgsl_constant(self) -> &'static str {
        match self {
            ShapeKind::Aabb => "KIND_AABB",
            ShapeKind::Box => "KIND_BOX",
            ShapeKind::Quad => "KIND_QUAD",
            ShapeKind::Sphere => "KIND_SPHERE",
            ShapeKind::Triangle => "KIND_TRIANGLE",
        }
    }

    /// The geometry.wgsl function that reconstructs its surface at a hit point.
    pub fn surface_function(self) -> &'static str {
        match self {
            ShapeKind::Aabb => "surface_aabb",
            ShapeKind::Box => "surface_box",
            ShapeKind::Quad => "surface_quad",
            ShapeKind::Sphere => "surface_sphere",
            ShapeKind::Triangle => "surface_triangle",
        }
    }
}

/// One shape as the shader tests it, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GpuShape {
    /// An axis-aligned box `[min, max]`.
    Aabb {
        min: Vec3,
        max: Vec3,
    },
    /// A box `[local_min, local_max]` rotated about +Y by the angle of (`cos`, `sin`), then moved
    /// by `offset`: world = R_y local + offset.
    Box {
        local_min: Vec3,
        local_max: Vec3,
        cos: f32,
        sin: f32,
        offset: Vec3,
    },
    /// The parallelogram `corner + s edge_u + t edge_v`, s and t in [0, 1].
    Quad {
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
    },
    Sphere {
        center: Vec3,
        radius: f32,
    },
}

impl GpuShape {
    pub fn kind(&self) -> ShapeKind {
        match self {
            GpuShape::Aabb { .. } => ShapeKind::Aabb,
            GpuShape::Box { .. } => ShapeKind::Box,
            GpuShape::Quad { .. } => ShapeKind::Quad,
            GpuShape::Sphere { .. } => ShapeKind::Sphere,
        }
    }

    /// Its axis-aligned bounds `[lo, hi]` (lo <= hi; flat for a quad on an axis plane).
    pub fn bounds(&self) -> [Vec3; 2] {
        let points: Vec<Vec3> = match *self {
            GpuShape::Aabb { min, max } => vec![min, max],
            GpuShape::Box { local_min, local_max, cos: c, sin: s, offset } => (0..8)
                .map(|i| {
                    let l = Vec3::select(
                        glam::BVec3::new(i & 1 == 0, i & 2 == 0, i & 4 == 0),
                        local_min,
                        local_max,
                    );
                    Vec3::new(c * l.x + s * l.z + offset.x, l.y + offset.y, -s * l.x + c * l.z + offset.z)
                })
                .collect(),
            GpuShape::Quad { corner, edge_u, edge_v } => {
                vec![corner, corner + edge_u, corner + edge_v, corner + edge_u + edge_v]
            }
            GpuShape::Sphere { center, radius } => vec![center - radius, center + radius],
        };
        points.into_iter().fold([Vec3::INFINITY, Vec3::NEG_INFINITY], |[lo, hi], p| [lo.min(p), hi.max(p)])
    }
}

/// One object of the uploaded scene: its shape, its material (an index into the scene's
/// materials) and whether it emits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuObject {
    pub shape: GpuShape,
    pub material: u32,
    pub emitter: bool,
}

impl GpuObject {
    /// The record the shader reads (see [`ObjectRecord`]).
    pub fn record(&self) -> ObjectRecord {
        let (a, b, c, d) = match self.shape {
            // Also a box rotated by zero (cos 1, sin 0, no offset) whose rebuilt points are exact
            // (error bound 0), so that surface_box can serve both kinds (traversal.rs).
            GpuShape::Aabb { min, max } => (v4(min, 1.0), v4(max, 0.0), [0.0; 4], [0.0; 4]),
            GpuShape::Box { local_min, local_max, cos, sin, offset } => {
                // The error bound of its rebuilt points (geometry.wgsl, surface_box), computed
                // here once instead of at every hit; the same f32 operations as the shader's.
                let magnitude = offset.abs().max_element()
                    + 2.0 * local_min.abs().max_element().max(local_max.abs().max_element());
                (v4(local_min, cos), v4(local_max, sin), v4(offset, spawn_error(magnitude)), [0.0; 4])
            }
            GpuShape::Quad { corner, edge_u, edge_v } => {
                (v4(corner, 0.0), v4(edge_u, 0.0), v4(edge_v, 0.0), v4(edge_u.cross(edge_v), 0.0))
            }
            GpuShape::Sphere { center, radius } => (v4(center, radius), [0.0; 4], [0.0; 4], [0.0; 4]),
        };
        ObjectRecord {
            kind: self.shape.kind().code(),
            material: self.material,
            emitter: self.emitter as u32,
            padding: 0,
            a,
            b,
            c,
            d,
        }
    }
}

/// Mirrors `struct Object` in geometry.wgsl: the storage form of a [`GpuObject`], whose four
/// vectors `a..d` hold each kind's own numbers (see there); only [`GpuObject::record`] fills it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct ObjectRecord {
    pub kind: u32,
    pub material: u32,
    pub emitter: u32,
    pub padding: u32,
    pub a: [f32; 4],
    pub b: [f32; 4],
    pub c: [f32; 4],
    pub d: [f32; 4],
}

/// The shape as the shader tests it: a box without rotation as world bounds, a rotated box by
/// its local bounds and the rotation's cosine and sine.
pub fn gpu_shape(shape: &Shape) -> GpuShape {
    match *shape {
        Shape::Box(b) if b.rotate_y_deg == 0.0 => {
            GpuShape::Aabb { min: b.min + b.translate, max: b.max + b.translate }
        }
        Shape::Box(b) => {
            let (rotation, offset) = b.local_to_world();
            // rotation is R_y(angle): its first column is (cos, 0, -sin).
            let (cos, sin) = (rotation.x_axis.x, -rotation.x_axis.z);
            GpuShape::Box { local_min: b.min, local_max: b.max, cos, sin, offset }
        }
        Shape::Quad(q) => GpuShape::Quad { corner: q.corner, edge_u: q.edge_u, edge_v: q.edge_v },
        Shape::Sphere(s) => GpuShape::Sphere { center: s.center, radius: s.radius },
        Shape::Mesh(_) => {
            unreachable!("a mesh is not an analytic shape: ordered_objects leaves it to the BVH")
        }
    }
}

/// The scene's analytic objects as every compute ray tracer stores them: non-emitters first,
/// then emitters (the shaders rely on this order to let a light win a tie with the surface it is
/// set into), each with its index in `scene.objects`; and the index of the first emitter. Mesh
/// objects are not among them: their triangles are under the scene's BVH (bvh.rs).
pub fn ordered_objects(scene: &Scene) -> (Vec<(usize, GpuObject)>, u32) {
    let object = |(i, o): (usize, &illum_scene::Object)| {
        let emitter = scene.materials[o.material].is_emitter();
        (i, GpuObject { shape: gpu_shape(&o.shape), material: o.material as u32, emitter })
    };
    let (mut ordered, emitters): (Vec<_>, Vec<_>) = scene
        .objects
        .iter()
        .enumerate()
        .filter(|(_, o)| !matches!(o.shape, Shape::Mesh(_)))
        .map(object)
        .partition(|(_, o)| !o.emitter);
    let first_emitter = ordered.len() as u32;
    ordered.extend(emitters);
    (ordered, first_emitter)
}
