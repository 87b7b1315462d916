//! The application: the mode switch, opening scene files, and the layout (top bar, the mode's
//! panel on the left, the image filling the rest). Each mode keeps its own settings and
//! renderer, so switching away and back finds them as they were. The camera follows a switch
//! between two modes that show the same scene file, so one view can be flipped between the
//! three renderers.
//!
//! Over 450 lines: the mode switch, the file opening and the layout all act on one `ViewerApp`.

use std::path::{Path, PathBuf};

use illum_gpu::GpuContext;
use illum_scene::RendererKind;

use crate::auto_panel::AutoMode;
use crate::camera::OrbitCamera;
use crate::frame_rate::FrameRate;
use crate::pathtrace_panel::PathTraceMode;
use crate::raster_panel::RasterMode;
use crate::scene_file::{self, DEFAULT_PATHTRACE_SCENE, DEFAULT_RASTER_SCENE};

/// Below this window width (in points) the top bar is compact (see `ViewerApp::top_bar`).
const COMPACT_BELOW_POINTS: f32 = 520.0;
use crate::screenshot::ScreenshotJob;
use crate::whitted_panel::WhittedMode;

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

    /// The scene file of the mode shown, as it was given.
    fn current_scene_path(&self) -> Option<String> {
        self.scene_path_of(self.mode)
    }

    /// The scene file of `mode`, as it was given.
    fn scene_path_of(&self, mode: RendererKind) -> Option<String> {
        match mode {
            RendererKind::Raster => self.raster.as_ref().ok().map(|m| m.scene_path().display().to_string()),
            RendererKind::PathTrace => {
                self.pathtrace.as_ref().ok().map(|m| m.scene_path().display().to_string())
            }
            RendererKind::Whitted => self.whitted.as_ref().ok().map(|m| m.scene_path().display().to_string()),
        }
    }

    /// The orbit camera of `mode`, when it has a scene.
    fn camera_of(&mut self, mode: RendererKind) -> Option<&mut OrbitCamera> {
        match mode {
            RendererKind::Raster => self.raster.as_mut().ok().map(|m| &mut m.camera),
            RendererKind::PathTrace => self.pathtrace.as_mut().ok().map(|m| &mut m.camera),
            RendererKind::Whitted => self.whitted.as_mut().ok().map(|m| &mut m.camera),
        }
    }

    /// Gives the mode now shown the camera of `from` if both show the same scene file (the
    /// renderer then draws the same view; each one redraws when its camera changes).
    fn carry_camera(&mut self, from: RendererKind) {
        let same_scene =
            self.scene_path_of(from).is_some() && self.scene_path_of(from) == self.current_scene_path();
        let Some(camera) = self.camera_of(from).copied() else { return };
        if let (true, Some(to)) = (same_scene, self.camera_of(self.mode)) {
            *to = camera;
        }
    }

    /// Switches to `mode` as the top bar's buttons do (the camera follows, see
    /// `carry_camera`).
    pub fn switch_to(&mut self, mode: RendererKind) {
        let before = std::mem::replace(&mut self.mode, mode);
        if mode != before {
            self.carry_camera(before);
            if let Some(current) = self.current_scene_path() {
                // The field follows the mode: it names the scene now shown.
                self.scene_field = current;
                self.open_error = None;
            }
        }
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

    /// Opens a scene file in every mode that can render it and returns the mode to show (the
    /// file's `renderer`, when it can). A mode that cannot render it keeps its scene. On error
    /// nothing changes and the loader's message is returned.
    pub fn open(&mut self, path: &Path) -> Result<RendererKind, String> {
        // The path as given names the scene in the UI and in saved metadata.
        let loaded = scene_file::load(path)?;
        Ok(self.install(path.to_path_buf(), loaded))
    }

    /// As [`Self::open`], for the text of a file dropped on the window or picked in the
    /// browser; `name` (its file name) names it in errors and in the UI.
    pub fn open_text(&mut self, name: &str, text: &str) -> Result<RendererKind, String> {
        let loaded = scene_file::load_text(name, text)?;
        Ok(self.install(PathBuf::from(name), loaded))
    }

    /// Opens a scene file dropped on the window like the Open button (natively: its path; in
    /// the browser its bytes arrive a few frames later, through the file picker's inbox).
    fn open_dropped(&mut self, ctx: &egui::Context, file: egui::DroppedFileHandle) {
        #[cfg(not(target_arch = "wasm32"))]
        {
            let _ = ctx;
            let result = self.open(file.path());
            self.opened(result);
        }
        #[cfg(target_arch = "wasm32")]
        self.picker.read_dropped(ctx, file);
    }

    /// Shows the outcome of opening a scene from the UI: its mode and name, or the error.
    fn opened(&mut self, result: Result<RendererKind, String>) {
        match result {
            Ok(mode) => {
                self.mode = mode;
                self.open_error = None;
                if let Some(current) = self.current_scene_path() {
                    self.scene_field = current;
                }
            }
            Err(e) => self.open_error = Some(e),
        }
    }

    /// Puts a loaded scene into every mode that can render it; returns the mode to show.
    /// The modes that cannot render it keep their scene, and their reasons are kept for the
    /// top bar ([`Self::refusal_of`]).
    fn install(&mut self, given: PathBuf, loaded: scene_file::LoadedScene) -> RendererKind {
        let mode = loaded.mode();
        let mut refusals = Vec::new();
        match loaded.pathtrace {
            Ok(scene) => match &mut self.pathtrace {
                Ok(mode) => mode.set_scene(given.clone(), scene),
                Err(_) => self.pathtrace = Ok(PathTraceMode::new(given.clone(), scene)),
            },
            Err(reason) => refusals.push((RendererKind::PathTrace, reason)),
        }
        match loaded.raster {
            Ok((raster, scene)) => match &mut self.raster {
                Ok(mode) => mode.set_scene(given.clone(), raster, scene),
                Err(_) => self.raster = Ok(RasterMode::new(given.clone(), raster, scene)),
            },
            Err(reason) => refusals.push((RendererKind::Raster, reason)),
        }
        match loaded.whitted {
            Ok(scene) => match &mut self.whitted {
                Ok(mode) => mode.set_scene(given.clone(), scene),
                Err(_) => self.whitted = Ok(WhittedMode::new(given.clone(), scene)),
            },
            Err(reason) => refusals.push((RendererKind::Whitted, reason)),
        }
        self.refused = (!refusals.is_empty()).then_some((given, refusals));
        mode
    }

    /// What the window shows, as (name, value) pairs: the mode, the scene, the last open
    /// error, the adapter, and each mode's progress. The web page publishes them on the page
    /// (`data-*` attributes of `#illum-status`) for scripts and browser tests.
    pub fn status(&self) -> Vec<(&'static str, String)> {
        // Every name every time (empty when it does not apply), so that a value never outlives
        // what it describes.
        let text = |value: Option<String>| value.unwrap_or_default();
        let pathtrace = self.pathtrace();
        let stats = pathtrace.map(PathTraceMode::stats);
        let image = pathtrace.and_then(PathTraceMode::image_mean);
        let seconds = pathtrace.and_then(PathTraceMode::submission_seconds);
        let whitted_image = self.whitted().and_then(|w| w.image_mean);
        let on_off = |on: bool| if on { "on" } else { "off" };
        vec![
            ("mode", self.mode.to_string()),
            ("scene", text(self.current_scene_path())),
            ("open-error", text(self.open_error.clone())),
            ("mode-refusal", text(self.refusal_of(self.mode))),
            ("window-fps", text(self.frame_rate.fps().map(|f| format!("{f:.1}")))),
            (
                "adapter",
                text(
                    self.gpu.as_ref().ok().map(|(gpu, _)| {
                        format!("{} ({:?})", gpu.adapter_info.name, gpu.adapter_info.backend)
                    }),
                ),
            ),
            ("pathtrace-spp", text(stats.map(|s| s.spp.to_string()))),
            ("pathtrace-samples-per-second", text(stats.map(|s| format!("{:.0}", s.samples_per_second)))),
            ("pathtrace-stopped", text(pathtrace.and_then(|p| p.stop_reason()).map(|r| r.name().to_owned()))),
            ("pathtrace-size", text(image.map(|(_, [w, h])| format!("{w}x{h}")))),
            ("pathtrace-mean", text(image.map(|(m, _)| format!("{} {} {}", m[0], m[1], m[2])))),
            ("pathtrace-submission-seconds", text(seconds.map(|(wall, _)| format!("{wall:.3}")))),
            ("pathtrace-gpu-seconds", text(seconds.map(|(_, gpu)| format!("{gpu:.3}")))),
            ("pathtrace-message", text(pathtrace.and_then(|p| p.message.clone()))),
            (
                "pathtrace-caustics",
                text(pathtrace.and_then(PathTraceMode::caustics_running).map(|on| on_off(on).to_owned())),
            ),
            (
                "pathtrace-denoise",
                text(pathtrace.filter(|p| p.settings.denoise).map(|p| p.denoise.summary())),
            ),
            ("raster-message", text(self.raster().and_then(|r| r.message.clone()))),
            ("view-rect", text(self.view_rect.map(|[x, y, w, h]| format!("{x} {y} {w} {h}")))),
            ("whitted-frames", text(self.whitted().map(|w| w.frames.to_string()))),
            ("whitted-size", text(whitted_image.map(|(_, [w, h])| format!("{w}x{h}")))),
            ("whitted-mean", text(whitted_image.map(|(m, _)| format!("{} {} {}", m[0], m[1], m[2])))),
            ("whitted-ms", text(self.whitted().and_then(|w| w.frame_ms).map(|ms| format!("{ms:.0}")))),
            ("whitted-message", text(self.whitted().and_then(|w| w.message.clone()))),
        ]
    }

    /// One line of the shown mode's statistics and the window's frame rate, as a
    /// `--screenshot` run prints them on exit (the smoke test and `bench --viewer` read it).
    pub fn summary(&self) -> String {
        let mode = match self.mode {
            RendererKind::PathTrace => self.pathtrace().map(PathTraceMode::summary),
            RendererKind::Raster => self.raster().map(|r| {
                let gpu = r
                    .pass_times()
                    .map_or("n/a".to_owned(), |t| format!("{:.2} ms", t.shadow_ms + t.cube_ms + t.main_ms));
                format!("raster: GPU time per frame {gpu}")
            }),
            RendererKind::Whitted => self.whitted().map(|w| {
                let ms = w.frame_ms.map_or("n/a".to_owned(), |ms| format!("{ms:.1} ms"));
                format!("whitted: {} rendered, last frame {ms}", count(w.frames, "frame", "frames"))
            }),
        };
        let fps = self.frame_rate.fps().map_or("n/a".to_owned(), |f| format!("{f:.1} fps"));
        let auto = if self.auto_shown { format!("{}; ", self.auto.summary()) } else { String::new() };
        format!("{auto}{}, window {fps}", mode.unwrap_or_else(|| format!("{}: no scene", self.mode)))
    }

    fn top_bar(&mut self, ui: &mut egui::Ui) {
        // A narrow window gets a compact bar (the modes in a drop-down, no status text), so
        // that the bar stays about two lines high and the image keeps most of the window.
        let compact = ui.available_width() < COMPACT_BELOW_POINTS;
        ui.horizontal_wrapped(|ui| {
            if compact {
                ui.toggle_value(&mut self.show_panel, "Settings");
            } else {
                let panel_button = if self.show_panel { "Hide settings" } else { "Show settings" };
                if ui.button(panel_button).clicked() {
                    self.show_panel = !self.show_panel;
                }
            }
            let mut chosen = self.mode;
            let modes = [
                (RendererKind::Raster, "Raster"),
                (RendererKind::PathTrace, "Path tracer"),
                (RendererKind::Whitted, "Whitted"),
            ];
            if compact {
                let shown = modes.iter().find(|(m, _)| *m == chosen).map_or("", |(_, name)| name);
                let shown = if self.auto_shown { "Auto" } else { shown };
                egui::ComboBox::from_id_salt("mode").selected_text(shown).show_ui(ui, |ui| {
                    for (mode, name) in modes {
                        if ui.selectable_label(!self.auto_shown && chosen == mode, name).clicked() {
                            chosen = mode;
                            self.auto_shown = false;
                        }
                    }
                    if ui.selectable_label(self.auto_shown, "Auto").clicked() {
                        self.auto_shown = true;
                    }
                });
            } else {
                for (mode, name) in modes {
                    if ui.selectable_label(!self.auto_shown && chosen == mode, name).clicked() {
                        chosen = mode;
                        self.auto_shown = false;
                    }
                }
                ui.separator();
            }
            self.switch_to(chosen);
            let field = if compact {
                // The field on a line of its own, as wide as the window allows, its label inside.
                ui.end_row();
                let width = (ui.available_width() - 72.0).clamp(40.0, 280.0);
                ui.add(
                    egui::TextEdit::singleline(&mut self.scene_field).desired_width(width).hint_text("Scene"),
                )
            } else {
                let label = ui.label("Scene");
                ui.add(egui::TextEdit::singleline(&mut self.scene_field).desired_width(280.0))
                    .labelled_by(label.id)
            };
            let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if ui.button("Open").clicked() || entered {
                let path = PathBuf::from(self.scene_field.trim());
                match self.open(&path) {
                    Ok(mode) => {
                        self.mode = mode;
                        self.open_error = None;
                    }
                    Err(e) => self.open_error = Some(e),
                }
            }
            #[cfg(target_arch = "wasm32")]
            self.web_open_buttons(ui);
            // After the buttons that open files, so that they keep their places (a compact bar
            // has Auto in its drop-down). Not in the browser's wide bar: there, after **Built-in
            // scenes** and **Open file...**, it wraps onto the status line and makes the bar 8 px
            // taller, and the page's tests compare the view at its height (`?mode=auto` and the
            // narrow window's drop-down show Auto there).
            #[cfg(not(target_arch = "wasm32"))]
            if !compact {
                ui.separator();
                if ui.selectable_label(self.auto_shown, "Auto").clicked() {
                    self.auto_shown = true;
                }
            }
            if compact {
                return;
            }
            if let Some(current) = self.current_scene_path() {
                ui.weak(format!("showing {current}"));
            }
            if let Some(fps) = self.frame_rate.fps() {
                ui.weak(format!("window {fps:.0} fps"));
            }
        });
        if let Some(error) = &self.open_error {
            ui.colored_label(ui.visuals().error_fg_color, format!("Could not open the scene: {error}"));
        }
        if let Some(refusal) = self.refusal_of(self.mode) {
            let text = egui::RichText::new(&refusal).color(ui.visuals().warn_fg_color);
            if compact {
                // One line in a narrow window; the whole sentence on hover.
                ui.add(egui::Label::new(text).truncate()).on_hover_text(refusal);
            } else {
                ui.label(text);
            }
        }
    }

    /// Why the mode shown is not showing the scene file opened last (it keeps its own scene),
    /// as a sentence for the top bar.
    pub fn refusal_of(&self, mode: RendererKind) -> Option<String> {
        let (opened, refusals) = self.refused.as_ref()?;
        let (_, reason) = refusals.iter().find(|(m, _)| *m == mode)?;
        let showing = self.scene_path_of(mode).map_or(String::new(), |p| format!("; showing {p}"));
        // The reason names the file when it comes from the file's validation; else say which.
        let file = opened.display().to_string();
        let named = if reason.contains(&file) { String::new() } else { format!("{file}: ") };
        Some(format!("{named}{reason}{showing}"))
    }

    fn side_panel(&mut self, ui: &mut egui::Ui) {
        egui::ScrollArea::vertical().show(ui, |ui| {
            if self.auto_shown {
                self.auto.panel(ui);
                ui.separator();
            }
            let result = match self.mode {
                RendererKind::Raster => self.raster.as_mut().map(|m| m.panel(ui)),
                RendererKind::PathTrace => self.pathtrace.as_mut().map(|m| m.panel(ui)),
                RendererKind::Whitted => self.whitted.as_mut().map(|m| m.panel(ui)),
            };
            if let Err(error) = result {
                ui.colored_label(ui.visuals().error_fg_color, error.as_str());
            }
            ui.separator();
            ui.weak("Mouse on the image: left drag orbits, right or middle drag pans, the wheel zooms.");
        });
    }

    /// The image of the shown mode, filling `ui`; `fill` where there is none yet.
    fn view(&mut self, ui: &mut egui::Ui, fill: egui::Color32) {
        let gpu = match &self.gpu {
            Ok((gpu, _)) => gpu,
            Err(error) => {
                ui.painter().rect_filled(ui.max_rect(), 0.0, fill);
                ui.colored_label(ui.visuals().error_fg_color, error.as_str());
                return;
            }
        };
        let size = ui.available_size().max(egui::vec2(1.0, 1.0));
        let pixels_per_point = ui.ctx().pixels_per_point();
        let view_pixels =
            [(size.x * pixels_per_point).round() as u32, (size.y * pixels_per_point).round() as u32];
        if self.auto_shown {
            let gpu = gpu.clone();
            if !self.auto_frame(ui, &gpu, view_pixels) {
                return;
            }
        }
        let (gpu, render_state) = match &self.gpu {
            Ok(pair) => pair,
            Err(_) => return,
        };
        let texture = match self.mode {
            RendererKind::Raster => {
                let truth = self.pathtrace.as_ref().ok().and_then(PathTraceMode::truth);
                self.raster
                    .as_mut()
                    .ok()
                    .and_then(|m| m.frame(gpu, ui.ctx(), render_state, view_pixels, truth))
            }
            RendererKind::PathTrace => self.pathtrace.as_mut().ok().and_then(|m| {
                m.frame(gpu, ui.ctx(), render_state, view_pixels);
                m.texture()
            }),
            RendererKind::Whitted => {
                let truth = self.pathtrace.as_ref().ok().and_then(PathTraceMode::truth);
                self.whitted.as_mut().ok().and_then(|m| m.frame(gpu, ui.ctx(), view_pixels, truth))
            }
        };
        let sense = egui::Sense::click_and_drag();
        let response = match texture {
            Some(id) => ui.add(egui::Image::new(egui::load::SizedTexture::new(id, size)).sense(sense)),
            None => {
                let response = ui.allocate_response(size, sense);
                ui.painter().rect_filled(response.rect, 0.0, fill);
                response
            }
        };
        let rect = response.rect;
        self.view_rect = Some(
            [rect.min.x, rect.min.y, rect.width(), rect.height()]
                .map(|v| (v * pixels_per_point).round() as u32),
        );
        if let Some(camera) = self.camera_of(self.mode)
            && camera.handle(ui, &response)
        {
            ui.ctx().request_repaint();
        }
        // The raster redraws every frame (it is a real-time renderer and its frame rate is
        // measured); the path tracer while it still has samples to take; Whitted on a change.
        let busy = match self.mode {
            RendererKind::Raster => self.raster.is_ok(),
            RendererKind::PathTrace => self.pathtrace.as_ref().is_ok_and(PathTraceMode::is_rendering),
            // Whitted redraws only when the view changes (handled above), and while its
            // frame is being read back (in the browser).
            RendererKind::Whitted => self.whitted.as_ref().is_ok_and(WhittedMode::is_busy),
        };
        if busy {
            ui.ctx().request_repaint();
        }
    }
}

