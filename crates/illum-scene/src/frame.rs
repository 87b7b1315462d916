//! The frame the renderers compute in: the scene's positions measured from an origin near the
//! camera, in f64, before they are rounded to the f32 every renderer uses.
//!
//! f32 spaces its values about |x| 2^-24 apart, so a renderer working in the file's coordinates
//! loses precision in proportion to the scene's distance from the world origin, not to its own
//! size: a scene written 1e5 units away has its hit points, refracted rays and shadow edges
//! rounded to 0.008 units, which moves the checkerboard seen through a glass sphere of radius 1.
//! Scenes far from the origin are ordinary (a model exported at its site, kilometre or geographic
//! coordinates), so the file is read in f64 (`file.rs`) and, when the world origin lies outside
//! the scene's neighbourhood, every position is measured from the camera's eye in f64 and only
//! then rounded: the renderers see numbers no larger than the scene itself wherever it sits, and
//! the same file moved by any such offset gives the same f32 scene (to f64 rounding, about 1e-16
//! of the offset), hence the same image. Real-time engines rebase to the camera for this reason.
//!
//! The rule ([`frame_origin`]): with `size` the largest side of the bounding box of the eye and
//! every object, the origin stays at the world origin when every coordinate of the eye is within
//! `size` of it, and is the eye otherwise. In the first case every coordinate is at most
//! `2 size` in magnitude, within a factor 2 (one bit) of the eye frame's `size`, and a scene near
//! the origin keeps the coordinates its file gives, which closed forms, tests and checkpoints
//! name. Directions, lengths and a checkerboard's tiles (counted from its quad's corner) do not
//! depend on the origin.
//!
//! The origin is a function of the file alone, so loading a file twice gives the same f32 scene
//! and the same content hash: a checkpoint resumes against it bit for bit. The hash is of the f32
//! numbers the renderers get, not of the origin, since those alone make the image.

use glam::{DMat3, DVec3};

use crate::file::{RawBox, RawObject, RawScene};

/// The origin of the frame the scene's f32 positions are measured from, in the file's (world)
/// coordinates: zero, or the eye (see the module's rule). Non-finite numbers are left to
/// validation, which refuses them; they do not count toward the bounding box. `meshes`: the
/// world bounds of the mesh objects, whose vertices only their files give.
pub(crate) fn frame_origin(raw: &RawScene, meshes: &[(DVec3, DVec3)]) -> DVec3 {
    let eye = DVec3::from_array(raw.camera.eye.0);
    if !eye.is_finite() {
        return DVec3::ZERO;
    }
    let (mut lo, mut hi) = (eye, eye);
    for (a, b) in raw.objects.iter().filter_map(object_bounds).chain(meshes.iter().copied()) {
        if a.is_finite() && b.is_finite() {
            lo = lo.min(a);
            hi = hi.max(b);
        }
    }
    let size = (hi - lo).max_element();
    if eye.abs().max_element() <= size { DVec3::ZERO } else { eye }
}

/// The world-space bounding box of an object as the file gives it, if it has exactly one shape.
fn object_bounds(o: &RawObject) -> Option<(DVec3, DVec3)> {
    let v = |a: [f64; 3]| DVec3::from_array(a);
    match (&o.box_, &o.quad, &o.sphere) {
        _ if o.mesh.is_some() => None,
        (Some(b), None, None) => {
            let corners = box_world_corners(b)?;
            Some(corners.iter().fold((corners[0], corners[0]), |(lo, hi), &c| (lo.min(c), hi.max(c))))
        }
        (None, Some(q), None) => {
            let (c, u, w) = (v(q.corner.0), v(q.edge_u.0), v(q.edge_v.0));
            let corners = [c, c + u, c + w, c + u + w];
            Some(corners.iter().fold((c, c), |(lo, hi), &p| (lo.min(p), hi.max(p))))
        }
        (None, None, Some(s)) => {
            let (c, r) = (v(s.center.0), DVec3::splat(s.radius.0.abs()));
            Some((c - r, c + r))
        }
        _ => None,
    }
}

