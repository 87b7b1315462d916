//! The path tracer on the Whitted scene where the scene's inputs run out: the sun at 0.1 and 89.9
//! degrees of elevation and of radius 0.01 and 20 degrees against the floor's closed form, and
//! albedo 1 everywhere with unbounded bounces.
//! (Indices of refraction 1.0001 and 4, with their grazing rays and total-internal-reflection
//! chains, are checked against the oracle in `oracle_agreement`.)
//!
//! The closed form: with no sky and no bounces, a floor point of albedo rho that sees the whole
//! sun has radiance rho E cos(theta) / pi, theta the sun's angle from the normal. That holds for
//! a delta sun and, exactly, for a disc of any radius wholly above the horizon (the integral of
//! cos over a spherical cap of half-angle a around the direction at theta is pi sin^2(a)
//! cos(theta), and the disc's radiance is E / (pi sin^2 a)).

use glam::{DVec3, Vec3};
use illum_oracle::closed_form::pixel_ray;
use illum_scene::{Bounces, MaterialKind, Overrides, Scene, Shape};

use crate::common;

const W: u32 = 64;
const H: u32 = 36;

/// The Whitted scene without sky, at bounces 0, its floor one albedo (0.8, 0.5, 0.2), lit by a
/// sun at `elevation` degrees above the horizon (same azimuth as the scene's) of `radius`
/// degrees.
fn sunlit_floor(elevation: f64, radius: f32, spp: u32) -> Scene {
    let mut scene = common::scene(
        "whitted",
        Overrides {
            width: Some(W),
            height: Some(H),
            spp: Some(spp),
            bounces: Some(Bounces::Fixed(0)),
            seed: Some(3),
            ..Default::default()
        },
    );
    scene.environment = None;
    for m in &mut scene.materials {
        if let MaterialKind::Checker(c) = &mut m.kind {
            c.even = Vec3::new(0.8, 0.5, 0.2);
            c.odd = c.even;
        }
    }
    let sun = scene.directional_light.as_mut().expect("the scene has a sun");
    let d = sun.direction.as_dvec3();
    let horizontal = DVec3::new(d.x, 0.0, d.z).normalize();
    let e = elevation.to_radians();
    sun.direction = (horizontal * e.cos() - DVec3::Y * e.sin()).as_vec3();
    sun.angular_radius_deg = radius;
    scene
}

/// The floor point the ray through image point (px, py) hits, if it hits the floor (a rectangle
/// in the plane y = 0) before any sphere.
fn floor_point(scene: &Scene, px: f64, py: f64) -> Option<DVec3> {
    let (o, d) = pixel_ray(&scene.camera, px, py);
    let floor_t = -o.y / d.y;
    let mut on_floor = false;
    for obj in &scene.objects {
        match &obj.shape {
            Shape::Sphere(s) => {
                let oc = o - s.center.as_dvec3();
                let b = oc.dot(d);
                if b * b - (oc.length_squared() - f64::from(s.radius).powi(2)) >= 0.0 && -b < floor_t {
                    return None;
                }
            }
            Shape::Quad(q) => {
                let (corner, u, v) = (q.corner.as_dvec3(), q.edge_u.as_dvec3(), q.edge_v.as_dvec3());
                let p = o + floor_t * d - corner;
                let (a, b) = (p.dot(u) / u.length_squared(), p.dot(v) / v.length_squared());
                on_floor = (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b);
            }
            Shape::Box(_) | Shape::Mesh(_) => unreachable!("the Whitted scene has no boxes or meshes"),
        }
    }
    (d.y < 0.0 && on_floor).then_some(o + floor_t * d)
}

/// Whether a disc of angular radius `radius` (degrees) around `to_sun`, seen from p, clears every
/// sphere by `margin` degrees.
fn sees_the_whole_sun(scene: &Scene, p: DVec3, to_sun: DVec3, radius: f64, margin: f64) -> bool {
    scene.objects.iter().all(|obj| match &obj.shape {
        Shape::Sphere(s) => {
            let to_centre = s.center.as_dvec3() - p;
            let distance = to_centre.length();
            let apparent = (f64::from(s.radius) / distance).asin().to_degrees();
            let angle = to_centre.normalize().dot(to_sun).clamp(-1.0, 1.0).acos().to_degrees();
            angle > radius + apparent + margin
        }
        _ => true,
    })
}

