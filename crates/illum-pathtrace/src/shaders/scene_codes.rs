//! The scene code's flags against the shader code behind their `#ifdef`s: every combination a
//! scene can give composes and validates, checked on variants of one scene that reach every flag
//! rather than on the scene files, which use only some.

use illum_scene::DirectionalLight;

use super::tests::{compose_and_validate, path_tracer_scenes};
use super::*;
use crate::scene_code::SceneCode;

/// A scene with one object of each material kind, two area lights, a sun and a sky: what
/// [`scene_variants`] takes subsets of.
const EVERY_KIND: &str = r#"
    name = "every-kind"
    [camera]
    eye = [0.0, 1.0, -5.0]
    target = [0.0, 1.0, 0.0]
    up = [0.0, 1.0, 0.0]
    vfov = 45.0
    width = 8
    height = 8
    [environment]
    radiance = [0.3, 0.5, 0.9]
    [directional_light]
    direction = [-1.0, -2.0, 0.5]
    irradiance = [3.0, 3.0, 3.0]
    [materials.board]
    checker = { even = [0.8, 0.8, 0.0], odd = [0.8, 0.0, 0.0], tile = 0.5 }
    [materials.glass]
    dielectric = { ior = 1.5 }
    [materials.grey]
    albedo = [0.5, 0.5, 0.5]
    [materials.lamp]
    emission = [5.0, 5.0, 5.0]
    [materials.metal]
    mirror = { reflectance = [0.9, 0.8, 0.7] }
    [[objects]]
    name = "floor"
    material = "board"
    quad = { corner = [-5.0, 0.0, -5.0], edge_u = [0.0, 0.0, 10.0], edge_v = [10.0, 0.0, 0.0] }
    [[objects]]
    name = "wall"
    material = "grey"
    quad = { corner = [-5.0, 0.0, 5.0], edge_u = [10.0, 0.0, 0.0], edge_v = [0.0, 10.0, 0.0] }
    [[objects]]
    name = "ball"
    material = "glass"
    sphere = { center = [0.0, 1.0, 0.0], radius = 1.0 }
    [[objects]]
    name = "mirror ball"
    material = "metal"
    sphere = { center = [-2.0, 1.0, 1.0], radius = 0.5 }
    [[objects]]
    name = "lamp"
    material = "lamp"
    quad = { corner = [-0.5, 4.0, -0.5], edge_u = [1.0, 0.0, 0.0], edge_v = [0.0, 0.0, 1.0] }
    [[objects]]
    name = "second lamp"
    material = "lamp"
    quad = { corner = [1.5, 4.0, -0.5], edge_u = [1.0, 0.0, 0.0], edge_v = [0.0, 0.0, 1.0] }
"#;

/// Every scene the inputs of [`SceneCode::new`] can describe, up to what it reads: each
/// subset of the four surface kinds, 0, 1 or 2 area lights, no sun, a delta sun or a sun
/// disc, with and without the sky, the caustic setting on and off with either method, both hemisphere samplings
/// and fixed or unbounded bounces.
fn scene_variants() -> Vec<Scene> {
    use illum_scene::{Bounces, CausticMethod, Sampling};
    let base = Scene::from_toml_str(EVERY_KIND, "every-kind.toml").unwrap_or_else(|e| panic!("{e}"));
    let (surfaces, lamps) = base.objects.split_at(4);
    let mut scenes = Vec::new();
    for subset in 0u32..1 << surfaces.len() {
        for lamp_count in 0..=lamps.len() {
            for sun in [None, Some(0.0), Some(0.25)] {
                for sky in [false, true] {
                    for (caustics, uniform, unbounded, manifold) in
                        (0u32..16).map(|b| (b & 1 != 0, b & 2 != 0, b & 4 != 0, b & 8 != 0))
                    {
                        let mut scene = base.clone();
                        scene.objects = (0..surfaces.len())
                            .filter(|i| subset & (1 << i) != 0)
                            .map(|i| surfaces[i].clone())
                            .chain(lamps[..lamp_count].iter().cloned())
                            .collect();
                        scene.directional_light = sun.and_then(|radius| {
                            base.directional_light
                                .map(|l| DirectionalLight { angular_radius_deg: radius, ..l })
                        });
                        scene.environment = base.environment.filter(|_| sky);
                        scene.pathtrace.caustics = caustics;
                        scene.pathtrace.caustic_method =
                            if manifold { CausticMethod::Manifold } else { CausticMethod::LightTracer };
                        scene.pathtrace.sampling = if uniform { Sampling::Uniform } else { Sampling::Cosine };
                        scene.pathtrace.bounces =
                            if unbounded { Bounces::Unbounded } else { Bounces::Fixed(4) };
                        scenes.push(scene);
                    }
                }
            }
        }
    }
    scenes
}

