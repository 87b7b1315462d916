//! Pinhole camera frame.
//!
//! The frame follows three.js (`lookAt` with a right-handed world): forward points from the eye
//! to the target, right = forward x up, and the true up = right x forward, so (right, up,
//! -forward) is a right-handed orthonormal basis. For the Cornell camera (looking down +Z with
//! +Y up) this makes screen-right world -X, which is why the red wall at x = 555 appears on the
//! image's left.
//!
//! A pixel position (px, py), measured from the image's top-left corner with y growing downward,
//! maps to normalised device coordinates x = 2 px / width - 1 and y = 1 - 2 py / height, both in
//! [-1, 1]. The plane at distance 1 in front of the eye is tan(vfov/2) high (half-height) and
//! aspect times that wide, so the ray direction is
//! `forward + x * aspect * tan_half_fov * right + y * tan_half_fov * up`.

use glam::Vec3;

/// Pinhole camera. `vfov_deg` is the full vertical field of view in degrees, in (0, 180).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub vfov_deg: f32,
    pub width: u32,
    pub height: u32,
}

/// Orthonormal camera frame. `right` is screen-right, `up` is screen-up, `forward` points from the
/// eye to the target; the frame is right-handed as in three.js (right = forward x up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraBasis {
    pub forward: Vec3,
    pub right: Vec3,
    pub up: Vec3,
    /// tan(vfov / 2): half the image plane's height at distance 1.
    pub tan_half_fov: f32,
    /// width / height.
    pub aspect: f32,
}

/// Near and far clip distances of a rasterizer's camera, 0 < near < far (the ray tracers need
/// none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipPlanes {
    pub near: f32,
    pub far: f32,
}

/// `v / |v|`, computed after dividing by the largest component so that neither very small nor
/// very large (but finite) vectors underflow or overflow in the squared length. `None` for zero
/// or non-finite vectors.
pub(crate) fn robust_normalize(v: Vec3) -> Option<Vec3> {
    let scale = v.abs().max_element();
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    (v / scale).try_normalize()
}

impl Camera {
    /// The orthonormal frame of this camera. The camera must be valid (as every camera of a
    /// loaded [`Scene`](crate::Scene) is): eye != target and up not parallel to the view
    /// direction; otherwise the vectors are NaN.
    pub fn basis(&self) -> CameraBasis {
        let nan = Vec3::splat(f32::NAN);
        let forward = robust_normalize(self.target - self.eye).unwrap_or(nan);
        let right = robust_normalize(forward.cross(self.up)).unwrap_or(nan);
        let up = right.cross(forward);
        CameraBasis {
            forward,
            right,
            up,
            tan_half_fov: (self.vfov_deg.to_radians() * 0.5).tan(),
            aspect: self.width as f32 / self.height as f32,
        }
    }

