//! The path tracer's Denoise toggle: the accumulation denoised with illum-denoise's à-trous
//! filter (WGSL, on the viewer's own device) and finished as every denoised image is
//! (`DenoiseInput::finish`: the bound, and the glint added back), and the halves' estimate of
//! the denoised image's error beside the noisy image's (docs/denoising.md).
//!
//! The halves without a second tracer: the samples of a pixel are indices 0, 1, 2, ..., so the
//! accumulation at an earlier spp (a snapshot, A) and what came after it (the whole less A, B)
//! are two independent sets of samples. While the toggle is on, the accumulation is copied
//! each time its spp has doubled (from 2 spp on; the last two copies are kept, a few MB each),
//! whether or not the guides are back yet. A refresh at spp n denoises the whole (n spp), and
//! with the newest snapshot A of s <= n - 2 spp (s >= 2) also A and B (n - s spp), estimates
//! the denoised error from A and B ([`HalvesError`]) and shows the denoised whole.
//!
//! When: every refresh costs three filter runs, each on lavapipe as much as 10 to 16 spp of
//! path tracing (docs/denoising.md, "Cost"). So the image is denoised again when the spp has
//! doubled since the last time ([`REFRESH_FACTOR`]), which makes the filter's share of the
//! work fall as the render goes on (one refresh per doubling), and the path tracer has had
//! [`PATIENCE`] times the frames' time of the last refresh since it ended, which caps that share
//! near a third at low spp, where the spp doubles faster than a refresh runs; and once more
//! when the render stops. The first image of an
//! accumulation (after a drag, a reset) is denoised as soon as it has [`FIRST_SPP`] samples
//! per pixel, without an estimate (the halves need 2 samples each). The guide buffers
//! (albedo, normal) are rendered once per accumulation, when the toggle is on.
//!
//! Nothing waits for the GPU: the guides and the filter's outputs are read back over later
//! frames ([`PathTracer::start_guides`], [`AtrousDenoiser::start`]), as in a web page.

use web_time::Instant;

use illum_denoise::input::DenoiseInput;
use illum_denoise::{AtrousDenoiser, AtrousSettings, HalvesError, PendingDenoise};
use illum_gpu::GpuContext;
use illum_image::{Encoding, RgbImage32};
use illum_pathtrace::{Accumulator, GUIDE_SAMPLES_MIN, Guides, PathTracer, PendingGuides};
use illum_scene::Scene;

/// The image is denoised again once the spp reached this factor times the last refresh's.
pub const REFRESH_FACTOR: u32 = 2;
/// After a refresh, the next waits until the path tracer has had this many times the frame
/// time the refresh took (so the denoiser takes at most a third of the frames' time, also at
/// low spp, where the spp doubles in less time than a refresh takes on lavapipe).
pub const PATIENCE: f64 = 2.0;
/// The spp at which an accumulation's first denoised image is made.
pub const FIRST_SPP: u32 = 2;

/// What the panel shows of the last refresh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DenoiseEstimate {
    /// Samples per pixel of the denoised image.
    pub spp: u32,
    /// The noisy image's estimated relative error at that spp (from its variance); `None`
    /// below 2 spp.
    pub noisy: Option<f64>,
    /// The halves' estimate of the denoised image's relative error (of a denoised half, so
    /// conservative for the denoised whole); `None` at the first refresh.
    pub denoised: Option<f64>,
    /// The halves' spp (A, B) behind `denoised`.
    pub halves: Option<(u32, u32)>,
    /// Wall seconds from the refresh's start to its estimate (its three filter runs, one per
    /// frame, with the frames between).
    pub seconds: f64,
}

