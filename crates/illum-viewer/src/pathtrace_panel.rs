//! The path-tracer mode: its settings, its `PathTracer` on the shared device, the per-frame
//! slice of rendering work, live statistics, stop rules and saving.
//!
//! Responsiveness: each frame runs one submission, sized by the [`FramePacer`] to what the rest
//! of the frame leaves of a 12 fps frame (short while the view changes), and covering the whole
//! image whenever one pass is at most [`WHOLE_PASS_SAMPLES`] paths, so that every frame shows a
//! complete image. A change of camera, window size or setting goes through `PathTracer::update_scene`,
//! which restarts the accumulation without recompiling the pipeline.
//!
//! Stop rules and time: the panel drives an [`illum_pathtrace::Progressive`], the stop rules
//! the `render` example uses too. Its clock is wall-clock time while this mode renders (not
//! while it is paused, stopped or hidden behind the raster mode), so "Elapsed", "Samples/s" and
//! "After time budget" include drawing the window, as a stopwatch would.
//!
//! Display: the tracer's display sum (on the GPU) is drawn by [`Display`] whenever new samples
//! arrived or the exposure changed; the f64 statistics are only read for the panel's numbers and
//! for saving.
//!
//! Over 450 lines: the path tracer's mode (settings, panel, stepping, saving) reads best whole.

use std::path::{Path, PathBuf};
use std::time::Duration;

use illum_gpu::GpuContext;
use illum_image::{Encoding, RgbImage32};
use illum_pathtrace::{PathTracer, Progressive, StopReason, StopRules};
use illum_scene::{Bounces, Sampling, Scene};

use crate::camera::OrbitCamera;
use crate::denoise_view::DenoiseView;
use crate::display::Display;
use crate::pacer::FramePacer;

/// Most paths a pass at the smallest spp may trace and still be one submission, a whole image
/// per frame, when it takes longer than the pacer's share: 2^20 paths, the default window's
/// image at the default scale several times over, a fraction of a second on lavapipe
/// (docs/performance.md has the rates). A larger image (a
/// large window at full resolution) is split into bands over several frames, so that the
/// window keeps repainting.
pub const WHOLE_PASS_SAMPLES: u64 = 1 << 20;
/// Highest fixed bounce count offered by the slider (the scene format allows more).
pub const MAX_UI_BOUNCES: u32 = 64;
/// Default resolution scale: half the view's pixels in each direction keeps lavapipe
/// interactive; raise it for a sharper image.
pub const DEFAULT_SCALE: f32 = 0.5;
/// The resolution scale's range in the panel (and in the web page's address).
pub const MIN_SCALE: f32 = 0.1;
pub const MAX_SCALE: f32 = 1.0;

/// Everything the user sets in the path-tracer panel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathTraceSettings {
    /// Bounces of indirect light (the scene's `[pathtrace] bounces` to start with).
    pub bounces: Bounces,
    /// Hemisphere sampling of the bounces.
    pub sampling: Sampling,
    /// Random seed.
    pub seed: u32,
    /// The caustic's light tracer (the scene's `[pathtrace] caustics` to start with); it runs
    /// only in a scene with a directional light and a mirror or glass object.
    pub caustics: bool,
    /// Render resolution = view size in pixels x this.
    pub resolution_scale: f32,
    /// Display-only exposure in stops (the saved files are not scaled).
    pub exposure: f32,
    /// Show the heat map of each pixel's estimated relative error instead of the image
    /// (`error_view.rs`); display only.
    pub error_view: bool,
    /// Show the accumulation denoised, with its estimated error (`denoise_view.rs`).
    pub denoise: bool,
    /// When to stop: the `render` example's own rules, set from the panel (`spp`: the spp
    /// target, `None` to keep going). Held as the tracer's type, not a copy of its fields, so
    /// that the panel and the command line cannot drift apart.
    pub stop: StopRules,
}

