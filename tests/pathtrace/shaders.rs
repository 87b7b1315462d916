//! naga parses and validates every WGSL file, without a GPU: each entry shader is composed with
//! the modules it imports, and every file under shaders/ must be part of some composition.

use std::collections::BTreeSet;

use illum::gpu::shader::{self, COMMON_MODULES, Def, ShaderFile};
use illum::pathtrace::{
    self, PATHTRACE_SHADER, Sequence, TracerOptions, Traversal, gpu_scene::GpuScene, shader_modules,
};
use illum::scene::{RendererKind, Scene};

use crate::common;

/// Composes `entry` with `modules` and validates the result with naga.
fn check(modules: &[ShaderFile], entry: &ShaderFile, defs: &[(&str, Def)], covered: &mut BTreeSet<String>) {
    let module = shader::compose(modules, entry, defs).unwrap_or_else(|e| panic!("{e}"));
    shader::validate(&module, &entry.path).unwrap_or_else(|e| panic!("{e}"));
    covered.insert(entry.path.to_string());
    covered.extend(modules.iter().map(|m| m.path.to_string()));
}

fn path_tracer_scenes() -> Vec<Scene> {
    let mut scenes = Vec::new();
    for entry in std::fs::read_dir(common::workspace_path("scenes")).expect("scenes/ exists") {
        let path = entry.expect("readable").path();
        // Every file loads (illum-scene's test); the ones that use features the path tracer
        // lacks are refused by name (the raster tests check the Whitted scene's refusal).
        if path.extension().is_some_and(|e| e == "toml") {
            let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
            if scene.require(RendererKind::PathTrace, pathtrace::FEATURES).is_ok() {
                scenes.push(scene);
            }
        }
    }
    assert!(scenes.iter().any(|s| s.name == "cornell"), "scenes/cornell.toml did not load");
    scenes
}

#[test]
fn every_wgsl_file_composes_and_validates() {
    let mut covered = BTreeSet::new();
    // Each common module on its own, as an import of a trivial entry point.
    for (i, module) in COMMON_MODULES.iter().enumerate() {
        let import_path = module
            .source
            .lines()
            .find_map(|l| l.strip_prefix("#define_import_path "))
            .unwrap_or_else(|| panic!("{} has no #define_import_path", module.path))
            .trim()
            .to_owned();
        let entry = ShaderFile::generated(
            format!("entry importing {import_path}"),
            format!("#import {import_path} as m\n@compute @workgroup_size(1)\nfn main() {{}}\n"),
        );
        check(&COMMON_MODULES[..=i], &entry, &[], &mut covered);
    }
    // The path tracer, generic and specialised for every scene file.
    for scene in path_tracer_scenes() {
        let gpu_scene = GpuScene::new(&scene).unwrap_or_else(|e| panic!("{e}"));
        for traversal in [Traversal::Generic, Traversal::Specialised] {
            for sequence in [Sequence::Independent, Sequence::LowDiscrepancy] {
                let defs = TracerOptions { traversal, sequence }.shader_defs();
                check(&shader_modules(&scene, &gpu_scene, traversal), &PATHTRACE_SHADER, &defs, &mut covered);
            }
        }
    }
    // The display sum's pass: a self-contained entry shader.
    check(&[], &pathtrace::DISPLAY_SUM_SHADER, &[], &mut covered);
    for shaders in extra_shader_sets() {
        for (modules, entry) in shaders {
            check(&modules, &entry, &[], &mut covered);
        }
    }

    let mut on_disk = BTreeSet::new();
    let mut stack = vec![common::workspace_path("shaders")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("readable dir") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "wgsl") {
                let relative = path.strip_prefix(common::workspace_path("")).expect("inside workspace");
                on_disk.insert(relative.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    let missing: Vec<_> = on_disk.difference(&covered).collect();
    assert!(missing.is_empty(), "WGSL files not validated by any composition: {missing:?}");
}

/// Shader sets of the other renderers: (modules, entry) pairs.
fn extra_shader_sets() -> Vec<Vec<(Vec<ShaderFile>, ShaderFile)>> {
    let raster = illum::raster::shaders::SHADERS
        .iter()
        .map(|entry| (illum::raster::shaders::modules(), entry.clone()))
        .collect();
    // The viewer's display pass: one self-contained file.
    let display = ShaderFile {
        path: "shaders/viewer/display.wgsl".into(),
        source: include_str!("../../shaders/viewer/display.wgsl").into(),
    };
    vec![raster, vec![(Vec::new(), display)]]
}

#[test]
fn a_broken_shader_is_reported_with_its_file() {
    let entry = ShaderFile::generated("broken.wgsl".into(), "fn main() { let x: f32 = 1u; }".into());
    let error = shader::compose(COMMON_MODULES, &entry, &[]).expect_err("type error must be caught");
    assert!(error.to_string().contains("broken.wgsl"), "{error}");
}
