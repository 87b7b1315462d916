//! The Difference view of a noise-free renderer (the rasterizer, the Whitted ray tracer): the signed difference
//! of its image from a truth, per pixel, in a diverging colour map. Such a renderer has no noise
//! but a bias, and this shows where the bias is.
//!
//! The truth is either a file given with `--reference FILE.exr` (desktop; checked against the
//! view by the rule every reader of a reference shares, `illum_pathtrace::reference`), or without one the path tracer's own
//! accumulation in this session when it shows the same scene from the same camera at the same
//! size (in the browser too). A truth that does not match the view is refused by name (a file
//! given is not replaced by the path tracer's image), and the panel says which truth is used
//! and how converged it is (its spp and estimated error). The truth's own noise shows in the
//! map too: at a few spp it sets the scale.
//!
//! The map shows the luminance of the difference, image minus truth: blue where the image is
//! darker than the truth, white where they agree, red where it is brighter. Its scale (the
//! value at full blue and full red) is the 99th percentile of the magnitude over the image,
//! rounded up to 1, 2 or 5 times a power of ten, so a few outliers do not wash the rest out;
//! the panel shows it. The colour-map code is the error view's ([`crate::error_view::ramp`]).

use std::path::Path;

use illum_image::RgbImage32;
use illum_image::rgb_image::REC709_LUMINANCE;
use illum_pathtrace::Accumulator;
use illum_pathtrace::metadata::scene_hash;
use illum_pathtrace::reference::{Reference, SizePolicy};
use illum_scene::Scene;

use crate::error_view::{colour_map, ramp};

/// The diverging ramp: blue (image darker than the truth), white (equal), red (brighter).
const DIVERGING: [[f32; 3]; 3] = [[40.0, 100.0, 230.0], [245.0, 245.0, 245.0], [225.0, 45.0, 40.0]];
/// The share of pixels whose difference is inside the scale (the rest saturate).
const SCALE_QUANTILE: f64 = 0.99;

/// The colour of signed difference `d` on a map whose ends are `-scale` and `+scale`.
pub fn diverging_colour(d: f32, scale: f32) -> [u8; 3] {
    if !d.is_finite() {
        return [0, 0, 0];
    }
    ramp(&DIVERGING, 0.5 + 0.5 * d / scale)
}

/// The smallest of 1, 2, 5 times a power of ten that is at least `x` (a positive value), within
/// f32 rounding (a difference of f32 luminances 0.1 apart is 0.1 to 1e-7 relative).
pub fn round_up_125(x: f64) -> f64 {
    let decade = 10f64.powf(x.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|&v| v >= x * (1.0 - 1e-6))
        .unwrap_or(10.0 * decade)
}

/// The path tracer's accumulation, offered as a truth.
#[derive(Clone, Copy)]
pub struct PathTracerTruth<'a> {
    /// Its scene, with the camera at its resolution.
    pub scene: &'a Scene,
    pub accumulator: &'a Accumulator,
    pub spp: u32,
}

/// What the panel shows of the difference shown.
#[derive(Clone, Debug, PartialEq)]
pub struct DifferenceSummary {
    /// Which truth, and how converged it is.
    pub truth: String,
    /// The map's ends, -scale (blue) and +scale (red), in linear luminance.
    pub scale: f64,
    /// Mean signed luminance difference, image minus truth, and the truth's mean luminance.
    pub mean_difference: f64,
    pub truth_mean: f64,
    /// Per pixel, the luminance of image minus truth (row-major).
    pub values: Vec<f32>,
}

/// A truth's identity, and how to get its image and the note that says what it is (the path
/// tracer's mean image is computed only when the difference must be drawn again).
type LazyTruth<'a> = Box<dyn FnOnce() -> (RgbImage32, String) + 'a>;

/// The Difference view of one mode.
#[derive(Default)]
pub struct DifferenceView {
    /// The panel's toggle.
    pub on: bool,
    /// The `--reference` file, read once and checked against every view.
    reference: Option<Reference>,
    texture: Option<egui::TextureHandle>,
    /// What the texture shows: the image's frame number and the truth's identity.
    shown: Option<(u64, String)>,
    summary: Option<DifferenceSummary>,
    /// Why no difference is shown (no truth that fits), when none is.
    pub refusal: Option<String>,
}

impl DifferenceView {
    /// Reads `path` as the truth (`--reference`, an EXR). Whether it fits the view is checked
    /// every time the view changes.
    pub fn load_reference(&mut self, path: &Path) -> Result<(), String> {
        self.reference = Some(Reference::read(path).map_err(|e| e.to_string())?);
        self.shown = None;
        Ok(())
    }

