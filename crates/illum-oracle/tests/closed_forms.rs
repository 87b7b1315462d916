//! The oracle against radiance values derived by hand.
//!
//! Each comparison allows 4 standard errors (the oracle's own variance of the mean) plus any
//! stated model error, and also checks that the standard error is small compared with the
//! value, so that a wrong estimator (a missing factor, a wrong pdf, a lost bounce) cannot hide
//! inside a wide tolerance.

use std::f64::consts::PI;

use glam::DVec3;
use illum_oracle::closed_form::lambert_irradiance_factor;
use illum_oracle::{Oracle, Rng};
use illum_scene::{Bounces, Sampling, Scene};

/// Irradiance at x (unit normal n) from a planar polygon of uniform radiance `le`, fully
/// visible from x and facing it: `le` times Lambert's form factor integral
/// ([`lambert_irradiance_factor`]).
fn polygon_irradiance(x: DVec3, n: DVec3, vertices: &[DVec3], le: f64) -> f64 {
    le * lambert_irradiance_factor(x, n, vertices)
}

/// Mean and variance of the mean of `n` independent samples of a vector quantity.
fn mean_and_variance(n: u64, mut sample: impl FnMut(u64) -> DVec3) -> (DVec3, DVec3) {
    let (mut sum, mut sum_sq) = (DVec3::ZERO, DVec3::ZERO);
    for i in 0..n {
        let x = sample(i);
        sum += x;
        sum_sq += x * x;
    }
    let nf = n as f64;
    let mean = sum / nf;
    let var = (sum_sq - sum * mean) / (nf - 1.0);
    (mean, var / nf)
}

/// |estimate - expected| <= 4 standard errors + `model_error`, per channel, and the standard
/// error is at most `max_rel_se` of a nonzero expectation (a zero expectation must come out
/// exactly zero).
fn assert_agrees(
    what: &str,
    mean: [f64; 3],
    var: [f64; 3],
    expected: [f64; 3],
    model_error: f64,
    max_rel_se: f64,
) {
    for c in 0..3 {
        let se = var[c].sqrt();
        let (m, e) = (mean[c], expected[c]);
        if e == 0.0 {
            assert_eq!(m, 0.0, "{what}, channel {c}: expected exactly 0");
            continue;
        }
        assert!(se <= max_rel_se * e, "{what}, channel {c}: standard error {se} too large for {e}");
        let tol = 4.0 * se + model_error * e;
        assert!(
            (m - e).abs() <= tol,
            "{what}, channel {c}: oracle {m} vs closed form {e} (diff {}, z = {:.2}, tol {tol})",
            m - e,
            (m - e) / se
        );
    }
}