impl ViewerApp {
    /// The Auto mode's part of a frame: runs its pilot's slice on the path tracer's scene and
    /// view, hands a new choice to its mode, and while the pilot measures shows its progress
    /// in the view. Returns whether the view should show the chosen mode's image.
    fn auto_frame(&mut self, ui: &mut egui::Ui, gpu: &GpuContext, view_pixels: [u32; 2]) -> bool {
        let Ok(pathtrace) = &self.pathtrace else { return true };
        let sizes = crate::auto_pilot::ViewSizes {
            raster: view_pixels.map(|v| v.max(1)),
            whitted: WhittedMode::render_size(view_pixels),
            pathtrace: pathtrace.render_size(view_pixels),
        };
        let [width, height] = sizes.raster;
        let scene = pathtrace.desired_scene(width, height);
        let path = pathtrace.scene_path().to_path_buf();
        if let Some(choice) = self.auto.frame(gpu, &path, &scene, sizes) {
            let kind = crate::auto_panel::apply_choice(
                &choice,
                self.raster.as_mut().ok(),
                self.whitted.as_mut().ok(),
                self.pathtrace.as_mut().ok(),
            );
            self.switch_to(kind);
        }
        let Some((done, what)) = self.auto.progress() else { return true };
        let rect = ui.available_rect_before_wrap();
        ui.scope_builder(egui::UiBuilder::new().max_rect(rect.shrink(24.0)), |ui| {
            ui.label("Auto: measuring this scene with every renderer and setting");
            ui.add(egui::ProgressBar::new(done).show_percentage());
            ui.label(what);
        });
        ui.ctx().request_repaint();
        false
    }
}