    /// Unit direction of the ray through the image point (px, py), in pixels from the top-left
    /// corner of the image with y down; pixel (i, j) covers [i, i+1] x [j, j+1], so its centre is
    /// (i + 0.5, j + 0.5).
    pub fn ray_direction(&self, px: f32, py: f32) -> Vec3 {
        let b = self.basis();
        let x = 2.0 * px / self.width as f32 - 1.0;
        let y = 1.0 - 2.0 * py / self.height as f32;
        (b.forward + x * b.aspect * b.tan_half_fov * b.right + y * b.tan_half_fov * b.up).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The assignment's Cornell camera (docs/scenes.md).
    fn cornell() -> Camera {
        Camera {
            eye: Vec3::new(278.0, 278.0, -724.26),
            target: Vec3::new(278.0, 278.0, 0.0),
            up: Vec3::Y,
            vfov_deg: 45.0,
            width: 512,
            height: 512,
        }
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-6
    }

    #[test]
    fn cornell_screen_right_is_world_minus_x() {
        let b = cornell().basis();
        assert!(close(b.forward, Vec3::Z), "{:?}", b.forward);
        assert!(close(b.right, Vec3::NEG_X), "{:?}", b.right);
        assert!(close(b.up, Vec3::Y), "{:?}", b.up);
        assert!((b.tan_half_fov - 22.5f32.to_radians().tan()).abs() < 1e-6);
        assert_eq!(b.aspect, 1.0);
    }

    #[test]
    fn red_wall_is_on_the_image_left() {
        // Follow a ray from the left part of the image (an eighth of the width in from the
        // edge) to the side walls: it must head toward +X and reach the red wall's plane
        // x = 555 inside the room (0 < z < 555). The view's half-width at z = 0 is
        // 724.26 * tan(22.5 deg) = 300, so this ray has slope 0.75 * 300 / 724.26 in x per z.
        let cam = cornell();
        let d = cam.ray_direction(64.0, 256.0);
        assert!(d.x > 0.0, "left-side ray {d:?} heads toward -X");
        let t = (555.0 - cam.eye.x) / d.x;
        let hit = cam.eye + t * d;
        assert!(hit.z > 0.0 && hit.z < 555.0, "hit {hit:?}");
        assert!((hit.y - 278.0).abs() < 1e-3);

        // The ray through the image centre hits the back wall's centre.
        let c = cam.ray_direction(256.0, 256.0);
        assert!(close(c, Vec3::Z), "{c:?}");
        // The top edge looks up (+Y).
        assert!(cam.ray_direction(256.0, 0.0).y > 0.0);
    }

    #[test]
    fn field_of_view_spans_the_back_plane() {
        // docs/scenes.md: the eye sits 300 / tan(22.5 deg) in front of z = 0, so the top edge of
        // the view meets z = 0 at y = 278 + 300.
        let cam = cornell();
        let d = cam.ray_direction(256.0, 0.0);
        let hit = cam.eye + (-cam.eye.z / d.z) * d;
        assert!((hit.y - 578.0).abs() < 0.05, "{hit:?}");
    }

    #[test]
    fn basis_is_orthonormal_and_right_handed_for_an_oblique_camera() {
        let cam = Camera {
            eye: Vec3::new(7.5, 2.3, -4.2),
            target: Vec3::new(4.2, 2.3, -4.2),
            up: Vec3::new(0.1, 1.0, 0.2),
            vfov_deg: 60.0,
            width: 640,
            height: 480,
        };
        let b = cam.basis();
        for v in [b.forward, b.right, b.up] {
            assert!((v.length() - 1.0).abs() < 1e-6);
        }
        assert!(b.forward.dot(b.right).abs() < 1e-6);
        assert!(b.forward.dot(b.up).abs() < 1e-6);
        assert!(b.right.dot(b.up).abs() < 1e-6);
        // right x up = -forward (three.js: the camera looks down its local -Z).
        assert!(close(b.right.cross(b.up), -b.forward));
        // The true up stays in the plane of forward and the given up, on the given up's side.
        assert!(b.up.dot(cam.up) > 0.0);
        assert!(b.right.dot(cam.up).abs() < 1e-6);
        assert!((b.aspect - 640.0 / 480.0).abs() < 1e-6);

        // docs/scenes.md, the Whitted scene: with up = +Y this camera looks along -X and screen-right is
        // world -Z.
        let level = Camera { up: Vec3::Y, ..cam }.basis();
        assert!(close(level.forward, Vec3::NEG_X), "{:?}", level.forward);
        assert!(close(level.right, Vec3::NEG_Z), "{:?}", level.right);
    }

    #[test]
    fn robust_normalize_handles_extreme_magnitudes() {
        assert_eq!(robust_normalize(Vec3::new(1e-30, 0.0, 0.0)), Some(Vec3::X));
        assert_eq!(robust_normalize(Vec3::new(0.0, 3e38, 0.0)), Some(Vec3::Y));
        assert_eq!(robust_normalize(Vec3::ZERO), None);
        assert_eq!(robust_normalize(Vec3::new(f32::INFINITY, 0.0, 0.0)), None);
        assert_eq!(robust_normalize(Vec3::new(f32::NAN, 0.0, 0.0)), None);
    }
}
