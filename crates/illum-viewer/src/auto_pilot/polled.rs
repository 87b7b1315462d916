//! The pilot itself: a state machine advanced one step per frame (`auto_pilot.rs` says what
//! it measures and how).

use web_time::Instant;

use illum_auto::measure::{denoised, denoised_spps, measured};
use illum_auto::plan::{Candidate, Setting};
use illum_auto::regions::{Regions, compare_with_map};
use illum_auto::settings::{apply, pilot_size, settings_with_variants, truth_scene};
use illum_denoise::{AtrousDenoiser, AtrousSettings, DenoiseInput};
use illum_gpu::GpuContext;
use illum_image::RgbImage32;
use illum_pathtrace::GUIDE_SAMPLES_MIN;
use illum_raster::{Options, RasterRenderer, RasterScene};
use illum_scene::{Bounces, Overrides, Scene};
use illum_whitted::WhittedTracer;

use super::pending::{Denoising, Pending, Truth};
use super::running::Running;
use super::{FILTER_RUNS, PilotOptions, SETTINGS, ViewSizes};
use crate::pacer::FramePacer;

/// The pilot of one view.
pub struct ViewerPilot {
    options: PilotOptions,
    /// The scene at the pilot's size.
    small: Scene,
    /// The scene at the raster's size in the view, and at the path tracer's.
    view_scene: Scene,
    pathtrace_scene: Scene,
    /// A path-tracer setting's image and estimated relMSE at the pilot's size, while its
    /// throughput is being measured.
    measured: Option<(RgbImage32, f64)>,
    /// A denoised setting's guides, images and filter times at the pilot's size (kept
    /// while its throughput is measured), and the filter (made once).
    denoising: Denoising,
    filter: Option<AtrousDenoiser>,
    sizes: ViewSizes,
    settings: Vec<Setting>,
    truth: Option<Truth>,
    /// The truth's tracer, then each path-tracer setting's, while it runs.
    running: Option<Running>,
    pending: Option<Pending>,
    /// One candidate per setting measured so far, in the order of `settings`.
    candidates: Vec<Candidate>,
    /// The rasterizer at the view's size and its set-up seconds (made once).
    raster: Option<(RasterRenderer, f64)>,
    /// When the pilot started, and its wall seconds once done.
    started: Instant,
    wall_seconds: Option<f64>,
    /// The longest a frame's step took: how long the window waited at most.
    longest_step: f64,
    /// Paces the path tracing as the path-tracer mode's frames are, and measures the rest
    /// of each frame; this frame's share.
    pacer: FramePacer,
    slice: f64,
    error: Option<String>,
}

impl ViewerPilot {
    /// A pilot of `scene` (its camera at the raster's size in the view) for views of `sizes`.
    pub fn new(scene: &Scene, sizes: ViewSizes, options: PilotOptions) -> Result<ViewerPilot, String> {
        let sized = |(width, height): (u32, u32)| {
            let mut sized = scene.clone();
            sized
                .apply_overrides(
                    &Overrides { width: Some(width), height: Some(height), ..Default::default() },
                    "the Auto pilot",
                )
                .map(|()| sized)
                .map_err(|e| e.to_string())
        };
        let pair = |[w, h]: [u32; 2]| (w, h);
        Ok(ViewerPilot {
            options,
            settings: settings_with_variants(scene, SETTINGS),
            small: sized(pilot_size(scene, options.longer_side))?,
            view_scene: sized(pair(sizes.raster))?,
            pathtrace_scene: sized(pair(sizes.pathtrace))?,
            measured: None,
            denoising: Denoising::default(),
            filter: None,
            sizes,
            truth: None,
            running: None,
            pending: None,
            candidates: Vec::new(),
            raster: None,
            started: Instant::now(),
            wall_seconds: None,
            longest_step: 0.0,
            pacer: FramePacer::default(),
            slice: crate::pacer::MOVING_SECONDS,
            error: None,
        })
    }

    pub fn sizes(&self) -> ViewSizes {
        self.sizes
    }

    /// The pilot's image size.
    pub fn size(&self) -> (u32, u32) {
        (self.small.camera.width, self.small.camera.height)
    }

    pub fn options(&self) -> PilotOptions {
        self.options
    }

    /// Wall seconds from the pilot's start to its end (so far, while it runs), the window's
    /// frames included.
    pub fn seconds(&self) -> f64 {
        self.wall_seconds.unwrap_or_else(|| self.started.elapsed().as_secs_f64())
    }

    /// The longest a frame spent in the pilot's work, in seconds.
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

    /// The share of the work done (the truth counts half, the settings the other half) and
    /// what is being measured.
    pub fn progress(&self) -> (f32, String) {
        match &self.truth {
            None => {
                let spp = self.running.as_ref().map_or(0, |r| r.tracer.spp_done());
                let done = spp as f32 / self.options.truth_spp as f32;
                (0.5 * done, format!("truth: {spp} / {} spp", self.options.truth_spp))
            }
            Some(_) => {
                let i = self.candidates.len();
                let done = i as f32 / self.settings.len().max(1) as f32;
                let what = self.settings.get(i).map_or("done".to_owned(), |s| {
                    format!("setting {} of {}: {s}", i + 1, self.settings.len())
                });
                (0.5 + 0.5 * done, what)
            }
        }
    }

