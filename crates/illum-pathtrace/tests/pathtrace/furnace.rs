//! Furnaces for the Whitted scene's materials on the GPU: a non-absorbing glass ball, a mirror of
//! reflectance 1 and a white Lambertian ball alone in a uniform sky are invisible, and so are
//! glass, mirror and white convex meshes. Every path then carries throughput 1 to the sky, so
//! every pixel equals the sky's radiance within f32 rounding at any spp, with zero variance (up
//! to the rounding of the sums); a grey mesh of albedo a with one bounce returns a x the sky.

use illum_scene::Scene;

use crate::common;

/// The ball of unit radius at (4.2, 2.6, -4.2), seen from 3.3 away, as a sphere or as `mesh`
/// (OBJ text of a closed mesh about the origin, placed there).
fn lone_ball(material: &str, bounces: u32) -> Scene {
    Scene::from_toml_str(
        &lone_text(material, bounces, "sphere = { center = [4.2, 2.6, -4.2], radius = 1.0 }"),
        "furnace.toml",
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

fn lone_mesh(material: &str, bounces: u32, mesh: &str) -> Scene {
    let text = lone_text(material, bounces, "mesh = { file = \"ball.obj\", translate = [4.2, 2.6, -4.2] }");
    illum_scene::testing::obj::scene_with_files(&text, "furnace.toml", &[("ball.obj", mesh)])
        .unwrap_or_else(|e| panic!("{e}"))
}

fn lone_text(material: &str, bounces: u32, shape: &str) -> String {
    format!(
        "[camera]\neye = [7.5, 2.3, -4.2]\ntarget = [4.2, 2.3, -4.2]\nup = [0.0, 1.0, 0.0]\nvfov = 60.0\n\
         width = 32\nheight = 24\n[environment]\nradiance = [0.3, 0.5, 0.9]\n[materials.ball]\n{material}\n\
         [[objects]]\nmaterial = \"ball\"\n{shape}\n\
         [pathtrace]\nspp = 16\nbounces = {bounces}\n"
    )
}

/// Every pixel of `scene`'s image is `sky` (within f32 rounding), with zero variance.
fn assert_invisible(label: &str, scene: &Scene, sky: [f32; 3]) {
    let tracer = common::render(scene);
    let (mean, variance) = (tracer.accumulator().mean_image(), tracer.accumulator().variance_image());
    assert_eq!(tracer.accumulator().dropped_samples(), 0, "{label}");
    for (p, v) in mean.pixels.iter().zip(&variance.pixels) {
        for c in 0..3 {
            assert!((p[c] - sky[c]).abs() <= 1e-6 * sky[c], "{label}: pixel {p:?}, sky {sky:?}");
            // Zero up to rounding: the variance comes from sum(x^2) - n mean^2 of f32 sums,
            // which cancels to about 1e-7 mean^2 when every sample is the same.
            assert!(v[c] <= 1e-7 * sky[c] * sky[c], "{label}: variance {v:?}");
        }
    }
}

#[test]
fn glass_mirror_and_white_balls_are_invisible_in_a_uniform_sky() {
    let sky = [0.3f32, 0.5, 0.9];
    for (material, bounces) in [
        ("dielectric = { ior = 1.5 }", 256),
        ("dielectric = { ior = 4.0 }", 256),
        ("mirror = { reflectance = [1.0, 1.0, 1.0] }", 1),
        ("albedo = [1.0, 1.0, 1.0]", 1),
    ] {
        assert_invisible(material, &lone_ball(material, bounces), sky);
    }
}

/// The same furnace with the ball a closed convex mesh, an icosphere of 80 flat triangles under
/// the BVH: a non-absorbing glass mesh is invisible, and since a ray that leaves a face of a
/// convex mesh outward meets no other, so are a mirror of reflectance 1 and a white Lambertian
/// mesh with one bounce. A grey one (albedo 0.5) with one bounce returns albedo x sky exactly
/// wherever every sample of a pixel meets it (the centre of the image), and between that and
/// the sky at its edges.
#[test]
fn glass_mirror_and_white_meshes_are_invisible_in_a_uniform_sky() {
    let sky = [0.3f32, 0.5, 0.9];
    let icosphere = illum_scene::testing::obj::icosphere_obj(1, false);
    for (material, bounces) in [
        ("dielectric = { ior = 1.5 }", 256),
        ("mirror = { reflectance = [1.0, 1.0, 1.0] }", 1),
        ("albedo = [1.0, 1.0, 1.0]", 1),
    ] {
        let scene = lone_mesh(material, bounces, &icosphere);
        assert!(illum_rtcore::Geometry::new(&scene).mesh_bvh().is_some());
        assert_invisible(&format!("mesh, {material}"), &scene, sky);
    }

    let tracer = common::render(&lone_mesh("albedo = [0.5, 0.5, 0.5]", 1, &icosphere));
    let mean = tracer.accumulator().mean_image();
    let grey = sky.map(|c| 0.5 * c);
    let close = |p: [f32; 3], q: [f32; 3]| (0..3).all(|c| (p[c] - q[c]).abs() <= 1e-6 * q[c]);
    let (centre, corner) = (mean.pixels[12 * 32 + 16], mean.pixels[0]);
    assert!(close(centre, grey), "grey mesh: centre {centre:?}, expected {grey:?}");
    assert!(close(corner, sky), "grey mesh: corner {corner:?}, expected the sky {sky:?}");
    let count = |q| mean.pixels.iter().filter(|p| close(**p, q)).count();
    println!(
        "grey mesh: {} pixels are grey x sky, {} the sky, of {}",
        count(grey),
        count(sky),
        mean.pixels.len()
    );
    for p in &mean.pixels {
        for c in 0..3 {
            assert!(
                grey[c] * (1.0 - 1e-6) <= p[c] && p[c] <= sky[c] * (1.0 + 1e-6),
                "grey mesh: pixel {p:?} outside [{grey:?}, {sky:?}]"
            );
        }
    }
}
