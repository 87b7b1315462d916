//! The GPU path tracer against the independent CPU oracle (crates/illum-oracle: f64, no shared
//! code with the WGSL), the way Mitsuba's render tests compare against references: a per-pixel
//! two-sample Z-test using both estimates' variances.
//!
//! Significance: alpha = 0.01 for the whole image, Sidak-corrected over all pixels and channels,
//! so a correct renderer fails a pixel with probability about alpha / N and the whole test
//! with probability about alpha. At least 99% of pixels must pass. The whole-image means must
//! also agree within 4 standard errors. The tests have power: each case checks that a 2%
//! brightness error fails the whole-image test, and a 25% error fails most pixels.

use illum_image::{RgbImage32, z_test_pass_fraction};
use illum_scene::{Bounces, Overrides};

use crate::common;

const SIZE: u32 = 24;
const GPU_SPP: u32 = 4096;
const ORACLE_SPP: u32 = 4096;
const ALPHA: f64 = 0.01;

fn image_from(width: u32, height: u32, pixels: &[[f64; 3]]) -> RgbImage32 {
    let mut image = RgbImage32::new(width, height);
    for (out, p) in image.pixels.iter_mut().zip(pixels) {
        *out = p.map(|v| v as f32);
    }
    image
}

fn compare(bounces: u32) {
    compare_scene(&format!("cornell, bounces {bounces}"), &scene("cornell", bounces));
}

/// A shipped scene at SIZE x SIZE, GPU_SPP samples, `bounces`.
pub(crate) fn scene(name: &str, bounces: u32) -> illum_scene::Scene {
    common::scene(
        name,
        Overrides {
            width: Some(SIZE),
            height: Some(SIZE),
            spp: Some(GPU_SPP),
            bounces: Some(Bounces::Fixed(bounces)),
            seed: Some(17),
            ..Default::default()
        },
    )
}

pub(crate) fn compare_scene(label: &str, scene: &illum_scene::Scene) {
    compare_scene_with(label, scene, ORACLE_SPP);
}

/// As [`compare_scene`], the oracle taking `oracle_spp` samples (the GPU: the scene's spp).
pub(crate) fn compare_scene_with(label: &str, scene: &illum_scene::Scene, oracle_spp: u32) {
    compare_render(label, &common::render(scene), oracle_spp);
}

