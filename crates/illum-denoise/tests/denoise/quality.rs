//! What the à-trous filter does to images whose answer is known: a converged Cornell box, a
//! furnace, the 16-spp Cornell box against the converged one, and the halves' estimate of the
//! denoised image's error against its true error.

use std::sync::atomic::AtomicBool;

use illum_denoise::{AtrousDenoiser, AtrousSettings, DenoiseInput, Denoiser, DenoiserKind, SplitRender};
use illum_image::{RgbImage32, luminance};
use illum_pathtrace::TracerOptions;
use illum_scene::Scene;

use crate::common;

fn filter() -> AtrousDenoiser {
    AtrousDenoiser::new(common::gpu()).expect("compiles")
}

/// Size and samples per pixel of the converged render [`a_converged_image_is_not_moved`]
/// denoises: 65536 spp (the issue's) at 16 x 16, so that the render takes tens of seconds on
/// lavapipe rather than hours.
const CONVERGED_SIZE: u32 = 32;
const CONVERGED_SPP: u32 = 65536;
/// False-alarm rate of the whole converged-image test.
const CONVERGED_ALPHA: f64 = 1e-3;

/// A bound on the variance of a pixel's mean luminance from its channels' variances of the
/// mean: Var(sum w_c x_c) <= (sum w_c sigma_c)^2 (Cauchy-Schwarz; the channels of one path are
/// strongly correlated, so their covariances cannot be left out).
fn luminance_variance_bound(variance: [f32; 3]) -> f64 {
    let sigma = variance.map(|v| f64::from(v).max(0.0).sqrt());
    luminance(sigma.map(|s| s as f32)).powi(2)
}

