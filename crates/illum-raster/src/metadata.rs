//! The EXR metadata of a rasterized frame: one builder for every program that saves one, so that
//! each key means the same everywhere. A frame carries the raster's own settings and none of the
//! path tracer's keys (spp, bounces, seed, sampling).

use illum_image::ExrMetadata;

use crate::{Look, Options, RasterScene};

/// The renderer name rasterized images carry (`illum.renderer`).
pub const RENDERER: &str = "raster";

/// Metadata for a frame of `scene` drawn with `options` on the adapter named `adapter`, in
/// `render_seconds` (wall-clock, setup included). Keys (each stored as `illum.<key>`):
///
/// - `renderer` = `raster`, `scene` = the scene's name, `render_seconds`;
/// - `look`: `figure` or `enhanced`; `options`: [`describe`]; `antialiasing`: how edges were
///   drawn (`analytic coverage, 1 sample per pixel` or `off, 1 sample per pixel`);
/// - `adapter`: the GPU adapter's name.
pub fn exr_metadata(
    scene: &RasterScene,
    options: &Options,
    adapter: &str,
    render_seconds: f64,
) -> ExrMetadata {
    ExrMetadata {
        renderer: RENDERER.to_owned(),
        scene: scene.name.clone(),
        render_seconds,
        fields: vec![
            ("look".into(), options.look.to_string()),
            ("options".into(), describe(options)),
            ("antialiasing".into(), antialiasing(options).into()),
            ("adapter".into(), adapter.to_owned()),
        ],
    }
}

/// The look and the effects that change the frame, e.g. `look enhanced, effects: shadows pcf
/// refraction reflection fresnel antialiasing` (`none` for no effect). Reflection and Fresnel
/// are listed only in the enhanced look, the only one that has them.
pub fn describe(options: &Options) -> String {
    let e = &options.effects;
    let effects: Vec<&str> = [
        (e.shadows, "shadows"),
        (e.pcf, "pcf"),
        (e.refraction, "refraction"),
        (e.reflection && options.look == Look::Enhanced, "reflection"),
        (e.fresnel && options.look == Look::Enhanced, "fresnel"),
        (e.antialiasing, "antialiasing"),
    ]
    .into_iter()
    .filter_map(|(on, name)| on.then_some(name))
    .collect();
    format!(
        "look {}, effects: {}",
        options.look,
        if effects.is_empty() { "none".into() } else { effects.join(" ") }
    )
}

/// The `antialiasing` field: how the frame's edges were drawn.
fn antialiasing(options: &Options) -> &'static str {
    if options.effects.antialiasing {
        "analytic coverage, 1 sample per pixel"
    } else {
        "off, 1 sample per pixel"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Effects;

    #[test]
    fn the_figure_look_lists_no_reflection_or_fresnel_and_no_effect_reads_none() {
        let figure = Options::all_on(Look::Figure);
        assert_eq!(describe(&figure), "look figure, effects: shadows pcf refraction antialiasing");
        let enhanced = Options::all_on(Look::Enhanced);
        assert_eq!(
            describe(&enhanced),
            "look enhanced, effects: shadows pcf refraction reflection fresnel antialiasing"
        );
        let none = Options {
            look: Look::Enhanced,
            effects: Effects {
                shadows: false,
                pcf: false,
                refraction: false,
                reflection: false,
                fresnel: false,
                antialiasing: false,
            },
        };
        assert_eq!(describe(&none), "look enhanced, effects: none");
        assert_eq!(antialiasing(&none), "off, 1 sample per pixel");
    }
}
