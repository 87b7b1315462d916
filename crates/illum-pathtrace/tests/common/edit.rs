//! Scene edits for the extremes tests: scaling and moving a whole scene, camera included.

use glam::Vec3;
use illum_scene::{MaterialKind, Scene, Shape};

/// The scene with every position x replaced by `scale * x + offset` (camera included) and every
/// length scaled by `scale`. Radiance is left alone, so a correct renderer draws the same image.
///
/// A box's world point is `R (local - pivot) + pivot + translate`; scaling local, pivot and
/// translate by s scales it by s, and adding the offset to translate moves it.
pub fn transformed(scene: &Scene, scale: f32, offset: Vec3) -> Scene {
    let mut out = scene.clone();
    let point = |p: Vec3| scale * p + offset;
    out.camera.eye = point(scene.camera.eye);
    out.camera.target = point(scene.camera.target);
    for object in &mut out.objects {
        match &mut object.shape {
            Shape::Box(b) => {
                b.min *= scale;
                b.max *= scale;
                b.pivot *= scale;
                b.translate = scale * b.translate + offset;
            }
            Shape::Quad(q) => {
                q.corner = point(q.corner);
                q.edge_u *= scale;
                q.edge_v *= scale;
            }
            Shape::Sphere(s) => {
                s.center = point(s.center);
                s.radius *= scale;
            }
            Shape::Mesh(m) => {
                let m = std::sync::Arc::make_mut(m);
                m.positions.iter_mut().for_each(|p| *p = point(*p));
                m.placement.translate = point(m.placement.translate);
                m.placement.scale *= scale;
            }
        }
    }
    out
}

/// Sets the albedo of every material that has one (emitters keep theirs).
pub fn set_albedo(scene: &mut Scene, albedo: f32) {
    for material in &mut scene.materials {
        if !material.is_emitter() {
            material.kind = MaterialKind::Lambertian { albedo: Vec3::splat(albedo) };
        }
    }
}
