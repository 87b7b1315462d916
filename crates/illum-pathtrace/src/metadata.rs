//! The EXR metadata of a path-traced image: one builder for every program that saves one (the
//! `render` example, the viewer, the convergence tool), so that each key means the same
//! everywhere.

use illum_image::ExrMetadata;
use illum_scene::Scene;

use crate::estimators::Estimators;
use crate::{PathTracer, StopReason};

/// The renderer name path-traced images carry (`illum.renderer`).
pub const RENDERER: &str = "pathtrace";

/// The metadata key of the end of a `--sample-range` a part was asked to render (one past its
/// last sample index), written by the `render` example beside `sample_start`.
pub const SAMPLE_END: &str = "sample_end";

/// The field of the estimators' token list ([`Estimators::key`]).
pub const ESTIMATORS: &str = "estimators";

/// The field in which files before the token list named their caustic's estimators by a sentence.
pub const LEGACY_ESTIMATORS: &str = "caustic_estimators";

/// The scene's identity as files store it (`illum.scene_hash`): [`Scene::content_hash`] in 16
/// hex digits. It covers the scene's physical content, not the settings (resolution, bounces,
/// seed, ...), which files store and compare one by one.
pub fn scene_hash(scene: &Scene) -> String {
    format!("{:016x}", scene.content_hash())
}

/// Metadata for the tracer's current image. Keys (each stored as `illum.<key>`):
///
/// - `renderer` = `pathtrace`, `scene` = the scene's name, `render_seconds` = `render_seconds`
///   (wall-clock time, see [`crate::progressive::RenderClock`]);
/// - `spp`: samples per pixel of the completed passes (every pixel has at least this many
///   paths; an interrupted pass may have added more to some rows), `bounces`, `seed`,
///   `sampling`, `sequence`: the settings; `caustics`: `on` when the caustic's light tracer
///   ran (`[pathtrace] caustics = true` on a scene with a sun and a mirror or glass), else `off`;
/// - `estimated_relative_error`: [`crate::Accumulator::estimated_relative_error`] (`inf` below
///   2 spp); `dropped_samples`: NaN/Inf samples left out;
/// - `stopped_by`: the stop rule that ended the render (`spp`, `target_error`, `time_budget`,
///   `cancelled`), or `none` for an image saved while rendering (the viewer);
/// - `adaptive`: `off`, or with adaptive sampling (`allocation.rs`) its blocks' samples per
///   pixel, e.g. `8x8 blocks, 16 to 4096 spp, mean 1023.5, pilot 16 spp`; `spp` then counts the
///   sample indices reached, which each block has taken up to its own count;
/// - `adapter`: the GPU adapter's name; `source`: the program that wrote the file;
/// - `glint_hash`: [`crate::accumulator::ExactPart::digest`], the digest of the image's exact part, which the layer
///   [`crate::checkpoint::GLINT_LAYER`] holds;
/// - `scene_hash`: [`scene_hash`]; `sample_start`: the first sample
///   index (see [`PathTracer::set_sample_offset`]); `partial_pass_spp` and `partial_pass_rows`:
///   a pass the render stopped inside (its spp and the rows it had done; 0 and 0 for none).
///   With the statistics layer of [`crate::checkpoint`], these let a render be continued.
pub fn exr_metadata(
    tracer: &PathTracer,
    render_seconds: f64,
    stopped_by: Option<StopReason>,
    source: &str,
) -> ExrMetadata {
    let scene = tracer.scene();
    let accumulator = tracer.accumulator();
    let fields = [
        ("spp", tracer.spp_done().to_string()),
        ("bounces", scene.pathtrace.bounces.to_string()),
        ("seed", scene.pathtrace.seed.to_string()),
        ("sampling", scene.pathtrace.sampling.to_string()),
        ("sequence", tracer.options().sequence_label()),
        ("caustics", Estimators::of(scene).caustics_label().to_owned()),
        (ESTIMATORS, Estimators::of(scene).key()),
        ("glint_hash", accumulator.exact().digest()),
        ("estimated_relative_error", accumulator.estimated_relative_error().to_string()),
        ("dropped_samples", accumulator.dropped_samples().to_string()),
        ("stopped_by", stopped_by.map_or("none", StopReason::name).to_owned()),
        (
            "adaptive",
            tracer
                .sample_allocation()
                .map_or("off".to_owned(), crate::allocation::SampleAllocation::describe),
        ),
        ("adapter", tracer.adapter_name().to_owned()),
        ("source", source.to_owned()),
        ("scene_hash", scene_hash(scene)),
        ("sample_start", tracer.sample_offset().to_string()),
        ("partial_pass_spp", tracer.partial_pass().map_or(0, |p| p.0).to_string()),
        ("partial_pass_rows", tracer.partial_pass().map_or(0, |p| p.1).to_string()),
    ];
    ExrMetadata {
        renderer: RENDERER.to_owned(),
        scene: scene.name.clone(),
        render_seconds,
        fields: fields.into_iter().map(|(k, v)| (k.to_owned(), v)).collect(),
    }
}