/// The four strips of `outer` around `inner` (top and bottom full width, left and right between
/// them), so that a frame around an opaque image is filled without filling under it.
fn margin_strips(outer: egui::Rect, inner: egui::Rect) -> [egui::Rect; 4] {
    use egui::{Rect, pos2};
    [
        Rect::from_min_max(outer.min, pos2(outer.max.x, inner.min.y)),
        Rect::from_min_max(pos2(outer.min.x, inner.max.y), outer.max),
        Rect::from_min_max(pos2(outer.min.x, inner.min.y), pos2(inner.min.x, inner.max.y)),
        Rect::from_min_max(pos2(inner.max.x, inner.min.y), pos2(outer.max.x, inner.max.y)),
    ]
}

fn load_pathtrace(path: &Path) -> Result<PathTraceMode, String> {
    Ok(PathTraceMode::new(path.to_path_buf(), scene_file::load(path)?.pathtrace?))
}

fn load_raster(path: &Path) -> Result<RasterMode, String> {
    let (raster, scene) = scene_file::load(path)?.raster?;
    Ok(RasterMode::new(path.to_path_buf(), raster, scene))
}

fn load_whitted(path: &Path) -> Result<WhittedMode, String> {
    Ok(WhittedMode::new(path.to_path_buf(), scene_file::load(path)?.whitted?))
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
        // A scene file dropped on the window opens like one named in the Scene field.
        let dropped = ui.ctx().input(|i| i.raw.dropped_files.clone());
        for file in dropped {
            self.open_dropped(ui.ctx(), file);
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
            let picked = self.picker.take();
            if let Some((name, text)) = picked {
                let result = text.and_then(|text| self.open_text(&name, &text));
                self.opened(result);
            }
            crate::browser::publish_status(&self.status());
        }
    }
}

/// The browser's extra ways to open a scene: the scenes built into the page, and a file from
/// the user's disk through the browser's file picker (the desktop types a path instead).
#[cfg(target_arch = "wasm32")]
impl ViewerApp {
    fn web_open_buttons(&mut self, ui: &mut egui::Ui) {
        ui.menu_button("Built-in scenes", |ui| {
            for (name, _) in crate::platform::BUILT_IN_SCENES {
                if ui.button(*name).clicked() {
                    self.scene_field = (*name).to_owned();
                    let result = self.open(Path::new(name));
                    self.opened(result);
                    ui.close();
                }
            }
        });
        if ui.button("Open file...").clicked()
            && let Err(e) = self.picker.open(ui.ctx())
        {
            self.open_error = Some(e);
        }
    }
}

/// `n` and the noun in the number it takes ("1 frame", "2 frames").
pub fn count(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

#[cfg(test)]
mod tests {
    #[test]
    fn counts_take_the_nouns_number() {
        assert_eq!(super::count(1, "frame", "frames"), "1 frame");
        assert_eq!(super::count(0, "frame", "frames"), "0 frames");
        assert_eq!(super::count(30, "refresh", "refreshes"), "30 refreshes");
    }
}
