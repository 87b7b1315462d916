//! The pilot itself: a state machine advanced one step at a time (`pilot.rs` says what it
//! measures and how).

use web_time::Instant;

use illum_denoise::AtrousDenoiser;
use illum_gpu::GpuContext;
use illum_image::RgbImage32;
use illum_pathtrace::reference::reference_scene;
use illum_raster::{Options, RasterRenderer, RasterScene};
use illum_scene::{Bounces, Overrides, Scene, Sequence};
use illum_whitted::WhittedTracer;

use super::pending::{Denoising, Pending, Truth};
use super::running::Running;
use super::{Pace, PilotOptions, Progress, Sizes, TimedAt};
use crate::measure::{Measured, measured};
use crate::plan::{Candidate, Setting};
use crate::regions::{Regions, compare_with_map};
use crate::settings::{apply, pilot_size, settings_with_variants, truth_scene};

/// What a step is spent on, for the seconds of each.
#[derive(Clone, Copy)]
enum Phase {
    Truth = 0,
    Bias = 1,
    Throughput = 2,
}

/// The pilot of one scene at one set of sizes.
pub struct Pilot {
    pub(super) options: PilotOptions,
    pub(super) sizes: Sizes,
    /// The scene at the pilot's size, at the rasterizer's size, and where the path tracer's
    /// throughput is timed.
    pub(super) small: Scene,
    raster_scene: Scene,
    pub(super) timing_scene: Scene,
    pub(super) settings: Vec<Setting>,
    /// The truth's image and estimated relMSE, when handed in.
    given_truth: Option<(RgbImage32, f64)>,
    /// Every setting's bias and noise, when handed in.
    given_measured: Option<Vec<Measured>>,
    pub(super) truth: Option<Truth>,
    /// The truth's tracer, then each path-tracer setting's, while it runs.
    pub(super) running: Option<Running>,
    pub(super) pending: Option<Pending>,
    /// What the path-tracer setting being measured has measured at the pilot's size (kept while
    /// its throughput is measured), the spp it has still to stop at and its own estimates there.
    pub(super) bias: Option<Measured>,
    pub(super) stops: Vec<u32>,
    pub(super) estimates: Vec<(u32, f64)>,
    pub(super) denoising: Denoising,
    /// The à-trous filter (made once).
    pub(super) filter: Option<AtrousDenoiser>,
    /// One measurement and one candidate per setting measured so far, in the order of
    /// `settings`.
    measured: Vec<Measured>,
    candidates: Vec<Candidate>,
    /// The rasterizer at its size and its set-up seconds (made once).
    raster: Option<(RasterRenderer, f64)>,
    started: Instant,
    wall_seconds: Option<f64>,
    phase_seconds: [f64; 3],
    longest_step: f64,
    /// This step's submission length, and the pace's wall time per traced second.
    pub(super) slice: f64,
    pub(super) wall_per_traced_second: f64,
    error: Option<String>,
}

impl Pilot {
    /// A pilot of `scene` for renders at `sizes`.
    pub fn new(scene: &Scene, sizes: Sizes, options: PilotOptions) -> Result<Pilot, String> {
        let sized = |[width, height]: [u32; 2]| {
            let mut sized = scene.clone();
            sized
                .apply_overrides(
                    &Overrides { width: Some(width), height: Some(height), ..Default::default() },
                    "the Auto pilot",
                )
                .map(|()| sized)
                .map_err(|e| e.to_string())
        };
        let (w, h) = pilot_size(scene, options.longer_side);
        let small = sized([w, h])?;
        Ok(Pilot {
            options,
            sizes,
            timing_scene: match options.timed_at {
                TimedAt::Pilot => small.clone(),
                TimedAt::Target => sized(sizes.pathtrace)?,
            },
            raster_scene: sized(sizes.raster)?,
            small,
            settings: settings_with_variants(scene, options.variants),
            given_truth: None,
            given_measured: None,
            truth: None,
            running: None,
            pending: None,
            bias: None,
            stops: Vec::new(),
            estimates: Vec::new(),
            denoising: Denoising::default(),
            filter: None,
            measured: Vec::new(),
            candidates: Vec::new(),
            raster: None,
            started: Instant::now(),
            wall_seconds: None,
            phase_seconds: [0.0; 3],
            longest_step: 0.0,
            slice: super::UNPACED_SLICE_SECONDS,
            wall_per_traced_second: 1.0,
            error: None,
        })
    }

