//! The scene in the form the oracle traces: f64 shapes, each with its material, the list of
//! emitting parallelograms for light sampling, the directional light and the sky.

use glam::DVec3;
use illum_scene::{Feature, MaterialKind, Scene, SceneError, Shape};

use crate::geometry::{Ball, OrientedBox, Parallelogram, Surface, dvec, mesh_surfaces};

/// What the oracle implements: every feature of the scene model, written independently of the
/// GPU path tracer (it shares no code with the WGSL).
pub fn implements(feature: Feature) -> bool {
    match feature {
        Feature::BoxShape
        | Feature::QuadShape
        | Feature::SphereShape
        | Feature::Lambertian
        | Feature::Checker
        | Feature::Dielectric
        | Feature::Mirror
        | Feature::AreaLight
        | Feature::DeltaDirectionalLight
        | Feature::SunDisc
        | Feature::MeshShape
        | Feature::SmoothShading
        | Feature::Environment => true,
    }
}

/// One object: its surface and its material (`albedo` is the Lambertian albedo, zero for every
/// other kind; `emission` an emitter's radiance).
#[derive(Clone, Copy, Debug)]
pub struct Primitive {
    pub surface: Surface,
    pub material: MaterialKind,
    pub albedo: DVec3,
    pub emission: DVec3,
    pub emitter: bool,
}

/// The directional light: `to_light` is the unit vector toward it (the disc's centre),
/// `irradiance` what a surface facing it receives. `cos_max` = cos(angular radius): 1 for a
/// delta light. A disc of angular radius a and uniform radiance L gives irradiance
/// L pi sin^2(a) at normal incidence, so its radiance is `irradiance / (pi sin^2 a)`.
#[derive(Clone, Copy, Debug)]
pub struct Sun {
    pub to_light: DVec3,
    pub irradiance: DVec3,
    pub cos_max: f64,
}

impl Sun {
    pub fn is_delta(&self) -> bool {
        self.cos_max >= 1.0
    }

    /// The radiance of a finite disc.
    pub fn radiance(&self) -> DVec3 {
        self.irradiance / (std::f64::consts::PI * (1.0 - self.cos_max * self.cos_max))
    }
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
    pub sun: Option<Sun>,
    /// The environment's radiance (zero without one).
    pub sky: DVec3,
}

impl TraceScene {
    /// Converts a validated scene. Objects whose material emits are emitters; validation allows
    /// emission on quads only.
    pub fn new(scene: &Scene) -> Result<TraceScene, SceneError> {
        scene.require("oracle", implements)?;
        let sun = scene.directional_light.map(|l| Sun {
            to_light: -dvec(l.direction).normalize(),
            irradiance: dvec(l.irradiance),
            cos_max: f64::from(l.angular_radius_deg).to_radians().cos(),
        });
        let mut out = TraceScene {
            surfaces: Vec::new(),
            emitters: Vec::new(),
            lights: Vec::new(),
            light_area: 0.0,
            sun,
            sky: scene.environment.map_or(DVec3::ZERO, |e| dvec(e.radiance)),
        };
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
                Shape::Mesh(mesh) => {
                    // Validation refuses emitting meshes: each triangle only scatters light.
                    out.surfaces.extend(mesh_surfaces(mesh).map(|surface| Primitive {
                        surface,
                        material: material.kind,
                        albedo: dvec(material.diffuse_albedo().unwrap_or_default()),
                        emission: DVec3::ZERO,
                        emitter: false,
                    }));
                    continue;
                }
            };
            let primitive = Primitive {
                surface,
                material: material.kind,
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
