//! The oracle's caustic estimator (light tracing from the directional light, `caustic.rs`)
//! against closed forms and against the camera path tracer it complements:
//! - a glass ball of index 1 is invisible, so the caustic plus next-event estimation must give
//!   the plain direct light of the floor inside the ball's shadow;
//! - a flat mirror of reflectance 1 sends a known irradiance onto the floor;
//! - with a sun disc the camera path tracer finds the caustic itself (slowly), so the image with
//!   the light tracer on must equal the image with it off (no path counted twice or missed);
//! - extremes stay finite.

use std::f64::consts::PI;

use glam::DVec3;
use illum_oracle::{Oracle, OracleImage};
use illum_scene::{Bounces, Scene};

const TOP_VIEW: &str = "eye = [0.0, 5.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\nvfov = 40.0";
const FLOOR: &str = "[materials.floor]\nalbedo = [0.6, 0.6, 0.6]\n[[objects]]\nmaterial = \"floor\"\n\
    quad = { corner = [-50.0, 0.0, -50.0], edge_u = [0.0, 0.0, 100.0], edge_v = [100.0, 0.0, 0.0] }\n";

fn scene(rest: &str) -> Scene {
    let text = format!("[camera]\n{TOP_VIEW}\nwidth = 24\nheight = 16\n{FLOOR}\n{rest}");
    Scene::from_toml_str(&text, "caustic.toml").unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// A ball of `material` at (3, 3, 0), radius 0.5, outside the camera's view, under a sun along
/// `direction` of irradiance 3: with direction (-1, -1, 0) its shadow is centred on the origin.
fn ball_scene(material: &str, sun: &str) -> Scene {
    scene(&format!(
        "[directional_light]\n{sun}\nirradiance = [3.0, 3.0, 3.0]\n[materials.ball]\n{material}\n\
         [[objects]]\nmaterial = \"ball\"\nsphere = {{ center = [3.0, 3.0, 0.0], radius = 0.5 }}\n"
    ))
}

fn render(s: &Scene, bounces: Bounces, caustics: bool, spp: u32, seed: u64) -> OracleImage {
    Oracle::new(s).unwrap_or_else(|e| panic!("{e}")).with_bounces(bounces).with_caustics(caustics).render(
        spp,
        seed,
        illum_oracle::default_threads(),
    )
}

/// The floor point pixel (x, y) of the 24 x 16 top view looks at through its centre.
fn floor_point(x: u32, y: u32) -> DVec3 {
    let t = 20f64.to_radians().tan();
    let sx = (2.0 * (f64::from(x) + 0.5) / 24.0 - 1.0) * 1.5 * t;
    let sy = (1.0 - 2.0 * (f64::from(y) + 0.5) / 16.0) * t;
    // right = (-1, 0, 0), up = (0, 0, 1), at height 5.
    DVec3::new(-5.0 * sx, 0.0, 5.0 * sy)
}

#[test]
fn an_index_1_ball_is_invisible_caustic_plus_direct_equals_the_plain_direct_light() {
    let s = ball_scene("dielectric = { ior = 1.0 }", "direction = [-1.0, -1.0, 0.0]");
    let image = render(&s, Bounces::Fixed(3), true, 256, 1);
    let expected = 0.6f32 as f64 * 3.0 / PI * 0.5f64.sqrt();
    let (mut in_shadow, mut z_fail) = (0, 0);
    let mut shadow_sum = 0.0;
    for y in 0..16 {
        for x in 0..24 {
            let i = image.index(x, y);
            let (mean, var) = (image.mean[i][0], image.variance_of_mean[i][0]);
            let p = floor_point(x, y);
            // The shadow: an ellipse of semi-axes 0.5 / sin 45 (x) and 0.5 (z) about the
            // origin; a margin of about one pixel (0.23) around its edge is left out.
            let e = shadow_ellipse(p);
            if e < 0.4 {
                in_shadow += 1;
                shadow_sum += mean;
                if (mean - expected).abs() > 4.0 * var.sqrt() {
                    z_fail += 1;
                }
            } else if e > 2.0 {
                // Lit by next-event estimation only, exactly; no particle lands here.
                assert!((mean - expected).abs() < 1e-9 * expected, "pixel ({x}, {y}) = {mean}");
            }
        }
    }
    assert!(in_shadow >= 8, "only {in_shadow} pixels inside the shadow");
    assert!(z_fail <= 1, "{z_fail} of {in_shadow} shadow pixels beyond 4 sigma of {expected}");
    let mean = shadow_sum / in_shadow as f64;
    assert!((mean / expected - 1.0).abs() < 0.01, "shadow mean {mean}, expected {expected}");
    // Without the light tracer the shadow is black: the caustic is all of its light.
    let off = render(&s, Bounces::Fixed(3), false, 4, 1);
    assert_eq!(off.mean[off.index(12, 8)][0], 0.0);
}

#[test]
fn a_flat_mirror_sends_the_sun_straight_down_with_its_full_irradiance() {
    // The sun travels along -x (horizontal: it lights no floor directly). A mirror of
    // reflectance 1 at 45 degrees above the camera (normal (1, -1, 0) / sqrt 2) sends it
    // straight down onto x in [0.75, 1.25], z in [-0.5, 0.5] with irradiance E = 3 at normal
    // incidence: the floor there has radiance rho E / pi.
    let s = scene(
        "[directional_light]\ndirection = [-1.0, 0.0, 0.0]\nirradiance = [3.0, 3.0, 3.0]\n\
         [materials.mirror]\nmirror = { reflectance = [1.0, 1.0, 1.0] }\n[[objects]]\nmaterial = \"mirror\"\n\
         quad = { corner = [0.75, 5.75, -0.5], edge_u = [0.0, 0.0, 1.0], edge_v = [0.5, 0.5, 0.0] }\n",
    );
    let image = render(&s, Bounces::Fixed(2), true, 512, 2);
    let radiance = 0.6f32 as f64 * 3.0 / PI;
    // Pixels seen wholly inside the patch (their footprint is 0.228 wide) see rho E / pi.
    let mut inside = 0;
    for y in 0..16 {
        for x in 0..24 {
            let p = floor_point(x, y);
            let i = image.index(x, y);
            if (p.x - 1.0).abs() < 0.25 - 0.12 && p.z.abs() < 0.5 - 0.12 {
                inside += 1;
                let (mean, sd) = (image.mean[i][0], image.variance_of_mean[i][0].sqrt());
                assert!(
                    (mean - radiance).abs() < 4.0 * sd,
                    "pixel ({x}, {y}) = {mean} +- {sd}, expected {radiance}"
                );
            } else if (p.x - 1.0).abs() > 0.25 + 0.12 || p.z.abs() > 0.5 + 0.12 {
                assert_eq!(image.mean[i][0], 0.0, "pixel ({x}, {y}) outside the patch");
            }
        }
    }
    assert!(inside >= 4, "{inside} pixels inside the patch");
    // All the reflected power: every pixel of this camera covers the same floor area
    // A_p h^2 (image plane parallel to the floor), so sum(pixel) A_p h^2 = rho E / pi x 0.5.
    let t = 20f64.to_radians().tan();
    let footprint = (2.0 * 1.5 * t / 24.0) * (2.0 * t / 16.0) * 25.0;
    let total: f64 = image.mean.iter().map(|p| p[0]).sum::<f64>() * footprint;
    let sd = image.variance_of_mean.iter().map(|v| v[0]).sum::<f64>().sqrt() * footprint;
    let expected = radiance * 0.5;
    assert!(
        (total - expected).abs() < 4.0 * sd && sd < 0.01 * expected,
        "{total} +- {sd}, expected {expected}"
    );
}

/// Below 1 inside the shadow the ball at (3, 3, 0) casts along (-1, -1, 0) onto the floor.
fn shadow_ellipse(p: DVec3) -> f64 {
    (p.x * 0.5f64.sqrt() / 0.5).powi(2) + (p.z / 0.5).powi(2)
}

/// Mean of channel 0 over the pixels of the glass ball's shadow, with its standard error.
fn shadow_mean(image: &OracleImage) -> (f64, f64) {
    let (mut sum, mut var, mut n) = (0.0, 0.0, 0.0);
    for y in 0..16 {
        for x in 0..24 {
            let p = floor_point(x, y);
            if shadow_ellipse(p) < 0.6 {
                let i = image.index(x, y);
                sum += image.mean[i][0];
                var += image.variance_of_mean[i][0];
                n += 1.0;
            }
        }
    }
    (sum / n, var.sqrt() / n)
}

#[test]
fn with_a_sun_disc_the_light_tracer_replaces_the_camera_paths_it_owns_exactly() {
    // A sun of radius 10 degrees: a camera path bouncing off the floor through the glass
    // reaches it by chance (E D S S L), so the caustic is in the image with the light tracer
    // off; with it on, those paths are left to the particles. The two images estimate the
    // same thing: neither counts a path twice nor misses one.
    let s = ball_scene("dielectric = { ior = 1.5 }", "direction = [-1.0, -1.0, 0.0]\nangular_radius = 10.0");
    let off = shadow_mean(&render(&s, Bounces::Fixed(3), false, 8192, 3));
    let on = shadow_mean(&render(&s, Bounces::Fixed(3), true, 1024, 4));
    let sd = (off.1 * off.1 + on.1 * on.1).sqrt();
    assert!(off.0 > 0.05 && on.0 > 0.05, "the shadow holds a caustic: {off:?} {on:?}");
    assert!((off.0 - on.0).abs() < 4.0 * sd, "caustic off {off:?}, on {on:?}");
    // The light tracer is the better estimator of it by far.
    assert!(on.1 < off.1, "standard error with the light tracer {} vs without {}", on.1, off.1);
}

#[test]
fn bounce_limits_count_the_specular_scatterings_as_the_camera_path_would() {
    // L S S D E is the camera path E D S S L: three continuation rays. At bounces 2 the
    // light tracer adds nothing through the glass ball; at 3 it does.
    let s = ball_scene("dielectric = { ior = 1.5 }", "direction = [-1.0, -1.0, 0.0]");
    let two = render(&s, Bounces::Fixed(2), true, 8, 5);
    assert_eq!(shadow_mean(&two).0, 0.0);
    let three = render(&s, Bounces::Fixed(3), true, 8, 5);
    assert!(shadow_mean(&three).0 > 0.0);
}

#[test]
fn extremes_stay_finite() {
    for (material, sun) in illum_oracle::caustic::EXTREME_CASES {
        let s = ball_scene(material, sun);
        for bounces in [Bounces::Fixed(8), Bounces::Unbounded] {
            let image = render(&s, bounces, true, 4, 6);
            assert_eq!(image.dropped, 0, "{material}, {sun}");
            assert!(
                image.mean.iter().flatten().all(|c| c.is_finite() && *c >= 0.0),
                "{material}, {sun}: a pixel is not finite"
            );
        }
    }
}

/// The photon gather against a closed form: a glass ball of index 1 is invisible, so a camera
/// looking at the floor through it along the sun's line sees the floor in the ball's shadow, lit
/// by the sun through the ball. Next-event estimation is blocked there (the ball stops shadow
/// rays) and the camera ray's first hit is the ball (no connection of the light tracer), so the
/// paths E S S D S S L are the gather's alone, and must give the plain direct light. Where the
/// ray misses the ball the floor is lit directly (next-event estimation, exactly).
#[test]
fn through_an_index_1_ball_the_gather_gives_the_plain_direct_light() {
    let mut s = ball_scene("dielectric = { ior = 1.0 }", "direction = [-1.0, -1.0, 0.0]");
    s.camera.eye = glam::Vec3::new(6.0, 6.0, 0.0);
    s.camera.target = glam::Vec3::ZERO;
    s.camera.up = glam::Vec3::Z;
    s.camera.vfov_deg = 20.0;
    s.camera.width = 48;
    s.camera.height = 32;
    // E S S D S S L takes 5 continuation rays.
    let oracle =
        Oracle::new(&s).unwrap_or_else(|e| panic!("{e}")).with_bounces(Bounces::Fixed(5)).with_caustics(true);
    assert!(oracle.gathers());
    let image = oracle.render(2048, 7, illum_oracle::default_threads());
    let expected = 0.6f32 as f64 * 3.0 / PI * 0.5f64.sqrt();
    let camera = illum_oracle::PinholeCamera::new(&s.camera);
    let (mut through, mut z_fail, mut sum, mut var) = (0, 0, 0.0, 0.0);
    for y in 0..32 {
        for x in 0..48 {
            let d = camera.direction(x, y, 0.5, 0.5);
            // Distance from the ball's centre to the centre ray: inside 0.5 the ray passes
            // through the ball; a margin of over a pixel (0.09 units at the ball) and the
            // kernel's radius (0.01) is left out at the silhouette.
            let m = DVec3::new(3.0, 3.0, 0.0) - camera.eye;
            let miss = (m - d * m.dot(d)).length();
            let i = image.index(x, y);
            let (mean, v) = (image.mean[i][0], image.variance_of_mean[i][0]);
            if miss < 0.35 {
                through += 1;
                sum += mean;
                var += v;
                if (mean - expected).abs() > 4.0 * v.sqrt() {
                    z_fail += 1;
                }
            } else if miss > 0.65 {
                assert!((mean - expected).abs() < 1e-9 * expected, "pixel ({x}, {y}) = {mean}");
            }
        }
    }
    let n = f64::from(through);
    let (mean, sd) = (sum / n, var.sqrt() / n);
    println!(
        "{through} pixels through the ball: {mean:.5} +- {sd:.5}, expected {expected:.5}; {z_fail} beyond 4 sigma"
    );
    assert!(through >= 100, "only {through} pixels see the floor through the ball");
    assert!(z_fail <= 1, "{z_fail} of {through} pixels beyond 4 sigma of {expected}");
    assert!((mean - expected).abs() < 4.0 * sd, "mean {mean} +- {sd}, expected {expected}");
    // Without the gather those pixels are black.
    let off = oracle.with_gather(false).render(4, 7, 1);
    let centre = off.index(24, 16);
    assert_eq!(off.mean[centre][0], 0.0);
}
