//! The oracle's physical materials and lights (the Whitted scene's physics) against closed
//! forms: furnaces in which a glass ball, a perfect mirror and a white Lambertian ball are
//! invisible (every path carries throughput 1, so the estimate is exact at any spp), the floor
//! under a delta light and under a sun disc, a tile under the open sky, and a tinted mirror.

use glam::DVec3;
use illum_oracle::Oracle;
use illum_scene::{Bounces, Scene};

/// A small scene: the given camera, materials, objects and extra sections.
fn scene(camera: &str, rest: &str) -> Scene {
    let text = format!("[camera]\n{camera}\nwidth = 24\nheight = 16\n{rest}");
    Scene::from_toml_str(&text, "physical.toml").unwrap_or_else(|e| panic!("{e}\n{text}"))
}

const SIDE_VIEW: &str =
    "eye = [7.5, 2.3, -4.2]\ntarget = [4.2, 2.3, -4.2]\nup = [0.0, 1.0, 0.0]\nvfov = 60.0";
const TOP_VIEW: &str = "eye = [0.0, 5.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\nvfov = 40.0";
const SKY: [f64; 3] = [0.3, 0.5, 0.9];

fn sky() -> DVec3 {
    DVec3::from_array(SKY.map(|c| f64::from(c as f32)))
}

/// A ball of `material` before a uniform sky, nothing else.
fn lone_ball(material: &str) -> Scene {
    scene(
        SIDE_VIEW,
        &format!(
            "[environment]\nradiance = [0.3, 0.5, 0.9]\n[materials.ball]\n{material}\n\
             [[objects]]\nmaterial = \"ball\"\nsphere = {{ center = [4.2, 2.6, -4.2], radius = 1.0 }}\n"
        ),
    )
}

fn render(s: &Scene, bounces: Bounces, spp: u32) -> illum_oracle::OracleImage {
    Oracle::new(s).unwrap_or_else(|e| panic!("{e}")).with_bounces(bounces).render(spp, 7, 2)
}

fn assert_every_pixel(
    image: &illum_oracle::OracleImage,
    expected: impl Fn(usize) -> DVec3,
    tol: f64,
    what: &str,
) {
    for (i, p) in image.mean.iter().enumerate() {
        let (got, want) = (DVec3::from_array(*p), expected(i));
        assert!(
            (got - want).abs().max_element() <= tol * want.max_element().max(1e-3),
            "{what}: pixel {i} = {got}, expected {want}"
        );
    }
}

#[test]
fn furnaces_glass_mirror_and_white_ball_are_invisible_in_a_uniform_sky() {
    for (material, bounces) in [
        ("dielectric = { ior = 1.5 }", Bounces::Fixed(256)),
        ("dielectric = { ior = 4.0 }", Bounces::Fixed(256)),
        ("mirror = { reflectance = [1.0, 1.0, 1.0] }", Bounces::Fixed(1)),
        ("albedo = [1.0, 1.0, 1.0]", Bounces::Fixed(1)),
    ] {
        let image = render(&lone_ball(material), bounces, 8);
        assert_every_pixel(&image, |_| sky(), 1e-12, material);
        assert!(image.variance_of_mean.iter().all(|v| v.iter().all(|&c| c < 1e-24)), "{material}: not exact");
    }
}

#[test]
fn a_tinted_mirror_shows_its_reflectance_times_the_sky() {
    let image = render(&lone_ball("mirror = { reflectance = [0.5, 0.25, 1.0] }"), Bounces::Fixed(1), 2);
    let tint = DVec3::new(0.5, 0.25, 1.0);
    let (mut on_ball, mut off) = (0, 0);
    for p in &image.mean {
        let p = DVec3::from_array(*p);
        // Each sample sees either the tinted or the plain sky: a pixel on the ball's rim is a
        // mix a x tint x sky + (1 - a) x sky with one fraction a for every channel.
        let a = (sky().y - p.y) / (sky().y - tint.y * sky().y);
        let mix = a * tint * sky() + (1.0 - a) * sky();
        assert!((p - mix).abs().max_element() < 1e-12 && (-1e-12..=1.0 + 1e-12).contains(&a), "pixel {p}");
        on_ball += usize::from(a > 1.0 - 1e-12);
        off += usize::from(a < 1e-12);
    }
    assert!(on_ball > 20 && off > 100, "{on_ball} on the ball, {off} off it");
}

