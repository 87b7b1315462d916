//! The application: the mode switch, opening scene files, and the layout (top bar, the mode's
//! panel on the left, the image filling the rest). Each mode keeps its own settings and
//! renderer, so switching away and back finds them as they were. The camera follows a switch
//! between two modes that show the same scene file, so one view can be flipped between the
//! three renderers.
//!
//! This file holds the application's state and lays out a frame; the parts of a frame and of
//! the state each have a file in `app/`:
//! - `switch`: which mode is shown, and the camera that follows a switch;
//! - `open`: opening scene files into the modes;
//! - `top_bar`: the bar above the view;
//! - `view`: the image (or the Auto pilot's progress) and its margin;
//! - `status`: the status published for scripts and the `--screenshot` summary.

mod open;
mod status;
mod switch;
mod top_bar;
mod view;

use open::{load_pathtrace, load_raster, load_whitted};
use top_bar::COMPACT_BELOW_POINTS;
use view::margin_strips;

use std::path::{Path, PathBuf};

use illum_gpu::GpuContext;
use illum_scene::RendererKind;

use crate::auto_panel::AutoMode;
use crate::difference_view::PathTracerTruth;
use crate::frame_rate::FrameRate;
use crate::mode::ViewMode;
use crate::pathtrace_mode::PathTraceMode;
use crate::raster_mode::RasterMode;
use crate::scene_file::{DEFAULT_PATHTRACE_SCENE, DEFAULT_RASTER_SCENE};
use crate::screenshot::ScreenshotJob;
use crate::whitted_mode::WhittedMode;

/// How the window starts.
pub struct StartOptions {
    /// A scene file of either kind; it opens in its own mode.
    pub scene: PathBuf,
    /// The mode shown first (default: the scene's).
    pub mode: Option<RendererKind>,
    pub screenshot: Option<ScreenshotJob>,
    /// The window is cleared to the panels' colour before egui paints (eframe's window and
    /// web page do that with [`eframe::App::clear_color`]; a test harness may not), so the
    /// panels need no fill of their own.
    pub clear_is_backdrop: bool,
}

/// The viewer.
pub struct ViewerApp {
    mode: RendererKind,
    /// eframe's device wrapped for the renderers, or why there is none.
    gpu: Result<(GpuContext, egui_wgpu::RenderState), String>,
    /// Each mode, or why its scene could not be loaded.
    pathtrace: Result<PathTraceMode, String>,
    raster: Result<RasterMode, String>,
    whitted: Result<WhittedMode, String>,
    /// The Auto mode (`auto_panel.rs`) and whether it is shown: it then shows its choice's mode.
    auto: AutoMode,
    auto_shown: bool,
    /// The "open scene" text field: the shown mode's scene file (or a path being typed).
    pub scene_field: String,
    /// Whether the settings panel is shown (the top bar's "Hide settings" / "Show settings").
    pub show_panel: bool,
    /// Whether the first frame has chosen `show_panel` for the window's width.
    panel_fitted: bool,
    /// The last open attempt's error (the current scenes stay).
    pub open_error: Option<String>,
    /// The scene file opened last and, for each mode that cannot render it, why.
    refused: Option<(PathBuf, Vec<(RendererKind, String)>)>,
    screenshot: Option<ScreenshotJob>,
    /// How often the window repaints (shown in the top bar, printed after a screenshot run).
    frame_rate: FrameRate,
    /// Where the image was drawn last, in physical pixels of the window: x, y, width, height
    /// (published for scripts, which crop screenshots to it).
    view_rect: Option<[u32; 4]>,
    /// The panels' own fill for the dark and the light theme, when the window's clear paints
    /// it instead (their fill is then transparent).
    backdrop: Option<[egui::Color32; 2]>,
    /// The browser's file picker ("Open file..."), which delivers a file a few frames later.
    #[cfg(target_arch = "wasm32")]
    picker: crate::browser::FilePicker,
}

