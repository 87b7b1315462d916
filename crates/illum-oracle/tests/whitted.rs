//! Whitted's algorithm in f64 (`illum_oracle::whitted`) against closed forms: what a lit and a
//! shadowed tile are, where the shadows fall, that a perfect mirror and a glass ball of index 1
//! show the background unchanged, and that nothing turns NaN at the extremes (depth 0 and 64,
//! index of refraction 1.0001 and 4, total internal reflection chains).

use glam::DVec3;
use illum_oracle::{PinholeCamera, WhittedOracle};
use illum_scene::Scene;
use illum_scene::testing::edit_once;

fn whitted_text() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/whitted.toml")).unwrap()
}

fn scene(text: &str, width: u32, height: u32) -> Scene {
    let mut s = Scene::from_toml_str(text, "whitted.toml").unwrap_or_else(|e| panic!("{e}"));
    s.camera.width = width;
    s.camera.height = height;
    s
}

/// Distance along the unit ray o + t d to the sphere (c, r), if it meets it in front of o.
fn hit_sphere(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<f64> {
    let oc = o - c;
    let b = oc.dot(d);
    let disc = b * b - (oc.length_squared() - r * r);
    if disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    (t > 1e-9).then_some(t)
}

#[test]
fn floor_pixels_are_colour_times_ambient_plus_n_dot_l_and_shadows_are_the_spheres_projections() {
    let s = scene(&whitted_text(), 160, 90);
    let mut oracle = WhittedOracle::new(&s).unwrap();
    oracle.aa = 1;
    let camera = PinholeCamera::new(&s.camera);
    let spheres = [(DVec3::new(4.2, 2.6, -4.2), 1.0), (DVec3::new(2.0, 1.9, -2.5), 1.0)];
    // Toward the light: from (10, 13, -2) to the origin, reversed.
    let to_light = DVec3::new(10.0, 13.0, -2.0).normalize();
    let (ambient, radiance) = (0.23, 1.0);
    let (mut lit, mut shadowed) = (0, 0);
    for y in 0..s.camera.height {
        for x in 0..s.camera.width {
            let d = camera.direction(x, y, 0.5, 0.5);
            if d.y >= 0.0 {
                continue;
            }
            let t = -camera.eye.y / d.y;
            let p = camera.eye + t * d;
            let on_floor = (-23.0..7.0).contains(&p.x) && (-7.5..7.5).contains(&p.z);
            let behind_sphere =
                spheres.iter().any(|&(c, r)| hit_sphere(camera.eye, d, c, r).is_some_and(|ts| ts < t));
            if !on_floor || behind_sphere {
                continue;
            }
            // Keep clear of tile edges, where the pixel's one ray may fall either side.
            let (fx, fz) = ((p.x + 23.0).fract(), (p.z + 7.5).fract());
            if fx.min(1.0 - fx) < 1e-6 || fz.min(1.0 - fz) < 1e-6 {
                continue;
            }
            let yellow = ((p.x + 23.0).floor() as i64 + (p.z + 7.5).floor() as i64) % 2 == 0;
            let colour = if yellow { DVec3::new(0.8, 0.8, 0.0) } else { DVec3::new(0.8, 0.0, 0.0) };
            let in_shadow = spheres.iter().any(|&(c, r)| hit_sphere(p, to_light, c, r).is_some());
            let expected = if in_shadow {
                shadowed += 1;
                colour * ambient
            } else {
                lit += 1;
                colour * (ambient + radiance * to_light.y)
            };
            let got = DVec3::from_array(oracle.pixel(x, y));
            // f32 scene numbers (0.23, 0.8, pi) widened to f64: agreement to 1e-6.
            assert!(
                (got - expected).abs().max_element() < 1e-6,
                "pixel ({x}, {y}) at {p}: {got} != {expected}"
            );
        }
    }
    assert!(lit > 2000 && shadowed > 200, "{lit} lit, {shadowed} shadowed floor pixels checked");
}

/// A scene of one sphere of `material` (a TOML material table body) before a uniform sky,
/// without any light, seen from the Whitted camera.
fn lone_sphere(material: &str, depth: u32) -> Scene {
    let text = format!(
        r#"[camera]
eye = [7.5, 2.3, -4.2]
target = [4.2, 2.3, -4.2]
up = [0.0, 1.0, 0.0]
vfov = 60.0
width = 48
height = 32
[environment]
radiance = [0.3, 0.5, 0.9]
[materials.ball]
{material}
[[objects]]
material = "ball"
sphere = {{ center = [4.2, 2.6, -4.2], radius = 1.0 }}
[shading]
ambient = [0.23, 0.23, 0.23]
mirror = {{ weight = 1.0 }}
[whitted]
depth = {depth}
aa = 2
"#
    );
    Scene::from_toml_str(&text, "lone.toml").unwrap_or_else(|e| panic!("{e}"))
}

fn assert_all_background(s: &Scene, what: &str) {
    let sky = [0.3f32, 0.5, 0.9].map(f64::from);
    for (i, p) in WhittedOracle::new(s).unwrap().render(2).iter().enumerate() {
        for c in 0..3 {
            assert!((p[c] - sky[c]).abs() < 1e-12, "{what}: pixel {i} = {p:?}, the sky is {sky:?}");
        }
    }
}

#[test]
fn a_perfect_mirror_and_a_glass_ball_of_index_1_show_the_background_unchanged() {
    assert_all_background(&lone_sphere("mirror = { reflectance = [1.0, 1.0, 1.0] }", 1), "mirror, weight 1");
    // Index 1: no reflection at any angle, the ray passes straight through both faces.
    assert_all_background(&lone_sphere("dielectric = { ior = 1.0 }", 2), "glass of index 1");
}

#[test]
fn depth_limits_what_the_ball_shows() {
    // Depth 0: no reflected or refracted ray; without a light the glass is black and a mirror of
    // weight 1 too, while the sky around them stays.
    let sky = DVec3::new(0.3, 0.5, 0.9);
    for material in ["dielectric = { ior = 1.5 }", "mirror = { reflectance = [1.0, 1.0, 1.0] }"] {
        let image = WhittedOracle::new(&lone_sphere(material, 0)).unwrap().render(2);
        let black = image.iter().filter(|p| p.iter().all(|&c| c == 0.0)).count();
        let sky_pixels =
            image.iter().filter(|p| (DVec3::from_array(**p) - sky).abs().max_element() < 1e-6).count();
        assert!(black > 100 && sky_pixels > 500, "{material}: {black} black, {sky_pixels} sky pixels");
    }
}

#[test]
fn extremes_stay_finite_and_bounded() {
    // Index 1.0001, 1.43 and 4 at depths 0, 1, 8 and 64 (4: long total-internal-reflection
    // chains inside the ball), on the full Whitted scene: no NaN or infinity, nothing brighter
    // than the brightest thing a path can pick up (light + highlights + ambient, a few units).
    for ior in ["1.0001", "1.4285715", "4.0"] {
        for depth in [0, 1, 8, 64] {
            let text = edit_once(&whitted_text(), "ior = 1.4285715", &format!("ior = {ior}"));
            let text = edit_once(
                &text,
                "[pathtrace]",
                &format!("[whitted]\ndepth = {depth}\naa = 1\n\n[pathtrace]"),
            );
            let s = scene(&text, 40, 24);
            for p in WhittedOracle::new(&s).unwrap().render(2) {
                assert!(
                    p.iter().all(|c| c.is_finite() && *c >= 0.0 && *c < 10.0),
                    "ior {ior}, depth {depth}: {p:?}"
                );
            }
        }
    }
}

#[test]
fn the_cornell_box_lit_by_its_light_as_a_point() {
    let s = illum_scene::testing::shipped_scene("cornell.toml", 32, 32);
    let image = WhittedOracle::new(&s).unwrap().render(2);
    assert!(image.iter().all(|p| p.iter().all(|c| c.is_finite() && *c >= 0.0)));
    // The light itself shows its radiance 30 (top centre of the image).
    assert!(image.iter().any(|p| p.iter().all(|&c| c == 30.0)), "the light is not visible");
    // No ambient in cornell.toml: the ceiling next to the light, which the point light (in the
    // ceiling's plane) cannot reach, is black.
    assert!(image.iter().filter(|p| p.iter().all(|&c| c == 0.0)).count() > 10);
}

#[test]
fn a_sun_of_finite_size_is_refused_by_name() {
    let text = edit_once(&whitted_text(), "angular_radius = 0.0", "angular_radius = 0.5");
    let err = WhittedOracle::new(&scene(&text, 8, 8)).unwrap_err().to_string();
    assert!(err.contains("Whitted ray tracer cannot render") && err.contains("sun disc"), "{err}");
}