/// A denoiser must not move a converged image: a 65536-spp Cornell box at 32 x 32 kept as two
/// independent halves A and B of 32768 spp; the denoised half D(A) is compared with the raw
/// half B in luminance (what the filter's edge stop compares), per pixel,
/// z = (L(D(A)) - L(B)) / sqrt(V_A + V_B), with V the luminance variance bound of the raw
/// halves' means. If the denoiser does not move the converged value, E D(A) = E B; D(A)
/// averages A's pixel with neighbours of its luminance, with weights summing to 1, so its
/// variance is taken as at most A's own (the printed mean z^2, 1 or below when that holds and
/// the bound is loose, shows it). Every pixel must pass the two-sided test at level
/// CONVERGED_ALPHA / pixels (Bonferroni over the pixels), so that a denoiser that leaves the
/// image alone fails with probability at most CONVERGED_ALPHA = 1e-3 whatever the correlation
/// between neighbouring pixels the filter makes (a binomial count of failures would assume them
/// independent). Power: the same D(A) 5% brighter in one 4 x 4 block must fail at 12 of its 16
/// pixels or more. The same test per channel (`z_test_pass_fraction`: each channel at level
/// CONVERGED_ALPHA / (3 pixels), |z| <= 5.10) must pass at every pixel too, with the same
/// false-alarm rate: a filter that moved colour between neighbours of one luminance would fail
/// it.
///
/// The denoised image is bounded (`illum_denoise::bound`): each channel of D(A) within 3.29
/// standard errors sigma_A of A. A denoiser that sat at that bound in a channel would make
/// |D(A) - B| up to 3.29 sigma_A + |A - B|, and so fail there with probability
/// P(z > 5.10 - 3.29 / sqrt 2) = 0.3% (sigma_A = sigma_B); the test prints how many channels
/// are at the bound, which says how much of the pass is the bound's and how much the filter's.
pub(crate) fn a_converged_image_is_not_moved(kind: DenoiserKind) {
    let started = std::time::Instant::now();
    let filter = Denoiser::new(common::gpu(), kind).expect("denoiser");
    let scene = common::cornell_sized(CONVERGED_SIZE, 1, 5);
    let mut split = SplitRender::new(common::gpu(), &scene, TracerOptions::default()).expect("two tracers");
    assert!(split.advance(CONVERGED_SPP / 2, &AtomicBool::new(false)).expect("renders"));
    let guides = split.a.guides(illum_pathtrace::guide_samples(split.spp_done())).expect("guides");
    let (a, b) = (split.a.accumulator(), split.b.accumulator());
    let input = DenoiseInput::from_render(a, &guides);
    let da = filter.denoise(&input).expect("denoises");
    let unbounded = unbounded(kind, &input);
    let (var_a, b_mean, var_b) = (a.variance_image(), b.mean_image(), b.variance_image());
    let pixels = da.pixels.len();
    let alpha = CONVERGED_ALPHA / pixels as f64;
    let z_critical = illum_image::inverse_normal_cdf(1.0 - alpha / 2.0);
    // Luminance z per pixel; a pixel of zero variance in both halves (the light, the black
    // outside the box: every sample the same) must keep its value up to f32 rounding.
    let failing = |image: &RgbImage32| {
        let (mut failures, mut z2, mut terms) = (0usize, 0.0, 0usize);
        for p in 0..pixels {
            let d = luminance(image.pixels[p]) - luminance(b_mean.pixels[p]);
            let v = luminance_variance_bound(var_a.pixels[p]) + luminance_variance_bound(var_b.pixels[p]);
            if v == 0.0 {
                failures += usize::from(d.abs() > 1e-6 * luminance(b_mean.pixels[p]).abs().max(1e-30));
                continue;
            }
            z2 += d * d / v;
            terms += 1;
            failures += usize::from(d.abs() / v.sqrt() > z_critical);
        }
        (failures, z2 / terms.max(1) as f64)
    };
    let at_bound = (0..pixels)
        .flat_map(|p| (0..3).map(move |c| (p, c)))
        .filter(|&(p, c)| {
            // Within f32 rounding of the noisy value (the bound clamps around the f32 mean).
            let x = a.pixel_mean(p)[c];
            let moved = (f64::from(da.pixels[p][c]) - x).abs();
            let radius = illum_denoise::BOUND_Z * a.pixel_variance_of_mean(p)[c].max(0.0).sqrt();
            radius > 0.0 && moved >= radius * (1.0 - 1e-3) - 1e-6 * x.abs()
        })
        .count();
    let channel_failing = |image: &RgbImage32| {
        pixels
            - (illum_image::z_test_pass_fraction(image, &var_a, &b_mean, &var_b, alpha).expect("sizes")
                * pixels as f64)
                .round() as usize
    };
    let channel_failures = channel_failing(&da);
    // The largest |z| of a channel, against the per-channel test's critical value.
    let worst_channel_z = (0..pixels)
        .flat_map(|p| (0..3).map(move |c| (p, c)))
        .map(|(p, c)| {
            let v = f64::from(var_a.pixels[p][c]).max(0.0) + f64::from(var_b.pixels[p][c]).max(0.0);
            let d = f64::from(da.pixels[p][c]) - f64::from(b_mean.pixels[p][c]);
            if v > 0.0 { d.abs() / v.sqrt() } else { 0.0 }
        })
        .fold(0.0, f64::max);
    let mut biased = da.clone();
    for y in 12..16 {
        for x in 12..16 {
            let p = y * CONVERGED_SIZE as usize + x;
            biased.pixels[p] = biased.pixels[p].map(|v| 1.05 * v);
        }
    }
    let ((failures, mean_z2), (biased_failures, _)) = (failing(&da), failing(&biased));
    let (unbounded_failures, unbounded_z2) = failing(&unbounded);
    println!(
        "{kind} without the bound: {unbounded_failures} of {pixels} pixels beyond in luminance (mean z^2 \
         {unbounded_z2:.3}); per channel {} pixels",
        channel_failing(&unbounded)
    );
    println!(
        "{kind}, converged ({CONVERGED_SPP} spp at {CONVERGED_SIZE} x {CONVERGED_SIZE}, {:.1} s): {failures} of {pixels} \
         pixels beyond |z| = {z_critical:.2} in luminance (mean z^2 {mean_z2:.3}); per channel {channel_failures} \
         pixels (largest |z| {worst_channel_z:.2}); {at_bound} of {} channels at the bound; 5% brighter in a 4 x 4 block: {biased_failures} of 16 \
         beyond",
        started.elapsed().as_secs_f64(),
        3 * pixels,
    );
    assert_eq!(failures, 0, "{kind} moved a converged image's luminance beyond its noise");
    assert_eq!(channel_failures, 0, "{kind} moved a converged image's colour beyond its noise");
    assert!(biased_failures >= 12, "{kind}: a 5% bias in a 4 x 4 block passes: no power");
}

