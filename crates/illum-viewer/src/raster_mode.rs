//! The raster mode's state: look and effects, the `RasterRenderer` on the shared device, and
//! its frame rate and GPU time per pass (its panel: `raster_panel.rs`).
//!
//! The renderer draws into its own output texture on eframe's device, which is registered with
//! egui_wgpu and shown as it is: no copy through the CPU. The output holds linear values in 8
//! bits, exactly the bytes of the raster's PNG output (whose default encoding is linear, as the
//! assignment's figure 1), so the window shows what a saved PNG would contain.
//!
//! With the Difference view on (`difference_view.rs`), each new view (camera, look or effects)
//! is read back once, without waiting (`RasterRenderer::read_polled`, polled over the next
//! frames, so it works in a web page too), and its signed difference from a truth is shown
//! instead of the image. The truth is compared with the 8-bit frame the window shows: values
//! above 1 (the light, a bright sky) are clipped there, and that clipping shows as a bias.

use std::path::{Path, PathBuf};

use illum_gpu::GpuContext;
use illum_image::RgbImage32;
use illum_raster::{Options, PassTimes, PendingFrame, RasterRenderer, RasterScene};
use illum_scene::{Camera, Scene};

use crate::camera::OrbitCamera;
use crate::difference_view::{DifferenceView, PathTracerTruth};
use crate::frame_rate::FrameRate;
use crate::mode::ViewMode;

/// The raster mode.
pub struct RasterMode {
    scene_path: PathBuf,
    scene: RasterScene,
    /// The scene file's own scene (the Difference view's identity of what is drawn).
    physical: Scene,
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
    pub difference: DifferenceView,
    /// The view last read back for the difference, and its readback while under way.
    read: Option<(Camera, Options)>,
    pending: Option<(Camera, PendingFrame)>,
    /// The last frame read back, with the scene it is of (camera at its size), and how many
    /// were read.
    last: Option<(RgbImage32, Scene)>,
    reads: u64,
}

/// The renderer and the egui texture its output is registered as.
struct RasterState {
    renderer: RasterRenderer,
    texture: Option<egui::TextureId>,
}

impl RasterMode {
    pub fn new(scene_path: PathBuf, scene: RasterScene, physical: Scene) -> Self {
        RasterMode {
            options: Options::from_scene(&scene),
            camera: OrbitCamera::new(scene.camera),
            scene_path,
            scene,
            physical,
            renderer: None,
            failed: None,
            frame_rate: FrameRate::default(),
            pass_times: None,
            message: None,
            difference: DifferenceView::default(),
            read: None,
            pending: None,
            last: None,
            reads: 0,
        }
    }

    /// Replaces the scene (opened from the UI); look, effects and camera start from its own.
    pub fn set_scene(&mut self, scene_path: PathBuf, scene: RasterScene, physical: Scene) {
        let renderer = self.renderer.take();
        let difference = std::mem::take(&mut self.difference);
        *self = RasterMode { difference, ..RasterMode::new(scene_path, scene, physical) };
        // Keep the renderer (and its registered egui texture): only the scene changes.
        self.renderer = renderer;
        if let Some(r) = &mut self.renderer
            && let Err(e) = r.renderer.set_scene(&self.scene)
        {
            self.message = Some(e.to_string());
        }
    }

    /// Frames per second over the last frames drawn.
    pub fn fps(&self) -> Option<f64> {
        self.frame_rate.fps()
    }

    /// The renderer's size in pixels ((0, 0) before its first frame).
    pub fn size(&self) -> (u32, u32) {
        self.renderer.as_ref().map_or((0, 0), |r| r.renderer.size())
    }

    pub fn pass_times(&self) -> Option<PassTimes> {
        self.pass_times
    }

    /// The last frame read back for the Difference view and the scene it is of (camera at its
    /// size).
    pub fn image(&self) -> Option<(&RgbImage32, &Scene)> {
        self.last.as_ref().map(|(image, scene)| (image, scene))
    }

    /// Polls the readback under way; starts one of the frame just drawn when its view has not
    /// been read yet.
    fn read_back(&mut self, gpu: &GpuContext) -> Result<(), String> {
        let Some(state) = self.renderer.as_ref() else { return Ok(()) };
        if let Some((camera, pending)) = &self.pending {
            let Some(result) = pending.poll(gpu) else { return Ok(()) };
            let camera = *camera;
            self.pending = None;
            let image = result.map_err(|e| e.to_string())?;
            let mut scene = self.physical.clone();
            scene.camera = camera;
            self.last = Some((image, scene));
            self.reads += 1;
        }
        let view = (state.renderer.scene().camera, self.options);
        if self.read != Some(view) {
            let pending = state.renderer.read_polled().map_err(|e| e.to_string())?;
            self.pending = Some((view.0, pending));
            self.read = Some(view);
        }
        Ok(())
    }

    /// Draws one frame at `view_pixels` and returns the texture that shows it.
    fn draw(
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
}

impl ViewMode for RasterMode {
    fn scene_path(&self) -> &Path {
        &self.scene_path
    }

    fn camera(&mut self) -> &mut OrbitCamera {
        &mut self.camera
    }

    fn panel(&mut self, ui: &mut egui::Ui) {
        self.controls(ui);
    }

    /// Draws one frame at `view_pixels` and returns the texture to show: with the Difference
    /// view on, its difference from a truth (`path_tracer`: the path tracer's accumulation,
    /// one of the truths it may use) once there is one.
    fn frame(
        &mut self,
        gpu: &GpuContext,
        ctx: &egui::Context,
        render_state: &egui_wgpu::RenderState,
        view_pixels: [u32; 2],
        path_tracer: Option<PathTracerTruth<'_>>,
    ) -> Option<egui::TextureId> {
        let image = self.draw(gpu, render_state, view_pixels)?;
        if !self.difference.on {
            self.read = None;
            self.pending = None;
            return Some(image);
        }
        if let Err(e) = self.read_back(gpu) {
            self.message = Some(e);
        }
        if let Some((last, scene)) = &self.last {
            self.difference.update(ctx, last, self.reads, scene, 1.0, path_tracer);
        }
        Some(self.difference.texture().unwrap_or(image))
    }

    /// A real-time renderer: it redraws every frame, and its frame rate is measured.
    fn busy(&self) -> bool {
        true
    }

    fn summary(&self) -> String {
        let gpu = self
            .pass_times()
            .map_or("n/a".to_owned(), |t| format!("{:.2} ms", t.shadow_ms + t.cube_ms + t.main_ms));
        format!("raster: GPU time per frame {gpu}")
    }
}