impl PathTraceSettings {
    /// The scene file's render settings, with no stop rule beyond its spp.
    pub fn from_scene(scene: &Scene) -> Self {
        PathTraceSettings {
            bounces: scene.pathtrace.bounces,
            sampling: scene.pathtrace.sampling,
            seed: scene.pathtrace.seed,
            caustics: scene.pathtrace.caustics,
            resolution_scale: DEFAULT_SCALE,
            exposure: 0.0,
            error_view: false,
            denoise: false,
            stop: StopRules::default(),
        }
    }
}

/// The statistics shown in the panel, refreshed as samples arrive.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    pub spp: u32,
    /// Samples per second of wall-clock rendering time.
    pub samples_per_second: f64,
    /// Wall-clock time spent rendering (not paused, not in the other mode).
    pub elapsed_seconds: f64,
    /// Estimated relative standard error; `None` before two samples per pixel.
    pub relative_error: Option<f64>,
    pub dropped_samples: u64,
    pub width: u32,
    pub height: u32,
}

/// The submissions since the accumulation last restarted: what the planner scheduled and what
/// the frames carried (a check that every frame's share of samples arrives).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WorkLog {
    /// Submissions folded.
    pub submissions: u64,
    /// Paths they were planned to trace.
    pub scheduled_samples: u64,
    /// The smallest submission's planned paths (`u64::MAX` before the first).
    pub smallest_submission: u64,
    /// Submissions that completed a pass over the whole image.
    pub passes: u64,
    /// Wall seconds the frames spent in the path tracer's steps (submitting, waiting, folding).
    pub step_seconds: f64,
}

/// The path-tracer mode.
pub struct PathTraceMode {
    scene_path: PathBuf,
    scene: Scene,
    pub settings: PathTraceSettings,
    pub camera: OrbitCamera,
    tracer: Option<PathTracer>,
    /// The scene the tracer last failed on, so a failure is not retried every frame.
    failed: Option<Scene>,
    display: Option<Display>,
    paused: bool,
    /// Whether this mode is the one shown (its clock stands still while it is not).
    active: bool,
    /// Stop rules, wall clock and why the render stopped.
    progressive: Progressive,
    /// Each frame's share of wall time for the path tracer.
    pacer: FramePacer,
    work: WorkLog,
    stats: Stats,
    /// Total samples at the last statistics update, to tell when new samples arrived.
    shown_samples: u64,
    shown_exposure: f32,
    /// The error view's texture, the heat map in it and the total samples it shows, while the
    /// view is on.
    error_texture: Option<(egui::TextureHandle, egui::ColorImage, u64)>,
    /// The Denoise toggle's images and estimates.
    pub denoise: DenoiseView,
    pub save_path: String,
    /// The last save's outcome or the renderer's last error, shown under the controls.
    pub message: Option<String>,
}

impl PathTraceMode {
    pub fn new(scene_path: PathBuf, scene: Scene) -> Self {
        let stem = scene.name.clone();
        let settings = PathTraceSettings::from_scene(&scene);
        PathTraceMode {
            progressive: Progressive::new(settings.stop),
            settings,
            camera: OrbitCamera::new(scene.camera),
            scene_path,
            scene,
            tracer: None,
            failed: None,
            display: None,
            paused: false,
            active: true,
            pacer: FramePacer::default(),
            work: WorkLog { smallest_submission: u64::MAX, ..WorkLog::default() },
            stats: Stats::default(),
            shown_samples: 0,
            shown_exposure: 0.0,
            error_texture: None,
            denoise: DenoiseView::default(),
            save_path: format!("out/viewer-{stem}.png"),
            message: None,
        }
    }

    /// Replaces the scene (opened from the UI); settings and camera start from its own.
    pub fn set_scene(&mut self, scene_path: PathBuf, scene: Scene) {
        let keep = self.settings;
        *self = PathTraceMode { display: self.display.take(), ..PathTraceMode::new(scene_path, scene) };
        self.settings.resolution_scale = keep.resolution_scale;
        self.settings.exposure = keep.exposure;
        self.settings.error_view = keep.error_view;
        self.settings.denoise = keep.denoise;
    }

