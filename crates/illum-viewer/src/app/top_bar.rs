//! The top bar: the settings toggle, the mode buttons (a drop-down in a narrow window), the
//! scene field and its Open button, and the errors of opening a scene.

#[cfg(target_arch = "wasm32")]
use std::path::Path;
use std::path::PathBuf;

use illum_scene::RendererKind;

use super::ViewerApp;

/// Below this window width (in points) the top bar is compact (see `ViewerApp::top_bar`).
pub(super) const COMPACT_BELOW_POINTS: f32 = 520.0;

impl ViewerApp {
    pub(super) fn top_bar(&mut self, ui: &mut egui::Ui) {
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
