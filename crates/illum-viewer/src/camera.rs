//! Orbit, pan and zoom with the mouse, for both modes.
//!
//! The camera moves on a sphere around its target: dragging with the primary button turns the
//! eye around the target (yaw about the scene's up axis, pitch about the camera's right axis),
//! dragging with the secondary or middle button moves eye and target together in the image
//! plane, and the scroll wheel scales the eye's distance to the target. Only eye and target
//! change; the field of view and the up vector stay the scene's.

use glam::{Quat, Vec3};
use illum_scene::Camera;

/// Radians of orbit per point dragged.
const ORBIT_PER_POINT: f32 = 0.008;
/// Pitch stays this far (radians) from straight up or down, where the view's frame would flip.
const POLE_MARGIN: f32 = 0.02;
/// Distance factor per point of scroll: e^(-0.0015 * 100) ~ 0.86 per wheel notch.
const ZOOM_PER_POINT: f32 = 0.0015;

/// The interactive camera of one mode. `home` is the scene's own camera, for the reset button.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    home: Camera,
    eye: Vec3,
    target: Vec3,
}

impl OrbitCamera {
    pub fn new(home: Camera) -> Self {
        OrbitCamera { home, eye: home.eye, target: home.target }
    }

    /// Back to the scene's own camera.
    pub fn reset(&mut self) {
        self.eye = self.home.eye;
        self.target = self.home.target;
    }

    /// True when the camera is the scene's own.
    pub fn is_home(&self) -> bool {
        self.eye == self.home.eye && self.target == self.home.target
    }

    /// The scene's camera with this eye and target, at `width` x `height` pixels.
    pub fn camera(&self, width: u32, height: u32) -> Camera {
        Camera { eye: self.eye, target: self.target, width, height, ..self.home }
    }

    /// Turns the eye around the target by a drag of (dx, dy) points.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        let up = self.home.up.normalize_or_zero();
        let offset = self.eye - self.target;
        let distance = offset.length();
        if distance <= 0.0 || up == Vec3::ZERO {
            return;
        }
        let yawed = Quat::from_axis_angle(up, -dx * ORBIT_PER_POINT) * offset;
        // Pitch is the angle from the up axis; keep it inside (margin, pi - margin).
        let polar = (yawed.dot(up) / distance).clamp(-1.0, 1.0).acos();
        let new_polar = (polar - dy * ORBIT_PER_POINT).clamp(POLE_MARGIN, std::f32::consts::PI - POLE_MARGIN);
        let right = up.cross(yawed).normalize_or_zero();
        if right == Vec3::ZERO {
            return;
        }
        let pitched = Quat::from_axis_angle(right, polar - new_polar) * yawed;
        self.eye = self.target + pitched;
    }

    /// Moves eye and target in the image plane by a drag of (dx, dy) points in a view
    /// `view_height` points high, so the point under the cursor follows it at the target's depth.
    pub fn pan(&mut self, dx: f32, dy: f32, view_height: f32) {
        let camera = self.camera(self.home.width, self.home.height);
        let basis = camera.basis();
        if !basis.right.is_finite() || view_height <= 0.0 {
            return;
        }
        let units_per_point = 2.0 * (self.eye - self.target).length() * basis.tan_half_fov / view_height;
        let shift = (-dx * basis.right + dy * basis.up) * units_per_point;
        self.eye += shift;
        self.target += shift;
    }

    /// Scales the distance to the target for `scroll` points of wheel (positive: closer).
    pub fn zoom(&mut self, scroll: f32) {
        let offset = self.eye - self.target;
        let home_distance = (self.home.eye - self.home.target).length();
        let distance = (offset.length() * (-scroll * ZOOM_PER_POINT).exp())
            .clamp(home_distance * 1e-3, home_distance * 1e3);
        self.eye = self.target + offset.normalize_or_zero() * distance;
    }

    /// Applies the mouse input over `response` (the image). Returns true when the camera moved.
    pub fn handle(&mut self, ui: &egui::Ui, response: &egui::Response) -> bool {
        let before = *self;
        let delta = response.drag_delta();
        if response.dragged_by(egui::PointerButton::Primary) {
            self.orbit(delta.x, delta.y);
        } else if response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle)
        {
            self.pan(delta.x, delta.y, response.rect.height());
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.zoom(scroll);
            }
        }
        *self != before
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn home() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 0.0, -5.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            vfov_deg: 45.0,
            width: 64,
            height: 48,
        }
    }

    #[test]
    fn orbit_keeps_distance_and_reset_returns_home() {
        let mut c = OrbitCamera::new(home());
        c.orbit(100.0, 40.0);
        assert!(!c.is_home());
        let cam = c.camera(10, 10);
        assert!(((cam.eye - cam.target).length() - 5.0).abs() < 1e-4);
        assert_eq!((cam.width, cam.height), (10, 10));
        c.reset();
        assert!(c.is_home());
    }

    #[test]
    fn pitch_never_reaches_the_pole() {
        let mut c = OrbitCamera::new(home());
        c.orbit(0.0, 10_000.0);
        let cam = c.camera(64, 48);
        assert!(cam.basis().right.is_finite());
        c.orbit(0.0, -20_000.0);
        assert!(c.camera(64, 48).basis().right.is_finite());
    }

    #[test]
    fn zoom_and_pan() {
        let mut c = OrbitCamera::new(home());
        c.zoom(100.0);
        assert!((c.camera(1, 1).eye - Vec3::ZERO).length() < 5.0);
        let before = c.camera(1, 1);
        c.pan(10.0, 0.0, 100.0);
        let after = c.camera(1, 1);
        assert!((after.target - before.target).length() > 0.0);
        // Panning moves eye and target together.
        assert!(((after.eye - after.target) - (before.eye - before.target)).length() < 1e-4);
    }
}
