//! The path tracer's WGSL: the modules it composes, in import order, and its pipeline.
//!
//! Its own sampling modules (constants, random numbers, sample sequences, hemisphere and light
//! sampling) come first, then illum-rtcore's shared modules (kind codes, spawning, geometry,
//! material record, optics, camera), then its scene module, the material lookup, the traversal
//! and the light choice (each generic, or generated per scene: `specialise.rs`), and the
//! surfaces module both estimators use.

use illum_gpu::shader::{self, ShaderFile};
use illum_gpu::{GpuContext, shader_file, wgpu};
use illum_scene::Scene;

use crate::gpu_scene::GpuScene;
use crate::options::{TracerOptions, Traversal};
use crate::specialise::Specialisation;
use crate::{PathTraceError, specialise};

/// The integrator (entry point `main`).
pub const PATHTRACE_SHADER: ShaderFile = shader_file!("shaders/pathtrace.wgsl");
/// Parameters, lights and bindings.
pub const SCENE_MODULE: ShaderFile = shader_file!("shaders/scene.wgsl");
/// What both estimators need: the sun's sampling, the path-length rule, dielectric scattering.
pub const SURFACES_MODULE: ShaderFile = shader_file!("shaders/surfaces.wgsl");
/// The caustic's light tracer (entry point `main`; shader def CAUSTIC).
pub const CAUSTIC_SHADER: ShaderFile = shader_file!("shaders/caustic.wgsl");
/// The denoiser's guide buffers (entry point `main`; tracer/guides.rs).
pub const GUIDES_SHADER: ShaderFile = shader_file!("shaders/guides.wgsl");
/// What the light tracer and the photon gather share: parameters, splats, photon maps.
pub const CAUSTIC_BUFFERS_MODULE: ShaderFile = shader_file!("shaders/caustic_buffers.wgsl");
/// How the light tracer and the photon gather walk through the scene.
pub const CAUSTIC_WALK_MODULE: ShaderFile = shader_file!("shaders/caustic_walk.wgsl");
/// The photon gather of E (S|D)* D S+ L but E D S+ L (entry point `main`; shader def
/// CAUSTIC_GATHER).
pub const GATHER_SHADER: ShaderFile = shader_file!("shaders/gather.wgsl");
/// The generic material lookup (a read of the material buffer).
pub const GENERIC_MATERIALS: ShaderFile = shader_file!("shaders/materials.wgsl");
/// The generic traversal (a loop over the object buffer).
pub const GENERIC_TRAVERSAL: ShaderFile = shader_file!("shaders/traversal.wgsl");
/// The generic light choice (a loop over the light buffer).
pub const GENERIC_LIGHT_CHOICE: ShaderFile = shader_file!("shaders/light_choice.wgsl");

/// The sampling modules, in dependency order (a module may import only those before it).
pub const SAMPLING_MODULES: &[ShaderFile] = &[
    shader_file!("shaders/constants.wgsl"),
    shader_file!("shaders/rng.wgsl"),
    shader_file!("shaders/sampling.wgsl"),
    shader_file!("shaders/sampler.wgsl"),
];

/// The shader modules, in import order, for `scene` with `traversal`.
pub fn shader_modules(scene: &Scene, gpu_scene: &GpuScene, traversal: Traversal) -> Vec<ShaderFile> {
    let mut modules = SAMPLING_MODULES.to_vec();
    modules.extend(illum_rtcore::shaders::core_modules());
    modules.push(crate::bindings::bindings_module());
    modules.push(SCENE_MODULE);
    match traversal {
        Traversal::Generic => modules.extend([GENERIC_MATERIALS, GENERIC_TRAVERSAL, GENERIC_LIGHT_CHOICE]),
        Traversal::Specialised => modules.extend([
            specialise::materials_module(scene, gpu_scene),
            specialise::traversal_module(scene, gpu_scene),
            specialise::light_choice_module(scene, gpu_scene),
        ]),
    }
    modules.push(SURFACES_MODULE);
    modules.push(crate::manifold::MANIFOLD_MODULE);
    modules.push(crate::manifold::manifold_spheres_module(scene, gpu_scene));
    modules.push(CAUSTIC_BUFFERS_MODULE);
    modules.push(CAUSTIC_WALK_MODULE);
    modules
}

