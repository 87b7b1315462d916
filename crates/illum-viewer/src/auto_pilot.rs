//! The Auto mode's pilot: what the planner needs, measured on the view's scene with the
//! viewer's own renderers, a slice of work per frame so that the window keeps drawing.
//!
//! It measures what `render --renderer auto`'s pilot measures (`illum_lab::auto::pilot`), with
//! the same settings, regions and bias rule (`illum_auto`), smaller so that it ends in seconds:
//! - a path-traced truth at [`PilotOptions::longer_side`] pixels on the longer side (the view's
//!   aspect, bounces unbounded, the caustic's light tracer where there is one), accumulated
//!   over frames to [`PilotOptions::truth_spp`];
//! - every setting of `illum_auto::settings::settings` at that size against it, one per frame
//!   (a path-tracer setting over several frames to [`PilotOptions::pilot_spp`]): its bias, its
//!   noise per sample and its worst region;
//! - the throughput at the size each mode renders the view at: the rasterizer's set-up and one
//!   frame; the Whitted ray tracer's set-up and frame at the pilot's size, the frame scaled by
//!   the ratio of pixel counts (a 4x4-ray frame at the view's size held the window for 3 s);
//!   the path tracer's set-up with its first sample per pixel and its time per spp over
//!   [`PilotOptions::timing_spp`] more at its own resolution, times the wall time per second of path tracing that the window's frames leave
//!   ([`FramePacer`]: the pilot's path tracing is paced as the path-tracer mode's is, so the
//!   rest of each frame is measured while it runs). The viewer's device is already set up, so
//!   no device time is added.
//!
//! Native only: the rasterizer's image and the object-ID image are read back with a blocking
//! wait, which a web page cannot do (the browser's Auto panel says so).

#[cfg(doc)]
use crate::pacer::FramePacer;
#[cfg(not(target_arch = "wasm32"))]
pub use native::ViewerPilot;

/// How the viewer's pilot measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PilotOptions {
    /// Pixels on the longer side of the pilot's images.
    pub longer_side: u32,
    /// Samples per pixel of the truth.
    pub truth_spp: u32,
    /// Samples per pixel of each path-tracer setting.
    pub pilot_spp: u32,
    /// Samples per pixel of each path-tracer setting's throughput at the view's size (after
    /// the first, which counts in its set-up).
    pub timing_spp: u32,
}

impl Default for PilotOptions {
    /// Half the CLI's pilot side and a quarter of its truth's spp: on lavapipe (2 cores) the
    /// Whitted scene's pilot takes about 15 s, so it is run while the user watches.
    fn default() -> Self {
        PilotOptions { longer_side: 64, truth_spp: 2048, pilot_spp: 64, timing_spp: 4 }
    }
}

/// The size, in pixels, at which each mode renders the view: what the throughput is scaled to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSizes {
    pub raster: [u32; 2],
    pub whitted: [u32; 2],
    pub pathtrace: [u32; 2],
}

/// The pilot itself, native only (see the module's comment).
#[cfg(not(target_arch = "wasm32"))]
mod native {
    use web_time::Instant;

    use illum_auto::measure::measured;
    use illum_auto::plan::{Candidate, Setting};
    use illum_auto::regions::{Regions, compare_with_map};
    use illum_auto::settings::{apply, has_caustic, pilot_size, settings};
    use illum_gpu::GpuContext;

    use super::{PilotOptions, ViewSizes};
    use crate::pacer::FramePacer;
    use illum_image::RgbImage32;
    use illum_pathtrace::PathTracer;
    use illum_raster::{Options, RasterRenderer, RasterScene};
    use illum_scene::{Bounces, Overrides, Scene};
    use illum_whitted::WhittedTracer;

    /// A path tracer being run to a number of samples over frames, with its timing.
    struct Running {
        tracer: PathTracer,
        /// Seconds to create it and run its first sample per pixel (pipeline, buffers).
        setup_seconds: f64,
        /// Seconds of the steps after the first sample, and the spp they added.
        step_seconds: f64,
        step_spp: u32,
    }

    impl Running {
        fn start(gpu: &GpuContext, scene: &Scene) -> Result<Running, String> {
            let started = Instant::now();
            let mut tracer = PathTracer::new(gpu, scene).map_err(|e| e.to_string())?;
            tracer.set_target_seconds(crate::pacer::MOVING_SECONDS);
            while tracer.spp_done() < 1 {
                tracer.render_step(Some(1)).map_err(|e| e.to_string())?;
            }
            Ok(Running {
                tracer,
                setup_seconds: started.elapsed().as_secs_f64(),
                step_seconds: 0.0,
                step_spp: 0,
            })
        }

        /// One submission of about `seconds` toward `spp`; true once it is reached.
        fn step(&mut self, spp: u32, seconds: f64) -> Result<bool, String> {
            if self.tracer.spp_done() >= spp {
                return Ok(true);
            }
            self.tracer.set_target_seconds(seconds);
            let before = self.tracer.spp_done();
            let started = Instant::now();
            self.tracer.render_step(Some(spp)).map_err(|e| e.to_string())?;
            self.step_seconds += started.elapsed().as_secs_f64();
            self.step_spp += self.tracer.spp_done() - before;
            Ok(self.tracer.spp_done() >= spp)
        }

        /// Seconds per spp over the whole pilot image (the first sample, counted in the set-up,
        /// aside).
        fn seconds_per_spp(&self) -> f64 {
            if self.step_spp == 0 { self.setup_seconds } else { self.step_seconds / f64::from(self.step_spp) }
        }
    }