impl ViewerApp {
    pub fn new(cc: &eframe::CreationContext<'_>, options: StartOptions) -> Self {
        let gpu = match &cc.wgpu_render_state {
            Some(rs) => {
                #[allow(unused_mut)]
                let mut info = rs.adapter.get_info();
                // Browsers do not tell WebGPU's adapter name to wgpu; the page asked for it.
                #[cfg(target_arch = "wasm32")]
                if info.name.is_empty() {
                    info.name = crate::browser::adapter_description();
                }
                let gpu = GpuContext::from_device(rs.device.clone(), rs.queue.clone(), info);
                log::info!("viewer adapter: {} ({:?})", gpu.adapter_info.name, gpu.adapter_info.backend);
                Ok((gpu, rs.clone()))
            }
            None => Err("eframe started without its wgpu renderer; the viewer needs wgpu".to_owned()),
        };
        let mut app = ViewerApp {
            mode: RendererKind::PathTrace,
            gpu,
            pathtrace: Err("no path-tracer scene loaded".to_owned()),
            raster: Err("no raster scene loaded".to_owned()),
            whitted: Err("no Whitted scene loaded".to_owned()),
            auto: AutoMode::default(),
            auto_shown: false,
            scene_field: options.scene.display().to_string(),
            show_panel: true,
            panel_fitted: false,
            open_error: None,
            refused: None,
            screenshot: options.screenshot,
            frame_rate: FrameRate::default(),
            view_rect: None,
            backdrop: None,
            #[cfg(target_arch = "wasm32")]
            picker: crate::browser::FilePicker::default(),
        };
        // On a software rasterizer every pixel egui fills is shaded, and the panels' fill was
        // a quarter of a frame's cost; a clear costs next to nothing (docs/viewer.md).
        if options.clear_is_backdrop {
            let fill = |theme| cc.egui_ctx.style_of(theme).visuals.panel_fill;
            app.backdrop = Some([fill(egui::Theme::Dark), fill(egui::Theme::Light)]);
            cc.egui_ctx.all_styles_mut(|style| style.visuals.panel_fill = egui::Color32::TRANSPARENT);
        }
        // Each mode starts on its default scene; the given file then replaces its mode's.
        app.pathtrace = load_pathtrace(Path::new(DEFAULT_PATHTRACE_SCENE));
        app.raster = load_raster(Path::new(DEFAULT_RASTER_SCENE));
        app.whitted = load_whitted(Path::new(DEFAULT_RASTER_SCENE));
        match app.open(&options.scene) {
            Ok(mode) => app.mode = mode,
            Err(e) => app.open_error = Some(e),
        }
        if let Some(mode) = options.mode {
            app.mode = mode;
        }
        // The field names the scene shown, unless the given file failed to open (then it keeps
        // the path, to be corrected).
        if app.open_error.is_none()
            && let Some(current) = app.current_scene_path()
        {
            app.scene_field = current;
        }
        app
    }

    pub fn whitted(&self) -> Option<&WhittedMode> {
        self.whitted.as_ref().ok()
    }

    pub fn whitted_mut(&mut self) -> Option<&mut WhittedMode> {
        self.whitted.as_mut().ok()
    }

    pub fn mode(&self) -> RendererKind {
        self.mode
    }

    pub fn pathtrace(&self) -> Option<&PathTraceMode> {
        self.pathtrace.as_ref().ok()
    }

    pub fn pathtrace_mut(&mut self) -> Option<&mut PathTraceMode> {
        self.pathtrace.as_mut().ok()
    }

    pub fn raster(&self) -> Option<&RasterMode> {
        self.raster.as_ref().ok()
    }

    pub fn raster_mut(&mut self) -> Option<&mut RasterMode> {
        self.raster.as_mut().ok()
    }

    pub fn auto(&self) -> &AutoMode {
        &self.auto
    }

    pub fn auto_mut(&mut self) -> &mut AutoMode {
        &mut self.auto
    }

    /// Whether the Auto mode is shown (with its choice's mode).
    pub fn auto_shown(&self) -> bool {
        self.auto_shown
    }

    /// Shows the Auto mode, as its top-bar button does (`--mode auto`).
    pub fn show_auto(&mut self) {
        self.auto_shown = true;
    }

    /// The mode of `kind`, or why its scene could not be loaded: the one place that tells the
    /// modes apart.
    fn mode_of(&mut self, kind: RendererKind) -> Result<&mut dyn ViewMode, &String> {
        match kind {
            RendererKind::Raster => self.raster.as_mut().map(|m| m as &mut dyn ViewMode).map_err(|e| &*e),
            RendererKind::PathTrace => {
                self.pathtrace.as_mut().map(|m| m as &mut dyn ViewMode).map_err(|e| &*e)
            }
            RendererKind::Whitted => self.whitted.as_mut().map(|m| m as &mut dyn ViewMode).map_err(|e| &*e),
        }
    }

