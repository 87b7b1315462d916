//! The caustic's light tracer on the GPU (`crates/illum-pathtrace/shaders/caustic.wgsl`, folded by
//! `tracer/caustic.rs`):
//! - a glass ball of index 1 is invisible, so with the light tracer its shadow holds exactly the
//!   plain direct light (and the sky) of the floor: a closed form for every pixel, against
//!   which the error estimate of the two estimators together is checked as well;
//! - per-pixel Z-test against the f64 oracle on a view of the Whitted scene's caustic, with a
//!   delta sun at bounces 3 and 8 and a sun disc, and on a view of the mirror ball reflecting
//!   the caustic (the photon gather, `shaders/gather.wgsl`);
//! - batching does not change the image; extremes stay finite; a very bright sun scales.

use glam::DVec3;
use illum_image::{RgbImage32, rel_mse, z_test_pass_fraction};
use illum_pathtrace::{PathTracer, Sequence, TracerOptions};
use illum_scene::Scene;

use crate::common;
use crate::oracle_agreement::{compare_scene, compare_scene_with, scene as shipped};

const TOP_VIEW: &str = "eye = [0.0, 5.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\nvfov = 40.0";

/// A grey floor seen from above, a ball of `material` of radius 1 at (3, 3, 0) outside the view,
/// a sun along `sun` of irradiance `irradiance`, `extra` sections (a sky), with the caustic on.
fn ball_scene(material: &str, sun: &str, irradiance: f32, extra: &str, bounces: &str) -> Scene {
    let text = format!(
        "[camera]\n{TOP_VIEW}\nwidth = 48\nheight = 32\n[pathtrace]\nbounces = {bounces}\ncaustics = true\n\
         seed = 5\nsampling = \"uniform\"\n{extra}\n\
         [directional_light]\n{sun}\nirradiance = [{irradiance:?}, {irradiance:?}, {irradiance:?}]\n\
         [materials.floor]\nalbedo = [0.6, 0.6, 0.6]\n[materials.ball]\n{material}\n\
         [[objects]]\nmaterial = \"floor\"\n\
         quad = {{ corner = [-50.0, 0.0, -50.0], edge_u = [0.0, 0.0, 100.0], edge_v = [100.0, 0.0, 0.0] }}\n\
         [[objects]]\nmaterial = \"ball\"\nsphere = {{ center = [3.0, 3.0, 0.0], radius = 1.0 }}\n"
    );
    Scene::from_toml_str(&text, "caustic.toml").unwrap_or_else(|e| panic!("{e}\n{text}"))
}

const SKY: &str = "[environment]\nradiance = [0.3, 0.5, 0.9]";

