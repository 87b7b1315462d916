//! The sun's glint solved on the host (`src/glint.rs`), without a GPU: closed forms of a mirror
//! ball and a glass ball seen along the sun's line, agreement with the oracle's independent 1-D
//! solve for every chain of one ball up to 4 scatterings, the bounce limit, and the Whitted
//! scene's glints.

use std::path::Path;

use illum_pathtrace::glint::{self, Event, GlintPoint};
use illum_scene::Scene;

/// A ball of `material` of radius `radius` at the origin, the eye on the +X axis at `distance`
/// looking at it, a sun of irradiance 2 along `to_sun` (toward the sun), no floor.
fn ball(material: &str, radius: f64, distance: f64, to_sun: [f64; 3], size: [u32; 2], bounces: u32) -> Scene {
    let [w, h] = size;
    let d = [-to_sun[0], -to_sun[1], -to_sun[2]];
    let text = format!(
        "[camera]\neye = [{distance:?}, 0.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nvfov = 30.0\n\
         width = {w}\nheight = {h}\n[pathtrace]\nbounces = {bounces}\ncaustics = true\n\
         [directional_light]\ndirection = [{:?}, {:?}, {:?}]\nirradiance = [2.0, 2.0, 2.0]\n\
         [materials.ball]\n{material}\n\
         [[objects]]\nmaterial = \"ball\"\nsphere = {{ center = [0.0, 0.0, 0.0], radius = {radius:?} }}\n",
        d[0], d[1], d[2]
    );
    Scene::from_toml_str(&text, "glint.toml").unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// Image-plane area (at distance 1) of one pixel of `scene`'s camera.
fn pixel_area(scene: &Scene) -> f64 {
    let b = scene.camera.basis();
    let (t, a) = (f64::from(b.tan_half_fov), f64::from(b.aspect));
    (2.0 * a * t / f64::from(scene.camera.width)) * (2.0 * t / f64::from(scene.camera.height))
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn only(points: &[GlintPoint], chain: &[(usize, Event)]) -> GlintPoint {
    let found: Vec<_> = points.iter().filter(|p| p.chain == chain).collect();
    assert_eq!(found.len(), 1, "chain {chain:?}: {points:#?}");
    found[0].clone()
}

#[test]
fn a_mirror_ball_facing_the_sun_behind_the_eye_matches_its_closed_form() {
    // Sun behind the eye on the axis: the glint is the ball's centre on the film. A convex
    // mirror of radius R sends the paraxial beam away from its virtual focus R / 2 behind the
    // vertex, so at the eye, D - R from the vertex, the irradiance is rho E (R / 2)^2 /
    // (D - R / 2)^2; on the axis the film's area element is the solid angle's, so the pixel's
    // value is that over the pixel's image-plane area.
    let (radius, distance, rho) = (1.0, 6.0, 0.8);
    let scene =
        ball("mirror = { reflectance = [0.8, 0.8, 0.8] }", radius, distance, [1.0, 0.0, 0.0], [63, 41], 1);
    let points = glint::solve(&scene);
    let g = only(&points, &[(0, Event::Reflect)]);
    assert!((g.film[0] - 31.5).abs() < 1e-6 && (g.film[1] - 20.5).abs() < 1e-6, "{:?}", g.film);
    assert_eq!(g.pixel, 20 * 63 + 31);
    let e = 2.0;
    let expected = f64::from(rho as f32) * e * (radius / 2.0f64).powi(2)
        / (distance - radius / 2.0).powi(2)
        / pixel_area(&scene);
    let err = relative(g.value[0], expected);
    assert!(err < 1e-7, "mirror glint {} against {expected}: relative error {err:e}", g.value[0]);
}

#[test]
fn a_glass_ball_seen_against_the_sun_matches_the_ball_lens() {
    // Sun straight behind the ball: the chain through both faces (T T) is a ball lens of
    // effective focal length f = n R / (2 (n - 1)) from its centre (both principal planes at the
    // centre), so the beam converges at f and reaches the eye at D with irradiance
    // (1 - F0)^2 E f^2 / (D - f)^2. The front face's reflection (R) faces away from the eye.
    let (radius, distance, n) = (1.0, 8.0, 1.5f64);
    let scene = ball("dielectric = { ior = 1.5 }", radius, distance, [-1.0, 0.0, 0.0], [63, 41], 2);
    let points = glint::solve(&scene);
    let g = only(&points, &[(0, Event::Refract), (0, Event::Refract)]);
    let f0 = ((n - 1.0) / (n + 1.0)).powi(2);
    let focal = n * radius / (2.0 * (n - 1.0));
    let e = 2.0;
    let expected = (1.0 - f0).powi(2) * e * focal * focal / (distance - focal).powi(2) / pixel_area(&scene);
    let err = relative(g.value[0], expected);
    assert!(err < 1e-7, "ball lens glint {} against {expected}: relative error {err:e}", g.value[0]);
    // The glass's own reflection, R, with the sun behind the eye instead: a mirror of reflectance F0.
    let scene = ball("dielectric = { ior = 1.5 }", radius, distance, [1.0, 0.0, 0.0], [63, 41], 1);
    let g = only(&glint::solve(&scene), &[(0, Event::Reflect)]);
    let expected =
        f0 * e * (radius / 2.0f64).powi(2) / (distance - radius / 2.0).powi(2) / pixel_area(&scene);
    let err = relative(g.value[0], expected);
    assert!(err < 1e-7, "glass reflection glint {} against {expected}: relative error {err:e}", g.value[0]);
}

#[test]
fn the_bounce_limit_counts_each_scattering_once() {
    // The sun 15 degrees off the line behind the eye: the glass ball shows it by its reflection
    // (R, 1 scattering) and inside the primary rainbow's cone (T R T, 3 scatterings); a limit
    // of n bounces keeps exactly the chains of at most n scatterings.
    let to_sun = [15f64.to_radians().cos(), 15f64.to_radians().sin(), 0.0];
    let solve =
        |bounces| glint::solve(&ball("dielectric = { ior = 1.5 }", 1.0, 8.0, to_sun, [128, 128], bounces));
    let mut previous = solve(1);
    assert_eq!(previous.len(), 1, "{previous:#?}");
    assert_eq!(previous[0].chain, [(0, Event::Reflect)]);
    for bounces in 2..=6 {
        let points = solve(bounces);
        let shorter: Vec<_> = points.iter().filter(|p| p.chain.len() < bounces as usize).cloned().collect();
        assert_eq!(shorter, previous, "bounces {bounces}");
        assert!(points.iter().all(|p| p.chain.len() <= bounces as usize), "bounces {bounces}: {points:#?}");
        if bounces == 3 {
            let trt = [(0, Event::Refract), (0, Event::Reflect), (0, Event::Refract)];
            assert!(points.iter().any(|p| p.chain == trt), "no T R T at bounces 3: {points:#?}");
        }
        previous = points;
    }
}

/// The host's chain as the oracle names a lone sphere's: R, TT, TRT, ...
fn letters(chain: &[(usize, Event)]) -> String {
    chain.iter().map(|(_, e)| if *e == Event::Reflect { 'R' } else { 'T' }).collect()
}

#[test]
fn the_host_solve_agrees_with_the_oracles_1d_solve_for_every_chain_up_to_4_scatterings() {
    // Suns around the ball, each with the chains R, TT, TRT, TRRT of a glass ball that reach it
    // (and R of a mirror ball); the sun never in view. The host solves in 2-D over the film with
    // its own ray casting; the oracle in 1-D in the plane of the axis and the sun.
    let mut compared = 0;
    let mut worst = (0.0f64, 0.0f64);
    let mut grazing = 0;
    for material in ["dielectric = { ior = 1.4285715 }", "mirror = { reflectance = [0.792, 0.863, 0.851] }"] {
        for degrees in [10.0f64, 25.0, 40.0, 60.0, 80.0, 100.0, 120.0, 135.0, 150.0, 170.0] {
            let (s, c) = degrees.to_radians().sin_cos();
            let to_sun = [c, s * 0.8, s * 0.6];
            let scene = ball(material, 1.0, 5.0, to_sun, [160, 120], 4);
            let host = glint::solve(&scene);
            let oracle = illum_oracle::glint::single_sphere_glints(&scene, 4);
            assert_eq!(
                host.len(),
                oracle.len(),
                "{material}, sun at {degrees} deg: host {host:#?}\noracle {oracle:#?}"
            );
            for o in &oracle {
                let h = host
                    .iter()
                    .filter(|h| letters(&h.chain) == o.chain)
                    .min_by(|a, b| {
                        angle(a.direction, o.direction).total_cmp(&angle(b.direction, o.direction))
                    })
                    .unwrap_or_else(|| panic!("{material}, sun at {degrees} deg: the host lacks {o:?}"));
                let direction_error = angle(h.direction, o.direction);
                let irradiance_error =
                    (0..3).map(|c| relative(h.eye_irradiance[c], o.eye_irradiance[c])).fold(0.0, f64::max);
                // Where the camera ray meets the ball, from its centre (0) to its rim (1).
                let rim = angle(h.direction, glam::DVec3::NEG_X) / (1.0f64 / 5.0).asin();
                let tolerance = if rim < 0.999 {
                    worst = (worst.0.max(direction_error), worst.1.max(irradiance_error));
                    5e-9
                } else {
                    // A grazing chain: beta changes as sqrt(rim distance), and differences of
                    // step 1e-3 pixel no longer resolve it (docs/glint.md, "Limits").
                    grazing += 1;
                    1e-2
                };
                assert!(
                    direction_error < 1e-9 && irradiance_error < tolerance,
                    "{material}, sun at {degrees} deg, chain {}: direction off by {direction_error:e} rad, \
                     irradiance {:?} against {:?} ({irradiance_error:e})",
                    o.chain,
                    h.eye_irradiance,
                    o.eye_irradiance
                );
                compared += 1;
            }
        }
    }
    println!(
        "{compared} glints compared ({grazing} within 1e-3 of the rim): worst direction {:e} rad, worst irradiance {:e}",
        worst.0, worst.1
    );
    assert!(compared >= 20, "only {compared} glints compared");
}

fn angle(a: [f64; 3], b: glam::DVec3) -> f64 {
    let a = glam::DVec3::from_array(a);
    a.cross(b).length().atan2(a.dot(b))
}

#[test]
fn the_whitted_scene_shows_the_sun_in_both_balls() {
    // The Whitted view at 320 x 180, bounces 8: the sun's reflection in the mirror ball and in
    // the glass ball, each once, and chains through the glass and on to the mirror.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/whitted.toml");
    let mut scene = Scene::load(&path).expect("scenes/whitted.toml");
    scene.camera.width = 320;
    scene.camera.height = 180;
    let start = std::time::Instant::now();
    let points = glint::solve(&scene);
    let seconds = start.elapsed().as_secs_f64();
    println!("{} glints in {seconds:.3} s", points.len());
    for p in &points {
        println!("{:?} pixel ({}, {}) value {:?}", p.chain, p.pixel % 320, p.pixel / 320, p.value);
    }
    only(&points, &[(2, Event::Reflect)]);
    only(&points, &[(1, Event::Reflect)]);
    assert!(points.iter().any(|p| p.chain.iter().any(|s| s.0 == 1) && p.chain.iter().any(|s| s.0 == 2)));
    assert!(points.iter().all(|p| p.chain.len() <= 8 && p.value.iter().all(|v| v.is_finite() && *v > 0.0)));
    // The floor (object 0) is diffuse: no chain scatters on it.
    assert!(points.iter().all(|p| p.chain.iter().all(|s| s.0 != 0)));
    // With the caustic's estimators off, or a sun disc, there is no glint to solve.
    let mut off = scene.clone();
    off.pathtrace.caustics = false;
    assert!(glint::solve(&off).is_empty());
    let mut disc = scene.clone();
    disc.directional_light.as_mut().unwrap().angular_radius_deg = 0.5;
    assert!(glint::solve(&disc).is_empty());
}
