//! What the à-trous filter does to images whose answer is known: a converged Cornell box, a
//! furnace, the 16-spp Cornell box against the converged one, and the halves' estimate of the
//! denoised image's error against its true error.

use std::sync::atomic::AtomicBool;

use illum_denoise::input::luminance_variance;
use illum_denoise::{AtrousDenoiser, AtrousSettings, DenoiseInput, Denoiser, DenoiserKind, SplitRender};
use illum_image::{RgbImage32, luminance};
use illum_pathtrace::TracerOptions;
use illum_scene::Scene;

use crate::common;

fn filter() -> AtrousDenoiser {
    AtrousDenoiser::new(common::gpu()).expect("compiles")
}

/// A converged image (illum-pathtrace's 16384-spp reference) is left within its noise: the
/// denoised luminance moves by at most 3 standard errors in all but 1% of the pixels, and by
/// less than one on average (the mean of the squared moves over the variances is below 1).
#[test]
fn a_converged_image_is_not_moved_beyond_its_noise() {
    let (reference, variance) = common::reference();
    let guides = common::render(&common::cornell(2, 1)).guides(64).expect("guides");
    let input = DenoiseInput {
        variance: variance.pixels.iter().map(|v| luminance_variance(v.map(f64::from))).collect(),
        image: reference.clone(),
        albedo: guides.albedo,
        normal: guides.normal,
    };
    let (denoised, _) = filter().denoise(&input, &AtrousSettings::default()).expect("denoises");
    // Pixels of zero variance (every sample the same: the light, the black outside the box)
    // must keep their value up to f32 rounding; the others are compared with their noise.
    let (mut outside, mut chi2, mut noisy) = (0usize, 0.0, 0usize);
    for (p, (d, r)) in denoised.pixels.iter().zip(&reference.pixels).enumerate() {
        let moved = luminance(*d) - luminance(*r);
        let sigma = f64::from(input.variance[p]).sqrt();
        if sigma == 0.0 {
            assert!(moved.abs() <= 1e-6 * luminance(*r).abs(), "pixel {p} of zero variance moved by {moved}");
            continue;
        }
        noisy += 1;
        chi2 += moved * moved / (sigma * sigma);
        if moved.abs() > 3.0 * sigma {
            outside += 1;
        }
    }
    let n = noisy;
    let mean_chi2 = chi2 / n as f64;
    println!(
        "converged: {outside} of {n} pixels moved beyond 3 sigma; mean (moved / sigma)^2 = {mean_chi2:.3}"
    );
    assert!(outside * 100 <= n, "{outside} of {n} pixels moved beyond 3 standard errors");
    assert!(mean_chi2 < 1.0, "mean (moved / sigma)^2 = {mean_chi2}");
}

