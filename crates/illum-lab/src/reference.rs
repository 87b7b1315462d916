//! The converged path-traced truth that the measuring tools (convergence, ladder) compare with:
//! rendered once, cached as an EXR under a name derived from everything that changes it, and
//! reused only when the cached file's full key matches.

use std::path::{Path, PathBuf};

use illum_gpu::GpuContext;
use illum_image::{ExrMetadata, RgbImage32, load_exr, save_exr};
use illum_pathtrace::reference::SizePolicy;
use illum_pathtrace::{PathTracer, Progressive};
use illum_scene::Scene;

/// A reference image and what is known of its own error.
pub struct Reference {
    pub image: RgbImage32,
    /// Where it is (the user's file, or the cache).
    pub path: PathBuf,
    /// Samples per pixel (0 if the user's file does not say).
    pub spp: u64,
    /// The relMSE the reference estimates for itself from its per-pixel variance (NaN if the
    /// user's file does not carry it).
    pub estimated_rel_mse: f64,
    /// Its file's metadata (renderer, scene, render time, settings), to go with any copy of it
    /// (empty for a file that has none).
    pub metadata: ExrMetadata,
}

/// Loads the user's reference, checked against `scene` at its camera's size by the rule every
/// reader of a reference shares ([`illum_pathtrace::reference::Reference`]); prints the note of
/// a file whose scene could not be checked.
pub fn load_reference(path: &Path, scene: &Scene) -> anyhow::Result<Reference> {
    let (file, note) = illum_pathtrace::reference::Reference::load(path, scene, SizePolicy::Flags)?;
    if let Some(note) = note {
        println!("{note}");
    }
    Ok(Reference {
        spp: file.number("spp").map_or(0, |v| v as u64),
        estimated_rel_mse: file.number("estimated_rel_mse").unwrap_or(f64::NAN),
        metadata: file.metadata.unwrap_or_default(),
        image: file.image,
        path: file.path,
    })
}

/// What a long render shows of its progress after each step (the command line's bar or lines).
pub type OnStep<'a> = &'a mut dyn FnMut(&PathTracer, &Progressive);

/// The cached reference of `scene` at `spp` samples per pixel in `folder`, rendered (and
/// written) if the cache has none made with exactly these settings, telling `on_step` how far
/// it is (a long render: minutes for the Whitted scene's caustic). `label` names the tool.
pub fn cached_reference(
    gpu: &GpuContext,
    scene: &Scene,
    spp: u32,
    folder: &Path,
    label: &str,
    on_step: OnStep,
) -> anyhow::Result<Reference> {
    let (reference_scene, key) = reference_settings(scene, spp);
    let path =
        folder.join(format!("reference-{}-{:016x}.exr", scene.name, illum_scene::fnv1a_64(key.as_bytes())));
    if path.exists() {
        let (image, attributes) = load_exr(&path)?;
        let stored = ExrMetadata::from_attributes(&path, &attributes)?;
        if stored.as_ref().and_then(|m| m.get("reference_key")) == Some(key.as_str()) {
            println!("reusing reference {}", path.display());
            let rel = stored.as_ref().and_then(|m| m.get("estimated_rel_mse")).and_then(|v| v.parse().ok());
            return Ok(Reference {
                image,
                path,
                spp: u64::from(spp),
                estimated_rel_mse: rel.unwrap_or(f64::NAN),
                metadata: stored.unwrap_or_default(),
            });
        }
        println!("{} was made for other settings: rendering it again", path.display());
    }
    println!("rendering the reference: {spp} spp (cached as {})", path.display());
    let mut tracer = PathTracer::new(gpu, &reference_scene)?;
    let rules = illum_pathtrace::StopRules { spp: Some(spp), target_error: None, time_budget: None };
    let never = std::sync::atomic::AtomicBool::new(false);
    illum_pathtrace::render_progressive(&mut tracer, &rules, &never, on_step)?;
    let image = tracer.accumulator().mean_image();
    let estimated_rel_mse = tracer.accumulator().estimated_rel_mse();
    let mut metadata = illum_pathtrace::metadata::exr_metadata(
        &tracer,
        tracer.wall_seconds(),
        Some(illum_pathtrace::StopReason::SppReached),
        label,
    );
    metadata.fields.push(("reference_key".into(), key));
    metadata.fields.push(("estimated_rel_mse".into(), format!("{estimated_rel_mse:e}")));
    save_exr(&path, &image, &metadata)?;
    Ok(Reference { image, path, spp: u64::from(spp), estimated_rel_mse, metadata })
}