/// The floor pixels whose whole footprint (centre and corners) lies on the floor and sees the
/// whole sun with `margin` degrees to spare, and those pixels' closed form.
fn closed_form(scene: &Scene, margin: f64) -> Vec<(usize, [f64; 3])> {
    let sun = scene.directional_light.expect("a sun");
    let to_sun = -sun.direction.as_dvec3().normalize();
    let albedo = DVec3::new(0.8, 0.5, 0.2);
    let expected = (albedo * sun.irradiance.as_dvec3() * to_sun.y / std::f64::consts::PI).to_array();
    let radius = f64::from(sun.angular_radius_deg);
    let mut pixels = Vec::new();
    for y in 0..scene.camera.height {
        for x in 0..scene.camera.width {
            let footprint = [(0.5, 0.5), (0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
            let lit = footprint.iter().all(|(dx, dy)| {
                floor_point(scene, f64::from(x) + dx, f64::from(y) + dy)
                    .is_some_and(|p| sees_the_whole_sun(scene, p, to_sun, radius, margin))
            });
            if lit {
                pixels.push(((y * scene.camera.width + x) as usize, expected));
            }
        }
    }
    pixels
}

/// A delta sun grazing the floor at 0.1 degrees and one straight overhead at 89.9: every floor
/// pixel that sees it (well inside, away from shadow and silhouette edges, so every sample of
/// the pixel sees the same thing) equals the closed form to f32 rounding.
#[test]
fn a_delta_sun_at_0_1_and_89_9_degrees_lights_the_floor_by_its_cosine() {
    for elevation in [0.1, 89.9, 51.9] {
        let scene = sunlit_floor(elevation, 0.0, 16);
        let tracer = common::render(&scene);
        let acc = tracer.accumulator();
        assert_eq!(acc.dropped_samples(), 0, "elevation {elevation}");
        let pixels = closed_form(&scene, 0.0);
        assert!(pixels.len() > 200, "elevation {elevation}: only {} lit floor pixels", pixels.len());
        let mut worst = 0.0f64;
        for (i, expected) in pixels {
            let got = acc.pixel_mean(i);
            for c in 0..3 {
                worst = worst.max((got[c] - expected[c]).abs() / expected[c]);
            }
        }
        // Pixels whose footprint crosses a shadow edge or the floor's edge are excluded; what is
        // left is f32 arithmetic.
        assert!(worst < 1e-4, "elevation {elevation}: relative error {worst:.2e} on lit floor pixels");
    }
}

/// A sun disc of 0.01 and of 20 degrees: the mean over the floor pixels that see the whole
/// disc agrees with the closed form within 4 standard errors (and a 1% error would not).
#[test]
fn a_sun_disc_of_0_01_and_20_degrees_gives_the_same_irradiance_as_a_delta_sun() {
    for radius in [0.01f32, 20.0] {
        let scene = sunlit_floor(51.9, radius, 64);
        let tracer = common::render(&scene);
        let acc = tracer.accumulator();
        assert_eq!(acc.dropped_samples(), 0, "radius {radius}");
        let pixels = closed_form(&scene, 0.0);
        assert!(pixels.len() > 200, "radius {radius}: only {} pixels see the whole disc", pixels.len());
        let n = pixels.len() as f64;
        for c in 0..3 {
            let (mut got, mut variance, mut expected) = (0.0, 0.0, 0.0);
            for &(i, e) in &pixels {
                got += acc.pixel_mean(i)[c] / n;
                variance += acc.pixel_variance_of_mean(i)[c] / (n * n);
                expected += e[c] / n;
            }
            // A tiny disc is almost a delta light: its variance can be ~0; allow f32 rounding.
            let sigma = variance.sqrt().max(1e-6 * expected);
            let z = (got - expected) / sigma;
            assert!(z.abs() < 4.0, "radius {radius}, channel {c}: {got} against {expected} (z = {z:.2})");
            assert!((0.01 * expected / sigma) > 4.0, "radius {radius}: the test could not see a 1% error");
        }
    }
}

/// Albedo 1 on the floor, a mirror of reflectance 1, glass, sky and sun, unbounded bounces
/// (Russian roulette): every sample finite and kept, and the lit floor at least as bright as
/// the sun alone makes it (sky and interreflection only add).
#[test]
fn albedo_one_everywhere_with_unbounded_bounces_stays_finite() {
    let mut scene = common::scene(
        "whitted",
        Overrides {
            width: Some(W),
            height: Some(H),
            spp: Some(64),
            bounces: Some(Bounces::Unbounded),
            seed: Some(5),
            ..Default::default()
        },
    );
    for m in &mut scene.materials {
        match &mut m.kind {
            MaterialKind::Checker(c) => {
                c.even = Vec3::ONE;
                c.odd = Vec3::ONE;
            }
            MaterialKind::Mirror { reflectance } => *reflectance = Vec3::ONE,
            _ => {}
        }
    }
    let tracer = common::render(&scene);
    let acc = tracer.accumulator();
    assert_eq!(acc.dropped_samples(), 0);
    let mean = acc.mean_image();
    common::assert_all_finite(&mean, "albedo 1, unbounded");
    let sun = scene.directional_light.expect("a sun");
    let cos = (-sun.direction.as_dvec3().normalize()).y;
    let sun_alone = f64::from(sun.irradiance.x) * cos / std::f64::consts::PI;
    let lit = closed_form(&scene, 0.0);
    let floor_mean = lit.iter().map(|&(i, _)| acc.pixel_mean(i)[0]).sum::<f64>() / lit.len() as f64;
    assert!(floor_mean > sun_alone, "lit floor {floor_mean} below the sun's own {sun_alone}");
    assert!(floor_mean < 10.0 * sun_alone, "lit floor {floor_mean}: energy is not conserved");
}
