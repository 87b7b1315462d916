//! The scene as the shader sees it: plain-old-data structs laid out like the WGSL ones.
//!
//! Over 400 lines, one concept: each struct beside the code that fills it from the scene, so a
//! field's meaning on both sides is read in one place.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use illum_scene::{Bounces, Feature, MaterialKind, RendererKind, Sampling, Scene, Shape};

use crate::PathTraceError;
use crate::spawn::spawn_error;

/// What the path tracer implements: every feature of the scene model. Each is compiled into a
/// scene's pipeline only when the scene uses it (see [`GpuScene::shader_defs`]).
pub const FEATURES: &[Feature] = &Feature::ALL;

/// `albedo.w` of a [`GpuMaterial`]: what kind of surface it is (MATERIAL_* in pathtrace.wgsl).
const MATERIAL_LAMBERTIAN: f32 = 0.0;
const MATERIAL_CHECKER: f32 = 1.0;
const MATERIAL_DIELECTRIC: f32 = 2.0;
const MATERIAL_MIRROR: f32 = 3.0;

/// `Params::bounces` value meaning "unbounded, with Russian roulette".
pub const UNBOUNDED: u32 = u32::MAX;

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
}

impl ShapeKind {
    /// Its `KIND_*` value in scene.wgsl.
    pub fn code(self) -> u32 {
        match self {
            ShapeKind::Box => 0,
            ShapeKind::Quad => 1,
            ShapeKind::Sphere => 2,
            ShapeKind::Aabb => 3,
        }
    }

    /// Its name: "aabb", "box", "quad" or "sphere".
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Aabb => "aabb",
            ShapeKind::Box => "box",
            ShapeKind::Quad => "quad",
            ShapeKind::Sphere => "sphere",
        }
    }

    /// The name of its `KIND_*` constant in scene.wgsl.
    pub fn wgsl_constant(self) -> &'static str {
        match self {
            ShapeKind::Aabb => "KIND_AABB",
            ShapeKind::Box => "KIND_BOX",
            ShapeKind::Quad => "KIND_QUAD",
            ShapeKind::Sphere => "KIND_SPHERE",
        }
    }

    /// The scene.wgsl function that reconstructs its surface at a hit point.
    pub fn surface_function(self) -> &'static str {
        match self {
            ShapeKind::Aabb => "surface_aabb",
            ShapeKind::Box => "surface_box",
            ShapeKind::Quad => "surface_quad",
            ShapeKind::Sphere => "surface_sphere",
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
}

/// One object of the uploaded scene: its shape, its material (an index into
/// [`GpuScene::materials`]) and whether it emits.
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
            // (error bound 0), so that surface_box can serve both kinds (specialise.rs).
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

/// Mirrors `struct Object` in scene.wgsl: the storage form of a [`GpuObject`], whose four
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

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuMaterial {
    pub albedo: [f32; 4],
    pub emission: [f32; 4],
}

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
    pub eye: [f32; 3],
    pub tan_half_fov: f32,
    pub right: [f32; 3],
    pub aspect: f32,
    pub up: [f32; 3],
    pub light_area: f32,
    pub forward: [f32; 3],
    pub num_objects: u32,
    pub width: u32,
    pub height: u32,
    pub row_offset: u32,
    pub rows: u32,
    pub sample_base: u32,
    pub sample_count: u32,
    pub seed: u32,
    pub bounces: u32,
    /// Unused: keeps the members after it where the WGSL struct has them (the hemisphere
    /// sampling is a shader def, UNIFORM_SAMPLING, not a parameter).
    pub padding: u32,
    pub num_lights: u32,
    pub first_emitter: u32,
    /// Samples per invocation: each invocation traces one chunk of a pixel's samples and writes
    /// its own slot (see the tracer).
    pub chunk_samples: u32,
    /// The directional light: xyz toward it, w = cos(angular radius); its irradiance (scaled
    /// like every emission by 2^-radiance_exponent).
    pub sun: [f32; 4],
    pub sun_irradiance: [f32; 4],
    /// The environment's radiance (scaled likewise).
    pub sky: [f32; 4],
}

