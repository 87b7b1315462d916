//! The raster mode: look and effect toggles, the `RasterRenderer` on the shared device,
//! and its frame rate and GPU time per pass.
//!
//! The renderer draws into its own output texture on eframe's device, which is registered with
//! egui_wgpu and shown as it is: no copy through the CPU. The output holds linear values in 8
//! bits, exactly the bytes of the raster's PNG output (whose default encoding is linear, as the
//! assignment's figure 1), so the window shows what a saved PNG would contain.

use std::path::{Path, PathBuf};

use illum_gpu::GpuContext;
use illum_raster::{Look, Options, PassTimes, RasterRenderer, RasterScene};

use crate::camera::OrbitCamera;
use crate::frame_rate::FrameRate;

/// The raster mode.
pub struct RasterMode {
    scene_path: PathBuf,
    scene: RasterScene,
    pub options: Options,
    pub camera: OrbitCamera,
    renderer: Option<RasterState>,
    /// The (scene, size) the renderer last failed to be created for, not retried every frame.
    failed: Option<(RasterScene, u32, u32)>,
    /// Frames drawn by the renderer, for its frame rate.
    frame_rate: FrameRate,
    pass_times: Option<PassTimes>,
    /// The renderer's last error, shown in the panel.
    pub message: Option<String>,
}

/// The renderer and the egui texture its output is registered as.
struct RasterState {
    renderer: RasterRenderer,
    texture: Option<egui::TextureId>,
}

impl RasterMode {
    pub fn new(scene_path: PathBuf, scene: RasterScene) -> Self {
        RasterMode {
            options: Options::from_scene(&scene),
            camera: OrbitCamera::new(scene.camera),
            scene_path,
            scene,
            renderer: None,
            failed: None,
            frame_rate: FrameRate::default(),
            pass_times: None,
            message: None,
        }
    }

    /// Replaces the scene (opened from the UI); look, effects and camera start from its own.
    pub fn set_scene(&mut self, scene_path: PathBuf, scene: RasterScene) {
        let renderer = self.renderer.take();
        *self = RasterMode::new(scene_path, scene);
        // Keep the renderer (and its registered egui texture): only the scene changes.
        self.renderer = renderer;
        if let Some(r) = &mut self.renderer
            && let Err(e) = r.renderer.set_scene(&self.scene)
        {
            self.message = Some(e.to_string());
        }
    }

    pub fn scene_path(&self) -> &Path {
        &self.scene_path
    }

    /// Frames per second over the last frames drawn.
    pub fn fps(&self) -> Option<f64> {
        self.frame_rate.fps()
    }

    pub fn pass_times(&self) -> Option<PassTimes> {
        self.pass_times
    }

    /// Draws one frame at `view_pixels` and returns the texture to show.
    pub fn frame(
        &mut self,
        gpu: &GpuContext,
        render_state: &egui_wgpu::RenderState,
        view_pixels: [u32; 2],
    ) -> Option<egui::TextureId> {
        let [width, height] = view_pixels.map(|v| v.max(1));
        let mut scene = self.scene.clone();
        scene.camera = self.camera.camera(width, height);
        if let Err(message) = self.sync_renderer(gpu, &scene, width, height) {
            self.message = Some(message);
            return None;
        }
        let state = self.renderer.as_mut()?;
        match state.renderer.draw(&self.options) {
            Ok(times) => {
                self.pass_times = times;
                self.message = None;
            }
            Err(e) => {
                self.message = Some(e.to_string());
                return None;
            }
        }
        self.frame_rate.tick();
        let view = state.renderer.output_view()?;
        let mut renderer = render_state.renderer.write();
        // The output texture is recreated on resize, so the egui
        // texture is pointed at the current view every frame (this only rebuilds a bind group).
        let id = match state.texture {
            Some(id) => {
                renderer.update_egui_texture_from_wgpu_texture(
                    &gpu.device,
                    view,
                    egui_wgpu::wgpu::FilterMode::Linear,
                    id,
                );
                id
            }
            None => renderer.register_native_texture(&gpu.device, view, egui_wgpu::wgpu::FilterMode::Linear),
        };
        state.texture = Some(id);
        Some(id)
    }

