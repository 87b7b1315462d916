//! Meshes in the GPU path tracer (BVH, watertight triangles) against the f64 oracle's
//! brute-force triangles, by oracle_agreement's per-pixel Z-test: the Cornell box with a flat
//! white icosphere, and with a glass one, direct light and two bounces. And the caustic's
//! estimators, which follow spheres only, are off for a scene with a mesh, with the reason.

use illum_pathtrace::Estimators;
use illum_scene::{Bounces, Overrides, Scene};

use crate::common;
use crate::oracle_agreement::compare_scene_with;

/// The Cornell box with an icosphere of 80 triangles (subdivision 1), radius 80, on the short
/// block, of `material`, at 24 x 24 and 4096 spp.
fn cornell_with_icosphere(material: &str, bounces: u32) -> Scene {
    let path = common::workspace_path("scenes/cornell.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let text = format!(
        "{text}\n[materials.glass]\ndielectric = {{ ior = 1.5 }}\n[[objects]]\nname = \"icosphere\"\nmaterial = \"{material}\"\n\
         mesh = {{ file = \"models/icosphere-1.obj\", translate = [157.95, 245.0, 168.95], scale = 80.0 }}\n"
    );
    let mut scene =
        Scene::from_toml_str(&text, &path.display().to_string()).unwrap_or_else(|e| panic!("{e}"));
    let overrides = Overrides {
        width: Some(24),
        height: Some(24),
        spp: Some(4096),
        bounces: Some(Bounces::Fixed(bounces)),
        seed: Some(17),
        ..Default::default()
    };
    scene.apply_overrides(&overrides, "test").unwrap();
    scene
}

#[test]
fn a_diffuse_mesh_agrees_with_the_oracle() {
    for bounces in [0, 2] {
        compare_scene_with(
            &format!("cornell + white icosphere, bounces {bounces}"),
            &cornell_with_icosphere("white", bounces),
            1024,
        );
    }
}

#[test]
fn a_glass_mesh_agrees_with_the_oracle() {
    compare_scene_with("cornell + glass icosphere, bounces 2", &cornell_with_icosphere("glass", 2), 1024);
}

#[test]
fn the_caustic_estimators_are_off_with_a_mesh() {
    let mut scene = cornell_with_icosphere("glass", 2);
    scene.pathtrace.caustics = true;
    scene.directional_light = Some(illum_scene::DirectionalLight {
        direction: glam::Vec3::new(0.1, -1.0, 0.2),
        irradiance: glam::Vec3::ONE,
        angular_radius_deg: 0.0,
    });
    assert!(!Estimators::of(&scene).caustics());
    assert!(Estimators::mesh_stops_caustics(&scene).is_some_and(|why| why.contains("meshes")));
}
