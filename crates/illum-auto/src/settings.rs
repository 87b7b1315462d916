//! The settings Auto chooses among for a scene, how a setting is applied to the scene, and the
//! size of a pilot's images.

use illum_pathtrace::TracerOptions;
use illum_raster::RasterScene;
use illum_scene::{Bounces, CausticMethod, DenoiserKind, Effects, Look, MaterialKind, Scene, Sequence};

use crate::plan::Setting;

/// Every setting `auto` chooses among for `scene`: the rasterizer's two looks and the enhanced
/// look with each effect off (where it can draw the scene), the Whitted ray tracer at depths 1,
/// 2, 4, 8 (depth 1 alone without a mirror or glass, where depth changes nothing) and 1 to 4
/// rays per pixel a side, and the path tracer at bounces 1, 2, 4, 8 and unbounded, with and
/// (where the scene has a caustic) without its light tracer.
pub fn settings(scene: &Scene) -> Vec<Setting> {
    let mut all = Vec::new();
    if RasterScene::from_scene(scene).is_ok() {
        all.push(Setting::Raster { look: Look::Figure, effects: Effects::ALL_ON });
        all.push(Setting::Raster { look: Look::Enhanced, effects: Effects::ALL_ON });
        for (_, off) in Effects::TOGGLES {
            let mut effects = Effects::ALL_ON;
            off(&mut effects);
            all.push(Setting::Raster { look: Look::Enhanced, effects });
        }
    }
    let depths: &[u32] = if has_specular(scene) { &[1, 2, 4, 8] } else { &[1] };
    for &depth in depths {
        for aa in 1..=4 {
            all.push(Setting::Whitted { depth, aa });
        }
    }
    let caustics: &[bool] = if has_caustic(scene) { &[false, true] } else { &[false] };
    for &caustics in caustics {
        for bounces in
            [Bounces::Fixed(1), Bounces::Fixed(2), Bounces::Fixed(4), Bounces::Fixed(8), Bounces::Unbounded]
        {
            all.push(Setting::PathTrace {
                bounces,
                caustics,
                sequence: Sequence::Independent,
                adaptive: false,
                denoise: None,
            });
        }
    }
    all
}

/// Which variants of each path-tracer setting a pilot measures besides the setting itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Variants<'a> {
    /// The low-discrepancy sequence.
    pub low_discrepancy: bool,
    /// Adaptive sampling (only without the caustic's light tracer: the path tracer refuses
    /// the two together).
    pub adaptive: bool,
    /// Denoised by each of these.
    pub denoisers: &'a [DenoiserKind],
}

/// [`settings`] and, after each path-tracer setting, its `variants`, each with independent
/// samples but the low-discrepancy one: `render --renderer auto` measures all three kinds,
/// the viewer's Auto mode the à-trous filter alone. Not among them, to keep the pilot's cost
/// down: adaptive sampling or denoising with the low-discrepancy sequence.
pub fn settings_with_variants(scene: &Scene, variants: Variants) -> Vec<Setting> {
    let mut all = Vec::new();
    for setting in settings(scene) {
        let Setting::PathTrace { bounces, caustics, .. } = setting else {
            all.push(setting);
            continue;
        };
        let variant = |sequence, adaptive, denoise| Setting::PathTrace {
            bounces,
            caustics,
            sequence,
            adaptive,
            denoise,
        };
        all.push(setting);
        if variants.low_discrepancy {
            all.push(variant(Sequence::LowDiscrepancy, false, None));
        }
        if variants.adaptive && !caustics {
            all.push(variant(Sequence::Independent, true, None));
        }
        for &denoiser in variants.denoisers {
            all.push(variant(Sequence::Independent, false, Some(denoiser)));
        }
    }
    all
}

fn has_specular(scene: &Scene) -> bool {
    scene
        .materials
        .iter()
        .any(|m| matches!(m.kind, MaterialKind::Dielectric { .. } | MaterialKind::Mirror { .. }))
}

/// Whether the path tracer's caustic light tracer has anything to trace in `scene`.
pub fn has_caustic(scene: &Scene) -> bool {
    let mut with = scene.clone();
    with.pathtrace.caustics = true;
    illum_pathtrace::Estimators::of(&with).caustics()
}

/// The scene of the converged solution every measure of error is taken against: `scene` path
/// traced with `bounces` (the rendering equation's solution is [`Bounces::Unbounded`]; the
/// ladder lets a user choose), with the caustic's light tracer wherever it has anything to trace.
pub fn truth_scene(scene: &Scene, bounces: Bounces) -> Scene {
    let mut truth = scene.clone();
    truth.pathtrace.bounces = bounces;
    truth.pathtrace.caustics = has_caustic(scene);
    // The light tracer covers every specular chain; the manifold solve leaves out chains through
    // two objects (docs/caustics-manifold.md), so a truth is never made with it.
    truth.pathtrace.caustic_method = CausticMethod::LightTracer;
    truth
}

/// `scene` with `setting` applied (its renderer's section), at the scene's size.
pub fn apply(scene: &Scene, setting: &Setting) -> Scene {
    let mut scene = scene.clone();
    match setting {
        Setting::Raster { look, effects } => {
            scene.raster.look = *look;
            scene.raster.effects = *effects;
        }
        Setting::Whitted { depth, aa } => {
            scene.whitted.depth = *depth;
            scene.whitted.aa = *aa;
        }
        Setting::PathTrace { bounces, caustics, sequence, .. } => {
            scene.pathtrace.bounces = *bounces;
            scene.pathtrace.caustics = *caustics;
            scene.pathtrace.sequence = *sequence;
        }
    }
    scene
}

/// The path tracer's options for `setting` (its sequence).
pub fn tracer_options(setting: &Setting) -> TracerOptions {
    match setting {
        Setting::PathTrace { sequence, .. } => TracerOptions { sequence: *sequence, ..Default::default() },
        _ => TracerOptions::default(),
    }
}

/// The pilot's size: the scene's aspect, `longer_side` pixels on the longer side, never more
/// than the scene's own.
pub fn pilot_size(scene: &Scene, longer_side: u32) -> (u32, u32) {
    let (w, h) = (scene.camera.width, scene.camera.height);
    if w.max(h) <= longer_side {
        return (w, h);
    }
    let scale = f64::from(longer_side) / f64::from(w.max(h));
    let side = |v: u32| ((f64::from(v) * scale).round() as u32).max(1);
    (side(w), side(h))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pilot_keeps_the_aspect_and_never_upsamples() {
        let mut scene = illum_scene::testing::shipped_scene("whitted.toml", 320, 180);
        assert_eq!(pilot_size(&scene, 128), (128, 72));
        scene.camera.width = 100;
        scene.camera.height = 50;
        assert_eq!(pilot_size(&scene, 128), (100, 50));
    }
}