    /// The truth once rendered: its image, its own estimated relMSE and the regions.
    struct Truth {
        image: RgbImage32,
        rel_mse: f64,
        regions: Regions,
    }

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
        sizes: ViewSizes,
        settings: Vec<Setting>,
        truth: Option<Truth>,
        /// The truth's tracer, then each path-tracer setting's, while it runs.
        running: Option<Running>,
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
                settings: settings(scene),
                small: sized(pilot_size(scene, options.longer_side))?,
                view_scene: sized(pair(sizes.raster))?,
                pathtrace_scene: sized(pair(sizes.pathtrace))?,
                measured: None,
                sizes,
                truth: None,
                running: None,
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

        /// Runs the next slice of work; does nothing once done or failed.
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
            if self.truth.is_none() {
                return self.step_truth(gpu);
            }
            let setting = self.settings[self.candidates.len()].clone();
            let variant = apply(&self.small, &setting);
            let (image, own_noise, fixed_seconds, seconds_per_spp) = match &setting {
                Setting::Raster { look, effects } => {
                    let options = Options { look: *look, effects: *effects };
                    let (w, h) = (variant.camera.width, variant.camera.height);
                    let image = RasterRenderer::new(gpu, &raster_scene(&variant)?, w, h)
                        .and_then(|mut small| small.render(&options))
                        .map_err(|e| e.to_string())?;
                    if self.raster.is_none() {
                        let scene = raster_scene(&self.view_scene)?;
                        let [w, h] = self.sizes.raster;
                        let t = Instant::now();
                        let renderer = RasterRenderer::new(gpu, &scene, w, h).map_err(|e| e.to_string())?;
                        self.raster = Some((renderer, t.elapsed().as_secs_f64()));
                    }
                    let (renderer, setup) = self.raster.as_mut().expect("made above");
                    let t = Instant::now();
                    renderer.render(&options).map_err(|e| e.to_string())?;
                    (image, None, *setup + t.elapsed().as_secs_f64(), 0.0)
                }
                Setting::Whitted { .. } => {
                    // Timed at the pilot's size, the frame scaled by the ratio of pixel counts to
                    // the Whitted mode's size: at that size a 4x4-ray, depth-8 frame holds the
                    // window for seconds, where a pilot frame holds it for a fraction of one.
                    let t = Instant::now();
                    let tracer = WhittedTracer::new(gpu, &variant).map_err(|e| e.to_string())?;
                    let setup = t.elapsed().as_secs_f64();
                    let t = Instant::now();
                    let image = tracer.render().map_err(|e| e.to_string())?;
                    let [w, h] = self.sizes.whitted;
                    let ratio = f64::from(w) * f64::from(h)
                        / (f64::from(variant.camera.width) * f64::from(variant.camera.height));
                    (image, None, setup + t.elapsed().as_secs_f64() * ratio, 0.0)
                }
                Setting::PathTrace { .. } => {
                    // First the bias and noise at the pilot's size, then the throughput at the
                    // size the path-tracer mode renders the view at.
                    let (scene, spp) = match &self.measured {
                        None => (variant, self.options.pilot_spp),
                        Some(_) => (apply(&self.pathtrace_scene, &setting), self.options.timing_spp + 1),
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
                    let running = self.running.take().expect("running above");
                    let Some((image, noise)) = self.measured.take() else {
                        let accumulator = running.tracer.accumulator();
                        self.measured = Some((accumulator.mean_image(), accumulator.estimated_rel_mse()));
                        return Ok(());
                    };
                    let wall = self.pacer.wall_per_traced_second().unwrap_or(1.0);
                    (image, Some(noise), running.setup_seconds, running.seconds_per_spp() * wall)
                }
            };
            let truth = self.truth.as_ref().expect("checked above");
            let errors = compare_with_map(&image, &truth.image, &truth.regions, Vec::new());
            let m = measured(&errors, &truth.regions, truth.rel_mse, own_noise, self.options.pilot_spp);
            self.candidates.push(Candidate {
                setting,
                bias_rel_mse: m.bias_rel_mse,
                noise: m.noise,
                spp_multiple: 1,
                fixed_seconds,
                seconds_per_spp,
                worst_region: m.worst_region,
            });
            Ok(())
        }

        /// The truth: the converged solution, as the CLI's pilot renders it.
        fn step_truth(&mut self, gpu: &GpuContext) -> Result<(), String> {
            let running = match &mut self.running {
                Some(running) => running,
                None => {
                    let mut truth_scene = self.small.clone();
                    truth_scene.pathtrace.bounces = Bounces::Unbounded;
                    truth_scene.pathtrace.caustics = has_caustic(&self.small);
                    self.running = Some(Running::start(gpu, &truth_scene)?);
                    return Ok(());
                }
            };
            if !running.step(self.options.truth_spp, self.slice)? {
                return Ok(());
            }
            let running = self.running.take().expect("running above");
            let accumulator = running.tracer.accumulator();
            let rel_mse = accumulator.estimated_rel_mse();
            let ids = WhittedTracer::new(gpu, &self.small)
                .and_then(|t| t.object_ids())
                .map_err(|e| e.to_string())?;
            self.truth = Some(Truth {
                image: accumulator.mean_image(),
                rel_mse: if rel_mse.is_finite() { rel_mse } else { 0.0 },
                regions: Regions::from_ids(&self.small, &ids),
            });
            Ok(())
        }
    }

    fn raster_scene(scene: &Scene) -> Result<RasterScene, String> {
        RasterScene::from_scene(scene).map_err(|e| e.to_string())
    }
}
