//! The scene in the form the oracle traces: f64 shapes, each with its material, and the list of
//! emitting parallelograms for light sampling.

use glam::{DVec3, Vec3};
use illum_scene::{Feature, RendererKind, Scene, SceneError, Shape};

use crate::geometry::{Ball, OrientedBox, Parallelogram, Surface};

/// What the oracle implements: the same scenes as the GPU path tracer today, written
/// independently (it shares no code with the WGSL).
pub const FEATURES: &[Feature] =
    &[Feature::BoxShape, Feature::QuadShape, Feature::SphereShape, Feature::Lambertian, Feature::AreaLight];

pub(crate) fn dvec(v: Vec3) -> DVec3 {
    v.as_dvec3()
}

/// One object: its surface and, as Lambertian albedo or emitted radiance, its material.
#[derive(Clone, Copy, Debug)]
pub struct Primitive {
    pub surface: Surface,
    pub albedo: DVec3,
    pub emission: DVec3,
    pub emitter: bool,
}

/// An emitting parallelogram and the running total of light area up to and including it.
#[derive(Clone, Copy, Debug)]
pub struct Light {
    pub shape: Parallelogram,
    pub emission: DVec3,
    pub cumulative_area: f64,
}

#[derive(Clone, Debug)]
pub struct TraceScene {
    /// Non-emitters: the surfaces that reflect light and cast shadows.
    pub surfaces: Vec<Primitive>,
    /// Emitters: seen by camera rays (front side only) and ending bounce rays; they cast no
    /// shadows.
    pub emitters: Vec<Primitive>,
    pub lights: Vec<Light>,
    pub light_area: f64,
}

impl TraceScene {
    /// Converts a validated scene of Lambertian surfaces and area lights (anything else is
    /// refused by name). Objects whose material emits are emitters; validation allows emission
    /// on quads only.
    pub fn new(scene: &Scene) -> Result<TraceScene, SceneError> {
        scene.require(RendererKind::PathTrace, FEATURES)?;
        let mut out =
            TraceScene { surfaces: Vec::new(), emitters: Vec::new(), lights: Vec::new(), light_area: 0.0 };
        for object in &scene.objects {
            let material = &scene.materials[object.material];
            let surface = match &object.shape {
                Shape::Box(b) => Surface::Box(OrientedBox::from_shape(b)),
                Shape::Quad(q) => {
                    Surface::Parallelogram(Parallelogram::new(dvec(q.corner), dvec(q.edge_u), dvec(q.edge_v)))
                }
                Shape::Sphere(s) => {
                    Surface::Ball(Ball { center: dvec(s.center), radius: f64::from(s.radius) })
                }
            };
            let primitive = Primitive {
                surface,
                albedo: dvec(material.diffuse_albedo().unwrap_or_default()),
                emission: dvec(material.emission()),
                emitter: material.is_emitter(),
            };
            if !primitive.emitter {
                out.surfaces.push(primitive);
                continue;
            }
            out.emitters.push(primitive);
            if let Surface::Parallelogram(shape) = surface {
                out.light_area += shape.area;
                out.lights.push(Light {
                    shape,
                    emission: primitive.emission,
                    cumulative_area: out.light_area,
                });
            }
        }
        Ok(out)
    }
}
