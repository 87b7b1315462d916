//! Every WGSL file in a crate's `shaders/` folder belongs to some crate's list of shaders, so
//! that the crate's own naga test validates it without a GPU:
//! - illum-rtcore (`shaders.rs`): spawning, geometry, material record, optics, camera;
//! - illum-pathtrace (`shaders.rs`): the sampling modules, the scene module, the generic
//!   material lookup, traversal and light choice (the specialised ones generated), the surfaces
//!   module, the integrator, manifold next-event estimation, the caustic's light tracer and
//!   photon gather with their shared buffers, the
//!   guide buffers and the display-sum
//!   pass, for every scene file;
//! - illum-denoise (`atrous.rs`): the à-trous filter;
//! - illum-raster (`shaders.rs`): its modules and entry files;
//! - illum-whitted (`tracer.rs`): its entry shader, composed with illum-rtcore's modules;
//! - illum-viewer (`display.rs`): its display pass.
//!
//! A file no list names would be validated by nobody; this test names it.

use std::collections::BTreeSet;
use std::path::PathBuf;

use illum::pathtrace::{
    self, CAUSTIC_SHADER, GENERIC_LIGHT_CHOICE, GENERIC_MATERIALS, GENERIC_TRAVERSAL, PATHTRACE_SHADER,
    SAMPLING_MODULES, SCENE_MODULE, SURFACES_MODULE,
};

/// The viewer's shader, validated by illum-viewer's own test (the facade does not depend on the
/// viewer crate, so it is named here by its path).
const VIEWER_SHADERS: &[&str] = &["crates/illum-viewer/shaders/display.wgsl"];

#[test]
fn every_wgsl_file_is_validated_by_its_crate() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut covered: BTreeSet<String> = SAMPLING_MODULES
        .iter()
        .chain(illum::rtcore::shaders::FILES.iter())
        .chain([
            &SCENE_MODULE,
            &GENERIC_MATERIALS,
            &GENERIC_TRAVERSAL,
            &GENERIC_LIGHT_CHOICE,
            &PATHTRACE_SHADER,
            &SURFACES_MODULE,
            &CAUSTIC_SHADER,
            &pathtrace::CAUSTIC_BUFFERS_MODULE,
            &pathtrace::CAUSTIC_WALK_MODULE,
            &pathtrace::MANIFOLD_MODULE,
            &pathtrace::GATHER_SHADER,
            &pathtrace::GUIDES_SHADER,
            &pathtrace::DISPLAY_SUM_SHADER,
            &illum_denoise::ATROUS_SHADER,
        ])
        .chain(illum::raster::shaders::MODULES)
        .chain(illum::raster::shaders::SHADERS)
        .chain([&illum::whitted::WHITTED_SHADER])
        .map(|file| file.path.to_string())
        .collect();
    covered.extend(VIEWER_SHADERS.iter().map(|path| (*path).to_owned()));

    let mut on_disk = BTreeSet::new();
    let crates = std::fs::read_dir(root.join("crates")).expect("crates/ is readable");
    let mut stack: Vec<PathBuf> =
        crates.map(|entry| entry.expect("entry").path().join("shaders")).filter(|p| p.is_dir()).collect();
    assert!(stack.len() >= 5, "the crates' shaders/ folders were not found: {stack:?}");
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("readable dir") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "wgsl") {
                let relative = path.strip_prefix(&root).expect("inside workspace");
                on_disk.insert(relative.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    let missing: Vec<_> = on_disk.difference(&covered).collect();
    assert!(missing.is_empty(), "WGSL files not validated by any composition: {missing:?}");
}