#[test]
fn an_index_1_ball_vanishes_and_the_error_estimate_of_both_estimators_is_honest() {
    // Sun from 45 degrees: the ball's shadow is an ellipse about the origin, 22% of the view,
    // lit only by the light tracer's particles; the sky, sampled by uniform bounces, adds
    // noise of the camera paths everywhere. The truth is the same in every pixel:
    // rho (E cos 45 / pi + sky).
    let scene = ball_scene("dielectric = { ior = 1.0 }", "direction = [-1.0, -1.0, 0.0]", 3.0, SKY, "3");
    let sky = [0.3f32, 0.5, 0.9];
    let truth: [f64; 3] = std::array::from_fn(|c| {
        0.6f32 as f64 * (3.0 / std::f64::consts::PI * 0.5f64.sqrt() + f64::from(sky[c]))
    });
    let mut reference = RgbImage32::new(48, 32);
    for p in &mut reference.pixels {
        *p = truth.map(|v| v as f32);
    }
    // Both sequences: the low-discrepancy one estimates its error from replicates, to which the
    // light tracer's frames belong as the camera samples of the same index do.
    let mut tracers = [Sequence::LowDiscrepancy, Sequence::Independent].map(|sequence| {
        let mut tracer =
            PathTracer::with_options(common::gpu(), &scene, TracerOptions { sequence, ..Default::default() })
                .expect("builds");
        assert!(tracer.caustics(), "the light tracer runs");
        let mut done = 0;
        for spp in [16, 64, 256] {
            tracer.add_samples_in_one_pass(spp - done).expect("renders");
            done = spp;
            let acc = tracer.accumulator();
            let estimated = acc.estimated_rel_mse();
            let measured = rel_mse(&acc.mean_image(), &reference).expect("same size");
            let ratio = estimated / measured;
            println!("{sequence}, {spp} spp: estimated relMSE {estimated:.3e}, measured {measured:.3e}, ratio {ratio:.3}");
            assert!(
                (1.0 / 1.5..=1.5).contains(&ratio),
                "{sequence}, {spp} spp: ratio {ratio:.3} of estimated to true error"
            );
        }
        tracer
    });
    // The per-pixel Z-test below assumes normal errors, which s^2 / n with hundreds of samples
    // gives and 4 replicates (a t distribution with 3 degrees of freedom) do not.
    let tracer = tracers.last_mut().expect("two tracers");
    let acc = tracer.accumulator();
    assert_eq!(acc.dropped_samples(), 0);
    // Per pixel against the closed form (Sidak over 3 N tests at alpha = 0.01; the reference
    // has no variance).
    let zero = RgbImage32::new(48, 32);
    let per_test = 1.0 - (1.0 - 0.01f64).powf(1.0 / (3.0 * 48.0 * 32.0));
    let pass =
        z_test_pass_fraction(&acc.mean_image(), &acc.variance_image(), &reference, &zero, 3.0 * per_test)
            .expect("same size");
    println!("{pass:.4} of pixels agree with the closed form");
    assert!(pass >= 0.99, "only {pass:.4} of pixels agree with rho (E cos / pi + sky)");
    // The shadow's pixels: the ellipse (x sin 45)^2 + z^2 < 1, well inside.
    let mut shadow = Vec::new();
    for y in 0..32u32 {
        for x in 0..48u32 {
            let t = 20f64.to_radians().tan();
            let sx = (2.0 * (f64::from(x) + 0.5) / 48.0 - 1.0) * 1.5 * t;
            let sy = (1.0 - 2.0 * (f64::from(y) + 0.5) / 32.0) * t;
            let p = DVec3::new(-5.0 * sx, 0.0, 5.0 * sy);
            if (p.x * 0.5f64.sqrt()).powi(2) + p.z.powi(2) < 0.5 {
                shadow.push((y * 48 + x) as usize);
            }
        }
    }
    let n = shadow.len() as f64;
    let mean = shadow.iter().map(|&p| acc.pixel_mean(p)[0]).sum::<f64>() / n;
    let sd = shadow.iter().map(|&p| acc.pixel_variance_of_mean(p)[0]).sum::<f64>().sqrt() / n;
    println!("shadow ({n} pixels): {mean:.5} +- {sd:.5}, truth {:.5}", truth[0]);
    assert!(
        (mean - truth[0]).abs() < 4.0 * sd && sd < 0.005 * truth[0],
        "shadow {mean} +- {sd} vs {}",
        truth[0]
    );

    // Without the light tracer the shadow lacks the sun entirely.
    let mut off = scene.clone();
    off.pathtrace.caustics = false;
    let mut tracer = PathTracer::new(common::gpu(), &off).expect("builds");
    assert!(!tracer.caustics());
    tracer.add_samples_in_one_pass(16).expect("renders");
    let dark = shadow.iter().map(|&p| tracer.accumulator().pixel_mean(p)[0]).sum::<f64>() / n;
    assert!(dark < 0.5 * truth[0], "without the caustic the shadow is {dark}, truth {}", truth[0]);
}