/// The image `gpu` has rendered (SIZE x SIZE, of its scene) against the oracle's at
/// `oracle_spp`: the per-pixel Z-test and the whole-image means, each with its power check.
pub(crate) fn compare_render(label: &str, gpu: &illum_pathtrace::PathTracer, oracle_spp: u32) {
    let scene = gpu.scene().clone();
    let oracle = illum_oracle::render(&scene, oracle_spp, 99).expect("the oracle renders this scene");
    assert_eq!(oracle.dropped, 0);
    let (mean, variance) = (gpu.accumulator().mean_image(), gpu.accumulator().variance_image());
    let oracle_mean = image_from(SIZE, SIZE, &oracle.mean);
    let oracle_variance = image_from(SIZE, SIZE, &oracle.variance_of_mean);

    // Sidak: per-test level so that all 3 N tests together have level ALPHA; the Z-test helper
    // splits its alpha over the 3 channels of a pixel itself.
    let tests = 3.0 * (SIZE * SIZE) as f64;
    let per_test = 1.0 - (1.0 - ALPHA).powf(1.0 / tests);
    let pass = z_test_pass_fraction(&mean, &variance, &oracle_mean, &oracle_variance, 3.0 * per_test)
        .expect("same size");
    println!("{label}: {pass:.4} of pixels agree with the oracle");
    if pass < 0.99 {
        let written = illum_image::save_diff_images(
            common::failure_dir(),
            &format!("oracle-{}", label.replace([' ', ','], "-")),
            &mean,
            &oracle_mean,
        );
        panic!("{label}: only {pass:.4} of pixels agree with the CPU oracle; see {written:?}");
    }

    // Whole-image mean per channel over the pixels that do not see the light (whose
    // partial coverage of a radiance-30 emitter would swamp the variance): the pixel means are
    // independent, so their variances add.
    let lit: Vec<bool> = oracle.mean.iter().map(|p| p[0] < 1.0).collect();
    let n = lit.iter().filter(|&&k| k).count() as f64;
    let whole = |pixels: &[[f64; 3]], variances: &[[f64; 3]], c: usize| {
        let m = pixels.iter().zip(&lit).filter(|(_, k)| **k).map(|(p, _)| p[c]).sum::<f64>() / n;
        let v = variances.iter().zip(&lit).filter(|(_, k)| **k).map(|(p, _)| p[c]).sum::<f64>() / (n * n);
        (m, v)
    };
    let gpu_pixels: Vec<[f64; 3]> =
        (0..(SIZE * SIZE) as usize).map(|p| gpu.accumulator().pixel_mean(p)).collect();
    let gpu_variances: Vec<[f64; 3]> =
        (0..(SIZE * SIZE) as usize).map(|p| gpu.accumulator().pixel_variance_of_mean(p)).collect();
    for c in 0..3 {
        let (a, va) = whole(&gpu_pixels, &gpu_variances, c);
        let (b, vb) = whole(&oracle.mean, &oracle.variance_of_mean, c);
        let z = (a - b) / (va + vb).sqrt();
        println!("{label}, channel {c}: GPU {a:.6}, oracle {b:.6}, z = {z:.2}");
        assert!(z.abs() < 4.0, "{label}, channel {c}: whole-image means differ by {z:.2} sigma");
        let z_biased = (1.02 * a - b) / (va + vb).sqrt();
        assert!(z_biased.abs() > 4.0, "{label}: a 2% bias would pass (z = {z_biased:.2}): no power");
    }

    // Per-pixel power: an image 25% too bright must fail most pixels.
    let mut brighter = mean.clone();
    for p in &mut brighter.pixels {
        *p = p.map(|v| v * 1.25);
    }
    let biased_pass =
        z_test_pass_fraction(&brighter, &variance, &oracle_mean, &oracle_variance, 3.0 * per_test)
            .expect("same size");
    assert!(biased_pass < 0.5, "{label}: a 25% bias still passes {biased_pass:.3} of pixels");
}

#[test]
fn direct_light_agrees_with_the_oracle() {
    compare(0);
}

#[test]
fn one_bounce_agrees_with_the_oracle() {
    compare(1);
}

#[test]
fn two_bounces_agree_with_the_oracle() {
    compare(2);
}

#[test]
fn eight_bounces_agree_with_the_oracle() {
    compare(8);
}

// The Whitted scene's physics: checkerboard, mirror, glass (exact Fresnel, reflect or refract
// by it), the delta sun and the sky, with the caustic's light tracer on as scenes/whitted.toml
// has it (at bounces 0 and 1 no caustic path fits; tests/pathtrace/caustic.rs aims a camera
// at the caustic).

#[test]
fn the_whitted_scene_agrees_with_the_oracle_at_bounces_0_1_8() {
    for bounces in [0, 1, 8] {
        compare_scene(&format!("whitted, bounces {bounces}"), &scene("whitted", bounces));
    }
}

/// Glass barely denser than air (1.0001: grazing refraction, reflectance near 0) and far denser
/// (4: the critical angle is 14.5 degrees, so rays bounce inside by total internal reflection
/// many times).
#[test]
fn extreme_indices_of_refraction_agree_with_the_oracle() {
    for ior in [1.0001f32, 4.0] {
        let mut s = scene("whitted", 8);
        for m in &mut s.materials {
            if let illum_scene::MaterialKind::Dielectric { ior: value } = &mut m.kind {
                *value = ior;
            }
        }
        compare_scene(&format!("whitted, ior {ior}, bounces 8"), &s);
    }
}

#[test]
fn a_sun_disc_agrees_with_the_oracle() {
    let mut s = scene("whitted", 1);
    if let Some(sun) = &mut s.directional_light {
        sun.angular_radius_deg = 5.0;
    }
    compare_scene("whitted, sun of radius 5 degrees, bounces 1", &s);
}