/// A refresh under way: the filter's inputs (the whole, then with a snapshot the two halves),
/// submitted one per frame, and their results as they come back.
struct Job {
    spp: u32,
    whole: Accumulator,
    /// The halves' statistics (A = the snapshot, B = the whole less A) with their spp.
    halves: Option<[(Accumulator, u32); 2]>,
    /// Inputs not submitted yet, the run in flight with its input (which the bound reads),
    /// and the results.
    inputs: Vec<DenoiseInput>,
    pending: Option<(PendingDenoise, DenoiseInput)>,
    done: Vec<RgbImage32>,
    started: Instant,
}

/// The denoised image shown, as an egui texture.
struct Shown {
    image: RgbImage32,
    exposure: f32,
    texture: egui::TextureHandle,
}

/// The Denoise toggle's state for one accumulation.
#[derive(Default)]
pub struct DenoiseView {
    filter: Option<AtrousDenoiser>,
    /// The scene (camera, settings) the state below belongs to: another one restarts it.
    scene: Option<Scene>,
    guides: Option<Guides>,
    pending_guides: Option<PendingGuides>,
    /// The accumulation at its last two doublings of spp, oldest first: the first halves.
    snapshots: Vec<(Accumulator, u32)>,
    /// The last refresh's spp, when it ended, and the frames' time it took.
    refreshed: Option<(u32, Instant, f64)>,
    /// `seconds` when the refresh under way started.
    job_seconds: f64,
    /// The render took no more samples at the last frame.
    stopped: bool,
    job: Option<Job>,
    shown: Option<Shown>,
    estimate: Option<DenoiseEstimate>,
    /// Refreshes since the viewer started (tests and statistics read it).
    pub refreshes: u64,
    /// Wall seconds the frames spent in this module (submitting the guides and the filter
    /// runs, which on lavapipe run them, collecting them, the estimate, the texture), summed
    /// since the viewer started: what the denoiser takes from the frames.
    pub seconds: f64,
    pub error: Option<String>,
    /// A refresh was due at the last frame (so the window must draw another one).
    due: bool,
}

impl DenoiseView {
    /// Forgets everything of the current accumulation (the toggle went off, or it restarted).
    pub fn clear(&mut self) {
        *self = DenoiseView {
            filter: self.filter.take(),
            refreshes: self.refreshes,
            seconds: self.seconds,
            ..DenoiseView::default()
        };
    }

    /// The last refresh's estimate for the current accumulation.
    pub fn estimate(&self) -> Option<DenoiseEstimate> {
        self.estimate
    }

    /// The denoised image shown (linear RGB), once there is one for the current accumulation.
    pub fn image(&self) -> Option<&RgbImage32> {
        self.shown.as_ref().map(|s| &s.image)
    }

    /// The guide buffers of the current accumulation, once read back.
    pub fn guides(&self) -> Option<&Guides> {
        self.guides.as_ref()
    }

    /// The texture to show in place of the noisy image, once there is one.
    pub fn texture(&self) -> Option<egui::TextureId> {
        self.shown.as_ref().map(|s| s.texture.id())
    }

    /// True while guides or filter runs are being read back (the window must keep repainting).
    pub fn is_busy(&self) -> bool {
        self.pending_guides.is_some() || self.job.is_some() || self.due
    }

    /// One frame of work: follows `tracer`'s accumulation, starts or collects guides and filter
    /// runs, and shows the newest denoised image with `exposure` stops. `stopped`: the render
    /// takes no more samples (paused or a stop rule fired), so the last samples are denoised
    /// without waiting for the spp to double.
    pub fn frame(
        &mut self,
        gpu: &GpuContext,
        ctx: &egui::Context,
        tracer: &PathTracer,
        exposure: f32,
        stopped: bool,
    ) {
        let accumulator = tracer.accumulator();
        let restarted = self.scene.as_ref() != Some(tracer.scene())
            || self.snapshots.last().is_some_and(|(s, _)| s.total_samples() > accumulator.total_samples())
            || self.job.as_ref().is_some_and(|j| j.whole.total_samples() > accumulator.total_samples());
        if restarted {
            self.clear();
            self.scene = Some(tracer.scene().clone());
        }
        let clock = Instant::now();
        let stepped = self.step(gpu, ctx, tracer, exposure, stopped);
        self.seconds += clock.elapsed().as_secs_f64();
        if let Err(e) = stepped {
            self.error = Some(e);
            self.job = None;
            self.pending_guides = None;
        }
        if let Some(shown) = &mut self.shown
            && shown.exposure != exposure
        {
            shown.texture.set(colour_image(&shown.image, exposure), egui::TextureOptions::LINEAR);
            shown.exposure = exposure;
        }
    }

