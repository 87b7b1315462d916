//! Direct illumination against Lambert's closed form.
//!
//! With bounces = 0 the radiance leaving a Lambertian floor point x is
//!     L(x) = albedo / pi * E(x),
//! and the irradiance from a uniformly emitting polygon of radiance Le is Lambert's formula
//!     E(x) = Le / 2 * | sum_i theta_i (n . g_i) |,
//! where theta_i is the angle subtended at x by the edge (v_i, v_{i+1}) and g_i is the unit
//! normal of the plane through x and that edge. The formula (`illum_oracle::closed_form`) is
//! evaluated in f64, independently of the shader, and compared with the GPU estimate within 4
//! standard errors.

use glam::DVec3;
use illum_pathtrace::PathTracer;
use illum_scene::Scene;

use crate::common;

use illum_oracle::closed_form::lambert_irradiance_factor;

/// The assignment's box without the two blocks, so nothing but the geometry of the light
/// decides the direct light on the floor. Camera placeholders are replaced per point.
const ROOM: &str = include_str!("room.toml");

const LIGHT: [DVec3; 4] = [
    DVec3::new(213.0, 555.0, 225.5),
    DVec3::new(343.0, 555.0, 225.5),
    DVec3::new(343.0, 555.0, 330.5),
    DVec3::new(213.0, 555.0, 330.5),
];
const RADIANCE: f64 = 30.0;
const ALBEDO: f64 = 0.5;

/// Renders a tiny image of the floor around `x` (camera 1 unit above, looking straight down
/// with a 0.01 degree field of view, so every pixel sees x to within 1e-4 units) and returns the
/// estimate of L(x) with its standard error.
fn estimate_floor_radiance(x: DVec3, spp: u32) -> (f64, f64) {
    let mut scene = Scene::from_toml_str(ROOM, "closed-form room").expect("room parses");
    scene.camera.eye = (x + DVec3::Y).as_vec3();
    scene.camera.target = x.as_vec3();
    scene.camera.up = glam::Vec3::Z;
    scene.camera.vfov_deg = 0.01;
    scene.pathtrace.spp = spp;
    let mut tracer = PathTracer::new(common::gpu(), &scene).expect("builds");
    tracer.render_to_spp(spp).expect("renders");
    assert_eq!(tracer.accumulator().dropped_samples(), 0);
    let (mean, variance) = common::image_mean_and_variance(&tracer, 0);
    (mean, variance.sqrt())
}

fn check_point(label: &str, x: DVec3) {
    let expected = ALBEDO / std::f64::consts::PI * RADIANCE * lambert_irradiance_factor(x, DVec3::Y, &LIGHT);
    let (estimate, standard_error) = estimate_floor_radiance(x, 1024);
    let z = (estimate - expected) / standard_error;
    println!(
        "{label}: x = {x}, closed form {expected:.6}, estimate {estimate:.6} +- {standard_error:.6} (z = {z:.2})"
    );
    assert!(standard_error < 0.01 * expected, "{label}: the estimate is too noisy to test anything");
    assert!(
        z.abs() < 4.0,
        "{label}: estimate {estimate} differs from Lambert's {expected} by {z:.2} standard errors"
    );
}

/// The floor points checked, each with the label its messages give (the floor's inner face is
/// y = 1): one table instead of a test body per point, since every point is checked alike.
const FLOOR_POINTS: [(&str, DVec3); 4] = [
    // Under the light's centre.
    ("centre", DVec3::new(278.0, 1.0, 278.0)),
    // Under the light's edge.
    ("edge", DVec3::new(342.0, 1.0, 329.0)),
    // Far from the light.
    ("far corner", DVec3::new(20.0, 1.0, 20.0)),
    // Far across the room, near the back wall: the light is seen at about 63 degrees from the
    // floor's normal and its edges subtend small, nearly parallel angles (grazing incidence).
    ("grazing", DVec3::new(545.0, 1.0, 545.0)),
];

#[test]
fn floor_points_match_lamberts_closed_form() {
    for (label, x) in FLOOR_POINTS {
        check_point(label, x);
    }
}

#[test]
fn lambert_formula_matches_the_small_source_limit() {
    // Independent check of the formula itself: far away, a source of area A looks like a point,
    // E = Le * A * cos(theta_x) cos(theta_y) / r^2.
    let small = [
        DVec3::new(0.0, 1000.0, 0.0),
        DVec3::new(0.0, 1000.0, 1.0),
        DVec3::new(1.0, 1000.0, 1.0),
        DVec3::new(1.0, 1000.0, 0.0),
    ];
    let x = DVec3::new(0.5, 0.0, 0.5);
    let expected = 1.0 / (1000.0f64 * 1000.0);
    let factor = lambert_irradiance_factor(x, DVec3::Y, &small);
    assert!((factor - expected).abs() < 1e-6 * expected, "{factor} vs {expected}");
}
