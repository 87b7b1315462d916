//! The pinhole camera in f64, for the glint's solve: film points in pixels to directions and back.

use glam::DVec3;
use illum_scene::Scene;

/// The pinhole camera in f64, built from the same f32 basis the GPU uses.
pub(super) struct Film {
    pub(super) eye: DVec3,
    pub(super) forward: DVec3,
    pub(super) right: DVec3,
    pub(super) up: DVec3,
    pub(super) tan_half_fov: f64,
    pub(super) aspect: f64,
    pub(super) width: f64,
    pub(super) height: f64,
}

impl Film {
    pub(super) fn new(scene: &Scene) -> Self {
        let b = scene.camera.basis();
        Self {
            eye: scene.camera.eye.as_dvec3(),
            forward: b.forward.as_dvec3(),
            right: b.right.as_dvec3(),
            up: b.up.as_dvec3(),
            tan_half_fov: f64::from(b.tan_half_fov),
            aspect: f64::from(b.aspect),
            width: f64::from(scene.camera.width),
            height: f64::from(scene.camera.height),
        }
    }

    /// Unit direction of the camera ray through film point s (pixels).
    pub(super) fn direction(&self, s: [f64; 2]) -> DVec3 {
        self.direction_and_derivatives(s).0
    }

    /// Unit direction d of the camera ray through film point s (pixels), and its derivatives
    /// dd/ds_c: with v = forward + x right + y up (x, y linear in s) and d = v / |v|,
    /// dd = (dv - d (d . dv)) / |v|.
    pub(super) fn direction_and_derivatives(&self, s: [f64; 2]) -> (DVec3, [DVec3; 2]) {
        let x = (2.0 * s[0] / self.width - 1.0) * self.aspect * self.tan_half_fov;
        let y = (1.0 - 2.0 * s[1] / self.height) * self.tan_half_fov;
        let v = self.forward + x * self.right + y * self.up;
        let length = v.length();
        let d = v / length;
        let dv = [
            (2.0 * self.aspect * self.tan_half_fov / self.width) * self.right,
            (-2.0 * self.tan_half_fov / self.height) * self.up,
        ];
        (d, dv.map(|dv| (dv - d * d.dot(dv)) / length))
    }

    /// Film point (pixels) of direction d from the eye; None behind the eye.
    pub(super) fn film_point(&self, d: DVec3) -> Option<[f64; 2]> {
        let z = d.dot(self.forward);
        if z <= 1e-9 {
            return None;
        }
        let x = d.dot(self.right) / z;
        let y = d.dot(self.up) / z;
        Some([
            (x / (self.aspect * self.tan_half_fov) + 1.0) * 0.5 * self.width,
            (1.0 - y / self.tan_half_fov) * 0.5 * self.height,
        ])
    }

    /// Area of one pixel on the image plane at distance 1.
    pub(super) fn pixel_area(&self) -> f64 {
        (2.0 * self.aspect * self.tan_half_fov / self.width) * (2.0 * self.tan_half_fov / self.height)
    }

    pub(super) fn pixel(&self, s: [f64; 2]) -> Option<usize> {
        let inside = s[0] >= 0.0 && s[0] < self.width && s[1] >= 0.0 && s[1] < self.height;
        inside.then(|| s[1].floor() as usize * self.width as usize + s[0].floor() as usize)
    }
}
