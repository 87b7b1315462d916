//! Open Image Denoise beside the à-trous filter, on the same 16-spp Cornell box and the same
//! guides (only in builds with the cargo feature `oidn`; docs/denoising-oidn.md says how to get the
//! library): its true error against the converged reference, per region, its cost in ms per
//! megapixel measured in the same run as à-trous's, and the halves' estimate of its error.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use illum_denoise::{DenoiseInput, Denoiser, DenoiserKind, SplitRender, halves_rel_mse};
use illum_image::{RgbImage32, luminance, median};
use illum_pathtrace::TracerOptions;

use crate::common;
use crate::quality::regions;

fn denoiser(kind: DenoiserKind) -> Denoiser {
    Denoiser::new(common::gpu(), kind).unwrap_or_else(|e| panic!("{kind}: {e}"))
}

/// Median wall milliseconds of 5 runs of `denoiser` on `input` after a warm-up, per megapixel.
fn ms_per_megapixel(denoiser: &Denoiser, input: &DenoiseInput) -> f64 {
    denoiser.denoise(input).expect("denoises");
    let mut ms: Vec<f64> = (0..5)
        .map(|_| {
            let started = Instant::now();
            denoiser.denoise(input).expect("denoises");
            started.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    let megapixels = f64::from(input.width()) * f64::from(input.height()) / 1e6;
    median(&mut ms) / megapixels
}

/// At 16 spp on the Cornell box (64 x 64) OIDN's true relMSE is at least 2.5 times below the
/// raw image's, like the à-trous filter's; the table prints both per region with their
/// luminance bias, and both filters' cost.
#[test]
fn at_16_spp_oidn_beside_atrous() {
    let (reference, reference_variance) = common::reference();
    let tracer = common::render(&common::cornell(16, 7));
    let guides = tracer.guides(illum_pathtrace::guide_samples(tracer.spp_done())).expect("guides");
    let input = DenoiseInput::from_render(tracer.accumulator(), &guides);
    let (atrous, oidn) = (denoiser(DenoiserKind::Atrous), denoiser(DenoiserKind::Oidn));
    let atrous_image = atrous.denoise(&input).expect("denoises");
    let oidn_image = oidn.denoise(&input).expect("denoises");
    let subset = |image: &RgbImage32, pixels: &[usize]| RgbImage32 {
        width: pixels.len() as u32,
        height: 1,
        pixels: pixels.iter().map(|&p| image.pixels[p]).collect(),
    };
    let bias = |image: &RgbImage32, pixels: &[usize]| {
        pixels.iter().map(|&p| luminance(image.pixels[p]) - luminance(reference.pixels[p])).sum::<f64>()
            / pixels.iter().map(|&p| luminance(reference.pixels[p])).sum::<f64>()
    };
    println!("| region | pixels | raw relMSE | à-trous relMSE | OIDN relMSE | à-trous bias | OIDN bias |");
    println!("|---|---|---|---|---|---|---|");
    let mut whole = (0.0, 0.0);
    for (name, pixels) in regions(&guides.albedo, &guides.normal) {
        let (r, v) = (subset(&reference, &pixels), subset(&reference_variance, &pixels));
        let error = |image: &RgbImage32| common::true_rel_mse(&subset(image, &pixels), &r, &v);
        let raw_error = error(&input.image);
        let oidn_error = error(&oidn_image);
        println!(
            "| {name} | {} | {raw_error:.4} | {:.4} | {oidn_error:.4} | {:+.2}% | {:+.2}% |",
            pixels.len(),
            error(&atrous_image),
            100.0 * bias(&atrous_image, &pixels),
            100.0 * bias(&oidn_image, &pixels)
        );
        if name == "whole image" {
            whole = (raw_error, oidn_error);
        }
    }
    let atrous_ms = ms_per_megapixel(&atrous, &input);
    let oidn_ms = ms_per_megapixel(&oidn, &input);
    println!(
        "cost at 64 x 64, ms per megapixel: à-trous {atrous_ms:.0}, OIDN {oidn_ms:.0} (OIDN / à-trous {:.2})",
        oidn_ms / atrous_ms
    );
    let gain = whole.0 / whole.1;
    assert!(gain >= 2.5, "relMSE raw {} / OIDN {} = {gain:.2}", whole.0, whole.1);
}

/// The halves' estimate of OIDN's error against its true error, from 4 to 1024 spp in total
/// (4: the fewest that give each half the 2 samples its variance needs). The estimate averages
/// two directions (D(A) against B, D(B) against A), so it is compared with the mean true relMSE
/// of the two denoised halves against the converged reference. It must be within a factor 1.6
/// of it at every spp (as the à-trous estimate), and not below the true error of the denoised
/// whole, the image a render writes.
///
/// Beside it, the cause of the former 3-to-13-fold overstatement below 64 spp: the same terms
/// divided by the raw mean of both halves alone (the former denominator, correlated with the
/// other half: see `illum_denoise::estimate`) and by the reference's values.
#[test]
fn the_halves_estimate_of_oidns_error() {
    let (reference, reference_variance) = common::reference();
    let filter = denoiser(DenoiserKind::Oidn);
    let cancel = AtomicBool::new(false);
    let mut split = SplitRender::new(common::gpu(), &common::cornell(1, 11), TracerOptions::default())
        .expect("two tracers");
    println!(
        "| spp | raw relMSE | OIDN halves, true | estimate | estimate / true | raw-mean denominator / true | \
         reference denominator / true | OIDN whole, true | OIDN halves without the bound, true |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut worst: f64 = 1.0;
    for spp in [4u32, 8, 16, 32, 64, 128, 256, 512, 1024] {
        assert!(split.advance(spp / 2, &cancel).expect("renders"));
        let result = split.denoise(&filter).expect("denoises");
        let (a, b) = (split.a.accumulator(), split.b.accumulator());
        let da = filter.denoise(&DenoiseInput::from_render(a, &result.guides)).expect("denoises");
        let db = filter.denoise(&DenoiseInput::from_render(b, &result.guides)).expect("denoises");
        let true_error = |image: &RgbImage32| common::true_rel_mse(image, &reference, &reference_variance);
        let halves_true = 0.5 * (true_error(&da) + true_error(&db));
        let oidn = illum_denoise::oidn::OidnDenoiser::new().expect("OIDN");
        let unbounded_true = 0.5
            * (true_error(&oidn.denoise(&DenoiseInput::from_render(a, &result.guides)).expect("denoises"))
                + true_error(
                    &oidn.denoise(&DenoiseInput::from_render(b, &result.guides)).expect("denoises"),
                ));
        let whole_true = true_error(&result.image);
        let with = |den: &RgbImage32| {
            0.5 * (halves_rel_mse(&da, &b.mean_image(), &b.variance_image(), den)
                + halves_rel_mse(&db, &a.mean_image(), &a.variance_image(), den))
        };
        let raw_mean = result.raw.mean_image();
        let ratio = result.estimate.rel_mse / halves_true;
        println!(
            "| {spp} | {:.5} | {halves_true:.5} | {:.5} | {ratio:.2} | {:.2} | {:.2} | {whole_true:.5} | \
             {unbounded_true:.5} |",
            true_error(&raw_mean),
            result.estimate.rel_mse,
            with(&raw_mean) / halves_true,
            with(&reference) / halves_true,
        );
        // A ratio of 0 or below (an estimate of no error or less) strays infinitely.
        worst = worst.max(if ratio > 0.0 { ratio.max(1.0 / ratio) } else { f64::INFINITY });
        assert!(
            result.estimate.rel_mse >= whole_true,
            "{spp} spp: estimate {} below the denoised whole's true error {whole_true}",
            result.estimate.rel_mse
        );
    }
    assert!(worst <= 1.6, "the estimate strays from the true error by a factor {worst:.2}");
}

/// Open Image Denoise, bounded as every denoiser is (`illum_denoise::bound`), leaves a
/// converged image within its noise (without the bound it moved 213 of 1024 pixels beyond
/// |z| = 4.90: docs/denoising.md, docs/denoising-oidn.md).
#[test]
fn oidn_does_not_move_a_converged_image() {
    crate::quality::a_converged_image_is_not_moved(DenoiserKind::Oidn);
}