    fn step(
        &mut self,
        gpu: &GpuContext,
        ctx: &egui::Context,
        tracer: &PathTracer,
        exposure: f32,
        stopped: bool,
    ) -> Result<(), String> {
        self.stopped = stopped;
        let spp = tracer.spp_done();
        let accumulator = tracer.accumulator();
        if spp >= 2
            && accumulator_complete(accumulator, spp)
            && self.snapshots.last().is_none_or(|(_, s)| spp >= s.saturating_mul(2))
        {
            self.snapshots.push((accumulator.clone(), spp));
            if self.snapshots.len() > 2 {
                self.snapshots.remove(0);
            }
        }
        if self.guides.is_none() {
            match &self.pending_guides {
                None => {
                    let pending = tracer.start_guides(GUIDE_SAMPLES_MIN).map_err(|e| e.to_string())?;
                    self.pending_guides = Some(pending);
                    return Ok(());
                }
                Some(pending) => match pending.poll(gpu) {
                    None => return Ok(()),
                    Some(result) => {
                        self.guides = Some(result.map_err(|e| e.to_string())?);
                        self.pending_guides = None;
                    }
                },
            }
        }
        if self.job.is_some() {
            return self.collect(gpu, ctx, exposure);
        }
        let due = match self.refreshed {
            None => spp >= FIRST_SPP,
            Some((last, _, _)) if stopped => spp > last,
            Some((last, ended, cost)) => {
                spp >= last.saturating_mul(REFRESH_FACTOR) && ended.elapsed().as_secs_f64() >= PATIENCE * cost
            }
        };
        self.due = due && self.error.is_none();
        if due && accumulator_complete(tracer.accumulator(), spp) {
            self.start(tracer.accumulator().clone(), spp)?;
            return self.collect(gpu, ctx, exposure);
        }
        Ok(())
    }

    /// Prepares the filter runs of a refresh at `spp`.
    fn start(&mut self, whole: Accumulator, spp: u32) -> Result<(), String> {
        let guides = self.guides.as_ref().ok_or("no guide buffers")?;
        let halves = match self.snapshots.iter().rev().find(|(_, a_spp)| *a_spp >= 2 && a_spp + 2 <= spp) {
            Some((a, a_spp)) => Some([(a.clone(), *a_spp), (difference(&whole, a)?, spp - a_spp)]),
            None => None,
        };
        let mut inputs: Vec<DenoiseInput> = std::iter::once(&whole)
            .chain(halves.iter().flat_map(|h| h.iter().map(|(a, _)| a)))
            .map(|accumulator| DenoiseInput::from_render(accumulator, guides))
            .collect();
        // Submitted from the back.
        inputs.reverse();
        self.job =
            Some(Job { spp, whole, halves, inputs, pending: None, done: vec![], started: Instant::now() });
        self.job_seconds = self.seconds;
        Ok(())
    }