/// A grey ball (albedo 0.5) alone in a uniform sky, sampled with uniform hemisphere
/// directions (so every pixel on it is noisy) and one bounce: every pixel on it has the
/// expected value 0.5 x sky. The denoised mean over the pixels wholly on the ball (their guide
/// albedo is exactly 0.5) equals it within 4 standard errors of the raw region mean.
#[test]
fn a_furnace_flat_region_keeps_its_mean() {
    let sky = [0.3f64, 0.5, 0.9];
    let text = "[camera]\neye = [7.5, 2.6, -4.2]\ntarget = [4.2, 2.6, -4.2]\nup = [0.0, 1.0, 0.0]\nvfov = 40.0\n\
        width = 48\nheight = 48\n[environment]\nradiance = [0.3, 0.5, 0.9]\n[materials.ball]\nalbedo = [0.5, 0.5, 0.5]\n\
        [[objects]]\nmaterial = \"ball\"\nsphere = { center = [4.2, 2.6, -4.2], radius = 1.0 }\n\
        [pathtrace]\nspp = 16\nbounces = 1\nsampling = \"uniform\"\n";
    let scene = Scene::from_toml_str(text, "furnace.toml").unwrap_or_else(|e| panic!("{e}"));
    let tracer = common::render(&scene);
    let guides = tracer.guides(64).expect("guides");
    let accumulator = tracer.accumulator();
    let (denoised, _) = filter()
        .denoise(&DenoiseInput::from_render(accumulator, &guides), &AtrousSettings::default())
        .expect("denoises");
    let region: Vec<usize> = (0..guides.albedo.len()).filter(|&p| guides.albedo[p] == [0.5; 3]).collect();
    assert!(region.len() > 500, "the ball covers {} pixels", region.len());
    for (c, sky) in sky.iter().enumerate() {
        let truth = 0.5 * sky;
        let n = region.len() as f64;
        let raw: f64 = region.iter().map(|&p| accumulator.pixel_mean(p)[c]).sum::<f64>() / n;
        let mean: f64 = region.iter().map(|&p| f64::from(denoised.pixels[p][c])).sum::<f64>() / n;
        let sigma = region.iter().map(|&p| accumulator.pixel_variance_of_mean(p)[c]).sum::<f64>().sqrt() / n;
        println!(
            "furnace channel {c}: truth {truth:.5}, raw {raw:.5} ({:+.2} sigma), denoised {mean:.5} ({:+.2} sigma)",
            (raw - truth) / sigma,
            (mean - truth) / sigma
        );
        assert!(
            (mean - truth).abs() <= 4.0 * sigma,
            "channel {c}: denoised {mean}, truth {truth}, sigma {sigma}"
        );
    }
}

/// A region of the Cornell box for the bias table: its name and its pixels.
pub(crate) fn regions(albedo: &[[f32; 3]], normal: &[[f32; 3]]) -> Vec<(&'static str, Vec<usize>)> {
    let size = common::SIZE as usize;
    let edge = |p: usize| {
        let (x, y) = (p % size, p / size);
        let neighbours = [(x.wrapping_sub(1), y), (x + 1, y), (x, y.wrapping_sub(1)), (x, y + 1)];
        neighbours.iter().any(|&(qx, qy)| {
            qx < size
                && qy < size
                && (albedo[qy * size + qx] != albedo[p] || normal[qy * size + qx] != normal[p])
        })
    };
    let of = |want: [f32; 3]| {
        move |p: usize| albedo[p].iter().zip(want).all(|(a, w)| (a - w).abs() < 1e-3) && !edge(p)
    };
    let all: Vec<usize> = (0..albedo.len()).collect();
    let pick = |f: &dyn Fn(usize) -> bool| all.iter().copied().filter(|&p| f(p)).collect::<Vec<_>>();
    vec![
        ("whole image", all.clone()),
        ("edges (albedo or normal changes)", pick(&edge)),
        ("red wall", pick(&of([0.5608, 0.0627, 0.0627]))),
        ("green wall", pick(&of([0.0588, 0.3961, 0.0863]))),
        ("white surfaces", pick(&of([0.5, 0.5, 0.5]))),
    ]
}

