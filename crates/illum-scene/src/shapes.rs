//! Shapes: the geometry an object has. Every value here has passed validation (see
//! `validate.rs`): vectors are finite and extents positive.

use glam::{Mat3, Vec3};

use crate::mesh::MeshRef;

#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Box(BoxShape),
    Quad(Quad),
    Sphere(Sphere),
    /// A triangle mesh read from a file (`mesh.rs`).
    Mesh(MeshRef),
}

impl Shape {
    /// The word a file uses for this shape (`box`, `quad`, `sphere`, `mesh`).
    pub fn kind(&self) -> &'static str {
        match self {
            Shape::Box(_) => "box",
            Shape::Quad(_) => "quad",
            Shape::Sphere(_) => "sphere",
            Shape::Mesh(_) => "mesh",
        }
    }
}

/// An axis-aligned box [min, max] in its local frame, rotated by `rotate_y_deg` about the +Y axis
/// through `pivot` (right-handed, as glam's `Mat3::from_rotation_y`), then moved by `translate`:
/// `world = R (local - pivot) + pivot + translate`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxShape {
    pub min: Vec3,
    pub max: Vec3,
    pub rotate_y_deg: f32,
    pub pivot: Vec3,
    pub translate: Vec3,
}

impl BoxShape {
    /// The rotation and offset of `world = rotation * local + offset`.
    pub fn local_to_world(&self) -> (Mat3, Vec3) {
        let rotation = Mat3::from_rotation_y(self.rotate_y_deg.to_radians());
        let offset = self.pivot + self.translate - rotation * self.pivot;
        (rotation, offset)
    }

    /// The eight world-space corners; bit 0, 1, 2 of the index pick max over min in x, y, z.
    pub fn world_corners(&self) -> [Vec3; 8] {
        let (rotation, offset) = self.local_to_world();
        std::array::from_fn(|i| {
            let pick = |bit: usize, lo: f32, hi: f32| if i >> bit & 1 == 1 { hi } else { lo };
            let local = Vec3::new(
                pick(0, self.min.x, self.max.x),
                pick(1, self.min.y, self.max.y),
                pick(2, self.min.z, self.max.z),
            );
            rotation * local + offset
        })
    }
}

/// A parallelogram `corner + s * edge_u + t * edge_v`, s, t in [0, 1]. Its front side (the side
/// an emitter lights) faces `normalize(edge_u x edge_v)`. A checkerboard material counts its
/// tiles from `corner` along `edge_u` and `edge_v` (see [`Checker`](crate::Checker)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quad {
    pub corner: Vec3,
    pub edge_u: Vec3,
    pub edge_v: Vec3,
}

impl Quad {
    /// The unit normal (NaN for a degenerate quad), normalised after dividing by the largest
    /// component, so that a quad whose area is finite in f32 has a finite normal even where the
    /// squared length of `edge_u x edge_v` would overflow.
    pub fn normal(&self) -> Vec3 {
        crate::camera::robust_normalize(self.edge_u.cross(self.edge_v)).unwrap_or(Vec3::NAN)
    }
    /// `|edge_u x edge_v|`, measured the same way: finite for every quad whose area f32 holds.
    pub fn area(&self) -> f32 {
        let cross = self.edge_u.cross(self.edge_v);
        let scale = cross.abs().max_element();
        if scale > 0.0 && scale.is_finite() { (cross / scale).length() * scale } else { cross.length() }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
}