    /// Collects the filter run in flight and submits the next: one per frame, because on a
    /// software device (lavapipe) a submission runs the filter before it returns, and three in
    /// one frame would freeze the window for the time of three. The denoised whole is shown as
    /// soon as it is back; with the halves back too, the error is estimated.
    fn collect(&mut self, gpu: &GpuContext, ctx: &egui::Context, exposure: f32) -> Result<(), String> {
        if self.filter.is_none() {
            self.filter = Some(AtrousDenoiser::new(gpu).map_err(|e| e.to_string())?);
        }
        let job = self.job.as_mut().expect("called with a job");
        if let Some((pending, input)) = &job.pending {
            match pending.poll(gpu) {
                None => return Ok(()),
                Some(result) => {
                    let mut image = result.map_err(|e| e.to_string())?.0;
                    input.finish(&mut image);
                    job.done.push(image);
                    job.pending = None;
                    if job.done.len() == 1 {
                        let image = job.done[0].clone();
                        self.show(ctx, image, exposure);
                    }
                }
            }
        }
        let job = self.job.as_mut().expect("still there");
        if let Some(input) = job.inputs.pop() {
            let filter = self.filter.as_ref().expect("made above");
            job.pending =
                Some((filter.start(&input, &AtrousSettings::default()).map_err(|e| e.to_string())?, input));
            return Ok(());
        }
        let job = self.job.take().expect("present");
        let mut images = job.done.into_iter();
        let denoised_whole = images.next().expect("the whole is denoised first");
        let denoised = job.halves.as_ref().map(|[(a, _), (b, _)]| {
            let (da, db) = (images.next().expect("half A"), images.next().expect("half B"));
            HalvesError::new(
                (&a.mean_image(), &a.variance_image(), &da),
                (&b.mean_image(), &b.variance_image(), &db),
                &denoised_whole,
            )
            .relative_error()
        });
        let noisy = job.whole.estimated_relative_error();
        self.estimate = Some(DenoiseEstimate {
            spp: job.spp,
            noisy: noisy.is_finite().then_some(noisy),
            denoised: denoised.filter(|e| e.is_finite()),
            halves: job.halves.as_ref().map(|[(_, a), (_, b)]| (*a, *b)),
            seconds: job.started.elapsed().as_secs_f64(),
        });
        self.refreshed = Some((job.spp, Instant::now(), self.seconds - self.job_seconds));
        self.refreshes += 1;
        self.error = None;
        Ok(())
    }

    /// Shows the denoised `image` with `exposure` stops.
    fn show(&mut self, ctx: &egui::Context, image: RgbImage32, exposure: f32) {
        let colours = colour_image(&image, exposure);
        match &mut self.shown {
            Some(shown) => {
                shown.texture.set(colours, egui::TextureOptions::LINEAR);
                shown.image = image;
                shown.exposure = exposure;
            }
            None => {
                let texture = ctx.load_texture("path tracer denoised", colours, egui::TextureOptions::LINEAR);
                self.shown = Some(Shown { image, exposure, texture });
            }
        }
    }

    /// The panel's line: "estimated error: noisy X%, denoised Y%".
    pub fn summary(&self) -> String {
        let percent = |e: Option<f64>| e.map_or("n/a".to_owned(), |e| format!("{:.2}%", 100.0 * e));
        match (&self.error, &self.estimate) {
            (Some(e), _) => format!("denoiser: {e}"),
            (None, None) => "estimated error: (denoising...)".to_owned(),
            (None, Some(est)) => {
                let denoised = match (est.denoised, est.halves) {
                    (Some(e), _) => percent(Some(e)),
                    (None, _) if self.stopped => {
                        "n/a (the render stopped before it had two halves)".to_owned()
                    }
                    (None, _) => format!("n/a until {} spp", (est.spp * REFRESH_FACTOR).max(4)),
                };
                format!(
                    "estimated error: noisy {}, denoised {denoised} (at {} spp)",
                    percent(est.noisy),
                    est.spp
                )
            }
        }
    }
}

impl DenoiseView {
    /// What a `--screenshot` run prints of the denoiser: its line in the panel, the refreshes,
    /// the last refresh's wall time and the frames' time spent in this module.
    pub fn statistics(&self) -> String {
        format!(
            "denoise: {}, {}, last {:.0} ms from start to estimate, {:.2} s of the frames in the denoiser",
            self.summary(),
            crate::plural::count(self.refreshes, "refresh", "refreshes"),
            self.estimate.map_or(0.0, |e| 1e3 * e.seconds),
            self.seconds
        )
    }
}