/// The scene the reference is rendered with ([`illum_pathtrace::reference::reference_scene`]), and
/// its cache key: everything that changes the reference image, written out explicitly: the
/// scene's content hash ([`Scene::content_hash`], with the version of its canonical form), the
/// resolution and every `[pathtrace]` setting.
pub fn reference_settings(scene: &Scene, spp: u32) -> (Scene, String) {
    let reference_scene = illum_pathtrace::reference::reference_scene(scene, spp);
    let (camera, settings) = (&reference_scene.camera, &reference_scene.pathtrace);
    let key = format!(
        "scene {} (canonical form {}), {}x{}, spp {}, bounces {}, seed {}, sampling {}, sequence {}, caustics {}, \
         estimators {}",
        illum_pathtrace::metadata::scene_hash(&reference_scene),
        illum_scene::CONTENT_VERSION,
        camera.width,
        camera.height,
        settings.spp,
        settings.bounces,
        settings.seed,
        settings.sampling,
        settings.sequence,
        settings.caustics,
        illum_pathtrace::Estimators::of(&reference_scene).key()
    );
    (reference_scene, key)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reference_cache_key_changes_with_anything_that_changes_the_image() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell.toml");
        let scene = Scene::load(Path::new(path)).unwrap();
        let (_, key) = reference_settings(&scene, 1024);
        assert_eq!(reference_settings(&scene.clone(), 1024).1, key, "the same scene, the same key");
        // A copy with the light twice as bright and the same name (a key of the name alone
        // would reuse the first scene's reference), more spp, another seed, size, bounce count,
        // sequence, or the caustic's tracer.
        let mut brighter = scene.clone();
        for m in &mut brighter.materials {
            if let illum_scene::MaterialKind::Emitter { radiance } = &mut m.kind {
                *radiance *= 2.0;
            }
        }
        let mut seeded = scene.clone();
        seeded.pathtrace.seed += 1;
        let mut wider = scene.clone();
        wider.camera.width += 1;
        let mut taller = scene.clone();
        taller.camera.height += 1;
        let mut deeper = scene.clone();
        deeper.pathtrace.bounces = illum_scene::Bounces::Unbounded;
        let mut low_discrepancy = scene.clone();
        low_discrepancy.pathtrace.sequence = illum_scene::Sequence::LowDiscrepancy;
        let mut caustics = scene.clone();
        caustics.pathtrace.caustics = true;
        for (what, other) in [
            ("emission", reference_settings(&brighter, 1024).1),
            ("spp", reference_settings(&scene, 2048).1),
            ("seed", reference_settings(&seeded, 1024).1),
            ("width", reference_settings(&wider, 1024).1),
            ("height", reference_settings(&taller, 1024).1),
            ("bounces", reference_settings(&deeper, 1024).1),
            ("sequence", reference_settings(&low_discrepancy, 1024).1),
            ("caustics", reference_settings(&caustics, 1024).1),
        ] {
            assert_ne!(other, key, "{what} changed but the key did not");
        }
        // The sampling of the measured rows does not change the reference (always cosine).
        let mut uniform = scene.clone();
        uniform.pathtrace.sampling = illum_scene::Sampling::Uniform;
        assert_eq!(reference_settings(&uniform, 1024).1, key);
        // Nor does what only another renderer reads.
        let mut raster = scene.clone();
        raster.raster.pcf_radius += 1.0;
        assert_eq!(reference_settings(&raster, 1024).1, key);
    }
}
