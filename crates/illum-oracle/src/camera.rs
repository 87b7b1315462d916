//! The pinhole camera, in f64.
//!
//! Frame: forward = normalize(target - eye), right = normalize(forward x up), up' = right x
//! forward. The image plane at distance 1 spans [-aspect tan(vfov/2), aspect tan(vfov/2)] along
//! right and [-tan(vfov/2), tan(vfov/2)] along up'. Pixel (x, y), row 0 at the top, with jitter
//! (jx, jy) in [0, 1)^2 looks through the plane point
//!     sx = (2 (x + jx) / w - 1) aspect tan(vfov/2),   sy = (1 - 2 (y + jy) / h) tan(vfov/2).

use glam::DVec3;

use crate::geometry::dvec;

#[derive(Clone, Copy, Debug)]
pub struct PinholeCamera {
    pub eye: DVec3,
    pub forward: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    pub tan_half_fov: f64,
    pub aspect: f64,
    pub width: u32,
    pub height: u32,
}

impl PinholeCamera {
    pub fn new(camera: &illum_scene::Camera) -> PinholeCamera {
        let eye = dvec(camera.eye);
        let forward = (dvec(camera.target) - eye).normalize();
        let right = forward.cross(dvec(camera.up)).normalize();
        let up = right.cross(forward);
        PinholeCamera {
            eye,
            forward,
            right,
            up,
            tan_half_fov: (f64::from(camera.vfov_deg).to_radians() / 2.0).tan(),
            aspect: f64::from(camera.width) / f64::from(camera.height),
            width: camera.width,
            height: camera.height,
        }
    }

    /// Unit direction through image point (x + jx, y + jy), in pixels from the top-left corner.
    pub fn direction(&self, x: u32, y: u32, jx: f64, jy: f64) -> DVec3 {
        let ndc_x = 2.0 * (f64::from(x) + jx) / f64::from(self.width) - 1.0;
        let ndc_y = 1.0 - 2.0 * (f64::from(y) + jy) / f64::from(self.height);
        let sx = ndc_x * self.aspect * self.tan_half_fov;
        let sy = ndc_y * self.tan_half_fov;
        (self.forward + sx * self.right + sy * self.up).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cornell_camera() -> illum_scene::Camera {
        illum_scene::Camera {
            eye: glam::Vec3::new(278.0, 278.0, -724.26),
            target: glam::Vec3::new(278.0, 278.0, 0.0),
            up: glam::Vec3::Y,
            vfov_deg: 45.0,
            width: 64,
            height: 32,
        }
    }

    #[test]
    fn cornell_frame_and_image_corners() {
        let cam = PinholeCamera::new(&cornell_camera());
        assert!((cam.forward - DVec3::Z).length() < 1e-12);
        assert!((cam.right - DVec3::NEG_X).length() < 1e-12, "screen-right is world -X");
        assert!((cam.up - DVec3::Y).length() < 1e-12);
        // The image centre looks straight ahead.
        assert!((cam.direction(32, 16, 0.0, 0.0) - DVec3::Z).length() < 1e-12);
        // The top-left corner of the image: up and toward +X (the red wall), with slopes
        // tan(22.5 deg) vertically and aspect times that horizontally.
        let d = cam.direction(0, 0, 0.0, 0.0);
        let t = (22.5f64).to_radians().tan();
        assert!((d.y / d.z - t).abs() < 1e-12, "{d:?}");
        assert!((d.x / d.z - 2.0 * t).abs() < 1e-12, "{d:?}");
        // Jitter 1 in x reaches the next pixel's left edge.
        let a = cam.direction(3, 5, 1.0, 0.25);
        let b = cam.direction(4, 5, 0.0, 0.25);
        assert!((a - b).length() < 1e-14);
    }
}