    /// [`Self::mode_of`] for a shared borrow.
    fn mode_ref(&self, kind: RendererKind) -> Result<&dyn ViewMode, &String> {
        match kind {
            RendererKind::Raster => self.raster.as_ref().map(|m| m as &dyn ViewMode),
            RendererKind::PathTrace => self.pathtrace.as_ref().map(|m| m as &dyn ViewMode),
            RendererKind::Whitted => self.whitted.as_ref().map(|m| m as &dyn ViewMode),
        }
    }

    /// The mode shown, with the path tracer's accumulation as the truth a deterministic mode's
    /// Difference view may use (none for the path tracer itself).
    fn shown(&mut self) -> (Option<&mut dyn ViewMode>, Option<PathTracerTruth<'_>>) {
        fn truth(p: &Result<PathTraceMode, String>) -> Option<PathTracerTruth<'_>> {
            p.as_ref().ok().and_then(PathTraceMode::truth)
        }
        match self.mode {
            RendererKind::Raster => (self.raster.as_mut().ok().map(|m| m as _), truth(&self.pathtrace)),
            RendererKind::Whitted => (self.whitted.as_mut().ok().map(|m| m as _), truth(&self.pathtrace)),
            RendererKind::PathTrace => (self.pathtrace.as_mut().ok().map(|m| m as _), None),
        }
    }

    fn side_panel(&mut self, ui: &mut egui::Ui) {
        egui::ScrollArea::vertical().show(ui, |ui| {
            if self.auto_shown {
                self.auto.panel(ui);
                ui.separator();
            }
            if let Err(error) = self.mode_of(self.mode).map(|m| m.panel(ui)) {
                ui.colored_label(ui.visuals().error_fg_color, error.as_str());
            }
            ui.separator();
            ui.weak("Mouse on the image: left drag orbits, right or middle drag pans, the wheel zooms.");
        });
    }
}

impl eframe::App for ViewerApp {
    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        let fill = match self.backdrop {
            Some([dark, light]) => {
                if visuals.dark_mode {
                    dark
                } else {
                    light
                }
            }
            None => visuals.panel_fill,
        };
        fill.to_normalized_gamma_f32()
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.frame_rate.tick();
        // A scene file dropped on the window (with its mesh files) opens like one named in
        // the Scene field.
        let dropped = ui.ctx().input(|i| i.raw.dropped_files.clone());
        if !dropped.is_empty() {
            self.open_dropped(ui.ctx(), dropped);
        }
        // The path tracer's wall clock runs only while its mode is shown.
        let showing_pathtrace =
            self.mode == RendererKind::PathTrace && !(self.auto_shown && self.auto.measuring());
        if let Ok(pathtrace) = &mut self.pathtrace {
            pathtrace.set_active(showing_pathtrace);
        }
        // A window that starts narrow starts with the settings hidden, so that the image has
        // the window (the top bar's Settings toggle shows them).
        if !self.panel_fitted {
            self.panel_fitted = true;
            if ui.available_width() < COMPACT_BELOW_POINTS {
                self.show_panel = false;
            }
        }
        egui::Panel::top("top bar").show(ui, |ui| self.top_bar(ui));
        if self.show_panel {
            // At most half the window, so a small window still shows the image.
            let max = (ui.available_width() * 0.5).max(1.0);
            egui::Panel::left("settings")
                .resizable(true)
                .default_size(320.0f32.min(max))
                .max_size(max)
                .show(ui, |ui| self.side_panel(ui));
        }
        // The image covers the central panel but for its margin, so only the margin is filled
        // (by the clear where that paints the panels): a fill under the image was a third of
        // a frame's cost on a software rasterizer (docs/viewer.md).
        let frame = egui::Frame::central_panel(ui.style());
        let fill = frame.fill;
        egui::CentralPanel::default().frame(frame.fill(egui::Color32::TRANSPARENT)).show(ui, |ui| {
            let inner = ui.max_rect();
            let outer = inner + frame.inner_margin;
            let painter = ui.painter().with_clip_rect(outer);
            for strip in margin_strips(outer, inner) {
                painter.rect_filled(strip, 0.0, fill);
            }
            self.view(ui, fill)
        });
        if let Some(mut job) = self.screenshot.take() {
            job.tick(ui.ctx(), || self.summary());
            self.screenshot = Some(job);
        }
        #[cfg(target_arch = "wasm32")]
        {
            if let Some(files) = self.picker.take() {
                let result = self.open_files(&files);
                self.opened(result);
            }
            crate::browser::publish_status(&self.status());
        }
    }
}