/// The path-tracing pipeline for `scene` with `options`, and the traversal source it was built
/// with. The context caches pipelines by their source: two scenes with the same specialisation
/// share one, so switching back to a scene does not recompile. `adaptive`: each block of pixels
/// takes its own number of samples (allocation.rs).
pub(crate) fn pathtrace_pipeline(
    gpu: &GpuContext,
    scene: &Scene,
    gpu_scene: &GpuScene,
    options: TracerOptions,
    adaptive: bool,
) -> Result<(wgpu::ComputePipeline, String), PathTraceError> {
    let specialisation = Specialisation { scene: gpu_scene.code, options, adaptive };
    let modules = shader_modules(scene, gpu_scene, options.traversal);
    let traversal_source = traversal_source(&modules).to_owned();
    let defs = specialisation.shader_defs();
    let pipeline = shader::compute_pipeline(gpu, &modules, &PATHTRACE_SHADER, &defs, "path-tracing")?;
    Ok((pipeline, traversal_source))
}

/// The text of the traversal module among `modules`.
fn traversal_source(modules: &[ShaderFile]) -> &str {
    modules
        .iter()
        .map(|m| m.source.as_ref())
        .find(|s| s.starts_with("#define_import_path illum::rtcore::traversal"))
        .expect("the modules include a traversal")
}

/// A pipeline that runs beside `scene`'s path-tracing pipeline: `shader` built from the same
/// modules and defs, without adaptive sampling, so that it follows the same specular chains
/// with the same numbers. The light tracer (`CAUSTIC_SHADER`, a scene code with the caustic),
/// the photon gather (`GATHER_SHADER`, one with the gather) and the guide buffers
/// (`GUIDES_SHADER`, tracer/guides.rs).
pub(crate) fn companion_pipeline(
    gpu: &GpuContext,
    scene: &Scene,
    gpu_scene: &GpuScene,
    options: TracerOptions,
    shader: &ShaderFile,
    label: &str,
) -> Result<wgpu::ComputePipeline, PathTraceError> {
    let specialisation = Specialisation { scene: gpu_scene.code, options, adaptive: false };
    let modules = shader_modules(scene, gpu_scene, options.traversal);
    let defs = specialisation.shader_defs();
    Ok(shader::compute_pipeline(gpu, &modules, shader, &defs, label)?)
}

// The tests below compose the scene files' pipelines; `scene_codes` composes every combination
// of the scene code's flags, on variants of one scene.
#[cfg(test)]
mod scene_codes;

#[cfg(test)]
mod tests {
    use std::mem::size_of;

    use illum_gpu::members;
    use illum_gpu::shader::wgsl_struct;
    use illum_scene::{RendererKind, Sequence};

    use super::*;
    use crate::display_sum::DISPLAY_SUM_SHADER;
    use crate::gpu_scene::{GpuLight, GpuParams};

    /// Every scene file the path tracer can render.
    pub(super) fn path_tracer_scenes() -> Vec<Scene> {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes");
        let mut scenes = Vec::new();
        for entry in std::fs::read_dir(dir).expect("scenes/ exists") {
            let path = entry.expect("readable").path();
            // Every file loads (illum-scene's test); the ones that use features the path tracer
            // lacks are refused by name (the raster tests check the Whitted scene's refusal).
            if path.extension().is_some_and(|e| e == "toml") {
                let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
                if scene.require(RendererKind::PathTrace.noun(), crate::implements).is_ok() {
                    scenes.push(scene);
                }
            }
        }
        assert!(scenes.iter().any(|s| s.name == "cornell"), "scenes/cornell.toml did not load");
        scenes
    }

    pub(super) fn compose_and_validate(
        modules: &[ShaderFile],
        entry: &ShaderFile,
        defs: &[(&str, shader::Def)],
    ) -> naga::Module {
        let module = shader::compose(modules, entry, defs).unwrap_or_else(|e| panic!("{e}"));
        shader::validate(&module, &entry.path).unwrap_or_else(|e| panic!("{e}"));
        // Every pipeline composed of the path tracer's modules binds by the table.
        if !modules.is_empty() {
            check_bindings(&module, &format!("{} with {defs:?}", entry.path));
        }
        module
    }