/// A box's local bounds as the file gives them (centre +- half-extent, or min and max).
pub(crate) fn box_local_bounds(b: &RawBox) -> Option<(DVec3, DVec3)> {
    let v = |a: [f64; 3]| DVec3::from_array(a);
    match (b.center, b.half_extent, b.min, b.max) {
        (Some(c), Some(h), None, None) => Some((v(c.0) - v(h.0), v(c.0) + v(h.0))),
        (None, None, Some(lo), Some(hi)) => Some((v(lo.0), v(hi.0))),
        _ => None,
    }
}

/// `world = rotation * local + offset` for a box, in f64 (see [`crate::BoxShape`]).
pub(crate) fn box_local_to_world(b: &RawBox) -> (DMat3, DVec3) {
    let rotation = DMat3::from_rotation_y(b.rotate_y.0.to_radians());
    let pivot = DVec3::from_array(b.pivot.0);
    (rotation, pivot + DVec3::from_array(b.translate.0) - rotation * pivot)
}

fn box_world_corners(b: &RawBox) -> Option<[DVec3; 8]> {
    let (lo, hi) = box_local_bounds(b)?;
    let (rotation, offset) = box_local_to_world(b);
    Some(std::array::from_fn(|i| {
        let pick = |bit: usize, l: f64, h: f64| if i >> bit & 1 == 1 { h } else { l };
        rotation * DVec3::new(pick(0, lo.x, hi.x), pick(1, lo.y, hi.y), pick(2, lo.z, hi.z)) + offset
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame_origin_of(raw: &RawScene) -> DVec3 {
        frame_origin(raw, &[])
    }

    fn raw(text: &str) -> RawScene {
        toml::from_str(text).unwrap()
    }

    const CAMERA: &str = "[camera]\nup = [0, 1, 0]\nvfov = 45\nwidth = 8\nheight = 8\n";

    fn scene(eye: [f64; 3], objects: &str) -> RawScene {
        raw(&format!(
            "{CAMERA}eye = [{}, {}, {}]\ntarget = [0, 0, 1e9]\n[materials.m]\nalbedo = [0.5, 0.5, 0.5]\n{objects}",
            eye[0], eye[1], eye[2]
        ))
    }

    #[test]
    fn a_scene_around_the_world_origin_keeps_it() {
        // The Whitted scene's numbers: the floor spans 30 units, the eye is 7.5 from the origin.
        let objects = "[[objects]]\nmaterial = \"m\"\nquad = { corner = [-23, 0, -7.5], edge_u = [0, 0, 15], \
                       edge_v = [30, 0, 0] }\n[[objects]]\nmaterial = \"m\"\nsphere = { center = [4.2, 2.6, -4.2], radius = 1 }\n";
        assert_eq!(frame_origin_of(&scene([7.5, 2.3, -4.2], objects)), DVec3::ZERO);
    }

    #[test]
    fn a_scene_farther_than_its_size_from_the_origin_is_measured_from_the_eye() {
        let objects = "[[objects]]\nmaterial = \"m\"\nsphere = { center = [1e5, 2.6, -4.2], radius = 1 }\n";
        let eye = [100_003.5, 2.3, -4.2];
        assert_eq!(frame_origin_of(&scene(eye, objects)), DVec3::from_array(eye));
        // A rotated box's corners count: a block turned about a far pivot lies near it.
        let block = "[[objects]]\nmaterial = \"m\"\nbox = { min = [0, 0, 0], max = [1, 1, 1], rotate_y = 90, \
                     pivot = [50, 0, 0], translate = [0, 0, 0] }\n";
        // R_y(90) takes local (x, z) around the pivot to (50 + z, 50 - x): the box spans x and z
        // in [50, 51] x [49, 50]. An eye at z = 51.5 beside it spans 2.5 units with it, 51.5 from
        // the origin; an eye at x = 1 spans 50 units with it, and the origin is within that.
        let eye = [50.5, 0.5, 51.5];
        assert_eq!(frame_origin_of(&scene(eye, block)), DVec3::from_array(eye));
        let near = frame_origin_of(&scene([1.0, 0.5, 0.5], block));
        assert_eq!(near, DVec3::ZERO, "the eye within the box's 50-unit span of the origin");
    }
}
