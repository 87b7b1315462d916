//! The Whitted mode's panel: depth and rays per pixel, the camera's reset, the frame time, and
//! the Difference view's controls (the mode's state: `whitted_mode.rs`).

use illum_scene::{MAX_WHITTED_AA, MAX_WHITTED_DEPTH};

use crate::whitted_mode::WhittedMode;

impl WhittedMode {
    /// The panel's controls.
    pub(crate) fn controls(&mut self, ui: &mut egui::Ui) {
        ui.heading("Whitted ray tracer");
        ui.horizontal(|ui| {
            let label = ui.label("Depth");
            ui.add(egui::Slider::new(&mut self.depth, 0..=MAX_WHITTED_DEPTH)).labelled_by(label.id);
        });
        ui.horizontal(|ui| {
            let label = ui.label("Rays per pixel (n x n)");
            ui.add(egui::Slider::new(&mut self.aa, 1..=MAX_WHITTED_AA.min(4))).labelled_by(label.id);
        });
        if ui.add_enabled(!self.camera.is_home(), egui::Button::new("Reset camera")).clicked() {
            self.camera.reset();
        }
        ui.separator();
        egui::Grid::new("whitted stats").num_columns(2).show(ui, |ui| {
            ui.label("Frame time (wall)");
            ui.label(self.frame_ms.map_or("-".to_owned(), |ms| format!("{ms:.1} ms")));
            ui.end_row();
            ui.label("Frames");
            ui.label(self.frames.to_string());
            ui.end_row();
        });
        ui.weak("Rendered at half the view's size each way; a frame is drawn when the view changes.");
        self.difference.panel(ui);
        if let Some(message) = &self.message {
            ui.colored_label(ui.visuals().error_fg_color, message);
        }
    }
}