    /// Creates the renderer or brings it to the wanted size and camera.
    fn sync_renderer(
        &mut self,
        gpu: &GpuContext,
        scene: &RasterScene,
        width: u32,
        height: u32,
    ) -> Result<(), String> {
        if self.renderer.is_none() {
            let attempt = (scene.clone(), width, height);
            if self.failed.as_ref() == Some(&attempt) {
                return Err(self.message.clone().unwrap_or_default());
            }
            // The raster reads its pass times back with a blocking wait, which a web page cannot
            // do: there it runs without them (as on an adapter without timestamp queries).
            let mut gpu = gpu.clone();
            gpu.timestamps &= !crate::platform::POLLED_READBACK;
            match RasterRenderer::new(&gpu, scene, width, height) {
                Ok(mut renderer) => {
                    // An edited scene (a moved sphere) redraws at interactive rates; a still
                    // one at full quality (RasterRenderer::set_reduced_cubes_while_changing).
                    renderer.set_reduced_cubes_while_changing(true);
                    self.renderer = Some(RasterState { renderer, texture: None })
                }
                Err(e) => {
                    self.failed = Some(attempt);
                    return Err(e.to_string());
                }
            }
        }
        let state = self.renderer.as_mut().expect("created above");
        if state.renderer.size() != (width, height) {
            state.renderer.resize(width, height).map_err(|e| e.to_string())?;
        }
        if state.renderer.scene().camera != scene.camera {
            state.renderer.set_scene(scene).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    /// The panel's controls.
    pub fn panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Raster");
        ui.horizontal(|ui| {
            ui.label("Look");
            for look in Look::ALL {
                ui.radio_value(&mut self.options.look, look, look.as_str());
            }
        });
        let e = &mut self.options.effects;
        ui.checkbox(&mut e.shadows, "Shadows");
        ui.add_enabled(e.shadows, egui::Checkbox::new(&mut e.pcf, "PCF soft shadows"));
        ui.checkbox(&mut e.refraction, "Refraction");
        // Reflection and Fresnel exist only in the enhanced look.
        let enhanced = self.options.look == Look::Enhanced;
        ui.add_enabled(enhanced, egui::Checkbox::new(&mut e.reflection, "Reflection"));
        ui.add_enabled(enhanced, egui::Checkbox::new(&mut e.fresnel, "Fresnel"));
        ui.checkbox(&mut e.antialiasing, "Anti-aliasing");
        if ui.add_enabled(!self.camera.is_home(), egui::Button::new("Reset camera")).clicked() {
            self.camera.reset();
        }

        ui.separator();
        egui::Grid::new("raster stats").num_columns(2).show(ui, |ui| {
            let size = self.renderer.as_ref().map_or((0, 0), |r| r.renderer.size());
            ui.label("Resolution");
            ui.label(format!("{} x {}", size.0, size.1));
            ui.end_row();
            ui.label("Frame rate");
            ui.label(self.fps().map_or("-".to_owned(), |fps| format!("{fps:.1} fps")));
            ui.end_row();
            match self.pass_times {
                Some(t) => {
                    for (name, ms) in [
                        ("GPU shadow map", t.shadow_ms),
                        ("GPU cube maps", t.cube_ms),
                        ("GPU main pass", t.main_ms),
                        ("GPU total", t.total_ms()),
                    ] {
                        ui.label(name);
                        ui.label(format!("{ms:.2} ms"));
                        ui.end_row();
                    }
                }
                None => {
                    ui.label("GPU time");
                    ui.label("(no timestamp queries on this adapter)");
                    ui.end_row();
                }
            }
        });
        if let Some(message) = &self.message {
            ui.colored_label(ui.visuals().error_fg_color, message);
        }
    }
}