/// The uploaded form of a scene.
#[derive(Clone, Debug)]
pub struct GpuScene {
    /// Non-emitters first, then emitters: the shader relies on this order to let a light win a
    /// tie with the surface it is set into.
    pub objects: Vec<GpuObject>,
    pub materials: Vec<GpuMaterial>,
    pub lights: Vec<GpuLight>,
    /// Sum of all light areas (the light-sampling pdf is its inverse).
    pub light_area: f32,
    /// Index of the first emitter in `objects`.
    pub first_emitter: u32,
    /// The shader defs of the features this scene uses (see [`GpuScene::shader_defs`]).
    pub defs: Vec<&'static str>,
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
        scene.require(RendererKind::PathTrace, FEATURES)?;
        let sun = scene.directional_light.map_or(0.0, |l| l.irradiance.max_element());
        let sky = scene.environment.map_or(0.0, |e| e.radiance.max_element());
        let max_emission =
            scene.materials.iter().map(|m| m.emission().max_element()).fold(sun.max(sky), f32::max);
        let radiance_exponent = crate::accumulator::radiance_exponent(max_emission);
        let emission_scale = 2f32.powi(-radiance_exponent);
        let materials = scene
            .materials
            .iter()
            .map(|m| match m.kind {
                MaterialKind::Lambertian { albedo } => {
                    GpuMaterial { albedo: v4(albedo, MATERIAL_LAMBERTIAN), emission: [0.0; 4] }
                }
                MaterialKind::Emitter { radiance } => GpuMaterial {
                    albedo: v4(Vec3::ZERO, MATERIAL_LAMBERTIAN),
                    emission: v4(radiance * emission_scale, 0.0),
                },
                MaterialKind::Checker(c) => {
                    GpuMaterial { albedo: v4(c.even, MATERIAL_CHECKER), emission: v4(c.odd, c.tile) }
                }
                MaterialKind::Dielectric { ior } => GpuMaterial {
                    albedo: v4(Vec3::ZERO, MATERIAL_DIELECTRIC),
                    emission: [0.0, 0.0, 0.0, ior],
                },
                MaterialKind::Mirror { reflectance } => {
                    GpuMaterial { albedo: v4(reflectance, MATERIAL_MIRROR), emission: [0.0; 4] }
                }
            })
            .collect::<Vec<_>>();
        let (objects, first_emitter) = ordered_objects(scene);
        let mut lights = Vec::new();
        let mut light_area = 0.0f32;
        for (index, object) in &objects {
            let material = &scene.materials[object.material as usize];
            match (object.emitter, scene.objects[*index].shape) {
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
        let mut defs = Vec::new();
        if !lights.is_empty() {
            defs.push("AREA_LIGHTS");
        }
        if lights.len() > 1 {
            defs.push("LIGHT_CHOICE");
        }
        if let Some(sun) = &scene.directional_light {
            defs.push("SUN");
            if !sun.is_delta() {
                defs.push("SUN_DISC");
            }
        }
        if scene.environment.is_some() {
            defs.push("SKY");
        }
        let kinds = || scene.objects.iter().map(|o| scene.material_of(o).kind);
        if kinds().any(|k| matches!(k, MaterialKind::Mirror { .. } | MaterialKind::Dielectric { .. })) {
            defs.push("SPECULAR");
        }
        if kinds().any(|k| matches!(k, MaterialKind::Checker(_))) {
            defs.push("CHECKER");
        }
        if caustics_active(scene) {
            defs.push("CAUSTIC");
        }
        // Render settings that choose code rather than numbers: lavapipe runs both sides of a
        // branch on a uniform parameter for every lane, so the unused side costs its full price.
        if scene.pathtrace.sampling == Sampling::Uniform {
            defs.push("UNIFORM_SAMPLING");
        }
        if scene.pathtrace.bounces == Bounces::Unbounded {
            defs.push("UNBOUNDED_BOUNCES");
        }
        let objects = objects.into_iter().map(|(_, object)| object).collect();
        Ok(Self { objects, materials, lights, light_area, first_emitter, defs, radiance_exponent })
    }
}

/// Whether the caustic's light tracer runs for `scene`: `[pathtrace] caustics = true`, a
/// directional light, and a mirror or dielectric object that can send its light onward.
pub fn caustics_active(scene: &Scene) -> bool {
    scene.pathtrace.caustics
        && scene.directional_light.is_some()
        && scene.objects.iter().any(|o| {
            matches!(scene.material_of(o).kind, MaterialKind::Mirror { .. } | MaterialKind::Dielectric { .. })
        })
}

/// `on` or `off`: [`caustics_active`] as EXR metadata and checkpoints store it.
pub fn caustics_label(scene: &Scene) -> &'static str {
    if caustics_active(scene) { "on" } else { "off" }
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
    }
}

