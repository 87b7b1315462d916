//! The pinhole camera as both compute ray tracers read it (`struct Camera` in
//! `shaders/camera.wgsl`): the scene camera's basis, from which `camera_ray` builds a primary ray
//! and `camera_film_point` finds the pixel a point is seen in.

use bytemuck::{Pod, Zeroable};
use illum_scene::Camera;

/// Mirrors `struct Camera` in camera.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct CameraRecord {
    pub eye: [f32; 3],
    pub tan_half_fov: f32,
    pub right: [f32; 3],
    pub aspect: f32,
    pub up: [f32; 3],
    pub up_padding: f32,
    pub forward: [f32; 3],
    pub forward_padding: f32,
}

impl CameraRecord {
    pub fn new(camera: &Camera) -> Self {
        let basis = camera.basis();
        Self {
            eye: camera.eye.to_array(),
            tan_half_fov: basis.tan_half_fov,
            right: basis.right.to_array(),
            aspect: basis.aspect,
            up: basis.up.to_array(),
            up_padding: 0.0,
            forward: basis.forward.to_array(),
            forward_padding: 0.0,
        }
    }
}
