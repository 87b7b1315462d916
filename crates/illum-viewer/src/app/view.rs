//! The central view: the shown mode's image (or the Auto pilot's progress in its place),
//! which the mouse steers, and the margin around it.

use illum_gpu::GpuContext;

use super::ViewerApp;
use crate::whitted_mode::WhittedMode;

impl ViewerApp {
    /// The image of the shown mode, filling `ui`; `fill` where there is none yet.
    pub(super) fn view(&mut self, ui: &mut egui::Ui, fill: egui::Color32) {
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
        let (gpu, render_state) = (gpu.clone(), render_state.clone());
        let texture = match self.shown() {
            (Some(mode), truth) => mode.frame(&gpu, ui.ctx(), &render_state, view_pixels, truth),
            (None, _) => None,
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
        // Each mode says whether it has work under way; a camera change is handled above.
        if self.mode_ref(self.mode).is_ok_and(|m| m.busy()) {
            ui.ctx().request_repaint();
        }
    }
    /// The Auto mode's part of a frame: runs its pilot's slice on the path tracer's scene and
    /// view, hands a new choice to its mode, and while the pilot measures shows its progress
    /// in the view. Returns whether the view should show the chosen mode's image.
    fn auto_frame(&mut self, ui: &mut egui::Ui, gpu: &GpuContext, view_pixels: [u32; 2]) -> bool {
        let Ok(pathtrace) = &self.pathtrace else { return true };
        let sizes = illum_auto::pilot::Sizes {
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
pub(super) fn margin_strips(outer: egui::Rect, inner: egui::Rect) -> [egui::Rect; 4] {
    use egui::{Rect, pos2};
    [
        Rect::from_min_max(outer.min, pos2(outer.max.x, inner.min.y)),
        Rect::from_min_max(pos2(outer.min.x, inner.max.y), outer.max),
        Rect::from_min_max(pos2(outer.min.x, inner.min.y), pos2(inner.min.x, inner.max.y)),
        Rect::from_min_max(pos2(inner.max.x, inner.min.y), pos2(outer.max.x, inner.max.y)),
    ]
}
