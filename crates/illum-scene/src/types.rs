//! The validated, in-memory scene: what the renderers consume.
//!
//! Every value here has passed validation (see `validate.rs`): vectors are finite, extents are
//! positive, the camera is not degenerate and material indices are in range.

use glam::{Mat3, Vec3};

/// Most fixed bounces a scene may ask for (the viewer offers 0..=64; the extremes tests use 64).
pub const MAX_BOUNCES: u32 = 256;

/// A whole scene as loaded from TOML.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Scene name (the file's `name`, or its file stem).
    pub name: String,
    /// Pinhole camera and output resolution.
    pub camera: Camera,
    /// Default render settings (command-line flags may override them).
    pub render: RenderSettings,
    /// Materials, referenced by index from `objects`.
    pub materials: Vec<Material>,
    /// Geometry, in file order.
    pub objects: Vec<Object>,
}

/// Pinhole camera. `vfov_deg` is the full vertical field of view in degrees, in (0, 180).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub vfov_deg: f32,
    pub width: u32,
    pub height: u32,
}

/// Orthonormal camera frame. `right` is screen-right, `up` is screen-up, `forward` points from the
/// eye to the target; the frame is right-handed as in three.js (right = forward x up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraBasis {
    pub forward: Vec3,
    pub right: Vec3,
    pub up: Vec3,
    /// tan(vfov / 2): half the image plane's height at distance 1.
    pub tan_half_fov: f32,
    /// width / height.
    pub aspect: f32,
}

/// How many bounces of indirect light a path takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bounces {
    /// 0 = direct illumination only, 1 = one bounce of global illumination, ...
    Fixed(u32),
    /// Unbounded depth, terminated without bias by Russian roulette.
    Unbounded,
}

/// Which pdf the path tracer draws bounce directions from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sampling {
    /// pdf = cos(theta) / pi (default; lower variance on Lambertian surfaces).
    Cosine,
    /// pdf = 1 / (2 pi) (the assignment's question 2b).
    Uniform,
}

/// Render settings stored in the scene file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// Samples per pixel, >= 1.
    pub spp: u32,
    pub bounces: Bounces,
    pub seed: u32,
    pub sampling: Sampling,
}

/// A Lambertian material with optional emission. Albedo channels are in [0, 1]; emission >= 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub albedo: Vec3,
    /// Emitted radiance (W sr^-1 m^-2 in the scene's units); zero for non-emitters.
    pub emission: Vec3,
}

impl Material {
    pub fn is_emitter(&self) -> bool {
        self.emission.max_element() > 0.0
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub name: String,
    /// Index into `Scene::materials`.
    pub material: usize,
    pub shape: Shape,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    Box(BoxShape),
    Quad(Quad),
    Sphere(Sphere),
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
/// an emitter lights) faces `normalize(edge_u x edge_v)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quad {
    pub corner: Vec3,
    pub edge_u: Vec3,
    pub edge_v: Vec3,
}

impl Quad {
    pub fn normal(&self) -> Vec3 {
        self.edge_u.cross(self.edge_v).normalize()
    }
    pub fn area(&self) -> f32 {
        self.edge_u.cross(self.edge_v).length()
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
}

/// Command-line overrides of the file's settings; `None` keeps the file's value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overrides {
    pub spp: Option<u32>,
    pub bounces: Option<Bounces>,
    pub seed: Option<u32>,
    pub sampling: Option<Sampling>,
    pub width: Option<u32>,
    pub height: Option<u32>,
}

/// What the device allows, for the resolution check (filled in from `wgpu::Limits` by the caller).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DeviceLimits {
    /// Largest 2D texture side.
    pub max_texture_dimension_2d: u32,
    /// Largest single storage buffer binding, in bytes.
    pub max_storage_buffer_binding_size: u64,
}