    pub fn scene_path(&self) -> &Path {
        &self.scene_path
    }

    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// The submissions since the accumulation last restarted.
    pub fn work(&self) -> WorkLog {
        self.work
    }

    /// Samples per pixel before the error can be estimated (2, or 8 with the low-discrepancy
    /// sequence).
    fn error_needs_spp(&self) -> u32 {
        self.tracer.as_ref().map_or(2, |t| t.accumulator().spp_for_error_estimate())
    }

    /// Total samples folded into the current accumulation.
    pub fn total_samples(&self) -> u64 {
        self.tracer.as_ref().map_or(0, |t| t.accumulator().total_samples())
    }

    /// One line of the mode's statistics, as a `--screenshot` run prints them on exit.
    pub fn summary(&self) -> String {
        let st = &self.stats;
        let error = illum_pathtrace::progressive::error_text(st.relative_error, self.error_needs_spp());
        // The share of the wall time in the path tracer's steps: what the window's drawing
        // leaves it (samples/s over that share is the rate while it runs).
        let stepping =
            if st.elapsed_seconds > 0.0 { self.work.step_seconds / st.elapsed_seconds } else { 0.0 };
        let line = format!(
            "pathtrace: {} x {}, spp done {}, samples/s (wall) {:.3} M, elapsed {:.2} s, estimated error {error}, stepping {:.0}% of the wall time",
            st.width,
            st.height,
            st.spp,
            st.samples_per_second / 1e6,
            st.elapsed_seconds,
            100.0 * stepping
        );
        if self.settings.denoise { format!("{line}; {}", self.denoise.statistics()) } else { line }
    }

    /// Whether the caustic's light tracer runs in the current render (`None` before a tracer
    /// was made).
    pub fn caustics_running(&self) -> Option<bool> {
        self.tracer.as_ref().map(PathTracer::caustics)
    }

    /// Whether the light tracer can add anything to this scene: it has a directional light
    /// and a mirror or glass object (else the caustics setting is not offered).
    pub fn caustics_apply(&self) -> bool {
        let mut scene = self.scene.clone();
        scene.pathtrace.caustics = true;
        illum_pathtrace::Estimators::of(&scene).caustics()
    }

    /// Wall-clock and GPU seconds of the tracer's submissions since the last reset (the GPU's
    /// where the adapter has timestamp queries, else 0).
    pub fn submission_seconds(&self) -> Option<(f64, f64)> {
        self.tracer.as_ref().map(|t| (t.wall_seconds(), t.gpu_seconds()))
    }

    /// The mean of the f64 image over all pixels (linear RGB) and the resolution it was
    /// rendered at, once something was rendered: a summary that a check can compare with a
    /// headless render of the same scene.
    pub fn image_mean(&self) -> Option<([f64; 3], [u32; 2])> {
        let tracer = self.tracer.as_ref()?;
        let accumulator = tracer.accumulator();
        (accumulator.total_samples() > 0)
            .then(|| (accumulator.mean_image().mean(), [accumulator.width, accumulator.height]))
    }

    pub fn paused(&self) -> bool {
        self.paused
    }

    pub fn stop_reason(&self) -> Option<StopReason> {
        self.progressive.stopped()
    }

    /// Still has work to do this frame (so the window should keep repainting).
    pub fn is_rendering(&self) -> bool {
        (!self.paused && self.progressive.stopped().is_none()) || self.denoise.is_busy()
    }

    /// Wall-clock seconds spent rendering the current accumulation (the clock of the stop
    /// rules, "Elapsed" in the panel).
    pub fn render_seconds(&self) -> f64 {
        self.progressive.clock().elapsed().as_secs_f64()
    }

    /// Pauses or resumes sampling (and the clock).
    pub fn set_paused(&mut self, paused: bool) {
        self.paused = paused;
        self.sync_clock();
    }

