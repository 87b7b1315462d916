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
//! The mode's state lives here and in `pathtrace_mode/`, apart from its egui panel
//! (`pathtrace_panel.rs`): `stepping` (a frame's work and what it shows), `stats` (the numbers
//! shown and printed) and `save` (the PNG and EXR files).

mod save;
mod stats;
mod stepping;

pub use stats::{Stats, WorkLog};

use std::path::{Path, PathBuf};

use illum_pathtrace::{PathTracer, Progressive, StopReason, StopRules};
use illum_scene::{Bounces, Sampling, Scene};

use crate::camera::OrbitCamera;
use crate::denoise_view::DenoiseView;
use crate::display::Display;
use crate::mode::ViewMode;
use crate::pacer::FramePacer;

/// Most paths a pass at the smallest spp may trace and still be one submission, a whole image
/// per frame, when it takes longer than the pacer's share: 2^20 paths, the default window's
/// image at the default scale several times over, a fraction of a second on lavapipe
/// (docs/performance.md has the rates). A larger image (a
/// large window at full resolution) is split into bands over several frames, so that the
/// window keeps repainting.
pub const WHOLE_PASS_SAMPLES: u64 = 1 << 20;
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
    /// Whether the image shown holds its exact part (the glint, solved beside the first
    /// samples: until it is, the samples are shown alone, so that no frame waits for it).
    shown_exact: bool,
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
            shown_exact: false,
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

    /// The scene as the file gave it (the panel's settings and the camera not applied).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// The submissions since the accumulation last restarted.
    pub fn work(&self) -> WorkLog {
        self.work
    }

    /// The estimated error as the panel and the summary write it (as the command line does).
    pub(crate) fn error_text(&self) -> String {
        let error = self.stats.relative_error;
        match &self.tracer {
            Some(tracer) => illum_pathtrace::progressive::render_error_text(tracer.accumulator(), error),
            None => illum_pathtrace::progressive::error_text(error, 2),
        }
    }

    /// Total samples folded into the current accumulation.
    pub fn total_samples(&self) -> u64 {
        self.tracer.as_ref().map_or(0, |t| t.accumulator().total_samples())
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
}

impl ViewMode for PathTraceMode {
    fn scene_path(&self) -> &Path {
        &self.scene_path
    }

    fn camera(&mut self) -> &mut OrbitCamera {
        &mut self.camera
    }

    fn panel(&mut self, ui: &mut egui::Ui) {
        self.controls(ui);
    }

    /// The path tracer is its own truth: `truth` is not used.
    fn frame(
        &mut self,
        gpu: &illum_gpu::GpuContext,
        ctx: &egui::Context,
        render_state: &egui_wgpu::RenderState,
        view_pixels: [u32; 2],
        _: Option<crate::difference_view::PathTracerTruth<'_>>,
    ) -> Option<egui::TextureId> {
        self.step_frame(gpu, ctx, render_state, view_pixels);
        self.texture()
    }

    /// Draws while it still has samples to take.
    fn busy(&self) -> bool {
        self.is_rendering()
    }

    fn summary(&self) -> String {
        PathTraceMode::summary(self)
    }
}