/// The denoiser's own output, before the bound (printed beside the bounded one).
fn unbounded(kind: DenoiserKind, input: &DenoiseInput) -> RgbImage32 {
    match kind {
        DenoiserKind::Atrous => filter().denoise(input, &AtrousSettings::default()).expect("denoises").0,
        #[cfg(feature = "oidn")]
        DenoiserKind::Oidn => {
            illum_denoise::oidn::OidnDenoiser::new().expect("OIDN").denoise(input).expect("denoises")
        }
        #[cfg(not(feature = "oidn"))]
        DenoiserKind::Oidn => unreachable!("OIDN's tests exist only in builds with the feature"),
    }
}

#[test]
fn atrous_does_not_move_a_converged_image() {
    a_converged_image_is_not_moved(DenoiserKind::Atrous);
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
    let guides = tracer.guides(illum_pathtrace::guide_samples(tracer.spp_done())).expect("guides");
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
/// factor 1.6 of that half's true error at every spp, and not below the true error of the
/// denoised whole (the image a render writes, from twice the samples).
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
        assert!(
            result.estimate.rel_mse >= whole_true,
            "{spp} spp: estimate {} below the denoised whole's true error {whole_true}",
            result.estimate.rel_mse
        );
    }
    assert!(worst <= 1.6, "the estimate strays from the true error by a factor {worst:.2}");
}

/// The denoiser's halves on the Whitted scene, whose photon gather shrinks its radius with the
/// sample index: the second half starts at index 2^31, and counts its radius from there
/// (`gather_radius` in caustic_buffers.wgsl), so the halves are exchangeable. Each half's, and
/// the raw whole's, estimate tracks its true error; the denoised estimate is not below the
/// denoised whole's true error (docs/denoising.md's promise, which `--target-error` with
/// `--denoise` relies on). Counted from index 0, the second half gathered at a radius 36 times
/// smaller: the raw whole's true error was 0.100 against an estimate of 0.068, and the denoised
/// estimate fell below the true error.
#[test]
fn the_halves_of_a_whitted_render_are_exchangeable_and_their_estimates_honest() {
    let (width, height) = (96, 54);
    let (truth, truth_variance) = common::whitted_truth(width, height, 1024);
    let filter = Denoiser::new(common::gpu(), DenoiserKind::Atrous).expect("compiles");
    let cancel = AtomicBool::new(false);
    let scene = common::whitted(width, height, 32, 5);
    let mut split = SplitRender::new(common::gpu(), &scene, TracerOptions::default()).expect("two tracers");
    assert!(split.advance(16, &cancel).expect("renders"));
    let result = split.denoise(&filter).expect("denoises");
    let mut worst: f64 = 1.0;
    for (what, accumulator) in
        [("half A", split.a.accumulator()), ("half B", split.b.accumulator()), ("raw whole", &result.raw)]
    {
        let estimated = accumulator.estimated_rel_mse();
        let measured = common::true_rel_mse(&accumulator.mean_image(), &truth, &truth_variance);
        println!(
            "{what}: estimated relMSE {estimated:.3e}, true {measured:.3e}, est./true {:.2}",
            estimated / measured
        );
        worst = worst.max(estimated / measured).max(measured / estimated);
    }
    let whole_true = common::true_rel_mse(&result.image, &truth, &truth_variance);
    println!(
        "denoised: halves' estimate {:.3e}, the whole's true error {whole_true:.3e}",
        result.estimate.rel_mse
    );
    assert!(worst <= 1.5, "an estimate strays from its true error by a factor {worst:.2}");
    assert!(
        result.estimate.rel_mse >= whole_true,
        "the denoised estimate {} is below the denoised whole's true error {whole_true}",
        result.estimate.rel_mse
    );
}
