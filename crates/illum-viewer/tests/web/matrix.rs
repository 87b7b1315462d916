//! The browser matrix: every built-in scene in every mode, and each cell's page address.

use illum_scene::RendererKind;
use illum_viewer::platform::BUILT_IN_SCENES;

/// The path tracer's samples per pixel in the browser (the page's `?spp=`) on the Cornell box,
/// whose cell the Save EXR and speed checks read.
pub(crate) const SPP: u32 = 8;
/// The same in the other path-traced cells. SwiftShader runs the light tracer at about 750
/// samples/s here, against 36 000 without it (230 s for 8 spp, 74 s for 2), and the classic
/// Cornell box's cell took 60 s at 8. The check keeps its power at 2: the same samples on two
/// drivers differ by f32 rounding only (the light tracer's by 2.8e-5 at 8 spp and 8.4e-5 at 2,
/// the others' by under 1e-5 at 8 and 3.8e-5 at 2), while another seed differs more at fewer
/// samples (7.6e-4 to 5.8e-3 at 8 spp, 2.8e-3 to 2.3e-2 at 2; printed beside each cell). The
/// classic box's cell still takes 52 s at 2 spp, most of it not sampling.
pub(crate) const OTHER_SPP: u32 = 2;
/// The path tracer's resolution scale in the browser (the page's `?scale=`): a quarter of the
/// view each way, about 160 x 140 pixels in browser.mjs's 960 x 600 page, so that the matrix's
/// path-traced cells take seconds each on SwiftShader.
pub(crate) const SCALE: &str = "0.25";

/// One cell of the browser matrix: a built-in scene in one mode (with the path tracer's light
/// tracer on or off where it applies), or the refusal of a mode that cannot render it.
pub(crate) struct Cell {
    pub(crate) name: String,
    pub(crate) scene: &'static str,
    pub(crate) mode: RendererKind,
    /// The path tracer's samples per pixel in the page (`?spp=`).
    pub(crate) spp: u32,
    /// The light tracer, for the path tracer on a scene where it can add a caustic.
    pub(crate) caustics: Option<bool>,
    /// Why `mode` cannot render the scene (the desktop's message), if it cannot.
    pub(crate) refusal: Option<String>,
}

impl Cell {
    /// The page's address for the cell.
    pub(crate) fn query(&self) -> String {
        let mut query = format!("?scene={}&mode={}", self.scene, self.mode);
        if self.mode == RendererKind::PathTrace {
            query += &format!("&spp={}&scale={SCALE}", self.spp);
        }
        if let Some(on) = self.caustics {
            query += if on { "&caustics=on" } else { "&caustics=off" };
        }
        query
    }

    /// What browser.mjs waits for before its screenshot.
    pub(crate) fn expect(&self) -> String {
        if self.refusal.is_some() { "refusal".to_owned() } else { self.mode.to_string() }
    }
}

/// Every built-in scene in every mode, as the desktop's loader sees them: a cell that renders
/// where the mode can (the path tracer twice, light tracer on and off, where the scene has a
/// sun and a mirror or glass object), a refusal where it cannot.
pub(crate) fn matrix() -> Vec<Cell> {
    let mut cells = Vec::new();
    for (scene, text) in BUILT_IN_SCENES {
        let loaded = illum_viewer::scene_file::load_text(scene, text).unwrap_or_else(|e| panic!("{e}"));
        let stem = scene.trim_start_matches("scenes/").trim_end_matches(".toml");
        for mode in [RendererKind::PathTrace, RendererKind::Raster, RendererKind::Whitted] {
            let refusal = match mode {
                RendererKind::PathTrace => loaded.pathtrace.as_ref().err().cloned(),
                RendererKind::Raster => loaded.raster.as_ref().err().cloned(),
                RendererKind::Whitted => loaded.whitted.as_ref().err().cloned(),
            };
            let caustic_applies = loaded.pathtrace.as_ref().is_ok_and(|s| {
                let mut on = s.clone();
                on.pathtrace.caustics = true;
                illum_pathtrace::Estimators::of(&on).caustics()
            });
            let variants: &[Option<bool>] = if mode == RendererKind::PathTrace && caustic_applies {
                &[Some(true), Some(false)]
            } else {
                &[None]
            };
            for &caustics in variants {
                let suffix = match caustics {
                    Some(true) => "-caustics-on",
                    Some(false) => "-caustics-off",
                    None => "",
                };
                let name = format!("{stem}-{mode}{suffix}");
                let spp = if *scene == "scenes/cornell.toml" { SPP } else { OTHER_SPP };
                cells.push(Cell { name, scene, mode, spp, caustics, refusal: refusal.clone() });
            }
        }
    }
    cells
}