/// The Whitted scene at the oracle tests' size, with the camera on the floor under the glass
/// ball: the caustic (about (2.2, 0, -3.8), the glass ball's shadow) and the mirror ball's.
pub(crate) fn caustic_view(bounces: u32) -> Scene {
    let mut s = shipped("whitted", bounces);
    assert!(s.pathtrace.caustics, "scenes/whitted.toml turns the caustic on");
    s.camera.eye = glam::Vec3::new(2.2, 6.0, -7.5);
    s.camera.target = glam::Vec3::new(2.2, 0.0, -3.8);
    s.camera.vfov_deg = 40.0;
    s
}

#[test]
fn the_caustic_agrees_with_the_oracle_at_bounces_3_and_8() {
    for bounces in [3, 8] {
        compare_scene(&format!("whitted caustic view, bounces {bounces}"), &caustic_view(bounces));
    }
}

/// The mirror ball from the side of the glass ball's caustic: its lower half reflects the
/// caustic, paths E S+ D S+ L that only the photon gather finds with the delta sun
/// (docs/caustics-gather.md).
pub(crate) fn mirror_view() -> Scene {
    let mut s = shipped("whitted", 8);
    s.camera.eye = glam::Vec3::new(2.6, 2.4, -7.0);
    s.camera.target = glam::Vec3::new(2.0, 1.9, -2.5);
    s.camera.vfov_deg = 30.0;
    s
}

#[test]
fn the_caustic_seen_in_the_mirror_agrees_with_the_oracle() {
    let scene = mirror_view();
    // The view depends on the gather: without it the oracle's image is darker in red and green
    // by many standard errors (printed), so the comparison below can tell.
    let threads = illum_oracle::default_threads();
    let oracle = |gather: bool| {
        illum_oracle::Oracle::new(&scene).expect("renders").with_gather(gather).render(1024, 5, threads)
    };
    let (with, without) = (oracle(true), oracle(false));
    for c in 0..3 {
        let (mut d, mut v) = (0.0, 0.0);
        for i in 0..with.mean.len() {
            d += with.mean[i][c] - without.mean[i][c];
            v += with.variance_of_mean[i][c] + without.variance_of_mean[i][c];
        }
        let z = d / v.sqrt();
        println!(
            "mirror view, channel {c}: the gather adds {:.5} per pixel, z = {z:.1}",
            d / with.mean.len() as f64
        );
        if c < 2 {
            assert!(z > 5.0, "channel {c}: the gather adds too little to test (z = {z:.1})");
        } else {
            assert_eq!(d, 0.0, "the floor's blue albedo is 0: the gather adds no blue");
        }
    }
    compare_scene("whitted mirror view, bounces 8", &scene);
}

/// A glass ball focusing a low sun onto a white wall beside a grey floor, seen from above the
/// ball: the floor by the wall is lit by the wall's caustic, paths E D D S+ L (and E D S+ D S+ L
/// off the ball) that only the gather at a diffuse vertex after the camera ray's own hit owns
/// with the delta sun. The ball's focus lies 1.5 radii beyond its centre, 0.7 units before the
/// wall, so the wall's caustic is a bright spot a little wider than the ball's focus.
pub(crate) fn wall_view() -> Scene {
    let text = "[camera]\neye = [1.6, 3.5, 3.0]\ntarget = [0.3, 0.3, 0.0]\nup = [0.0, 1.0, 0.0]\nvfov = 35.0\n\
                width = 24\nheight = 24\n[pathtrace]\nbounces = 8\ncaustics = true\nseed = 17\nspp = 4096\n\
                [directional_light]\ndirection = [-1.0, -0.18, 0.0]\nirradiance = [3.0, 3.0, 3.0]\n\
                [materials.floor]\nalbedo = [0.6, 0.6, 0.6]\n[materials.wall]\nalbedo = [0.8, 0.8, 0.8]\n\
                [materials.glass]\ndielectric = { ior = 1.5 }\n\
                [[objects]]\nmaterial = \"floor\"\n\
                quad = { corner = [-1.0, 0.0, -8.0], edge_u = [0.0, 0.0, 16.0], edge_v = [16.0, 0.0, 0.0] }\n\
                [[objects]]\nmaterial = \"wall\"\n\
                quad = { corner = [0.0, 0.0, -8.0], edge_u = [0.0, 6.0, 0.0], edge_v = [0.0, 0.0, 16.0] }\n\
                [[objects]]\nmaterial = \"glass\"\nsphere = { center = [2.2, 1.2, 0.0], radius = 1.0 }\n";
    Scene::from_toml_str(text, "wall.toml").unwrap_or_else(|e| panic!("{e}\n{text}"))
}

