//! The cameras of a frame as world -> clip matrices: the main perspective camera and the six
//! faces of a cube map. wgpu's clip space has x right, y up and depth z / w in [0, 1].

use glam::{Mat4, Vec3};
use illum_scene::ClipPlanes;

use crate::scene::RasterScene;

/// World -> clip for a pinhole at `origin` with screen axes `right`, `up` and viewing direction
/// `forward` (orthonormal), where a point at 1 unit ahead and `1 / sx` units right lands on the
/// right edge (x = 1), and `1 / sy` units up on the top edge. With d = p - origin:
/// clip = (sx right.d, sy up.d, a forward.d + b, forward.d), so depth z / w = a + b / w is 0 at
/// w = near and 1 at w = far: a = far / (far - near), b = -far near / (far - near).
fn pinhole(origin: Vec3, [right, up, forward]: [Vec3; 3], sx: f32, sy: f32, clip: ClipPlanes) -> Mat4 {
    let (near, far) = (clip.near, clip.far);
    let a = far / (far - near);
    let b = -far * near / (far - near);
    let row = |axis: Vec3, scale: f32, offset: f32| (axis * scale).extend(offset - scale * axis.dot(origin));
    Mat4::from_rows(row(right, sx, 0.0), row(up, sy, 0.0), row(forward, a, b), row(forward, 1.0, 0.0))
}

/// The main camera for an output of `width` x `height` pixels, in the frame of illum-scene's
/// camera basis (right = forward x up, as three.js): the image plane at distance 1 is
/// tan(vfov / 2) high (half-height) and aspect times that wide.
pub fn main_view_proj(scene: &RasterScene, width: u32, height: u32) -> Mat4 {
    let basis = scene.camera.basis();
    let aspect = width as f32 / height as f32;
    let sy = 1.0 / basis.tan_half_fov;
    pinhole(scene.camera.eye, [basis.right, basis.up, basis.forward], sy / aspect, sy, scene.clip)
}

/// Layer order of a cube texture: +X, -X, +Y, -Y, +Z, -Z.
pub const CUBE_FACE_NAMES: [&str; 6] = ["+X", "-X", "+Y", "-Y", "+Z", "-Z"];

/// (right, up, forward) of each cube face, chosen so that a render into layer i is what sampling
/// the cube along a direction d returns. The sampler (Vulkan / WebGPU, as OpenGL) picks the face
/// of d's largest component m and reads texel (s, t) = ((sc / |m| + 1) / 2, (tc / |m| + 1) / 2),
/// with t counting rows from the top of the layer and (sc, tc) per face:
/// +X (-z, -y), -X (+z, -y), +Y (+x, +z), -Y (+x, -z), +Z (+x, -y), -Z (-x, -y).
/// A render puts normalised x = sc / |m| to the right and y = -tc / |m| up (clip y up is row 0),
/// which gives these axes. The frames are mirror images of right-handed ones, so renders into a
/// cube must not cull by winding.
const CUBE_AXES: [[Vec3; 3]; 6] = [
    [Vec3::NEG_Z, Vec3::Y, Vec3::X],
    [Vec3::Z, Vec3::Y, Vec3::NEG_X],
    [Vec3::X, Vec3::NEG_Z, Vec3::Y],
    [Vec3::X, Vec3::Z, Vec3::NEG_Y],
    [Vec3::X, Vec3::Y, Vec3::Z],
    [Vec3::NEG_X, Vec3::Y, Vec3::NEG_Z],
];

/// World -> clip of cube face `face` (0..6) seen from `center`: a 90-degree square frustum,
/// so a point one unit ahead and one unit aside lands on the face's edge.
pub fn cube_face_view_proj(center: Vec3, face: usize, clip: ClipPlanes) -> Mat4 {
    pinhole(center, CUBE_AXES[face], 1.0, 1.0, clip)
}