/// A white-ish Lambertian floor (albedo 0.6) seen from above, under `light` and `extra`.
fn floor(light: &str, extra: &str) -> Scene {
    scene(
        TOP_VIEW,
        &format!(
            "{light}\n{extra}\n[materials.floor]\nalbedo = [0.6, 0.6, 0.6]\n[[objects]]\nmaterial = \"floor\"\n\
             quad = {{ corner = [-50.0, 0.0, -50.0], edge_u = [0.0, 0.0, 100.0], edge_v = [100.0, 0.0, 0.0] }}\n"
        ),
    )
}

#[test]
fn the_floor_under_a_delta_light_is_albedo_times_irradiance_over_pi_times_cos() {
    // From (1, 2, 0.5) toward the origin, irradiance 3.
    let light = "[directional_light]\ndirection = [-1.0, -2.0, -0.5]\nirradiance = [3.0, 3.0, 3.0]";
    let cos = 2.0 / (1.0f64 + 4.0 + 0.25).sqrt();
    let expected = DVec3::splat(0.6f32 as f64 * 3.0 / std::f64::consts::PI * cos);
    let image = render(&floor(light, ""), Bounces::Fixed(0), 4);
    assert_every_pixel(&image, |_| expected, 1e-6, "delta light");
}

#[test]
fn the_floor_under_a_sun_disc_receives_the_same_irradiance_on_average() {
    // A cap of half-angle a fully above the horizon has projected solid angle
    // pi sin^2(a) cos(theta_centre): the same irradiance as the delta light, in expectation.
    let light = "[directional_light]\ndirection = [-1.0, -2.0, -0.5]\nirradiance = [3.0, 3.0, 3.0]\nangular_radius = 10.0";
    let cos = 2.0 / (1.0f64 + 4.0 + 0.25).sqrt();
    let expected = 0.6f32 as f64 * 3.0 / std::f64::consts::PI * cos;
    let image = render(&floor(light, ""), Bounces::Fixed(0), 64);
    let n = image.mean.len() as f64;
    let mean: f64 = image.mean.iter().map(|p| p[0]).sum::<f64>() / n;
    let std_error = (image.variance_of_mean.iter().map(|v| v[0]).sum::<f64>()).sqrt() / n;
    assert!(std_error > 0.0, "a finite sun is sampled: the estimate has variance");
    assert!(
        (mean - expected).abs() < 4.0 * std_error,
        "mean {mean}, expected {expected}, standard error {std_error}"
    );
}

#[test]
fn a_tile_under_the_open_sky_is_albedo_times_the_sky() {
    // No light but the sky; the floor sees the whole upper hemisphere, so one diffuse bounce
    // returns the sky exactly: albedo x sky, with no variance under cosine sampling.
    let image = render(&floor("", "[environment]\nradiance = [0.3, 0.5, 0.9]"), Bounces::Fixed(1), 4);
    assert_every_pixel(&image, |_| 0.6f32 as f64 * sky(), 1e-12, "open sky");
    // Without a bounce the sky cannot light it: direct light only, and there is none.
    let image = render(&floor("", "[environment]\nradiance = [0.3, 0.5, 0.9]"), Bounces::Fixed(0), 1);
    assert_every_pixel(&image, |_| DVec3::ZERO, 0.0, "no bounce");
}

#[test]
fn the_whitted_scene_renders_finite_with_nothing_dropped() {
    let s = illum_scene::testing::shipped_scene("whitted.toml", 32, 18);
    let image = render(&s, Bounces::Fixed(8), 4);
    assert!(image.mean.iter().flatten().all(|c| c.is_finite() && *c >= 0.0));
    assert_eq!(image.dropped, 0);
}
