//! Furnaces for the Whitted scene's materials on the GPU: a non-absorbing glass ball, a mirror of
//! reflectance 1 and a white Lambertian ball alone in a uniform sky are invisible. Every path
//! then carries throughput 1 to the sky, so every pixel equals the sky's radiance within f32
//! rounding at any spp, with zero variance (up to the rounding of the sums).

use illum_scene::Scene;

use crate::common;

fn lone_ball(material: &str, bounces: u32) -> Scene {
    let text = format!(
        "[camera]\neye = [7.5, 2.3, -4.2]\ntarget = [4.2, 2.3, -4.2]\nup = [0.0, 1.0, 0.0]\nvfov = 60.0\n\
         width = 32\nheight = 24\n[environment]\nradiance = [0.3, 0.5, 0.9]\n[materials.ball]\n{material}\n\
         [[objects]]\nmaterial = \"ball\"\nsphere = {{ center = [4.2, 2.6, -4.2], radius = 1.0 }}\n\
         [pathtrace]\nspp = 16\nbounces = {bounces}\n"
    );
    Scene::from_toml_str(&text, "furnace.toml").unwrap_or_else(|e| panic!("{e}"))
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
        let tracer = common::render(&lone_ball(material, bounces));
        let (mean, variance) = (tracer.accumulator().mean_image(), tracer.accumulator().variance_image());
        assert_eq!(tracer.accumulator().dropped_samples(), 0, "{material}");
        for (p, v) in mean.pixels.iter().zip(&variance.pixels) {
            for c in 0..3 {
                assert!((p[c] - sky[c]).abs() <= 1e-6 * sky[c], "{material}: pixel {p:?}, sky {sky:?}");
                // Zero up to rounding: the variance comes from sum(x^2) - n mean^2 of f32 sums,
                // which cancels to about 1e-7 mean^2 when every sample is the same.
                assert!(v[c] <= 1e-7 * sky[c] * sky[c], "{material}: variance {v:?}");
            }
        }
    }
}
