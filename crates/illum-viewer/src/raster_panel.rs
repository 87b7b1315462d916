//! The raster mode's panel: look and effect toggles, the camera's reset, the frame rate and the
//! GPU time per pass, and the Difference view's controls (the mode's state: `raster_mode.rs`).

use illum_raster::Look;

use crate::raster_mode::RasterMode;

impl RasterMode {
    /// The panel's controls.
    pub(crate) fn controls(&mut self, ui: &mut egui::Ui) {
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
            let size = self.size();
            ui.label("Resolution");
            ui.label(format!("{} x {}", size.0, size.1));
            ui.end_row();
            ui.label("Frame rate");
            ui.label(self.fps().map_or("-".to_owned(), |fps| format!("{fps:.1} fps")));
            ui.end_row();
            match self.pass_times() {
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
        ui.separator();
        self.difference.panel(ui);
    }
}
