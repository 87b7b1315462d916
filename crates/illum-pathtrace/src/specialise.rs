//! The path tracer's pipeline specialised for one scene ("model only what a scene requires"):
//! illum-rtcore's traversal and materials generated with the scene's numbers as literals, and
//! the path tracer's own light choice likewise. A specialised pipeline binds neither the object
//! nor the material buffer; the generic modules (`shaders/traversal.wgsl`, `materials.wgsl`,
//! `light_choice.wgsl`) read them instead.

use illum_gpu::shader::{Def, ShaderFile};
use illum_rtcore::literal::lit;
use illum_scene::{Bounces, Feature, Sampling, Scene, Sequence};

use crate::estimators::Estimators;
use crate::gpu_scene::GpuScene;
use crate::options::{TracerOptions, Traversal};

/// What of the scene model a scene's pipeline contains, derived from [`Scene::features`], its
/// lights and the render settings that choose code rather than numbers. Code a scene does not
/// use is not compiled: on a CPU driver code costs time by being in the shader, even where no
/// lane runs it (docs/performance.md, "What lavapipe does with a branch").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SceneCode {
    /// Next-event estimation on rectangular lights.
    pub area_lights: bool,
    /// More than one area light: a light is chosen per sample.
    pub light_choice: bool,
    /// A directional light.
    pub sun: bool,
    /// ... of finite angular radius (sampled in its cone).
    pub sun_disc: bool,
    /// An environment light.
    pub sky: bool,
    /// A mirror or a dielectric.
    pub specular: bool,
    pub checker: bool,
    /// The caustic's light tracer ([`Estimators::light_tracer`]).
    pub caustic: bool,
    /// ... with the photon gather (E (S|D)* D S+ L but E D S+ L, `shaders/gather.wgsl`): the
    /// caustic with a delta sun and a diffuse surface to gather on.
    /// With a sun disc the camera paths find those paths themselves.
    pub caustic_gather: bool,
    /// `sampling = "uniform"` hemisphere sampling instead of cosine.
    pub uniform_sampling: bool,
    /// `bounces = "unbounded"`: Russian roulette.
    pub unbounded_bounces: bool,
}

impl SceneCode {
    /// The code `scene` needs, with `area_lights` uploaded lights.
    pub fn new(scene: &Scene, area_lights: usize) -> Self {
        let features = scene.features();
        SceneCode {
            area_lights: area_lights > 0,
            light_choice: area_lights > 1,
            sun: features.any(&[Feature::DeltaDirectionalLight, Feature::SunDisc]),
            sun_disc: features.contains(Feature::SunDisc),
            sky: features.contains(Feature::Environment),
            specular: features.any(&[Feature::Mirror, Feature::Dielectric]),
            checker: features.contains(Feature::Checker),
            caustic: Estimators::of(scene).light_tracer(),
            caustic_gather: Estimators::of(scene).photon_gather(),
            uniform_sampling: scene.pathtrace.sampling == Sampling::Uniform,
            unbounded_bounces: scene.pathtrace.bounces == Bounces::Unbounded,
        }
    }
}

/// Everything a path-tracing pipeline is specialised for: the scene's code, the tracer's
/// options and adaptive sampling. Two pipelines with equal specialisations (and, with
/// [`Traversal::Specialised`], equal generated modules) are the same pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Specialisation {
    pub scene: SceneCode,
    pub options: TracerOptions,
    /// Each block of pixels takes its own number of samples (allocation.rs).
    pub adaptive: bool,
}

impl Specialisation {
    /// The naga_oil shader defs: the one place where their names are written.
    pub fn shader_defs(&self) -> Vec<(&'static str, Def)> {
        let code = &self.scene;
        let options = &self.options;
        let low_discrepancy = options.sequence == Sequence::LowDiscrepancy;
        let flags = [
            ("AREA_LIGHTS", code.area_lights),
            ("LIGHT_CHOICE", code.light_choice),
            ("SUN", code.sun),
            ("SUN_DISC", code.sun_disc),
            ("SKY", code.sky),
            ("SPECULAR", code.specular),
            ("CHECKER", code.checker),
            ("CAUSTIC", code.caustic),
            ("CAUSTIC_GATHER", code.caustic_gather),
            ("UNIFORM_SAMPLING", code.uniform_sampling),
            ("UNBOUNDED_BOUNCES", code.unbounded_bounces),
            ("LOW_DISCREPANCY", low_discrepancy),
            // The low-discrepancy sequence also draws light points from the bilinear fit of the
            // geometric term (sampling.wgsl, sample_light_bilinear): it lowers that sequence's
            // error by more than it adds time; independent numbers' error is mostly in the
            // bounce directions, so for them it costs more than it buys (docs/performance-levers.md).
            ("BILINEAR_LIGHT", low_discrepancy),
            // Pairs pay with the specialised traversal only: with the generic one's loop over
            // the object buffer they are slower than one path at a time (same section).
            ("PAIRED_PATHS", options.paired_paths && options.traversal == Traversal::Specialised),
            ("ADAPTIVE", self.adaptive),
        ];
        illum_gpu::shader::flag_defs(&flags)
    }
}

/// The traversal generated for `gpu_scene` (illum-rtcore's traversal.rs).
pub fn traversal(gpu_scene: &GpuScene) -> illum_rtcore::Traversal {
    illum_rtcore::traversal::generate(&gpu_scene.geometry)
}

/// The generated traversal as a shader module.
pub fn traversal_module(scene: &Scene, gpu_scene: &GpuScene) -> ShaderFile {
    traversal(gpu_scene).module(&scene.name)
}

/// The scene's materials as literals (`illum::rtcore::materials`).
pub fn materials_module(scene: &Scene, gpu_scene: &GpuScene) -> ShaderFile {
    illum_rtcore::materials_module(&scene.name, &gpu_scene.materials)
}

/// `illum::pathtrace::light_choice` for `gpu_scene`: `choose_light` compares the pick with each
/// light's running area as a literal, and with one light (or none) chooses nothing.
pub fn light_choice_module(scene: &Scene, gpu_scene: &GpuScene) -> ShaderFile {
    let lights = &gpu_scene.lights;
    let body = if lights.len() <= 1 {
        "    // One light (or none: then nothing calls this): nothing to choose.\n    return 0u;\n".to_owned()
    } else {
        let mut code = String::new();
        for (i, light) in lights.iter().enumerate().take(lights.len() - 1) {
            code.push_str(&format!(
                "    if (pick < {}) {{\n        return {i}u;\n    }}\n",
                lit(light.corner[3])
            ));
        }
        code.push_str(&format!("    return {}u;\n", lights.len() - 1));
        code
    };
    let source = format!(
        "#define_import_path illum::pathtrace::light_choice

// Generated by illum-pathtrace (specialise.rs) for scene {name:?}: its {count} lights.

// The light whose share of the total light area contains `pick` (in [0, total area)).
fn choose_light(pick: f32) -> u32 {{
{body}}}
",
        name = scene.name,
        count = lights.len(),
    );
    ShaderFile::generated(format!("generated light choice for scene {:?}", scene.name), source)
}