/// At 16 spp on the Cornell box (64 x 64) the à-trous image's true relMSE is at least 2.5
/// times lower than the raw image's (3.2 measured; the issue aimed at 4: the light's edge,
/// where 16 samples often miss the light, is as wrong after the filter as before, and the
/// filter's bias, about -1% in luminance, remains), against the converged reference; the per-region table shows where the
/// gain comes from and the bias it costs (mean over the region of (denoised - reference) /
/// reference in luminance).
#[test]
fn at_16_spp_the_atrous_error_is_2_5_times_lower() {
    let (reference, reference_variance) = common::reference();
    let tracer = common::render(&common::cornell(16, 7));
    let guides = tracer.guides(illum_pathtrace::GUIDE_SAMPLES).expect("guides");
    let raw = tracer.accumulator().mean_image();
    let (denoised, _) = filter()
        .denoise(&DenoiseInput::from_render(tracer.accumulator(), &guides), &AtrousSettings::default())
        .expect("denoises");
    let subset = |image: &RgbImage32, pixels: &[usize]| RgbImage32 {
        width: pixels.len() as u32,
        height: 1,
        pixels: pixels.iter().map(|&p| image.pixels[p]).collect(),
    };
    println!("| region | pixels | raw relMSE | à-trous relMSE | gain | à-trous luminance bias |");
    println!("|---|---|---|---|---|---|");
    let mut whole = (0.0, 0.0);
    for (name, pixels) in regions(&guides.albedo, &guides.normal) {
        let (r, v) = (subset(&reference, &pixels), subset(&reference_variance, &pixels));
        let raw_error = common::true_rel_mse(&subset(&raw, &pixels), &r, &v);
        let denoised_error = common::true_rel_mse(&subset(&denoised, &pixels), &r, &v);
        let bias = pixels
            .iter()
            .map(|&p| luminance(denoised.pixels[p]) - luminance(reference.pixels[p]))
            .sum::<f64>()
            / pixels.iter().map(|&p| luminance(reference.pixels[p])).sum::<f64>();
        println!(
            "| {name} | {} | {raw_error:.4} | {denoised_error:.4} | {:.1}x | {:+.2}% |",
            pixels.len(),
            raw_error / denoised_error,
            100.0 * bias
        );
        if name == "whole image" {
            whole = (raw_error, denoised_error);
        }
    }
    let gain = whole.0 / whole.1;
    assert!(gain >= 2.5, "relMSE raw {} / à-trous {} = {gain:.2}", whole.0, whole.1);
}

/// The halves' estimate of a denoised image's relMSE against its true relMSE (against the
/// converged reference), from 4 to 1024 spp in total (2 per half at least: at 2 spp the
/// estimate is infinite, unknown). The estimate is of a denoised half; it must be within a
/// factor 1.5 of that half's true error at every spp, and is printed beside the denoised
/// whole's true error (which it overstates: the whole has twice the samples).
#[test]
fn the_halves_estimate_tracks_the_true_error() {
    let (reference, reference_variance) = common::reference();
    let filter = Denoiser::new(common::gpu(), DenoiserKind::Atrous).expect("compiles");
    let cancel = AtomicBool::new(false);
    let mut split = SplitRender::new(common::gpu(), &common::cornell(1, 11), TracerOptions::default())
        .expect("two tracers");
    println!("| spp | raw relMSE | à-trous half, true | estimate | estimate / true | à-trous whole, true |");
    println!("|---|---|---|---|---|---|");
    let mut worst: f64 = 1.0;
    assert!(split.advance(1, &cancel).expect("renders"));
    let unknown = split.denoise(&filter).expect("denoises").estimate;
    assert!(unknown.rel_mse.is_infinite(), "one sample per half: {unknown:?}");
    for spp in [4u32, 8, 16, 32, 64, 128, 256, 512, 1024] {
        assert!(split.advance(spp / 2, &cancel).expect("renders"));
        let result = split.denoise(&filter).expect("denoises");
        let half = filter
            .denoise(&DenoiseInput::from_render(split.a.accumulator(), &result.guides))
            .expect("denoises");
        let half_true = common::true_rel_mse(&half, &reference, &reference_variance);
        let whole_true = common::true_rel_mse(&result.image, &reference, &reference_variance);
        let raw_true = common::true_rel_mse(&result.raw.mean_image(), &reference, &reference_variance);
        let ratio = result.estimate.rel_mse / half_true;
        println!(
            "| {spp} | {raw_true:.5} | {half_true:.5} | {:.5} | {ratio:.2} | {whole_true:.5} |",
            result.estimate.rel_mse
        );
        worst = worst.max(ratio).max(1.0 / ratio);
    }
    assert!(worst <= 1.5, "the estimate strays from the true error by a factor {worst:.2}");
}
