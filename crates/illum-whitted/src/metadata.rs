//! The EXR metadata of a Whitted-traced image: one builder for every program that saves one, so
//! that each key means the same everywhere. The image is deterministic, so its settings are all
//! it needs: none of the path tracer's keys (spp, bounces, seed, sampling).

use illum_image::ExrMetadata;
use illum_scene::Scene;

/// The renderer name Whitted-traced images carry (`illum.renderer`).
pub const RENDERER: &str = "whitted";

/// Metadata for an image of `scene` traced on the adapter named `adapter` in `render_seconds`
/// (wall-clock, setup included). Keys (each stored as `illum.<key>`):
///
/// - `renderer` = `whitted`, `scene` = the scene's name, `render_seconds`;
/// - `depth`: `[whitted] depth`, the recursion depth of reflected and refracted rays;
/// - `aa`: `[whitted] aa`, n of the n x n rays per pixel;
/// - `adapter`: the GPU adapter's name.
pub fn exr_metadata(scene: &Scene, adapter: &str, render_seconds: f64) -> ExrMetadata {
    ExrMetadata {
        renderer: RENDERER.to_owned(),
        scene: scene.name.clone(),
        render_seconds,
        fields: vec![
            ("depth".into(), scene.whitted.depth.to_string()),
            ("aa".into(), scene.whitted.aa.to_string()),
            ("adapter".into(), adapter.to_owned()),
        ],
    }
}