/// Direct light only: a diffuse floor under a small tilted rectangular lamp, seen through a
/// one-pixel camera with a 0.05-degree field of view aimed at a floor point x. The pixel then
/// covers ~0.01 units of floor, over which the irradiance is flat to ~1e-5, so the pixel's
/// expected value is the radiance of x:
///     L(x) = albedo / pi * E(x),   E from Lambert's polygon formula.
#[test]
fn direct_light_matches_lamberts_polygon_formula() {
    let albedo = [0.8, 0.5, 0.2];
    let le = [10.0, 20.0, 5.0];
    // Lamp: corner (0.5, 2, -0.5), edges (1, 0, 0) and (0, 0.3, 1); front normal
    // (1,0,0) x (0,0.3,1) = (0, -1, 0.3): down and slightly toward +z.
    let lamp = [
        DVec3::new(0.5, 2.0, -0.5),
        DVec3::new(1.5, 2.0, -0.5),
        DVec3::new(1.5, 2.3, 0.5),
        DVec3::new(0.5, 2.3, 0.5),
    ];
    for target in [DVec3::new(0.0, 0.0, 0.0), DVec3::new(-3.0, 0.0, 2.0), DVec3::new(1.0, 0.0, -0.1)] {
        let text = format!(
            r#"
            [camera]
            eye = [0.0, 10.0, -10.0]
            target = [{}, {}, {}]
            up = [0.0, 1.0, 0.0]
            vfov = 0.05
            width = 1
            height = 1
            [pathtrace]
            bounces = 0
            [materials.floor]
            albedo = {albedo:?}
            [materials.lamp]
            emission = {le:?}
            [[objects]]
            material = "floor"
            quad = {{ corner = [-50.0, 0.0, -50.0], edge_u = [0.0, 0.0, 100.0], edge_v = [100.0, 0.0, 0.0] }}
            [[objects]]
            material = "lamp"
            quad = {{ corner = [0.5, 2.0, -0.5], edge_u = [1.0, 0.0, 0.0], edge_v = [0.0, 0.3, 1.0] }}
            "#,
            target.x, target.y, target.z
        );
        let scene = Scene::from_toml_str(&text, "lambert.toml").unwrap();
        let est =
            illum_oracle::radiance_at_pixel(&scene, 0, 0, 20_000, 11).expect("the oracle renders this scene");
        let expected: [f64; 3] =
            std::array::from_fn(|c| albedo[c] / PI * polygon_irradiance(target, DVec3::Y, &lamp, le[c]));
        assert!(expected.iter().all(|&e| e > 1e-3), "the lamp must light {target:?}: {expected:?}");
        assert_agrees(&format!("floor at {target:?}"), est.mean, est.variance_of_mean, expected, 1e-4, 0.003);
        assert_eq!(est.dropped, 0);
    }
}

/// A sphere of radius R with albedo a (per channel) enclosing a one-sided lamp: a 1 x 1 square
/// at the centre in the plane y = 0, facing +y, radiance Le.
///
/// Closed form. For two points y, z on a sphere the chord r = 2 R cos(theta) makes equal
/// angles with both inward normals, so cos_y cos_z / r^2 = 1 / (4 R^2): light reflected by the
/// sphere irradiates every point of it equally. Hence, with E0(z) the lamp's direct irradiance
/// (Lambert's formula; 0 below the lamp's plane), the lamp's power pi Le A all landing on the
/// sphere, and L_k = a / pi E_k:
///     E1 = int a/pi E0(y) dA / (4 R^2) = a Le A / (4 R^2)       (uniform),
///     E(k+1) = int a/pi E_k dA / (4 R^2) = a E_k,
/// so the radiance of z after n bounces is
///     L_n(z) = a/pi (E0(z) + E1 (1 + a + ... + a^(n-1))),   L_inf = a/pi (E0(z) + E1 / (1 - a)).
/// Model error: a bounce ray that meets the lamp (either side) ends the path, which removes the
/// light of the sphere behind it. The lamp subtends at most A / (pi d^2) < 4e-5 of the
/// cosine-weighted hemisphere of any sphere point (d >= 99 from it), so each indirect term is
/// low by less than ~1e-4 relative; the tolerance includes 2e-4.
#[test]
fn sphere_enclosure_matches_the_closed_form_for_every_bounce_setting() {
    let radius = 100.0;
    let albedo = [0.3, 0.5, 0.8];
    let le = 1.0e4;
    let area = 1.0;
    let text = format!(
        r#"
        [camera]
        eye = [0.0, -50.0, 0.0]
        target = [0.0, 0.0, 10.0]
        up = [0.0, 1.0, 0.0]
        vfov = 60.0
        width = 1
        height = 1
        [materials.shell]
        albedo = {albedo:?}
        [materials.lamp]
        emission = [{le}, {le}, {le}]
        [[objects]]
        material = "shell"
        sphere = {{ center = [0.0, 0.0, 0.0], radius = {radius} }}
        [[objects]]
        material = "lamp"
        quad = {{ corner = [-0.5, 0.0, -0.5], edge_u = [0.0, 0.0, 1.0], edge_v = [1.0, 0.0, 0.0] }}
        "#
    );
    let scene = Scene::from_toml_str(&text, "enclosure.toml").unwrap();
    let lamp = [
        DVec3::new(-0.5, 0.0, -0.5),
        DVec3::new(0.5, 0.0, -0.5),
        DVec3::new(0.5, 0.0, 0.5),
        DVec3::new(-0.5, 0.0, 0.5),
    ];
    let e1: [f64; 3] = std::array::from_fn(|c| albedo[c] * le * area / (4.0 * radius * radius));
    let origin = DVec3::new(0.0, -50.0, 0.0);
    let lit = radius * DVec3::new(30f64.to_radians().sin(), 30f64.to_radians().cos(), 0.0);
    let unlit = radius * DVec3::new(40f64.to_radians().sin(), -40f64.to_radians().cos(), 0.0);
    let e0 = |z: DVec3| if z.y > 0.0 { polygon_irradiance(z, -z / radius, &lamp, le) } else { 0.0 };

    let settings = [Bounces::Fixed(0), Bounces::Fixed(1), Bounces::Fixed(3), Bounces::Unbounded];
    let samplings = [Sampling::Cosine, Sampling::Uniform];
    std::thread::scope(|scope| {
        for (i, bounces) in settings.into_iter().enumerate() {
            for (j, sampling) in samplings.into_iter().enumerate() {
                let oracle = Oracle::new(&scene)
                    .expect("the oracle renders this scene")
                    .with_bounces(bounces)
                    .with_sampling(sampling);
                scope.spawn(move || {
                    for (k, z) in [lit, unlit].into_iter().enumerate() {
                        let expected: [f64; 3] = std::array::from_fn(|c| {
                            let a = albedo[c];
                            let series = match bounces {
                                Bounces::Fixed(n) => (0..n).map(|k| a.powi(k as i32)).sum::<f64>(),
                                Bounces::Unbounded => 1.0 / (1.0 - a),
                            };
                            a / PI * (e0(z) + e1[c] * series)
                        });
                        let seed = (i * 10 + j * 100 + k) as u64;
                        let (mean, var) = mean_and_variance(100_000, |s| {
                            oracle.radiance(origin, z - origin, &mut Rng::for_sample(seed, 0, s))
                        });
                        let what = format!("{bounces:?}, {sampling:?}, point {z:?}");
                        assert_agrees(&what, mean.to_array(), var.to_array(), expected, 2e-4, 0.01);
                    }
                });
            }
        }
    });
}