    /// The difference shown, while the view is on and has a truth.
    pub fn summary(&self) -> Option<&DifferenceSummary> {
        self.summary.as_ref().filter(|_| self.on)
    }

    /// The texture to show instead of the image, while the view is on and has a truth.
    pub fn texture(&self) -> Option<egui::TextureId> {
        self.texture.as_ref().filter(|_| self.on && self.summary.is_some()).map(egui::TextureHandle::id)
    }

    /// Brings the map up to date with `image` (frame number `frame`, rendered of `scene` at its
    /// camera's size, `view_scale` times the view's size each way) and the truths at hand: the
    /// `--reference` file first, else the path tracer's accumulation.
    pub fn update(
        &mut self,
        ctx: &egui::Context,
        image: &RgbImage32,
        frame: u64,
        scene: &Scene,
        view_scale: f32,
        path_tracer: Option<PathTracerTruth<'_>>,
    ) {
        if !self.on {
            return;
        }
        let mut refusals = vec![];
        let mut chosen: Option<(String, LazyTruth<'_>)> = None;
        if let Some(file) = &self.reference {
            let advice = format!(
                "the image is {view_scale} times the view's size each way: resize the window to match, or \
                 give a reference of this size"
            );
            match file.check(scene, SizePolicy::Advice(&advice)) {
                Err(why) => refusals.push(why.to_string()),
                Ok(unchecked) => {
                    let number = |key: &str| file.number(key);
                    let note = format!(
                        "truth: {} ({} spp, estimated error {}){}",
                        file.path.display(),
                        number("spp").map_or("?".to_owned(), |n| n.to_string()),
                        percent(number("estimated_relative_error")),
                        unchecked.map_or(String::new(), |n| format!("; {n}"))
                    );
                    let image = &file.image;
                    chosen = Some(("file".to_owned(), Box::new(move || (image.clone(), note))));
                }
            }
        }
        // A file given is the truth: when it does not fit, that is said, not replaced.
        if self.reference.is_none() {
            match path_tracer {
                None => refusals.push(
                    "no truth: show this scene in the path tracer's mode first (its accumulation is the truth), \
                     or start the viewer with --reference FILE.exr"
                        .to_owned(),
                ),
                Some(pt) => match path_tracer_refusal(pt, scene, view_scale) {
                    Some(why) => refusals.push(why),
                    None => {
                        let id = format!("path tracer {} {}", pt.accumulator.total_samples(), scene_hash(pt.scene));
                        let error = pt.accumulator.estimated_relative_error();
                        let note = format!(
                            "truth: the path tracer's accumulation, {} spp, estimated error {}",
                            pt.spp,
                            percent(error.is_finite().then_some(error))
                        );
                        let accumulator = pt.accumulator;
                        chosen = Some((id, Box::new(move || (accumulator.mean_image(), note))));
                    }
                },
            }
        }
        let Some((id, truth)) = chosen else {
            self.refusal = Some(refusals.join("; "));
            self.summary = None;
            self.shown = None;
            return;
        };
        self.refusal = None;
        let key = (frame, id);
        if self.shown.as_ref() == Some(&key) {
            return;
        }
        let (truth, note) = truth();
        let summary = difference(image, &truth, note);
        let map = colour_map(&summary.values, image.width, image.height, |d| {
            diverging_colour(d, summary.scale as f32)
        });
        // Nearest: each pixel's own difference, not a blend of neighbours.
        match &mut self.texture {
            Some(handle) => handle.set(map, egui::TextureOptions::NEAREST),
            None => {
                self.texture = Some(ctx.load_texture("difference view", map, egui::TextureOptions::NEAREST))
            }
        }
        self.summary = Some(summary);
        self.shown = Some(key);
    }

    /// The panel's rows: the toggle, and the scale and truth or why there is none.
    pub fn panel(&mut self, ui: &mut egui::Ui) {
        ui.checkbox(&mut self.on, "Difference").on_hover_text(
            "The signed difference from a truth (the path tracer's accumulation of the same view, or \
             --reference FILE.exr): blue darker, red brighter than the truth",
        );
        if !self.on {
            return;
        }
        if let Some(s) = &self.summary {
            ui.horizontal(|ui| {
                ui.colored_label(colour32(DIVERGING[0]), format!("-{}", short(s.scale)));
                ui.colored_label(colour32(DIVERGING[1]), "0");
                ui.colored_label(colour32(DIVERGING[2]), format!("+{}", short(s.scale)));
                ui.small("(luminance, linear)");
            });
            let relative = if s.truth_mean > 0.0 { 100.0 * s.mean_difference / s.truth_mean } else { 0.0 };
            ui.small(format!(
                "mean difference {:+.4} ({relative:+.1}% of the truth's mean)",
                s.mean_difference
            ));
            ui.small(&s.truth);
        } else if let Some(why) = &self.refusal {
            ui.colored_label(ui.visuals().warn_fg_color, why);
        }
    }
}

/// Why the path tracer's accumulation cannot be the truth of `scene` (at its camera's size).
fn path_tracer_refusal(pt: PathTracerTruth<'_>, scene: &Scene, view_scale: f32) -> Option<String> {
    if pt.accumulator.total_samples() == 0 || pt.accumulator.min_samples() == 0 {
        return Some("the path tracer has not covered the image yet".to_owned());
    }
    if scene_hash(pt.scene) != scene_hash(scene) {
        return Some(format!(
            "the path tracer's image is of {:?} from another camera or with other content: show this view \
             in the path tracer's mode (switching modes carries the camera) and let it accumulate",
            pt.scene.name
        ));
    }
    let (a, b) = ((pt.scene.camera.width, pt.scene.camera.height), (scene.camera.width, scene.camera.height));
    (a != b).then(|| {
        format!(
            "the path tracer's image is {} x {}, this one {} x {}: set its resolution scale to {view_scale}",
            a.0, a.1, b.0, b.1
        )
    })
}

/// The difference of `image` from `truth` (same size), its scale and means.
pub fn difference(image: &RgbImage32, truth: &RgbImage32, note: String) -> DifferenceSummary {
    let luminance =
        |p: [f32; 3]| -> f64 { p.iter().zip(REC709_LUMINANCE).map(|(&c, w)| f64::from(c) * w).sum() };
    let values: Vec<f32> =
        image.pixels.iter().zip(&truth.pixels).map(|(&a, &t)| (luminance(a) - luminance(t)) as f32).collect();
    let mut magnitudes: Vec<f32> = values.iter().map(|v| v.abs()).filter(|v| v.is_finite()).collect();
    magnitudes.sort_by(f32::total_cmp);
    let quantile = magnitudes
        .get(((magnitudes.len() as f64 * SCALE_QUANTILE) as usize).min(magnitudes.len().saturating_sub(1)))
        .copied()
        .unwrap_or(0.0);
    // An exact match still needs a scale: the smallest the map names.
    let scale = round_up_125(f64::from(quantile).max(1e-4));
    let n = values.len().max(1) as f64;
    let mean_difference = values.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let truth_mean = truth.pixels.iter().map(|&p| luminance(p)).sum::<f64>() / n;
    DifferenceSummary { truth: note, scale, mean_difference, truth_mean, values }
}

fn percent(error: Option<f64>) -> String {
    error.map_or("unknown".to_owned(), |e| format!("{:.2}%", 100.0 * e))
}

/// A scale as the panel writes it: few digits.
fn short(x: f64) -> String {
    format!("{x}")
}

fn colour32([r, g, b]: [f32; 3]) -> egui::Color32 {
    egui::Color32::from_rgb(r as u8, g as u8, b as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_rounds_up_to_one_two_or_five() {
        for (x, want) in [(0.013, 0.02), (0.02, 0.02), (0.021, 0.05), (0.5, 0.5), (0.7, 1.0), (3.0, 5.0)] {
            let got = round_up_125(x);
            assert!((got - want).abs() < 1e-12, "{x}: {got}, want {want}");
        }
    }

    #[test]
    fn the_map_diverges_from_white() {
        assert_eq!(diverging_colour(0.0, 1.0), [245, 245, 245]);
        assert_eq!(diverging_colour(-1.0, 1.0), [40, 100, 230]);
        assert_eq!(diverging_colour(5.0, 1.0), [225, 45, 40]);
        let half = diverging_colour(0.5, 1.0);
        assert!(half[0] > half[2] && half[2] < 245, "{half:?}");
    }

    #[test]
    fn the_difference_is_image_minus_truth_in_luminance() {
        let truth = RgbImage32 { width: 2, height: 1, pixels: vec![[0.5; 3], [0.2; 3]] };
        let image = RgbImage32 { width: 2, height: 1, pixels: vec![[0.6; 3], [0.1; 3]] };
        let s = difference(&image, &truth, String::new());
        assert!((s.values[0] - 0.1).abs() < 1e-6 && (s.values[1] + 0.1).abs() < 1e-6, "{:?}", s.values);
        assert!((s.scale - 0.1).abs() < 1e-12, "{}", s.scale);
        assert!(s.mean_difference.abs() < 1e-6 && (s.truth_mean - 0.35).abs() < 1e-6);
    }
}