#[test]
fn the_light_of_a_caustic_scattered_again_agrees_with_the_oracle() {
    let scene = wall_view();
    // The ball sits at the view's right edge; elsewhere each diffuse surface is seen directly,
    // where the camera ray's own hit gathers nothing, so what the gather adds there is light
    // scattered again after the caustic (E (S|D)* D S* D S+ L).
    // The oracle with and without it must fail the pixel criterion against each other: the
    // gather matters pixel by pixel, beyond what its noise explains.
    let oracle = |gather: bool| {
        illum_oracle::Oracle::new(&scene).expect("renders").with_gather(gather).render(
            4096,
            99,
            illum_oracle::default_threads(),
        )
    };
    let (with, without) = (oracle(true), oracle(false));
    let image = |pixels: &[[f64; 3]]| {
        let mut image = RgbImage32::new(scene.camera.width, scene.camera.height);
        for (out, p) in image.pixels.iter_mut().zip(pixels) {
            *out = p.map(|v| v as f32);
        }
        image
    };
    let n = with.mean.len() as f64;
    let gain = with.mean.iter().zip(&without.mean).map(|(a, b)| a[0] - b[0]).sum::<f64>() / n;
    let (failures, critical) = crate::oracle_agreement::pixel_criterion(
        &image(&with.mean),
        &image(&with.variance_of_mean),
        &image(&without.mean),
        &image(&without.variance_of_mean),
    );
    println!(
        "wall view: the oracle's gather adds {gain:.5} per pixel ({:.1}% of the image); with against without: \
         {failures} pixels fail (critical count {critical})",
        100.0 * gain / (with.mean.iter().map(|p| p[0]).sum::<f64>() / n)
    );
    assert!(failures >= critical, "wall view: the gather adds too little to test ({failures} pixels)");

    // The GPU against the oracle with the gather: the per-pixel criterion, its 10%-in-a-5 x 5-
    // block power check and the whole-image means.
    let gpu = common::render(&scene);
    crate::oracle_agreement::compare_render("wall view, bounces 8", &gpu, 4096);

    // Power against the error this estimator exists to remove: the GPU's image must fail the same
    // criterion against the oracle's image without the gather. (A GPU build gathering at the
    // first diffuse vertex alone fails the comparison above: docs/caustics-gather.md has the count.)
    let (failures, critical) = crate::oracle_agreement::pixel_criterion(
        &gpu.accumulator().mean_image(),
        &gpu.accumulator().variance_image(),
        &image(&without.mean),
        &image(&without.variance_of_mean),
    );
    println!(
        "wall view against the oracle without the gather: {failures} pixels fail (critical count {critical})"
    );
    assert!(
        failures >= critical,
        "wall view: an image without the light scattered again passes ({failures} pixels fail, critical {critical})"
    );
}

#[test]
fn the_caustic_of_a_sun_disc_agrees_with_the_oracle() {
    // With a sun of radius 5 degrees the camera paths E D S+ L are left to the light tracer
    // (both renderers), and the caustic is softer. Next-event estimation toward the disc adds
    // noise: four times the samples keep the test's power (a 2% bias fails it).
    let mut s = caustic_view(3);
    s.pathtrace.spp *= 4;
    if let Some(sun) = &mut s.directional_light {
        sun.angular_radius_deg = 5.0;
    }
    compare_scene_with("whitted caustic view, sun of radius 5 degrees, bounces 3", &s, 4 * 4096);
}

