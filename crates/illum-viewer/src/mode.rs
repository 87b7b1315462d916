//! What the window asks of every renderer's mode: one interface, so that the window's code
//! (`app/`) holds no per-mode `match` but the one that picks the mode shown
//! (`ViewerApp::shown`).

use std::path::Path;

use illum_gpu::GpuContext;

use crate::camera::OrbitCamera;
use crate::difference_view::PathTracerTruth;
use crate::pathtrace_mode::PathTraceMode;
use crate::plural::count;
use crate::raster_mode::RasterMode;
use crate::whitted_mode::WhittedMode;

/// One renderer's mode: its state (testable without egui), its panel and its frame.
pub trait ViewMode {
    /// The scene file, as it was given.
    fn scene_path(&self) -> &Path;
    /// The orbit camera.
    fn camera(&mut self) -> &mut OrbitCamera;
    /// Draws the mode's settings and statistics in the side panel.
    fn panel(&mut self, ui: &mut egui::Ui);
    /// Renders this frame's view at `view_pixels` and returns the texture to show; `truth` is
    /// the path tracer's accumulation, which a deterministic mode's Difference view may use.
    fn frame(
        &mut self,
        gpu: &GpuContext,
        ctx: &egui::Context,
        render_state: &egui_wgpu::RenderState,
        view_pixels: [u32; 2],
        truth: Option<PathTracerTruth<'_>>,
    ) -> Option<egui::TextureId>;
    /// Whether the window must draw another frame soon (work under way).
    fn busy(&self) -> bool;
    /// One line of the mode's statistics, as a `--screenshot` run prints it on exit (the smoke
    /// test and `bench --viewer` read it).
    fn summary(&self) -> String;
}

impl ViewMode for RasterMode {
    fn scene_path(&self) -> &Path {
        RasterMode::scene_path(self)
    }
    fn camera(&mut self) -> &mut OrbitCamera {
        &mut self.camera
    }
    fn panel(&mut self, ui: &mut egui::Ui) {
        RasterMode::panel(self, ui);
    }
    fn frame(
        &mut self,
        gpu: &GpuContext,
        ctx: &egui::Context,
        render_state: &egui_wgpu::RenderState,
        view_pixels: [u32; 2],
        truth: Option<PathTracerTruth<'_>>,
    ) -> Option<egui::TextureId> {
        RasterMode::frame(self, gpu, ctx, render_state, view_pixels, truth)
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

impl ViewMode for WhittedMode {
    fn scene_path(&self) -> &Path {
        WhittedMode::scene_path(self)
    }
    fn camera(&mut self) -> &mut OrbitCamera {
        &mut self.camera
    }
    fn panel(&mut self, ui: &mut egui::Ui) {
        WhittedMode::panel(self, ui);
    }
    fn frame(
        &mut self,
        gpu: &GpuContext,
        ctx: &egui::Context,
        _: &egui_wgpu::RenderState,
        view_pixels: [u32; 2],
        truth: Option<PathTracerTruth<'_>>,
    ) -> Option<egui::TextureId> {
        WhittedMode::frame(self, gpu, ctx, view_pixels, truth)
    }
    /// Redraws only when the view changes, and while its frame is read back (in a web page).
    fn busy(&self) -> bool {
        self.is_busy()
    }
    fn summary(&self) -> String {
        let ms = self.frame_ms.map_or("n/a".to_owned(), |ms| format!("{ms:.1} ms"));
        format!("whitted: {} rendered, last frame {ms}", count(self.frames, "frame", "frames"))
    }
}

impl ViewMode for PathTraceMode {
    fn scene_path(&self) -> &Path {
        PathTraceMode::scene_path(self)
    }
    fn camera(&mut self) -> &mut OrbitCamera {
        &mut self.camera
    }
    fn panel(&mut self, ui: &mut egui::Ui) {
        PathTraceMode::panel(self, ui);
    }
    /// The path tracer is its own truth: `truth` is not used.
    fn frame(
        &mut self,
        gpu: &GpuContext,
        ctx: &egui::Context,
        render_state: &egui_wgpu::RenderState,
        view_pixels: [u32; 2],
        _: Option<PathTracerTruth<'_>>,
    ) -> Option<egui::TextureId> {
        PathTraceMode::frame(self, gpu, ctx, render_state, view_pixels);
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
