//! What the window asks of every renderer's mode: one interface, so that the window's code
//! (`app/`) holds no per-mode `match` but the ones that pick the mode (`ViewerApp::mode_of`,
//! `mode_ref`, `shown`). Each mode implements it in its own file (`raster_mode.rs`,
//! `whitted_mode.rs`, `pathtrace_mode.rs`).

use std::path::Path;

use illum_gpu::GpuContext;

use crate::camera::OrbitCamera;
use crate::difference_view::PathTracerTruth;

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
