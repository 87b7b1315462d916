//! Meshes in the GPU path tracer (BVH, watertight triangles) against the f64 oracle's
//! brute-force triangles, by oracle_agreement's per-pixel Z-test: the Cornell box with a flat
//! white icosphere, a glass one and a mirror, direct light and two bounces, under the BVH (80
//! triangles) and as literals (20), flat and smoothly shaded; no light leaks through a smooth
//! mesh. And the caustic's estimators, which follow spheres only, are off for a scene with a
//! mesh, with the reason.

use illum_pathtrace::Estimators;
use illum_scene::{Bounces, Overrides, Scene};

use crate::common;
use crate::oracle_agreement::compare_scene_with;

/// The Cornell box with an icosphere of 80 triangles (subdivision 1), radius 80, on the short
/// block, of `material`, at 24 x 24 and 4096 spp.
fn cornell_with_icosphere(material: &str, bounces: u32) -> Scene {
    cornell_with_icosphere_of(material, bounces, 1, false)
}

/// As [`cornell_with_icosphere`], of subdivision `k`, shaded with its vertex normals when
/// `smooth`.
fn cornell_with_icosphere_of(material: &str, bounces: u32, k: u32, smooth: bool) -> Scene {
    let path = common::workspace_path("scenes/cornell.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let text = format!(
        "{text}\n[materials.glass]\ndielectric = {{ ior = 1.5 }}\n[materials.mirror]\nmirror = {{ reflectance = [0.9, 0.9, 0.9] }}\n[[objects]]\nname = \"icosphere\"\nmaterial = \"{material}\"\n\
         mesh = {{ file = \"models/icosphere-{k}.obj\", translate = [157.95, 245.0, 168.95], scale = 80.0 }}\n"
    );
    let file = format!("models/icosphere-{k}.obj");
    let obj = illum_scene::testing::obj::icosphere_obj(k, smooth);
    let mut scene =
        illum_scene::testing::obj::scene_with_files(&text, &path.display().to_string(), &[(&file, &obj)])
            .unwrap_or_else(|e| panic!("{e}"));
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

/// 20 triangles: literals in the generated traversal, not a BVH (mesh_traversal.rs).
#[test]
fn a_mesh_of_literal_triangles_agrees_with_the_oracle() {
    let scene = cornell_with_icosphere_of("glass", 2, 0, false);
    assert!(illum_rtcore::Geometry::new(&scene).mesh_bvh().is_none());
    compare_scene_with("cornell + glass icosahedron (literals), bounces 2", &scene, 1024);
}

#[test]
fn a_glass_mesh_agrees_with_the_oracle() {
    compare_scene_with("cornell + glass icosphere, bounces 2", &cornell_with_icosphere("glass", 2), 1024);
}

/// A mirror of reflectance 0.9 (crates/illum-oracle/tests/meshes.rs's): an icosahedron, whose
/// 20 literal triangles keep the oracle's brute force short (the BVH's walk is the white and
/// glass meshes' to test; a mirror differs in its shading only). The oracle takes 2048 samples,
/// for the whole-image test's power against a 2% bias: there its z is 4.98 to 6.61 over the
/// channels, at 1024 samples 4.10 to 5.06, too near the 4 required (measured with these seeds;
/// the 80-triangle icosphere at 1024 fell short, 3.69).
#[test]
fn a_mirror_mesh_agrees_with_the_oracle() {
    let scene = cornell_with_icosphere_of("mirror", 2, 0, false);
    assert!(illum_rtcore::Geometry::new(&scene).mesh_bvh().is_none());
    compare_scene_with("cornell + mirror icosahedron, bounces 2", &scene, 2048);
}

/// A smooth white icosphere under the BVH (next-event estimation and bounces about the shading
/// normal) and a smooth glass icosahedron as literals (refraction about it).
#[test]
fn smooth_meshes_agree_with_the_oracle() {
    for (material, k) in [("white", 1), ("glass", 0)] {
        let scene = cornell_with_icosphere_of(material, 2, k, true);
        assert_eq!(illum_rtcore::Geometry::new(&scene).mesh_bvh().is_some(), k > 0);
        compare_scene_with(&format!("cornell + smooth {material} icosphere-{k}, bounces 2"), &scene, 1024);
    }
}

/// Lit from behind, a square whose shading normals face the sun is black; lit from the front
/// (the control) it is not.
#[test]
fn no_light_leaks_through_a_smooth_mesh() {
    for behind in [true, false] {
        let scene = illum_scene::testing::obj::tilted_square(behind);
        let tracer = common::render(&scene);
        let image = tracer.accumulator().mean_image();
        let centre = image.pixels[16 * 32 + 16];
        println!("lit from behind: {behind}: centre {centre:?}");
        if behind {
            assert!(image.pixels.iter().all(|p| *p == [0.0; 3]), "light leaked: centre {centre:?}");
        } else {
            assert!(centre[0] > 0.1, "the control is not lit: {centre:?}");
        }
    }
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

/// The Cornell box with its 1280-triangle icosphere (scenes/cornell-mesh.toml) at 48 x 48 and
/// 512 spp, two bounces, transformed (every position x to scale x + offset, in f32 as
/// common::edit does, mesh vertices included), against the untransformed scene under another
/// seed: at least 97% of pixels pass the per-pixel Z-test at level 0.01 and the image means
/// agree within 4 standard errors (extremes.rs's criterion for the analytic box).
fn check_transformed(scale: f32, offset: f32) {
    let overrides = Overrides {
        width: Some(48),
        height: Some(48),
        spp: Some(512),
        bounces: Some(Bounces::Fixed(2)),
        ..Default::default()
    };
    let render = |scene: &Scene, seed: u32| {
        let mut scene = scene.clone();
        scene.pathtrace.seed = seed;
        let tracer = common::render(&scene);
        let acc = tracer.accumulator();
        assert_eq!(acc.dropped_samples(), 0, "scale {scale:e}, offset {offset:e}: NaN/Inf samples");
        (acc.mean_image(), acc.variance_image())
    };
    let base = common::scene("cornell-mesh", overrides);
    let moved = common::edit::transformed(&base, scale, glam::Vec3::splat(offset));
    let (a, va) = render(&base, 1);
    let (b, vb) = render(&moved, 2);
    let pass = illum_image::z_test_pass_fraction(&a, &va, &b, &vb, 0.01).expect("same size");
    let mean = |img: &illum_image::RgbImage32, c: usize| {
        img.pixels.iter().map(|p| f64::from(p[c])).sum::<f64>() / img.pixels.len() as f64
    };
    let n2 = (a.pixels.len() * a.pixels.len()) as f64;
    let worst = (0..3)
        .map(|c| {
            (mean(&a, c) - mean(&b, c)).abs()
                / ((mean(&va, c) + mean(&vb, c)) * a.pixels.len() as f64 / n2).sqrt()
        })
        .fold(0.0, f64::max);
    println!(
        "cornell-mesh, scale {scale:e}, offset {offset:e}: {pass:.4} of pixels pass; worst |z| of the means {worst:.2}"
    );
    assert!(pass >= 0.97, "scale {scale:e}, offset {offset:e}: only {pass:.4} of pixels agree");
    assert!(
        worst < 4.0,
        "scale {scale:e}, offset {offset:e}: the image mean differs by {worst:.2} standard errors"
    );
}

#[test]
fn a_mesh_scaled_by_1e_minus_4_and_1e4_draws_the_same_image() {
    check_transformed(1e-4, 0.0);
    check_transformed(1e4, 0.0);
}

#[test]
fn a_mesh_moved_1e4_from_the_origin_draws_the_same_image() {
    check_transformed(1.0, 1e4);
}