/// The clip planes of the cube maps captured at `center` (a sphere's centre). They are not the
/// camera's: a far plane set just beyond the floor's end as the camera sees it would, from the
/// sphere, cut the floor's far corners out of the environment the glass refracts and the metal
/// mirrors. Far reaches the farthest floor corner and the far side of the other sphere and of
/// each mesh's bounding sphere (with 1% slack); near is the camera's, but at most half the
/// distance to the nearest surface (the floor's plane, the other sphere or a mesh's bounding
/// sphere), so nothing the capture should see is clipped.
pub fn capture_clip(scene: &RasterScene, center: Vec3) -> ClipPlanes {
    let floor = &scene.floor;
    let (lo, hi) = (floor.min_corner(), floor.max_corner());
    let y = floor.height();
    let corners = [(lo.x, lo.y), (lo.x, hi.y), (hi.x, lo.y), (hi.x, hi.y)];
    let mut far = corners.iter().map(|&(x, z)| center.distance(Vec3::new(x, y, z))).fold(0.0f32, f32::max);
    let mut nearest = (center.y - y).abs();
    for (c, r) in scene.casters() {
        let d = center.distance(c);
        if d > r {
            far = far.max(d + r);
            nearest = nearest.min(d - r);
        }
    }
    let far = 1.01 * far.max(1e-3);
    let near = scene.clip.near.min(0.5 * nearest).max(1e-6 * far);
    ClipPlanes { near, far }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cube sampler's face selection and (s, t), written out from the Vulkan specification's
    /// table independently of CUBE_AXES.
    fn sample_face(d: Vec3) -> (usize, f32, f32) {
        let a = d.abs();
        let (face, sc, tc, m) = if a.x >= a.y && a.x >= a.z {
            if d.x > 0.0 { (0, -d.z, -d.y, a.x) } else { (1, d.z, -d.y, a.x) }
        } else if a.y >= a.z {
            if d.y > 0.0 { (2, d.x, d.z, a.y) } else { (3, d.x, -d.z, a.y) }
        } else if d.z > 0.0 {
            (4, d.x, -d.y, a.z)
        } else {
            (5, -d.x, -d.y, a.z)
        };
        (face, 0.5 * (sc / m + 1.0), 0.5 * (tc / m + 1.0))
    }

    #[test]
    fn cube_faces_render_what_the_sampler_reads() {
        let center = Vec3::new(4.2, 2.6, -4.2);
        let clip = ClipPlanes { near: 0.1, far: 3000.0 };
        // Directions on a lattice (avoiding exact ties between faces).
        for i in -3..=3 {
            for j in -3..=3 {
                for k in -3..=3 {
                    let d = Vec3::new(i as f32 + 0.13, j as f32 - 0.29, k as f32 + 0.41) * 1.7;
                    let (face, s, t) = sample_face(d);
                    let clip_pos = cube_face_view_proj(center, face, clip) * (center + d).extend(1.0);
                    assert!(clip_pos.w > 0.0, "{d:?} behind face {face}");
                    let ndc = clip_pos.truncate() / clip_pos.w;
                    let (s_render, t_render) = (0.5 * (ndc.x + 1.0), 0.5 * (1.0 - ndc.y));
                    assert!((s - s_render).abs() < 1e-5 && (t - t_render).abs() < 1e-5, "{d:?} face {face}");
                    assert!((0.0..=1.0).contains(&ndc.z), "{d:?}: depth {}", ndc.z);
                }
            }
        }
    }

    #[test]
    fn cube_depth_spans_near_to_far() {
        let clip = ClipPlanes { near: 0.5, far: 100.0 };
        let m = cube_face_view_proj(Vec3::ZERO, 4, clip);
        let depth = |z: f32| {
            let c = m * Vec3::new(0.0, 0.0, z).extend(1.0);
            c.z / c.w
        };
        assert!(depth(0.5).abs() < 1e-6);
        assert!((depth(100.0) - 1.0).abs() < 1e-6);
        assert!(depth(2.0) < depth(3.0));
    }

    #[test]
    fn captures_see_the_whole_floor_whatever_the_camera_clips() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/whitted.toml"))
            .unwrap();
        let mut scene = RasterScene::from_toml_str(&text, "whitted.toml").unwrap();
        scene.clip = ClipPlanes { near: 0.6, far: 5.0 };
        let clip = capture_clip(&scene, scene.glass.expect("glass").center);
        // The floor's farthest corner from the glass (4.2, 2.6, -4.2) is (-23, 0, 7.5): 29.7 away.
        let corner = scene.glass.expect("glass").center.distance(Vec3::new(-23.0, 0.0, 7.5));
        assert!(clip.far > corner && clip.far < 1.02 * corner, "{clip:?}");
        // The metal's surface is 1.87 from the glass's centre: near stays below half of that.
        assert!(clip.near > 0.0 && clip.near <= 0.5 * 1.87, "{clip:?}");
        assert_eq!(
            capture_clip(
                &{
                    scene.clip.near = 0.1;
                    scene
                },
                Vec3::new(4.2, 2.6, -4.2)
            )
            .near,
            0.1
        );
    }

    #[test]
    fn main_camera_puts_the_target_in_the_middle_and_world_minus_z_to_the_right() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/whitted.toml"))
            .unwrap();
        let scene = RasterScene::from_toml_str(&text, "whitted.toml").unwrap();
        let m = main_view_proj(&scene, 320, 180);
        let project = |p: Vec3| {
            let c = m * p.extend(1.0);
            c.truncate() / c.w
        };
        let target = project(scene.camera.target);
        assert!(target.x.abs() < 1e-5 && target.y.abs() < 1e-5, "{target:?}");
        // docs/scenes.md: the camera looks along -X, so screen-right is world -Z, up is +Y.
        assert!(project(scene.camera.target + Vec3::NEG_Z).x > 0.1);
        assert!(project(scene.camera.target + Vec3::Y).y > 0.1);
        // The top edge of the view is 30 degrees above the axis (vfov 60).
        let distance = scene.camera.eye.distance(scene.camera.target);
        let top = project(scene.camera.target + Vec3::Y * distance * 30f32.to_radians().tan());
        assert!((top.y - 1.0).abs() < 1e-4, "{top:?}");
    }
}
