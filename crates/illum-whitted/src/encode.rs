//! The scene as the Whitted shader reads it: its parameters and lights, laid out like the WGSL
//! structs of `shaders/whitted.wgsl` (the layout test compares them with naga's). The objects,
//! materials and camera are illum-rtcore's records.

use std::f32::consts::PI;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use illum_rtcore::{CameraRecord, MaterialRecord};
use illum_scene::{Feature, Scene, Shape};

/// The one feature of the scene model the Whitted ray tracer refuses: a sun of finite size
/// (its shadow rays are hard).
pub const FEATURES_BUT: Feature = Feature::SunDisc;

pub(crate) const LIGHT_DIRECTIONAL: u32 = 0;
pub(crate) const LIGHT_POINT: u32 = 1;

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WhittedParams {
    pub camera: CameraRecord,
    pub background: [f32; 4],
    pub ambient: [f32; 4],
    pub mirror_specular: [f32; 4],
    pub shading: [f32; 4],
    pub sizes: [u32; 4],
    pub counts: [u32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WhittedLight {
    pub kind: u32,
    pub pad: [u32; 3],
    pub a: [f32; 4],
    pub normal: [f32; 4],
    pub power: [f32; 4],
}

fn v4(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

/// The scene's materials, with their radiance as it is (the Whitted tracer scales nothing).
pub(crate) fn materials(scene: &Scene) -> Vec<MaterialRecord> {
    scene.materials.iter().map(|m| MaterialRecord::new(&m.kind, 1.0)).collect()
}

/// The directional light, and a point light at the centre of every emitting quad.
pub(crate) fn lights(scene: &Scene) -> Vec<WhittedLight> {
    let mut lights = Vec::new();
    if let Some(sun) = &scene.directional_light {
        lights.push(WhittedLight {
            kind: LIGHT_DIRECTIONAL,
            pad: [0; 3],
            a: v4(sun.to_light(), 0.0),
            normal: [0.0; 4],
            power: v4(sun.irradiance / PI, 0.0),
        });
    }
    for (_, object, quad) in scene.emitters() {
        let Shape::Quad(_) = object.shape else { continue };
        let centre = quad.corner + 0.5 * (quad.edge_u + quad.edge_v);
        lights.push(WhittedLight {
            kind: LIGHT_POINT,
            pad: [0; 3],
            a: v4(centre, 1.0),
            normal: v4(quad.normal(), 0.0),
            power: v4(scene.material_of(object).emission() * quad.area(), 0.0),
        });
    }
    lights
}

pub(crate) fn params(scene: &Scene, first_emitter: u32, num_lights: u32, output: u32) -> WhittedParams {
    let mirror = scene.shading.mirror;
    WhittedParams {
        camera: CameraRecord::new(&scene.camera),
        background: v4(scene.environment.map_or(Vec3::ZERO, |e| e.radiance), 0.0),
        ambient: v4(scene.shading.ambient, 0.0),
        mirror_specular: v4(mirror.specular, mirror.shininess),
        shading: [mirror.weight, scene.shading.dielectric.shininess, 0.0, 0.0],
        sizes: [scene.camera.width, scene.camera.height, first_emitter, 0],
        counts: [num_lights, scene.whitted.depth, scene.whitted.aa, output],
    }
}