/// Every combination of the scene code's flags that a scene can give composes and
/// validates, for the integrator, the guide buffers and (where the caustic is on) the light
/// tracer and the photon gather, without a GPU: the code behind each `#ifdef` is checked
/// before any scene file happens to need it. The combinations are those [`GpuScene::new`]
/// (through [`SceneCode::new`]) derives from every variant of a scene ([`scene_variants`]);
/// a scene it refuses (one with no light) has none. The generic modules make the
/// combinations independent of any one scene's geometry.
#[test]
fn every_combination_of_the_scene_code_validates() {
    let scene = path_tracer_scenes().remove(0);
    let gpu_scene = GpuScene::new(&scene).unwrap_or_else(|e| panic!("{e}"));
    let modules = shader_modules(&scene, &gpu_scene, Traversal::Generic);
    let options = TracerOptions { traversal: Traversal::Generic, ..TracerOptions::default() };
    let variants = scene_variants();
    let codes: std::collections::HashSet<SceneCode> =
        variants.iter().filter_map(|variant| GpuScene::new(variant).ok().map(|g| g.code)).collect();
    // Each flag is set by some scene and clear in another: the variants reach all the code.
    // (Destructured in full, so that a new flag must be listed here.)
    let flags = |c: &SceneCode| {
        let SceneCode {
            area_lights,
            light_choice,
            sun,
            sun_disc,
            sky,
            specular,
            checker,
            manifold,
            caustic,
            caustic_gather,
            uniform_sampling,
            unbounded_bounces,
            // Compiled with the specialised traversal only: smooth_meshes_compose_and_validate.
            smooth_shading: _,
        } = *c;
        [
            area_lights,
            light_choice,
            sun,
            sun_disc,
            sky,
            specular,
            checker,
            manifold,
            caustic,
            caustic_gather,
            uniform_sampling,
            unbounded_bounces,
        ]
    };
    for i in 0..12 {
        assert!(
            codes.iter().any(|c| flags(c)[i]) && codes.iter().any(|c| !flags(c)[i]),
            "flag {i} takes one value only in {} scene codes",
            codes.len()
        );
    }
    let mut composed = 0;
    for &code in &codes {
        let defs = Specialisation { scene: code, options, adaptive: false }.shader_defs();
        compose_and_validate(&modules, &PATHTRACE_SHADER, &defs);
        composed += 1;
        // The guide buffers, composed with the same defs (tracer/guides.rs).
        compose_and_validate(&modules, &GUIDES_SHADER, &defs);
        composed += 1;
        if code.caustic {
            compose_and_validate(&modules, &CAUSTIC_SHADER, &defs);
            composed += 1;
        }
        if code.caustic_gather {
            compose_and_validate(&modules, &GATHER_SHADER, &defs);
            composed += 1;
        }
    }
    println!("{} scene variants, {} scene codes, {composed} compositions", variants.len(), codes.len());
    assert!(composed > 600, "{composed} compositions");
}

/// With a smooth mesh (shader def SMOOTH_SHADING, compiled with the specialised traversal only)
/// the integrator and the guide buffers compose and validate, the mesh's triangles as literals
/// (20) and under a BVH (80), beside every material, under both hemisphere samplings and both
/// sequences (the low-discrepancy one samples lights by the bilinear fit, which reads the normal).
#[test]
fn smooth_meshes_compose_and_validate() {
    use illum_scene::testing::obj::{icosphere_obj, scene_with_files};
    use illum_scene::{Sampling, Sequence};
    for k in [0, 1] {
        let text = format!(
            "{EVERY_KIND}\n    [[objects]]\n    name = \"ball\"\n    material = \"grey\"\n    \
             mesh = {{ file = \"ball.obj\", translate = [1.5, 1.0, 1.0], scale = 0.5 }}\n"
        );
        let mut scene = scene_with_files(&text, "every-kind.toml", &[("ball.obj", &icosphere_obj(k, true))])
            .unwrap_or_else(|e| panic!("{e}"));
        for (uniform, sequence) in [(false, Sequence::Independent), (true, Sequence::LowDiscrepancy)] {
            scene.pathtrace.sampling = if uniform { Sampling::Uniform } else { Sampling::Cosine };
            let gpu_scene = GpuScene::new(&scene).unwrap_or_else(|e| panic!("{e}"));
            assert!(gpu_scene.code.smooth_shading && gpu_scene.code.specular);
            assert_eq!(gpu_scene.geometry.mesh_bvh().is_some(), k > 0);
            let options = TracerOptions {
                traversal: Traversal::Specialised,
                sequence,
                paired_paths: true,
                replicates: true,
            };
            let defs = Specialisation { scene: gpu_scene.code, options, adaptive: false }.shader_defs();
            assert!(defs.iter().any(|(name, _)| *name == "SMOOTH_SHADING"));
            let modules = shader_modules(&scene, &gpu_scene, Traversal::Specialised);
            compose_and_validate(&modules, &PATHTRACE_SHADER, &defs);
            compose_and_validate(&modules, &GUIDES_SHADER, &defs);
        }
    }
}
