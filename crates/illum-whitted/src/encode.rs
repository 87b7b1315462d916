//! The scene as the Whitted shader reads it: records laid out like the WGSL structs of
//! `shaders/whitted/whitted.wgsl` (the layout test compares them with naga's).

use std::f32::consts::PI;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use illum_scene::{Feature, MaterialKind, Scene, Shape};

/// The one feature of the scene model the Whitted ray tracer refuses: a sun of finite size
/// (its shadow rays are hard).
pub const FEATURES_BUT: Feature = Feature::SunDisc;

pub(crate) const MAT_LAMBERTIAN: u32 = 0;
pub(crate) const MAT_CHECKER: u32 = 1;
pub(crate) const MAT_DIELECTRIC: u32 = 2;
pub(crate) const MAT_MIRROR: u32 = 3;
pub(crate) const MAT_EMITTER: u32 = 4;
pub(crate) const LIGHT_DIRECTIONAL: u32 = 0;
pub(crate) const LIGHT_POINT: u32 = 1;

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WhittedParams {
    pub eye: [f32; 4],
    pub right: [f32; 4],
    pub up: [f32; 4],
    pub forward: [f32; 4],
    pub background: [f32; 4],
    pub ambient: [f32; 4],
    pub mirror_specular: [f32; 4],
    pub shading: [f32; 4],
    pub sizes: [u32; 4],
    pub counts: [u32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WhittedMaterial {
    pub kind: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
    pub a: [f32; 4],
    pub b: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WhittedLight {
    pub kind: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
    pub a: [f32; 4],
    pub normal: [f32; 4],
    pub power: [f32; 4],
}

fn v4(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

pub(crate) fn materials(scene: &Scene) -> Vec<WhittedMaterial> {
    scene
        .materials
        .iter()
        .map(|m| {
            let (kind, a, b) = match m.kind {
                MaterialKind::Lambertian { albedo } => (MAT_LAMBERTIAN, v4(albedo, 0.0), [0.0; 4]),
                MaterialKind::Checker(c) => (MAT_CHECKER, v4(c.even, c.tile), v4(c.odd, 0.0)),
                MaterialKind::Dielectric { ior } => (MAT_DIELECTRIC, [0.0, 0.0, 0.0, ior], [0.0; 4]),
                MaterialKind::Mirror { reflectance } => (MAT_MIRROR, v4(reflectance, 0.0), [0.0; 4]),
                MaterialKind::Emitter { radiance } => (MAT_EMITTER, v4(radiance, 0.0), [0.0; 4]),
            };
            WhittedMaterial { kind, pad0: 0, pad1: 0, pad2: 0, a, b }
        })
        .collect()
}

/// The directional light, and a point light at the centre of every emitting quad.
pub(crate) fn lights(scene: &Scene) -> Vec<WhittedLight> {
    let mut lights = Vec::new();
    if let Some(sun) = &scene.directional_light {
        lights.push(WhittedLight {
            kind: LIGHT_DIRECTIONAL,
            pad0: 0,
            pad1: 0,
            pad2: 0,
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
            pad0: 0,
            pad1: 0,
            pad2: 0,
            a: v4(centre, 1.0),
            normal: v4(quad.normal(), 0.0),
            power: v4(scene.material_of(object).emission() * quad.area(), 0.0),
        });
    }
    lights
}

pub(crate) fn params(scene: &Scene, first_emitter: u32, num_lights: u32, output: u32) -> WhittedParams {
    let b = scene.camera.basis();
    let mirror = scene.shading.mirror;
    WhittedParams {
        eye: v4(scene.camera.eye, b.tan_half_fov),
        right: v4(b.right, b.aspect),
        up: v4(b.up, 0.0),
        forward: v4(b.forward, 0.0),
        background: v4(scene.environment.map_or(Vec3::ZERO, |e| e.radiance), 0.0),
        ambient: v4(scene.shading.ambient, 0.0),
        mirror_specular: v4(mirror.specular, mirror.shininess),
        shading: [mirror.weight, scene.shading.dielectric.shininess, 0.0, 0.0],
        sizes: [scene.camera.width, scene.camera.height, first_emitter, 0],
        counts: [num_lights, scene.whitted.depth, scene.whitted.aa, output],
    }
}