    /// Tells the mode whether it is the one shown: its clock runs only while it is.
    pub fn set_active(&mut self, active: bool) {
        self.active = active;
        self.sync_clock();
    }

    /// The clock runs while this mode is shown, not paused, and not stopped.
    fn sync_clock(&mut self) {
        let running = self.active && !self.paused && self.progressive.stopped().is_none();
        let clock = self.progressive.clock_mut();
        if running {
            clock.resume();
        } else {
            clock.pause();
        }
    }

    /// Discards the accumulated samples and starts again.
    pub fn reset(&mut self) {
        if let Some(tracer) = &mut self.tracer {
            tracer.reset();
        }
        self.progressive.restart();
        self.sync_clock();
        self.stats = Stats { width: self.stats.width, height: self.stats.height, ..Stats::default() };
        self.shown_samples = u64::MAX;
        self.work = WorkLog { smallest_submission: u64::MAX, ..WorkLog::default() };
        // Its snapshots and denoised image are of the samples just discarded.
        self.denoise.clear();
    }

    /// The scene to render at `width` x `height`: the file's geometry with the panel's settings
    /// and the interactive camera.
    pub fn desired_scene(&self, width: u32, height: u32) -> Scene {
        let mut scene = self.scene.clone();
        scene.camera = self.camera.camera(width, height);
        scene.pathtrace.bounces = self.settings.bounces;
        scene.pathtrace.sampling = self.settings.sampling;
        scene.pathtrace.seed = self.settings.seed;
        scene.pathtrace.caustics = self.settings.caustics;
        if let Some(spp) = self.settings.stop.spp {
            scene.pathtrace.spp = spp.max(1);
        }
        scene
    }

    /// The size the tracer renders a view of `view_pixels` at (the resolution scale applied).
    pub fn render_size(&self, view_pixels: [u32; 2]) -> [u32; 2] {
        let scale = self.settings.resolution_scale.clamp(0.05, 2.0);
        view_pixels.map(|v| ((v as f32 * scale).round() as u32).max(1))
    }

    /// Brings the tracer in line with the settings, camera and `view_pixels` size, runs this
    /// frame's slice of work and refreshes the displayed texture.
    pub fn frame(
        &mut self,
        gpu: &GpuContext,
        ctx: &egui::Context,
        render_state: &egui_wgpu::RenderState,
        view_pixels: [u32; 2],
    ) {
        let [width, height] = self.render_size(view_pixels);
        let wanted = self.desired_scene(width, height);
        if self.failed.as_ref() == Some(&wanted) {
            return;
        }
        let restarted = match self.sync_tracer(gpu, &wanted) {
            Ok(restarted) => restarted,
            Err(message) => {
                self.message = Some(format!("path tracer: {message}"));
                self.tracer = None;
                self.failed = Some(wanted);
                return;
            }
        };
        self.failed = None;
        let Some(tracer) = self.tracer.as_mut() else { return };
        // The rules follow the panel (a changed spp target restarts the accumulation through
        // the scene; a changed error target or budget applies from now on).
        self.progressive.rules = self.settings.stop;
        if !self.paused {
            // The web page never waits for a band (each comes back a frame or more later), so
            // there the submission keeps its fixed size; natively the frame waits for it.
            if !crate::platform::POLLED_READBACK {
                tracer.set_target_seconds(self.pacer.submission_seconds(restarted));
            }
            let started = web_time::Instant::now();
            let stepped = self.progressive.step(tracer);
            let step_seconds = started.elapsed().as_secs_f64();
            self.pacer.stepped(started, step_seconds);
            self.work.step_seconds += step_seconds;
            if let Err(e) = stepped {
                self.message = Some(format!("path tracer: {e}"));
                self.set_paused(true);
                return;
            }
            let report = tracer.last_step();
            if report.scheduled_samples > 0 {
                let work = &mut self.work;
                work.submissions += 1;
                work.scheduled_samples += report.scheduled_samples;
                work.smallest_submission = work.smallest_submission.min(report.scheduled_samples);
                work.passes += u64::from(report.pass_completed);
            }
        }
        let total = tracer.accumulator().total_samples();
        let display = self.display.get_or_insert_with(|| Display::new(gpu));
        // The display sum holds radiance scaled by 2^-k for very bright lights (k = 0 below
        // 2^16): k more stops give the radiance back.
        let stops = self.settings.exposure + tracer.display_scale().log2();
        if total != self.shown_samples {
            self.shown_samples = total;
            self.stats = Self::measure(tracer, &self.progressive);
            let camera = tracer.scene().camera;
            if let Some(display_sum) = tracer.display_sum_buffer() {
                let mut renderer = render_state.renderer.write();
                // The glint is radiance; the display sum holds radiance / display_scale.
                let glint_scale = 1.0 / tracer.display_scale();
                let glint = tracer.accumulator().glint();
                display.show(
                    gpu,
                    &mut renderer,
                    display_sum,
                    [camera.width, camera.height],
                    stops,
                    glint,
                    glint_scale,
                );
            }
            self.shown_exposure = self.settings.exposure;
        } else if self.shown_exposure != self.settings.exposure {
            display.redraw(gpu, stops);
            self.shown_exposure = self.settings.exposure;
        }
        self.refresh_error_view(ctx);
        if self.settings.denoise
            && let Some(tracer) = &self.tracer
        {
            let stopped = self.paused || self.progressive.stopped().is_some();
            self.denoise.frame(gpu, ctx, tracer, self.settings.exposure, stopped);
        } else {
            self.denoise.clear();
        }
    }