    /// The truth at the pilot's size (`image`, with its own estimated relMSE), rendered
    /// elsewhere from [`Self::truth_scene`] as a reference is: the pilot takes its regions only.
    pub fn with_truth(mut self, image: RgbImage32, rel_mse: f64) -> Pilot {
        self.given_truth = Some((image, rel_mse));
        self
    }

    /// Every setting's bias and noise, measured before against the same truth ([`Self::measured`]
    /// of an earlier pilot): the pilot measures the throughput only. Ignored unless there is
    /// one per setting.
    pub fn with_measured(mut self, measured: Vec<Measured>) -> Pilot {
        if measured.len() == self.settings.len() {
            self.given_measured = Some(measured);
        }
        self
    }

    /// The truth's scene: the converged solution at the pilot's size. It is rendered as a
    /// reference is ([`reference_scene`]), to [`PilotOptions::truth_spp`].
    pub fn truth_scene(&self) -> Scene {
        truth_scene(&self.small, Bounces::Unbounded)
    }

    /// The settings measured, in order.
    pub fn settings(&self) -> &[Setting] {
        &self.settings
    }

    pub fn sizes(&self) -> Sizes {
        self.sizes
    }

    pub fn options(&self) -> PilotOptions {
        self.options
    }

    /// The pilot's image size.
    pub fn size(&self) -> (u32, u32) {
        (self.small.camera.width, self.small.camera.height)
    }

    /// Wall seconds from the pilot's start to its end (so far, while it runs).
    pub fn seconds(&self) -> f64 {
        self.wall_seconds.unwrap_or_else(|| self.started.elapsed().as_secs_f64())
    }

    /// Seconds spent in steps on the truth, on the biases and on the throughput.
    pub fn phase_seconds(&self) -> [f64; 3] {
        self.phase_seconds
    }

    /// The longest a step took: how long a window waited at most.
    pub fn longest_step(&self) -> f64 {
        self.longest_step
    }

    /// Why the pilot stopped, when it failed.
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    /// Every setting with its measurements, once all are measured.
    pub fn candidates(&self) -> Option<&[Candidate]> {
        (self.error.is_none() && self.candidates.len() == self.settings.len()).then_some(&self.candidates)
    }

    /// Every setting's bias and noise, once all are measured (what [`Self::with_measured`]
    /// takes back).
    pub fn measured(&self) -> Option<&[Measured]> {
        self.candidates().map(|_| self.measured.as_slice())
    }

    /// The truth's image and estimated relMSE, once it is rendered.
    pub fn truth(&self) -> Option<(&RgbImage32, f64)> {
        self.truth.as_ref().map(|t| (&t.image, t.rel_mse))
    }

    /// Where the pilot stands.
    pub fn progress(&self) -> Progress {
        if let Some(e) = &self.error {
            return Progress::Failed(e.clone());
        }
        if self.candidates().is_some() {
            return Progress::Done;
        }
        match &self.truth {
            None => {
                let spp = self.running.as_ref().map_or(0, |r| r.tracer.spp_done());
                let done = spp as f32 / self.options.truth_spp as f32;
                let what = format!("truth: {spp} / {} spp", self.options.truth_spp);
                Progress::Working { done: 0.5 * done, what }
            }
            Some(_) => {
                let i = self.candidates.len();
                let done = i as f32 / self.settings.len().max(1) as f32;
                let what = format!("setting {} of {}: {}", i + 1, self.settings.len(), self.settings[i]);
                Progress::Working { done: 0.5 + 0.5 * done, what }
            }
        }
    }

    /// Runs the next slice of work (or polls the readback under way) at `pace`; does nothing
    /// once done or failed.
    pub fn step(&mut self, gpu: &GpuContext, pace: &mut dyn Pace) -> Progress {
        if self.error.is_some() || self.candidates().is_some() {
            return self.progress();
        }
        self.slice = pace.slice_seconds();
        self.wall_per_traced_second = pace.wall_per_traced_second();
        let phase = match (&self.truth, &self.given_measured) {
            (None, _) => Phase::Truth,
            (Some(_), Some(_)) => Phase::Throughput,
            (Some(_), None) if self.bias.is_none() => Phase::Bias,
            (Some(_), None) => Phase::Throughput,
        };
        let started = Instant::now();
        if let Err(e) = self.try_step(gpu) {
            self.error = Some(e);
            self.running = None;
            self.pending = None;
        }
        let took = started.elapsed().as_secs_f64();
        pace.stepped(started, took);
        self.phase_seconds[phase as usize] += took;
        self.longest_step = self.longest_step.max(took);
        if self.candidates().is_some() {
            self.wall_seconds = Some(self.started.elapsed().as_secs_f64());
        }
        self.progress()
    }

