//! The path-tracer mode's panel (egui): its settings, stop rules, pause and reset, statistics
//! and saving. The state it edits is `pathtrace_mode.rs`.

use std::time::Duration;

use illum_pathtrace::StopReason;
use illum_scene::{Bounces, Sampling};

use crate::pathtrace_mode::{MAX_SCALE, MIN_SCALE, PathTraceMode};

/// Highest fixed bounce count offered by the slider (the scene format allows more).
pub const MAX_UI_BOUNCES: u32 = 64;

impl PathTraceMode {
    /// The panel's controls.
    pub(crate) fn controls(&mut self, ui: &mut egui::Ui) {
        ui.heading("Path tracer");
        let caustics_apply = self.caustics_apply();
        let scene_spp = self.scene().pathtrace.spp;
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
            let mut spp = s.stop.spp.unwrap_or(scene_spp.max(1));
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
            let label = if self.paused() { "Resume" } else { "Pause" };
            if ui.button(label).clicked() {
                self.set_paused(!self.paused());
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
        let st = self.stats();
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
            row("Rel. error", self.error_text());
            row("Dropped NaN/Inf", st.dropped_samples.to_string());
            let state = match (self.paused(), self.stop_reason()) {
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