    /// The composed pipeline's bindings are all in group 0, no two share a number, and each
    /// variable has the number the table gives it (bindings.rs), which the host binds it at; but
    /// a scene's hierarchies' buffers, in group 1 at illum-rtcore's numbers.
    fn check_bindings(module: &naga::Module, what: &str) {
        use crate::bindings::Binding;
        let mut seen = std::collections::HashMap::new();
        for (_, variable) in module.global_variables.iter() {
            let Some(binding) = &variable.binding else { continue };
            // naga_oil names an imported module's items NAME + "X_naga_oil_mod_X" + its path.
            let full = variable.name.as_deref().unwrap_or_default();
            let name = full.split("X_naga_oil_mod_X").next().unwrap_or_default();
            if binding.group == illum_rtcore::BvhBindGroup::GROUP {
                let bvh = illum_rtcore::BvhBindGroup::BINDINGS;
                assert!(bvh.contains(&(name, binding.binding)), "{what}: {name} at {binding:?}");
                continue;
            }
            assert_eq!(binding.group, 0, "{what}: {name} is in group {}", binding.group);
            if let Some(other) = seen.insert(binding.binding, name.to_owned()) {
                panic!("{what}: {name} and {other} share binding {}", binding.binding);
            }
            let expected = Binding::ALL
                .iter()
                .find(|b| b.variable() == name)
                .unwrap_or_else(|| panic!("{what}: {name} is bound but not in the bindings table"));
            assert_eq!(binding.binding, expected.index(), "{what}: {name}");
        }
        assert!(seen.values().any(|n| n == "params"), "{what}: no bindings found (names {seen:?})");
    }

    /// The check above fails a pipeline whose module declares a binding outside the table, or
    /// a variable at another number than the table gives it, or two variables at one number.
    /// naga refuses a collision only between variables one entry point uses; here the second is
    /// declared and unused, as a module's are under another def.
    #[test]
    fn the_binding_check_fails_a_collision_and_an_unknown_binding() {
        let entry = |body: &str| {
            ShaderFile::generated(
                "bindings.wgsl".into(),
                format!("{body}\n@compute @workgroup_size(1)\nfn main() {{ let x = params; }}\n"),
            )
        };
        for body in [
            "@group(0) @binding(0) var<uniform> params: u32;\n@group(0) @binding(0) var<storage, read> objects: array<u32>;",
            "@group(0) @binding(0) var<uniform> params: u32;\n@group(0) @binding(2) var<storage, read> objects: array<u32>;",
            "@group(0) @binding(0) var<uniform> params: u32;\n@group(0) @binding(20) var<storage, read> other: array<u32>;",
        ] {
            let module = shader::compose(&[], &entry(body), &[]).unwrap_or_else(|e| panic!("{e}"));
            let failed = std::panic::catch_unwind(|| check_bindings(&module, "a broken pipeline")).is_err();
            assert!(failed, "accepted: {body}");
        }
    }

    /// naga validates each sampling module on its own (as the import of a trivial entry point),
    /// the path tracer generic and specialised for every scene file under both sequences, with
    /// and without pairs and adaptive sampling, each with its scene's code, its guide-buffer pass,
    /// and the display-sum pass.
    #[test]
    fn every_pathtrace_shader_composes_and_validates() {
        shader::validate_each_module(SAMPLING_MODULES).unwrap_or_else(|e| panic!("{e}"));
        for scene in path_tracer_scenes() {
            let gpu_scene = GpuScene::new(&scene).unwrap_or_else(|e| panic!("{e}"));
            for traversal in [Traversal::Generic, Traversal::Specialised] {
                // The low-discrepancy sequence with and without replicates (TracerOptions::replicates).
                for (sequence, replicates) in [
                    (Sequence::Independent, true),
                    (Sequence::LowDiscrepancy, true),
                    (Sequence::LowDiscrepancy, false),
                ] {
                    // Alone, with adaptive sampling, and with samples in pairs (native; the
                    // browser traces them one at a time) with and without it.
                    for (paired_paths, adaptive) in
                        [(false, false), (false, true), (true, false), (true, true)]
                    {
                        let options = TracerOptions { traversal, sequence, paired_paths, replicates };
                        let specialisation = Specialisation { scene: gpu_scene.code, options, adaptive };
                        compose_and_validate(
                            &shader_modules(&scene, &gpu_scene, traversal),
                            &PATHTRACE_SHADER,
                            &specialisation.shader_defs(),
                        );
                    }
                    // The guide buffers (tracer/guides.rs), with the scene's code.
                    let options = TracerOptions { traversal, sequence, paired_paths: false, replicates };
                    compose_and_validate(
                        &shader_modules(&scene, &gpu_scene, traversal),
                        &GUIDES_SHADER,
                        &Specialisation { scene: gpu_scene.code, options, adaptive: false }.shader_defs(),
                    );
                    if gpu_scene.code.caustic {
                        let options = TracerOptions { traversal, sequence, paired_paths: false, replicates };
                        let specialisation =
                            Specialisation { scene: gpu_scene.code, options, adaptive: false };
                        compose_and_validate(
                            &shader_modules(&scene, &gpu_scene, traversal),
                            &CAUSTIC_SHADER,
                            &specialisation.shader_defs(),
                        );
                    }
                    if gpu_scene.code.caustic_gather {
                        let options = TracerOptions { traversal, sequence, paired_paths: false, replicates };
                        let specialisation =
                            Specialisation { scene: gpu_scene.code, options, adaptive: false };
                        compose_and_validate(
                            &shader_modules(&scene, &gpu_scene, traversal),
                            &GATHER_SHADER,
                            &specialisation.shader_defs(),
                        );
                    }
                }
            }
        }
        compose_and_validate(&[], &DISPLAY_SUM_SHADER, &[]);
    }