/// The scene's objects as every compute ray tracer stores them: non-emitters first, then
/// emitters (the shaders rely on this order to let a light win a tie with the surface it is set
/// into), each with its index in `scene.objects`; and the index of the first emitter.
pub fn ordered_objects(scene: &Scene) -> (Vec<(usize, GpuObject)>, u32) {
    let object = |(i, o): (usize, &illum_scene::Object)| {
        let emitter = scene.materials[o.material].is_emitter();
        (i, GpuObject { shape: gpu_shape(&o.shape), material: o.material as u32, emitter })
    };
    let (mut ordered, emitters): (Vec<_>, Vec<_>) =
        scene.objects.iter().enumerate().map(object).partition(|(_, o)| !o.emitter);
    let first_emitter = ordered.len() as u32;
    ordered.extend(emitters);
    (ordered, first_emitter)
}

impl GpuScene {
    /// naga_oil shader defs for the features the scene uses: AREA_LIGHTS (and LIGHT_CHOICE with
    /// more than one area light), SUN, SUN_DISC, SKY,
    /// SPECULAR (a mirror or a dielectric), CHECKER, and CAUSTIC (`caustics = true` with a
    /// directional light and a specular object: the light tracer, see tracer/caustic.rs); and
    /// for two render settings, UNIFORM_SAMPLING (`sampling = "uniform"`) and UNBOUNDED_BOUNCES
    /// (Russian roulette). The Cornell box at its defaults compiles with AREA_LIGHTS alone: none
    /// of the other features' code is in its pipeline.
    pub fn shader_defs(&self) -> Vec<(&'static str, illum_gpu::shader::Def)> {
        self.defs.iter().map(|&d| (d, illum_gpu::shader::Def::Bool(true))).collect()
    }

    /// The objects as the shader's storage buffer holds them.
    pub fn object_records(&self) -> Vec<ObjectRecord> {
        self.objects.iter().map(GpuObject::record).collect()
    }
}

/// The per-dispatch parameters for `scene` with its current render settings.
pub fn params(scene: &Scene, gpu_scene: &GpuScene) -> GpuParams {
    let basis = scene.camera.basis();
    let scale = 2f32.powi(-gpu_scene.radiance_exponent);
    GpuParams {
        eye: scene.camera.eye.to_array(),
        tan_half_fov: basis.tan_half_fov,
        right: basis.right.to_array(),
        aspect: basis.aspect,
        up: basis.up.to_array(),
        light_area: gpu_scene.light_area,
        forward: basis.forward.to_array(),
        num_objects: gpu_scene.objects.len() as u32,
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
        padding: 0,
        num_lights: gpu_scene.lights.len() as u32,
        first_emitter: gpu_scene.first_emitter,
        chunk_samples: crate::batch::CHUNK_SAMPLES,
        sun: scene
            .directional_light
            .map_or([0.0; 4], |l| v4(l.to_light(), one_minus_cos(l.angular_radius_deg))),
        sun_irradiance: scene.directional_light.map_or([0.0; 4], |l| v4(l.irradiance * scale, 1.0)),
        sky: scene.environment.map_or([0.0; 4], |e| v4(e.radiance * scale, 1.0)),
    }
}
