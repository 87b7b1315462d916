//! The path tracer's scene as its shaders see it: lights and parameters laid out like the WGSL
//! structs of `shaders/scene.wgsl`, beside the code that fills them; the objects, materials and
//! camera are illum-rtcore's records.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use illum_scene::{Bounces, Feature, RendererKind, Scene, Shape};

use illum_rtcore::{CameraRecord, Geometry, MaterialRecord, ObjectRecord, ordered_objects};

use crate::PathTraceError;
use crate::scene_code::SceneCode;

/// What of the scene model the path tracer implements: all of it. Each feature is compiled
/// into a scene's pipeline only when the scene uses it (see [`crate::specialise`]).
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

/// `Params::bounces` value meaning "unbounded, with Russian roulette".
pub const UNBOUNDED: u32 = u32::MAX;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuLight {
    /// xyz = corner, w = running sum of light areas up to and including this one.
    pub corner: [f32; 4],
    /// xyz = edge_u, w = this light's area.
    pub edge_u: [f32; 4],
    pub edge_v: [f32; 4],
    pub normal: [f32; 4],
    pub emission: [f32; 4],
}

/// Mirrors `struct Params` in scene.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuParams {
    pub camera: CameraRecord,
    pub light_area: f32,
    pub num_objects: u32,
    pub width: u32,
    pub height: u32,
    pub row_offset: u32,
    pub rows: u32,
    pub sample_base: u32,
    pub sample_count: u32,
    pub seed: u32,
    pub bounces: u32,
    pub num_lights: u32,
    pub first_emitter: u32,
    /// Samples per invocation: each invocation traces one chunk of a pixel's samples and writes
    /// its own slot (see the tracer).
    pub chunk_samples: u32,
    /// Unused: the vectors after them start at a multiple of 16 bytes, as in WGSL.
    pub padding_a: u32,
    pub padding_b: u32,
    pub padding_c: u32,
    /// The directional light: xyz toward it, w = 1 - cos(angular radius) (see
    /// [`one_minus_cos`]); its irradiance (scaled
    /// like every emission by 2^-radiance_exponent).
    pub sun: [f32; 4],
    pub sun_irradiance: [f32; 4],
    /// The environment's radiance (scaled likewise).
    pub sky: [f32; 4],
}

/// The uploaded form of a scene.
#[derive(Clone, Debug)]
pub struct GpuScene {
    /// The objects, emitters last, as the traversal is generated from them.
    pub geometry: Geometry,
    pub materials: Vec<MaterialRecord>,
    pub lights: Vec<GpuLight>,
    /// Sum of all light areas (the light-sampling pdf is its inverse).
    pub light_area: f32,
    /// What of the scene model its pipeline contains.
    pub code: SceneCode,
    /// Every emission above was multiplied by 2^-`radiance_exponent` (0 unless a light exceeds
    /// 2^16; see [`crate::accumulator::radiance_exponent`]), so the GPU's samples are the true
    /// ones times 2^-k, exactly.
    pub radiance_exponent: i32,
}

/// 1 - cos(a) for a sun of angular radius `degrees`, as 2 sin^2(a / 2) in f64: exact to f32
/// precision for any radius (cos a itself rounds to 1 in f32 below about 0.02 degrees).
fn one_minus_cos(degrees: f32) -> f32 {
    let half = f64::from(degrees).to_radians() / 2.0;
    (2.0 * half.sin() * half.sin()) as f32
}

fn v4(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

impl GpuScene {
    pub fn new(scene: &Scene) -> Result<Self, PathTraceError> {
        scene.require(RendererKind::PathTrace.noun(), implements)?;
        let sun = scene.directional_light.map_or(0.0, |l| l.irradiance.max_element());
        let sky = scene.environment.map_or(0.0, |e| e.radiance.max_element());
        let max_emission =
            scene.materials.iter().map(|m| m.emission().max_element()).fold(sun.max(sky), f32::max);
        let radiance_exponent = crate::accumulator::radiance_exponent(max_emission);
        let emission_scale = 2f32.powi(-radiance_exponent);
        let materials =
            scene.materials.iter().map(|m| MaterialRecord::new(&m.kind, emission_scale)).collect();
        let (objects, _) = ordered_objects(scene);
        let mut lights = Vec::new();
        let mut light_area = 0.0f32;
        for (index, object) in &objects {
            let material = &scene.materials[object.material as usize];
            match (object.emitter, &scene.objects[*index].shape) {
                (true, Shape::Quad(q)) => {
                    let area = q.area();
                    light_area += area;
                    lights.push(GpuLight {
                        corner: v4(q.corner, light_area),
                        edge_u: v4(q.edge_u, area),
                        edge_v: v4(q.edge_v, 0.0),
                        normal: v4(q.normal(), 0.0),
                        emission: v4(material.emission() * emission_scale, 0.0),
                    });
                }
                (true, _) => {
                    return Err(PathTraceError::Unsupported {
                        scene: scene.name.clone(),
                        message: format!(
                            "object {:?} emits light but is not a quad; only rectangular lights can be sampled",
                            scene.objects[*index].name
                        ),
                    });
                }
                (false, _) => {}
            }
        }
        if lights.is_empty() && scene.directional_light.is_none() && scene.environment.is_none() {
            return Err(PathTraceError::Unsupported {
                scene: scene.name.clone(),
                message: "the scene has no light (a quad whose material has emission > 0, a \
                          [directional_light] or an [environment]); the path tracer would render black"
                    .to_owned(),
            });
        }
        let code = SceneCode::new(scene, lights.len());
        Ok(Self { geometry: Geometry::new(scene), materials, lights, light_area, code, radiance_exponent })
    }
}

impl GpuScene {
    /// The objects as the shader's storage buffer holds them.
    pub fn object_records(&self) -> Vec<ObjectRecord> {
        self.geometry.object_records()
    }
}

/// The per-dispatch parameters for `scene` with its current render settings.
pub fn params(scene: &Scene, gpu_scene: &GpuScene) -> GpuParams {
    let scale = 2f32.powi(-gpu_scene.radiance_exponent);
    GpuParams {
        camera: CameraRecord::new(&scene.camera),
        light_area: gpu_scene.light_area,
        num_objects: gpu_scene.geometry.objects.len() as u32,
        width: scene.camera.width,
        height: scene.camera.height,
        row_offset: 0,
        rows: scene.camera.height,
        sample_base: 0,
        sample_count: 0,
        seed: scene.pathtrace.seed,
        bounces: match scene.pathtrace.bounces {
            Bounces::Fixed(n) => n,
            Bounces::Unbounded => UNBOUNDED,
        },
        num_lights: gpu_scene.lights.len() as u32,
        first_emitter: gpu_scene.geometry.first_emitter,
        chunk_samples: crate::batch::CHUNK_SAMPLES,
        padding_a: 0,
        padding_b: 0,
        padding_c: 0,
        sun: scene
            .directional_light
            .map_or([0.0; 4], |l| v4(l.to_light(), one_minus_cos(l.angular_radius_deg))),
        sun_irradiance: scene.directional_light.map_or([0.0; 4], |l| v4(l.irradiance * scale, 1.0)),
        sky: scene.environment.map_or([0.0; 4], |e| v4(e.radiance * scale, 1.0)),
    }
}