    /// Computes the error view's heat map again when it is on and new samples arrived.
    fn refresh_error_view(&mut self, ctx: &egui::Context) {
        let Some(tracer) = self.tracer.as_ref().filter(|_| self.settings.error_view) else {
            self.error_texture = None;
            return;
        };
        let accumulator = tracer.accumulator();
        let total = accumulator.total_samples();
        if self.error_texture.as_ref().is_some_and(|(_, _, shown)| *shown == total) {
            return;
        }
        let errors = illum_pathtrace::error_map::ErrorMap::of(accumulator).relative_error();
        let image = crate::error_view::heat_map(&errors, accumulator.width, accumulator.height);
        // Nearest: each pixel's own error, not a blend of neighbours.
        let options = egui::TextureOptions::NEAREST;
        match &mut self.error_texture {
            Some((handle, shown_image, shown)) => {
                handle.set(image.clone(), options);
                *shown_image = image;
                *shown = total;
            }
            None => {
                let handle = ctx.load_texture("path tracer error view", image.clone(), options);
                self.error_texture = Some((handle, image, total));
            }
        }
    }

    /// The texture to show, once something was rendered: the image, or with the error view on,
    /// its heat map.
    pub fn texture(&self) -> Option<egui::TextureId> {
        match &self.error_texture {
            Some((handle, _, _)) => Some(handle.id()),
            None => self
                .denoise
                .texture()
                .filter(|_| self.settings.denoise)
                .or_else(|| self.display.as_ref().and_then(Display::texture_id)),
        }
    }

    /// The error view's heat map as shown and the total samples it is of, while the view is on
    /// (tests read it).
    pub fn error_view(&self) -> Option<(&egui::ColorImage, u64)> {
        self.error_texture.as_ref().map(|(_, image, total)| (image, *total))
    }