/// The EXR metadata a save records with Denoise on (as `illum.<key>`): the denoiser, the spp
/// of the denoised image shown, and its estimated relative error; `None` before the first
/// denoised image.
pub fn exr_fields(view: &DenoiseView) -> Option<Vec<(String, String)>> {
    let estimate = view.estimate()?;
    let mut fields = vec![
        ("viewer_shown".to_owned(), "denoised (atrous); this file holds the raw samples".to_owned()),
        ("denoised_spp".to_owned(), estimate.spp.to_string()),
    ];
    if let Some(e) = estimate.denoised {
        fields.push(("denoised_estimated_relative_error".to_owned(), e.to_string()));
    }
    Some(fields)
}

/// Whether every pixel of `accumulator` has `spp` samples or more (a refresh is never made of
/// a pass that covers only some of the image's bands).
fn accumulator_complete(accumulator: &Accumulator, spp: u32) -> bool {
    accumulator.total_samples() > 0 && accumulator.min_samples() >= u64::from(spp)
}

/// The samples of `whole` that are not in `earlier` (an earlier state of the same
/// accumulation): per pixel the sums and counts less `earlier`'s, in f64.
pub fn difference(whole: &Accumulator, earlier: &Accumulator) -> Result<Accumulator, String> {
    let (w, e) = (whole.state(), earlier.state());
    if (whole.width, whole.height) != (earlier.width, earlier.height) {
        return Err("the snapshot is of another size".to_owned());
    }
    let sub = |a: &[[f64; 3]], b: &[[f64; 3]]| -> Vec<[f64; 3]> {
        a.iter().zip(b).map(|(x, y)| [0, 1, 2].map(|c| x[c] - y[c])).collect()
    };
    let count = w.count.iter().zip(e.count).map(|(x, y)| x.saturating_sub(*y)).collect();
    Accumulator::from_state(
        whole.width,
        whole.height,
        sub(w.sum, e.sum),
        sub(w.sum_sq, e.sum_sq),
        count,
        w.dropped.saturating_sub(e.dropped),
    )
}

/// `image` as the viewer shows it: `exposure` stops, clamped, gamma 2.2 (the PNG's encoding,
/// and the display pass's).
pub fn colour_image(image: &RgbImage32, exposure: f32) -> egui::ColorImage {
    let rgba = illum_image::tonemap::to_rgba8(image, exposure, Encoding::Gamma22);
    egui::ColorImage::from_rgba_unmultiplied([image.width as usize, image.height as usize], rgba.as_raw())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The second half is exactly the samples folded after the snapshot.
    #[test]
    fn the_difference_of_accumulations_is_the_later_samples() {
        let first = [[1.0, 2.0, 3.0, 2.0], [0.5, 0.5, 0.5, 1.0]];
        let first_sq = [[0.5, 2.5, 4.5, 0.0], [0.25, 0.25, 0.25, 0.0]];
        let later = [[4.0, 1.0, 0.0, 3.0], [2.0, 2.0, 2.0, 2.0]];
        let later_sq = [[6.0, 0.5, 0.0, 0.0], [2.5, 2.5, 2.5, 0.0]];
        let mut whole = Accumulator::new(2, 1);
        whole.fold(0, &first, &first_sq);
        let snapshot = whole.clone();
        whole.fold(0, &later, &later_sq);
        let mut expected = Accumulator::new(2, 1);
        expected.fold(0, &later, &later_sq);
        let b = difference(&whole, &snapshot).unwrap();
        assert_eq!(b.state().count, expected.state().count);
        assert_eq!(b.state().sum, expected.state().sum);
        assert_eq!(b.state().sum_sq, expected.state().sum_sq);
        assert_eq!(b.total_samples(), 5);
        assert!(difference(&whole, &Accumulator::new(1, 1)).is_err());
    }
}