    fn try_step(&mut self, gpu: &GpuContext) -> Result<(), String> {
        if let Some(pending) = self.pending.take() {
            return self.poll(gpu, pending);
        }
        if self.truth.is_none() {
            return self.step_truth(gpu);
        }
        let setting = self.settings[self.candidates.len()].clone();
        let variant = apply(&self.small, &setting);
        match &setting {
            Setting::Raster { look, effects } => {
                if self.given().is_some() {
                    let fixed = self.raster_frame_seconds(gpu, Options { look: *look, effects: *effects })?;
                    self.push(None, fixed, 0.0);
                    return Ok(());
                }
                let (w, h) = (variant.camera.width, variant.camera.height);
                let mut small =
                    RasterRenderer::new(gpu, &raster_scene(&variant)?, w, h).map_err(|e| e.to_string())?;
                small.draw(&Options { look: *look, effects: *effects }).map_err(|e| e.to_string())?;
                self.pending = Some(Pending::Raster(small.read_polled().map_err(|e| e.to_string())?));
                Ok(())
            }
            Setting::Whitted { .. } => {
                let t = Instant::now();
                let tracer = WhittedTracer::new(gpu, &variant).map_err(|e| e.to_string())?;
                let setup = t.elapsed().as_secs_f64();
                let submitted = Instant::now();
                let image = tracer.render_polled();
                wait_natively(gpu)?;
                self.pending = Some(Pending::Whitted { image, setup, submitted });
                Ok(())
            }
            Setting::PathTrace { .. } => self.step_path_tracer(gpu, &setting),
        }
    }

    /// The measurement handed in for the setting being measured.
    pub(super) fn given(&self) -> Option<&Measured> {
        self.given_measured.as_ref().map(|m| &m[self.candidates.len()])
    }

    /// Polls `pending`; once its result is back, measures what it is of.
    fn poll(&mut self, gpu: &GpuContext, pending: Pending) -> Result<(), String> {
        match pending {
            Pending::Regions { ids, image, rel_mse } => match ids.poll(gpu) {
                None => self.pending = Some(Pending::Regions { ids, image, rel_mse }),
                Some(ids) => {
                    let ids = ids.map_err(|e| e.to_string())?;
                    let regions = Regions::from_ids(&self.small, &ids);
                    self.truth = Some(Truth { image, rel_mse, regions });
                }
            },
            Pending::Raster(frame) => match frame.poll(gpu) {
                None => self.pending = Some(Pending::Raster(frame)),
                Some(image) => {
                    let image = image.map_err(|e| e.to_string())?;
                    let Setting::Raster { look, effects } = self.settings[self.candidates.len()] else {
                        unreachable!("a raster frame is read for a raster setting")
                    };
                    let fixed = self.raster_frame_seconds(gpu, Options { look, effects })?;
                    let m = self.measure(&image, None, 1);
                    self.push(Some(m), fixed, 0.0);
                }
            },
            Pending::Whitted { image, setup, submitted } => match image.poll(gpu) {
                None => self.pending = Some(Pending::Whitted { image, setup, submitted }),
                Some(result) => {
                    let frame = submitted.elapsed().as_secs_f64();
                    let image = result.map_err(|e| e.to_string())?;
                    // Timed at the pilot's size, the frame scaled by the ratio of pixel counts:
                    // at a view's or a render's size a 4x4-ray, depth-8 frame holds the GPU for
                    // seconds, a pilot frame for a fraction of one.
                    let ratio = pixels(self.sizes.whitted) / pixels([image.width, image.height]);
                    let m = self.measure(&image, None, 1);
                    self.push(Some(m), setup + frame * ratio, 0.0);
                }
            },
            pending @ (Pending::Guides { .. } | Pending::Denoised { .. }) => {
                self.poll_denoising(gpu, pending)?
            }
        }
        Ok(())
    }