    /// The accumulation as a truth for the other modes' Difference view, once it exists.
    pub fn truth(&self) -> Option<crate::difference_view::PathTracerTruth<'_>> {
        let tracer = self.tracer.as_ref()?;
        Some(crate::difference_view::PathTracerTruth {
            scene: tracer.scene(),
            accumulator: tracer.accumulator(),
            spp: tracer.spp_done(),
        })
    }

    /// The tracer's statistics, once it exists.
    pub fn accumulator(&self) -> Option<&illum_pathtrace::Accumulator> {
        self.tracer.as_ref().map(PathTracer::accumulator)
    }

    /// The display pass (tests read what it shows).
    pub fn display(&self) -> Option<&Display> {
        self.display.as_ref()
    }

    /// Creates the tracer, or hands it the new scene when anything changed (which restarts the
    /// accumulation). Returns whether it restarted. Errors are the renderer's messages.
    fn sync_tracer(&mut self, gpu: &GpuContext, wanted: &Scene) -> Result<bool, String> {
        match &mut self.tracer {
            Some(tracer) if tracer.scene() == wanted => return Ok(false),
            Some(tracer) => tracer.update_scene(wanted).map_err(|e| e.to_string())?,
            None => {
                let mut tracer = PathTracer::new(gpu, wanted).map_err(|e| e.to_string())?;
                tracer.set_target_seconds(crate::platform::submission_seconds(crate::pacer::MOVING_SECONDS));
                tracer.set_whole_passes_up_to(Some(WHOLE_PASS_SAMPLES));
                // Natively the device's default (mapped, or a staging copy), waited for.
                if crate::platform::POLLED_READBACK {
                    tracer.set_readback(illum_pathtrace::Readback::Polled);
                }
                // The window shows the GPU-resident sum; it follows resets and resizes itself.
                tracer.enable_display_sum().map_err(|e| e.to_string())?;
                self.tracer = Some(tracer);
            }
        }
        // A fresh accumulation: the stop rules, the clock and the denoised image start over too.
        self.denoise.clear();
        self.progressive.restart();
        self.sync_clock();
        self.shown_samples = u64::MAX;
        self.work = WorkLog { smallest_submission: u64::MAX, ..WorkLog::default() };
        Ok(true)
    }

    fn measure(tracer: &PathTracer, progressive: &Progressive) -> Stats {
        let accumulator = tracer.accumulator();
        let status = progressive.status(tracer);
        Stats {
            spp: status.spp_done,
            samples_per_second: status.samples_per_second(),
            elapsed_seconds: status.elapsed.as_secs_f64(),
            relative_error: status.relative_error,
            dropped_samples: accumulator.dropped_samples(),
            width: accumulator.width,
            height: accumulator.height,
        }
    }

    /// Writes the mean image to `save_path` with the given extension ("png" or "exr"),
    /// atomically (illum-image writes a temporary file and renames it). Returns the path.
    pub fn save(&mut self, extension: &str) -> Result<PathBuf, String> {
        let tracer = self.tracer.as_ref().ok_or("nothing rendered yet")?;
        if tracer.accumulator().total_samples() == 0 {
            return Err("nothing rendered yet".to_owned());
        }
        let path = Path::new(self.save_path.trim()).with_extension(extension);
        if path.as_os_str().is_empty() || path.file_stem().is_none() {
            return Err(format!("{:?} is not a file name", self.save_path));
        }
        // With Denoise on, the PNG is the denoised image shown; the EXR stays the raw samples'
        // checkpoint (which `render --resume` continues) and records the denoised estimate.
        let denoised = self.denoise.image().filter(|_| self.settings.denoise);
        let denoise_fields = crate::denoise_view::exr_fields(&self.denoise).filter(|_| self.settings.denoise);
        let metadata = || {
            let mut metadata = illum_pathtrace::metadata::exr_metadata(
                tracer,
                self.progressive.clock().elapsed().as_secs_f64(),
                self.progressive.stopped(),
                "illum-viewer",
            );
            metadata.fields.extend(denoise_fields.clone().unwrap_or_default());
            metadata
        };
        #[cfg(not(target_arch = "wasm32"))]
        if extension == "exr" {
            // With the statistics layer, so that `render --resume` can continue it (at the size
            // the viewer rendered).
            illum_pathtrace::checkpoint::save_checkpoint(&path, tracer, &metadata())?;
        } else {
            // The PNG is the image as rendered (or denoised): gamma 2.2, no display exposure.
            let image: RgbImage32 = denoised.cloned().unwrap_or_else(|| tracer.accumulator().mean_image());
            illum_image::save_png(&path, &image, 0.0, Encoding::Gamma22).map_err(|e| error_chain(&e))?;
        }
        // In the browser the same file, made in memory, is downloaded under the field's file name.
        #[cfg(target_arch = "wasm32")]
        {
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            let (bytes, mime) = if extension == "exr" {
                (illum_pathtrace::checkpoint::checkpoint_bytes(&name, tracer, &metadata())?, "image/x-exr")
            } else {
                let image: RgbImage32 =
                    denoised.cloned().unwrap_or_else(|| tracer.accumulator().mean_image());
                let bytes = illum_image::png_bytes(&name, &image, 0.0, Encoding::Gamma22)
                    .map_err(|e| error_chain(&e))?;
                (bytes, "image/png")
            };
            crate::browser::download(&name, &bytes, mime)?;
            Ok(PathBuf::from(name))
        }
        #[cfg(not(target_arch = "wasm32"))]
        Ok(path)
    }

    /// The panel's controls.
    pub fn panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Path tracer");
        let caustics_apply = self.caustics_apply();
        let s = &mut self.settings;
        ui.horizontal(|ui| {
            let mut unbounded = s.bounces == Bounces::Unbounded;
            let mut fixed = match s.bounces {
                Bounces::Fixed(n) => n.min(MAX_UI_BOUNCES),
                Bounces::Unbounded => 2,
            };
            ui.add_enabled(!unbounded, egui::Slider::new(&mut fixed, 0..=MAX_UI_BOUNCES).text("Bounces"));
            ui.checkbox(&mut unbounded, "Unbounded");
            s.bounces = if unbounded { Bounces::Unbounded } else { Bounces::Fixed(fixed) };
        });
        ui.horizontal(|ui| {
            let mut unlimited = s.stop.spp.is_none();
            let mut spp = s.stop.spp.unwrap_or(self.scene.pathtrace.spp.max(1));
            let label = ui.label("spp target");
            ui.add_enabled(!unlimited, egui::DragValue::new(&mut spp).range(1..=1_000_000).speed(1.0))
                .labelled_by(label.id);
            ui.checkbox(&mut unlimited, "Unlimited");
            s.stop.spp = if unlimited { None } else { Some(spp) };
        });
        ui.horizontal(|ui| {
            ui.label("Sampling");
            ui.radio_value(&mut s.sampling, Sampling::Cosine, "Cosine");
            ui.radio_value(&mut s.sampling, Sampling::Uniform, "Uniform");
        });
        if caustics_apply {
            ui.checkbox(&mut s.caustics, "Light tracer (caustics)").on_hover_text(
                "Particles from the sun through the mirror and glass objects, for the caustics that \
                 camera paths cannot find (docs/caustics.md)",
            );
        }
        ui.horizontal(|ui| {
            let label = ui.label("Seed");
            ui.add(egui::DragValue::new(&mut s.seed).speed(1.0)).labelled_by(label.id);
        });
        ui.add(egui::Slider::new(&mut s.resolution_scale, MIN_SCALE..=MAX_SCALE).text("Resolution scale"));
        ui.add(egui::Slider::new(&mut s.exposure, -8.0..=8.0).text("Exposure (display)").suffix(" stops"));
        ui.checkbox(&mut s.error_view, "Error view").on_hover_text(
            "A heat map of each pixel's estimated relative standard error instead of the image \
             (the EXR layer illum.error)",
        );
        if s.error_view {
            ui.small("black 0.01%, purple 0.1%, red 1%, orange 10%, yellow 100%; blue: not known yet");
        }
        ui.checkbox(&mut s.denoise, "Denoise").on_hover_text(
            "Shows the accumulation through the à-trous filter, denoised again each time the spp \
             doubles; the denoised error is estimated from two independent halves of the samples \
             (docs/denoising.md)",
        );
        if s.denoise {
            ui.small(self.denoise.summary());
        }

        ui.separator();
        ui.label("Stop rules");
        ui.horizontal(|ui| {
            let mut on = s.stop.target_error.is_some();
            let mut value = s.stop.target_error.unwrap_or(0.01);
            let check = ui.checkbox(&mut on, "At relative error");
            ui.add_enabled(on, egui::DragValue::new(&mut value).range(0.0001..=1.0).speed(0.001))
                .labelled_by(check.id);
            s.stop.target_error = on.then_some(value);
        });
        ui.horizontal(|ui| {
            let mut on = s.stop.time_budget.is_some();
            // Edited in seconds; Duration rounds to the nearest nanosecond, so the round trip
            // each frame is stable (a budget of at most a day is far inside f64's precision).
            let mut value = s.stop.time_budget.map_or(10.0, |d| d.as_secs_f64());
            let check = ui.checkbox(&mut on, "After time budget");
            ui.add_enabled(
                on,
                egui::DragValue::new(&mut value).range(0.1..=86_400.0).speed(0.5).suffix(" s"),
            )
            .labelled_by(check.id);
            s.stop.time_budget = if on { Duration::try_from_secs_f64(value).ok() } else { None };
        });

        ui.separator();
        ui.horizontal(|ui| {
            let label = if self.paused { "Resume" } else { "Pause" };
            if ui.button(label).clicked() {
                self.set_paused(!self.paused);
            }
            if ui.button("Reset").clicked() {
                self.reset();
            }
            if ui.add_enabled(!self.camera.is_home(), egui::Button::new("Reset camera")).clicked() {
                self.camera.reset();
            }
        });
        self.stats_ui(ui);

        ui.separator();
        ui.horizontal(|ui| {
            let label = ui.label("Save to");
            ui.text_edit_singleline(&mut self.save_path).labelled_by(label.id);
        });
        ui.horizontal(|ui| {
            for (button, extension) in [("Save PNG", "png"), ("Save EXR", "exr")] {
                if ui.button(button).clicked() {
                    self.message = Some(match self.save(extension) {
                        Ok(path) => format!("{} {}", crate::platform::SAVED, path.display()),
                        Err(e) => format!("not saved: {e}"),
                    });
                }
            }
        });
        if let Some(message) = &self.message {
            ui.label(message);
        }
    }

    fn stats_ui(&self, ui: &mut egui::Ui) {
        let st = &self.stats;
        egui::Grid::new("pathtrace stats").num_columns(2).show(ui, |ui| {
            let mut row = |name: &str, value: String| {
                ui.label(name);
                ui.label(value);
                ui.end_row();
            };
            row("Resolution", format!("{} x {}", st.width, st.height));
            row("spp done", st.spp.to_string());
            // Both over wall-clock time spent rendering, drawing the window included.
            row("Samples/s (wall)", format!("{:.3} M", st.samples_per_second / 1e6));
            row("Elapsed (wall)", format!("{:.1} s", st.elapsed_seconds));
            row(
                "Rel. error",
                illum_pathtrace::progressive::error_text(st.relative_error, self.error_needs_spp()),
            );
            row("Dropped NaN/Inf", st.dropped_samples.to_string());
            let state = match (self.paused, self.progressive.stopped()) {
                (true, _) => "paused".to_owned(),
                (false, Some(StopReason::SppReached)) => "done: spp target reached".to_owned(),
                (false, Some(StopReason::ErrorReached)) => "done: error target reached".to_owned(),
                (false, Some(StopReason::TimeBudget)) => "done: time budget spent".to_owned(),
                (false, Some(StopReason::Cancelled)) => "stopped".to_owned(),
                (false, None) => "rendering".to_owned(),
            };
            row("State", state);
        });
    }
}

/// An error with its causes, "outer: inner: ...", so a failed save says why.
fn error_chain(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        text.push_str(": ");
        text.push_str(&cause.to_string());
        source = cause.source();
    }
    text
}