/// A one-sided lamp is seen (at its radiance) only from the front, and it casts no shadow of
/// itself on a surface behind it lit by a second lamp.
#[test]
fn emitters_are_one_sided_for_camera_rays() {
    let text = include_str!("scenes/lamp.toml");
    // Front normal (0,2,0) x (2,0,0) = (0, 0, -4): toward -z, i.e. toward the camera. The
    // pixel sees 5 tan(5 deg) = 0.44 units either side of the centre: all lamp.
    let scene = Scene::from_toml_str(text, "lamp.toml").unwrap();
    let oracle = Oracle::new(&scene).expect("the oracle renders this scene");
    let mut rng = Rng::for_sample(0, 0, 0);
    let front = oracle.radiance(DVec3::new(0.2, 0.1, -5.0), DVec3::Z, &mut rng);
    assert_eq!(front, DVec3::new(3.0, 2.0, 1.0));
    let back = oracle.radiance(DVec3::new(0.2, 0.1, 5.0), DVec3::NEG_Z, &mut rng);
    assert_eq!(back, DVec3::ZERO);
    let miss = oracle.radiance(DVec3::new(2.0, 0.1, -5.0), DVec3::Z, &mut rng);
    assert_eq!(miss, DVec3::ZERO);
    let pixel = illum_oracle::radiance_at_pixel(&scene, 0, 0, 8, 3).expect("the oracle renders this scene");
    assert_eq!(pixel.mean, [3.0, 2.0, 1.0]);
    assert_eq!(pixel.variance_of_mean, [0.0; 3]);
}
