//! The scene as the Whitted shader reads it: its parameters and lights, laid out like the WGSL
//! structs of `shaders/whitted.wgsl` (the layout test compares them with naga's). The objects,
//! materials and camera are illum-rtcore's records.

use std::f32::consts::PI;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use illum_gpu::shader::Def;
use illum_rtcore::{CameraRecord, MaterialRecord};
use illum_scene::{Feature, Scene, Shape};

/// What of the scene model the Whitted ray tracer implements: everything but a sun of finite
/// size (its shadow rays are hard).
pub fn implements(feature: Feature) -> bool {
    match feature {
        Feature::BoxShape
        | Feature::QuadShape
        | Feature::SphereShape
        | Feature::Lambertian
        | Feature::Checker
        | Feature::Dielectric
        | Feature::Mirror
        | Feature::AreaLight
        | Feature::DeltaDirectionalLight
        | Feature::MeshShape
        | Feature::SmoothShading
        | Feature::Environment => true,
        Feature::SunDisc => false,
    }
}

/// What a scene's Whitted pipeline is specialised for ("model only what a scene requires"),
/// derived from [`Scene::features`] and the scene's depth; also its pipeline's cache key
/// together with the generated traversal and materials.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Specialisation {
    /// Entries of the ray stack: the depth, at least 1 (see the shader's header).
    pub stack: u32,
    pub checker: bool,
    pub mirrors: bool,
    pub dielectrics: bool,
    /// An emitting surface a ray can see.
    pub emitters: bool,
    pub directional_light: bool,
    /// A point light at the centre of an emitting quad.
    pub point_lights: bool,
    /// A mesh shaded with its vertex normals (illum-rtcore's mesh_shading.wgsl).
    pub smooth_shading: bool,
}

impl Specialisation {
    pub fn new(scene: &Scene) -> Self {
        let features = scene.features();
        Specialisation {
            stack: scene.whitted.depth.max(1),
            checker: features.contains(Feature::Checker),
            mirrors: features.contains(Feature::Mirror),
            dielectrics: features.contains(Feature::Dielectric),
            emitters: features.contains(Feature::AreaLight),
            directional_light: scene.directional_light.is_some(),
            point_lights: lights(scene).iter().any(|l| l.kind == LIGHT_POINT),
            smooth_shading: features.contains(Feature::SmoothShading),
        }
    }

    /// The naga_oil shader defs: the one place where their names are written.
    pub fn shader_defs(&self) -> Vec<(&'static str, Def)> {
        let flags = [
            ("CHECKER", self.checker),
            ("MIRRORS", self.mirrors),
            ("DIELECTRICS", self.dielectrics),
            ("EMITTERS", self.emitters),
            ("DIRECTIONAL_LIGHT", self.directional_light),
            ("POINT_LIGHTS", self.point_lights),
            ("SMOOTH_SHADING", self.smooth_shading),
        ];
        let mut defs = vec![("WHITTED_STACK", Def::UInt(self.stack))];
        defs.extend(illum_gpu::shader::flag_defs(&flags));
        defs
    }
}

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