    /// The rasterizer's set-up (once) and one frame at its size, in seconds.
    fn raster_frame_seconds(&mut self, gpu: &GpuContext, options: Options) -> Result<f64, String> {
        if self.raster.is_none() {
            let scene = raster_scene(&self.raster_scene)?;
            let [w, h] = self.sizes.raster;
            let t = Instant::now();
            let renderer = RasterRenderer::new(gpu, &scene, w, h).map_err(|e| e.to_string())?;
            self.raster = Some((renderer, t.elapsed().as_secs_f64()));
        }
        let (renderer, setup) = self.raster.as_mut().expect("made above");
        let t = Instant::now();
        // Natively `draw` waits for the GPU; in a web page this is the submission's time.
        renderer.draw(&options).map_err(|e| e.to_string())?;
        Ok(*setup + t.elapsed().as_secs_f64())
    }

    /// `image` (at the pilot's size, `spp` samples per pixel, with its own estimated relMSE
    /// where it has one) against the truth.
    pub(super) fn measure(&self, image: &RgbImage32, own_noise: Option<f64>, spp: u32) -> Measured {
        let truth = self.truth.as_ref().expect("settings are measured after the truth");
        let errors = compare_with_map(image, &truth.image, &truth.regions, Vec::new());
        measured(&errors, &truth.regions, truth.rel_mse, own_noise, spp)
    }

    /// The candidate of the setting being measured: its measurement (`None`: the one handed
    /// in) and its costs at the size it will be rendered at.
    pub(super) fn push(&mut self, m: Option<Measured>, fixed_seconds: f64, seconds_per_spp: f64) {
        let setting = self.settings[self.candidates.len()].clone();
        let m = m.or_else(|| self.given().cloned()).expect("measured, or handed in");
        self.candidates.push(Candidate {
            spp_multiple: spp_multiple(&setting, self.options.denoising),
            setting,
            bias_rel_mse: m.bias_rel_mse,
            noise: m.noise.clone(),
            fixed_seconds: self.options.overhead_seconds + fixed_seconds,
            seconds_per_spp,
            worst_region: m.worst_region.clone(),
        });
        self.measured.push(m);
        self.bias = None;
        self.denoising = Denoising::default();
        self.stops.clear();
        self.estimates.clear();
    }

    /// The truth: the converged solution at the pilot's size (rendered here unless handed in);
    /// then its regions.
    fn step_truth(&mut self, gpu: &GpuContext) -> Result<(), String> {
        let (image, rel_mse) = match self.given_truth.take() {
            Some(given) => given,
            None => {
                let running = match &mut self.running {
                    Some(running) => running,
                    None => {
                        let scene = reference_scene(&self.truth_scene(), self.options.truth_spp);
                        let options = Default::default();
                        self.running = Some(Running::start(gpu, &scene, options, false, self.slice)?);
                        return Ok(());
                    }
                };
                if !running.step(self.options.truth_spp, self.slice)? {
                    return Ok(());
                }
                let running = self.running.take().expect("running above");
                let accumulator = running.tracer.accumulator();
                (accumulator.mean_image(), accumulator.estimated_rel_mse())
            }
        };
        let ids = WhittedTracer::new(gpu, &self.small).map_err(|e| e.to_string())?.object_ids_polled();
        let rel_mse = if rel_mse.is_finite() { rel_mse } else { 0.0 };
        self.pending = Some(Pending::Regions { ids, image, rel_mse });
        Ok(())
    }
}

/// The spp a setting renders in multiples of: a denoised render's halves as `denoising` makes
/// them; a low-discrepancy render's error estimate needs whole replicate runs.
fn spp_multiple(setting: &Setting, denoising: super::Denoising) -> u32 {
    match setting {
        Setting::PathTrace { denoise: Some(_), .. } => denoising.spp_multiple(),
        Setting::PathTrace { sequence: Sequence::LowDiscrepancy, .. } => {
            illum_pathtrace::replicates::REPLICATE_RUN
        }
        _ => 1,
    }
}

pub(super) fn pixels([w, h]: [u32; 2]) -> f64 {
    f64::from(w) * f64::from(h)
}

fn raster_scene(scene: &Scene) -> Result<RasterScene, String> {
    RasterScene::from_scene(scene).map_err(|e| e.to_string())
}

/// Natively, waits for the GPU (so that a submission's time is the GPU's); in a web page
/// nothing may wait, and the readback is polled on later steps.
pub(super) fn wait_natively(gpu: &GpuContext) -> Result<(), String> {
    #[cfg(not(target_arch = "wasm32"))]
    gpu.wait_idle("the Auto pilot's step").map_err(|e| e.to_string())?;
    #[cfg(target_arch = "wasm32")]
    let _ = gpu;
    Ok(())
}