    /// Runs the next slice of work (or polls the readback under way); does nothing once
    /// done or failed.
    pub fn step(&mut self, gpu: &GpuContext) {
        if self.error.is_some() || self.candidates().is_some() {
            return;
        }
        // The view is still while the pilot runs (it shows the progress).
        self.slice = self.pacer.submission_seconds(false);
        let what = self.progress().1;
        let started = Instant::now();
        if let Err(e) = self.try_step(gpu) {
            self.error = Some(e);
            self.running = None;
            self.pending = None;
        }
        let took = started.elapsed().as_secs_f64();
        self.pacer.stepped(started, took);
        self.longest_step = self.longest_step.max(took);
        log::debug!("auto pilot: {took:.3} s on {what}");
        if self.candidates().is_some() {
            self.wall_seconds = Some(self.started.elapsed().as_secs_f64());
        }
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
                let options = Options { look: *look, effects: *effects };
                let (w, h) = (variant.camera.width, variant.camera.height);
                let mut small =
                    RasterRenderer::new(gpu, &raster_scene(&variant)?, w, h).map_err(|e| e.to_string())?;
                small.draw(&options).map_err(|e| e.to_string())?;
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
            Setting::PathTrace { .. } => self.step_path_tracer(gpu, setting, variant),
        }
    }

    /// Polls `pending`; once its image is back, measures what it is of.
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
                    self.push(image, None, fixed, 0.0);
                }
            },
            Pending::Whitted { image, setup, submitted } => match image.poll(gpu) {
                None => self.pending = Some(Pending::Whitted { image, setup, submitted }),
                Some(result) => {
                    let frame = submitted.elapsed().as_secs_f64();
                    let image = result.map_err(|e| e.to_string())?;
                    // Timed at the pilot's size, the frame scaled by the ratio of pixel
                    // counts to the Whitted mode's size: at that size a 4x4-ray, depth-8
                    // frame holds the GPU for seconds, a pilot frame for a fraction of one.
                    let [w, h] = self.sizes.whitted;
                    let (sw, sh) = (image.width, image.height);
                    let ratio = f64::from(w) * f64::from(h) / (f64::from(sw) * f64::from(sh));
                    self.push(image, None, setup + frame * ratio, 0.0);
                }
            },
            Pending::Guides { guides, submitted } => match guides.poll(gpu) {
                None => self.pending = Some(Pending::Guides { guides, submitted }),
                Some(result) => {
                    self.denoising.guides = Some(result.map_err(|e| e.to_string())?);
                    self.denoising.guide_seconds = submitted.elapsed().as_secs_f64();
                }
            },
            Pending::Denoised { pending, input, spp, submitted } => match pending.poll(gpu) {
                None => self.pending = Some(Pending::Denoised { pending, input, spp, submitted }),
                Some(result) => {
                    let seconds = submitted.elapsed().as_secs_f64();
                    let mut image = result.map_err(|e| e.to_string())?.0;
                    // Finished as every denoised image is (the Denoise toggle's, the CLI's).
                    input.finish(&mut image);
                    // As a deterministic image: its relMSE less the truth's noise.
                    let truth = self.truth.as_ref().expect("settings are measured after the truth");
                    let errors = compare_with_map(&image, &truth.image, &truth.regions, Vec::new());
                    let m = measured(&errors, &truth.regions, truth.rel_mse, None, spp);
                    let denoising = &mut self.denoising;
                    let first = denoising.at.is_empty();
                    denoising.filter_seconds =
                        if first { seconds } else { denoising.filter_seconds.min(seconds) };
                    denoising.at.push((spp, m));
                }
            },
        }
        Ok(())
    }

    /// The raster's set-up (once) and one frame at the view's size, in seconds.
    fn raster_frame_seconds(&mut self, gpu: &GpuContext, options: Options) -> Result<f64, String> {
        if self.raster.is_none() {
            let scene = raster_scene(&self.view_scene)?;
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

    /// A path-tracer setting: first its bias and noise at the pilot's size, then its
    /// throughput at the size the path-tracer mode renders the view at. A denoised setting
    /// also has its guides made and its accumulation filtered at each spp of
    /// `denoised_spps` at the pilot's size, their time scaled by the ratio of pixel counts
    /// as the Whitted frame's is (at the view's size one filter run held the window for
    /// 2.4 s on lavapipe; the filter's work is the same per pixel).
    fn step_path_tracer(&mut self, gpu: &GpuContext, setting: Setting, variant: Scene) -> Result<(), String> {
        let denoise = matches!(setting, Setting::PathTrace { denoise: Some(_), .. });
        let pilot_spp = self.options.pilot_spp;
        let measuring = self.measured.is_none();
        let (scene, spp) = if measuring {
            // A denoised setting stops at each spp it is denoised at, the first not yet.
            let at = &self.denoising.at;
            let next = denoised_spps(pilot_spp).into_iter().find(|n| !at.iter().any(|(m, _)| m == n));
            (variant, if denoise { next.unwrap_or(pilot_spp) } else { pilot_spp })
        } else {
            (apply(&self.pathtrace_scene, &setting), self.options.timing_spp + 1)
        };
        let running = match &mut self.running {
            Some(running) => running,
            None => {
                self.running = Some(Running::start(gpu, &scene)?);
                return Ok(());
            }
        };
        if !running.step(spp, self.slice)? {
            return Ok(());
        }
        if denoise && measuring {
            let Some(guides) = &self.denoising.guides else {
                let submitted = Instant::now();
                // The Denoise toggle's guides (denoise_view.rs), which show the choice.
                let guides = running.tracer.start_guides(GUIDE_SAMPLES_MIN).map_err(|e| e.to_string())?;
                wait_natively(gpu)?;
                self.pending = Some(Pending::Guides { guides, submitted });
                return Ok(());
            };
            if !self.denoising.at.iter().any(|(n, _)| *n == spp) {
                if self.filter.is_none() {
                    self.filter = Some(AtrousDenoiser::new(gpu).map_err(|e| e.to_string())?);
                }
                let filter = self.filter.as_ref().expect("made above");
                let input = DenoiseInput::from_render(running.tracer.accumulator(), guides);
                let submitted = Instant::now();
                let pending = filter.start(&input, &AtrousSettings::default()).map_err(|e| e.to_string())?;
                wait_natively(gpu)?;
                self.pending = Some(Pending::Denoised { pending, input, spp, submitted });
                return Ok(());
            }
            if spp < pilot_spp {
                return Ok(());
            }
        }
        let running = self.running.take().expect("running above");
        let Some((image, noise)) = self.measured.take() else {
            let accumulator = running.tracer.accumulator();
            self.measured = Some((accumulator.mean_image(), accumulator.estimated_rel_mse()));
            // The guides are of the tracer just finished.
            self.denoising.guides = None;
            return Ok(());
        };
        let wall = self.pacer.wall_per_traced_second().unwrap_or(1.0);
        let setup = running.setup_seconds.unwrap_or(0.0);
        let filtering = if denoise {
            let [w, h] = self.sizes.pathtrace;
            let (sw, sh) = self.size();
            let ratio = f64::from(w) * f64::from(h) / (f64::from(sw) * f64::from(sh));
            (self.denoising.guide_seconds + FILTER_RUNS * self.denoising.filter_seconds) * ratio
        } else {
            0.0
        };
        self.push(image, Some(noise), setup + filtering, running.seconds_per_spp() * wall);
        Ok(())
    }

    /// The candidate of the setting being measured, from its image at the pilot's size.
    fn push(&mut self, image: RgbImage32, own_noise: Option<f64>, fixed_seconds: f64, seconds_per_spp: f64) {
        let setting = self.settings[self.candidates.len()].clone();
        let truth = self.truth.as_ref().expect("settings are measured after the truth");
        let errors = compare_with_map(&image, &truth.image, &truth.regions, Vec::new());
        let mut m = measured(&errors, &truth.regions, truth.rel_mse, own_noise, self.options.pilot_spp);
        let denoising = std::mem::take(&mut self.denoising);
        if let Setting::PathTrace { denoise: Some(_), .. } = setting {
            m = denoised(m, &denoising.at);
        }
        self.candidates.push(Candidate {
            setting,
            bias_rel_mse: m.bias_rel_mse,
            noise: m.noise,
            spp_multiple: 1,
            fixed_seconds,
            seconds_per_spp,
            worst_region: m.worst_region,
        });
    }

    /// The truth: the converged solution, as the CLI's pilot renders it; then its regions.
    fn step_truth(&mut self, gpu: &GpuContext) -> Result<(), String> {
        let running = match &mut self.running {
            Some(running) => running,
            None => {
                let truth = truth_scene(&self.small, Bounces::Unbounded);
                self.running = Some(Running::start(gpu, &truth)?);
                return Ok(());
            }
        };
        if !running.step(self.options.truth_spp, self.slice)? {
            return Ok(());
        }
        let running = self.running.take().expect("running above");
        let accumulator = running.tracer.accumulator();
        let rel_mse = accumulator.estimated_rel_mse();
        let ids = WhittedTracer::new(gpu, &self.small).map_err(|e| e.to_string())?.object_ids_polled();
        self.pending = Some(Pending::Regions {
            ids,
            image: accumulator.mean_image(),
            rel_mse: if rel_mse.is_finite() { rel_mse } else { 0.0 },
        });
        Ok(())
    }
}

fn raster_scene(scene: &Scene) -> Result<RasterScene, String> {
    RasterScene::from_scene(scene).map_err(|e| e.to_string())
}

/// Natively, waits for the GPU (so that a frame's time is the GPU's); in a web page nothing
/// may wait, and the readback is polled on later frames.
fn wait_natively(gpu: &GpuContext) -> Result<(), String> {
    #[cfg(not(target_arch = "wasm32"))]
    gpu.wait_idle("the Auto pilot's frame").map_err(|e| e.to_string())?;
    #[cfg(target_arch = "wasm32")]
    let _ = gpu;
    Ok(())
}