#[test]
fn batching_does_not_change_the_image_bit_for_bit() {
    let scene = caustic_view(8);
    let mut one = PathTracer::new(common::gpu(), &scene).expect("builds");
    one.add_samples_in_one_pass(32).expect("renders");
    let mut two = PathTracer::new(common::gpu(), &scene).expect("builds");
    two.add_samples_in_one_pass(16).expect("renders");
    two.add_samples_in_one_pass(16).expect("renders");
    let (a, b) = (one.accumulator().state(), two.accumulator().state());
    assert!(a.sum.iter().flatten().any(|&v| v > 0.0));
    assert_eq!(a.sum, b.sum);
    assert_eq!(a.sum_sq, b.sum_sq);
    assert_eq!(a.count, b.count);
}

#[test]
fn a_very_bright_sun_scales_the_image_and_nothing_overflows() {
    // The fixed point follows the sun: 1e30 gives the image of irradiance 3 times 1e30 / 3
    // (no pixel's 64-bit sum overflows, no particle is dropped).
    let dim = ball_scene("dielectric = { ior = 1.5 }", "direction = [-1.0, -1.0, 0.0]", 3.0, "", "8");
    let bright = ball_scene("dielectric = { ior = 1.5 }", "direction = [-1.0, -1.0, 0.0]", 1e30, "", "8");
    let a = common::render(&Scene {
        pathtrace: illum_scene::PathTraceSettings { spp: 16, ..dim.pathtrace },
        ..dim
    });
    let b = common::render(&Scene {
        pathtrace: illum_scene::PathTraceSettings { spp: 16, ..bright.pathtrace },
        ..bright
    });
    let (a, b) = (a.accumulator(), b.accumulator());
    assert_eq!((a.dropped_samples(), b.dropped_samples()), (0, 0));
    let ratio = 1e30f32 as f64 / 3.0;
    let mut caustic_pixels = 0;
    for p in 0..(48 * 32) {
        let (x, y) = (a.pixel_mean(p)[1], b.pixel_mean(p)[1]);
        assert!(y.is_finite() && b.pixel_variance_of_mean(p)[1].is_finite(), "pixel {p}: {y}");
        if x > 0.0 {
            caustic_pixels += 1;
            assert!((y / x / ratio - 1.0).abs() < 1e-5, "pixel {p}: {y} vs {x} x {ratio}");
        }
    }
    assert!(caustic_pixels > 100, "{caustic_pixels} pixels lit");
}

#[test]
fn extremes_stay_finite_with_nothing_dropped() {
    for (material, sun) in illum_oracle::caustic::EXTREME_CASES {
        for bounces in ["8", "\"unbounded\""] {
            let mut s = ball_scene(material, sun, 3.0, SKY, bounces);
            s.pathtrace.spp = 8;
            let tracer = common::render(&s);
            let acc = tracer.accumulator();
            assert_eq!(acc.dropped_samples(), 0, "{material}, {sun}, bounces {bounces}");
            common::assert_all_finite(&acc.mean_image(), &format!("{material}, {sun}"));
            common::assert_all_finite(&acc.variance_image(), &format!("{material}, {sun}"));
        }
    }
}

#[test]
fn the_cornell_box_and_a_scene_without_the_setting_have_no_light_tracer() {
    let mut cornell = common::scene("cornell", common::small(16, 16, 1));
    cornell.pathtrace.caustics = true;
    assert!(!PathTracer::new(common::gpu(), &cornell).expect("builds").caustics(), "no sun, no specular");
    let mut whitted = shipped("whitted", 8);
    whitted.pathtrace.caustics = false;
    assert!(!PathTracer::new(common::gpu(), &whitted).expect("builds").caustics());
}