    #[test]
    fn a_broken_shader_is_reported_with_its_file() {
        let entry = ShaderFile::generated("broken.wgsl".into(), "fn main() { let x: f32 = 1u; }".into());
        let error = shader::compose(SAMPLING_MODULES, &entry, &[]).expect_err("type error must be caught");
        assert!(error.to_string().contains("broken.wgsl"), "{error}");
    }

    /// The Rust mirrors of the scene's WGSL structs have naga's size and member offsets.
    #[test]
    fn layouts_match_the_wgsl_structs() {
        let scene = path_tracer_scenes().remove(0);
        let gpu_scene = GpuScene::new(&scene).unwrap_or_else(|e| panic!("{e}"));
        let module = compose_and_validate(
            &shader_modules(&scene, &gpu_scene, Traversal::Generic),
            &PATHTRACE_SHADER,
            &[],
        );
        let wgsl = |name: &str| {
            wgsl_struct(&module, "illum::pathtrace::scene", name)
                .unwrap_or_else(|| panic!("no struct {name} in scene.wgsl"))
        };
        wgsl("Params").assert_matches(
            size_of::<GpuParams>(),
            &members!(GpuParams: camera, light_area, num_objects, width, height, row_offset, rows,
                sample_base, sample_count, seed, bounces, num_lights, first_emitter, chunk_samples, padding_a,
                padding_b, padding_c,                 sun, sun_irradiance, sky),
        );
        // The caustic's parameters, in a scene that has the light tracer.
        let whitted =
            path_tracer_scenes().into_iter().find(|s| s.name == "whitted").expect("scenes/whitted.toml");
        let gpu_scene = GpuScene::new(&whitted).unwrap_or_else(|e| panic!("{e}"));
        assert!(gpu_scene.code.caustic, "whitted.toml turns the caustic on: {:?}", gpu_scene.code);
        let specialisation =
            Specialisation { scene: gpu_scene.code, options: TracerOptions::default(), adaptive: false };
        let module = compose_and_validate(
            &shader_modules(&whitted, &gpu_scene, Traversal::Generic),
            &CAUSTIC_SHADER,
            &specialisation.shader_defs(),
        );
        wgsl_struct(&module, "illum::pathtrace::caustic_buffers", "CausticParams").expect("struct CausticParams in caustic.wgsl").assert_matches(
            size_of::<crate::CausticParams>(),
            &members!(crate::CausticParams: particles, row_stride, frame_base, frame_count, num_discs, seed,
                pixel_area, area_per_particle, scene_centre, scene_radius, fixed_scale, fixed_cap, disc_area, gather_radius,
                buckets, first_index, index_end, radius_origin),
        );
        wgsl("Light").assert_matches(
            size_of::<GpuLight>(),
            &members!(GpuLight: corner, edge_u, edge_v, normal, emission),
        );
    }

    /// The WGSL constants R2_STEP_X and R2_STEP_Y are 1/phi and 1/phi^2 in 0.32 fixed point,
    /// phi the plastic number (the real root of x^3 = x + 1): the R_2 sequence's steps.
    #[test]
    fn r2_steps_match_the_plastic_number() {
        let source = include_str!("../shaders/sampler.wgsl");
        let constant = |name: &str| -> u64 {
            source
                .split(&format!("const {name}: u32 = "))
                .nth(1)
                .and_then(|rest| rest.split("u;").next())
                .unwrap_or_else(|| panic!("{name} present"))
                .parse()
                .expect("an integer")
        };
        // Newton's method on x^3 - x - 1 from 1.5 converges to the plastic number.
        let mut phi = 1.5f64;
        for _ in 0..50 {
            phi -= (phi.powi(3) - phi - 1.0) / (3.0 * phi * phi - 1.0);
        }
        assert!((phi - 1.324_717_957_244_746).abs() < 1e-15, "{phi}");
        for (name, step) in [("R2_STEP_X", 1.0 / phi), ("R2_STEP_Y", 1.0 / (phi * phi))] {
            let exact = step * 2f64.powi(32);
            assert!((constant(name) as f64 - exact).abs() <= 0.5, "{name}: {} vs {exact}", constant(name));
        }
    }
}
