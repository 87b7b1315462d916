//! `render --denoise`: a path-traced render kept as two independent halves, denoised, with the
//! denoised image's error estimated from the halves (illum-denoise, docs/denoising.md).
//!
//! With an error target or a time budget the halves advance in rounds, each doubling their spp
//! (1, 2, 4, ... per half); after each round the image is denoised and the stop rules are
//! checked with the denoised image's estimated error, so `--target-error` stops at the error of
//! what is written. An spp target alone is one round. An spp target is
//! rounded up to an even number (both halves take the same samples).

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use illum_denoise::Denoiser;
pub use illum_denoise::DenoiserKind;
use illum_denoise::split::{Denoised, SplitRender};
use illum_gpu::GpuContext;
use illum_image::{Encoding, Exposure, F32Layer, RgbImage32, save_exr_with_f32_layers, save_png};
use illum_pathtrace::{Status, StopReason, StopRules, TracerOptions};
use illum_scene::Scene;

use crate::{OutputFormat, output_format};

/// Parses `--denoise` (`atrous` or `oidn`).
pub fn denoiser_arg(text: &str) -> Result<DenoiserKind, String> {
    text.parse()
}

/// What a denoised render needs.
pub struct DenoiseRequest<'a> {
    pub gpu: &'a GpuContext,
    pub scene: &'a Scene,
    pub options: TracerOptions,
    pub rules: StopRules,
    pub denoiser: DenoiserKind,
    pub cancel: &'a AtomicBool,
    /// Checked already (`check_outputs`).
    pub outputs: &'a [PathBuf],
    pub encoding: Option<Encoding>,
    pub exposure: Option<Exposure>,
}

/// Renders, denoises and writes; returns why it stopped and the denoised image's estimated
/// relative error. `Ok(None)` when cancelled before the first round ended (nothing written).
pub fn render_denoised(request: &DenoiseRequest) -> anyhow::Result<Option<(StopReason, f64)>> {
    let DenoiseRequest { gpu, scene, options, rules, denoiser, cancel, outputs, .. } = request;
    let clock = Instant::now();
    let filter = Denoiser::new(gpu, *denoiser).map_err(|e| anyhow::anyhow!("--denoise {denoiser}: {e}"))?;
    let mut split = SplitRender::new(gpu, scene, *options)?;
    let half_target = rules.spp.map(|spp| spp.div_ceil(2).max(1));
    // Rounds are for the error and time rules; an spp target alone is one round. The first
    // round has 2 samples per half: with 1 the halves' estimate is unknown (infinite), and a time
    // budget spent in that round would write an image whose error is "inf".
    let mut half = match half_target {
        Some(target) if rules.target_error.is_none() && rules.time_budget.is_none() => target,
        _ => 2u32,
    };
    let mut last: Option<Denoised> = None;
    let reason = loop {
        let target = half_target.map_or(half, |t| half.min(t));
        if !split.advance(target, cancel)? {
            break StopReason::Cancelled;
        }
        let denoised = split.denoise(&filter)?;
        let error = denoised.estimate.relative_error();
        let status = Status {
            spp_done: split.spp_done(),
            samples: denoised.raw.total_samples(),
            run_samples: denoised.raw.total_samples(),
            elapsed: clock.elapsed(),
            relative_error: denoised.estimate.rel_mse.is_finite().then_some(error),
            ..Status::default()
        };
        eprintln!(
            "progress: {:.1} s  {} spp  denoised error {}  (raw {:.4})",
            clock.elapsed().as_secs_f64(),
            status.spp_done,
            status.relative_error.map_or("unknown (below 2 spp per half)".to_owned(), |e| format!("{e:.4}")),
            denoised.raw.estimated_relative_error()
        );
        last = Some(denoised);
        if let Some(reason) = rules.check(&status) {
            break reason;
        }
        half = half.saturating_mul(2);
    };
    let Some(result) = last else {
        eprintln!("error: stopped before the first round of the denoised render: nothing was written");
        return Ok(None);
    };
    let seconds = clock.elapsed().as_secs_f64();
    write(request, &split, &result, reason, seconds)?;
    println!(
        "{}: {}x{}, {} spp in two halves, denoised ({}), {:.2} s (filter {:.3} s, guides {:.3} s), estimated \
         relative error {:.4} denoised, {:.4} raw",
        scene.name,
        scene.camera.width,
        scene.camera.height,
        split.spp_done(),
        denoiser,
        seconds,
        result.filter_seconds,
        result.guide_seconds,
        result.estimate.relative_error(),
        result.raw.estimated_relative_error()
    );
    for output in outputs.iter() {
        println!("wrote {}", output.display());
    }
    Ok(Some((reason, result.estimate.relative_error())))
}

/// The PNG of the denoised image; the EXR of the denoised image with layers `noisy` (the raw
/// image of both halves), `albedo` and `normal`, and the metadata of a path-traced render with
/// `spp` (both halves), `estimated_relative_error` (the denoised image's, from the halves),
/// `raw_estimated_relative_error`, `denoiser` and `guide_samples`.
fn write(
    request: &DenoiseRequest,
    split: &SplitRender,
    result: &Denoised,
    reason: StopReason,
    seconds: f64,
) -> anyhow::Result<()> {
    let mut metadata = illum_pathtrace::metadata::exr_metadata(
        &split.a,
        seconds,
        Some(reason),
        "render example (--denoise)",
    );
    let set = |fields: &mut Vec<(String, String)>, key: &str, value: String| match fields
        .iter_mut()
        .find(|(k, _)| k == key)
    {
        Some(field) => field.1 = value,
        None => fields.push((key.to_owned(), value)),
    };
    let fields = &mut metadata.fields;
    set(fields, "spp", split.spp_done().to_string());
    set(fields, "estimated_relative_error", result.estimate.relative_error().to_string());
    set(fields, "raw_estimated_relative_error", result.raw.estimated_relative_error().to_string());
    set(fields, "dropped_samples", result.raw.dropped_samples().to_string());
    set(fields, "denoiser", request.denoiser.to_string());
    set(fields, "guide_samples", result.guides.samples.to_string());
    set(fields, "sample_start", format!("0 and {} (two halves)", illum_denoise::split::SECOND_HALF));
    let rgb_layer = |name: &str, channels: [&str; 3], pixels: &[[f32; 3]]| F32Layer {
        name: name.to_owned(),
        channels: (0..3).map(|c| (channels[c].to_owned(), pixels.iter().map(|p| p[c]).collect())).collect(),
    };
    for output in request.outputs {
        match output_format(output)? {
            OutputFormat::Png => {
                let image: &RgbImage32 = &result.image;
                let stops = request.exposure.unwrap_or_default().stops_for(image);
                save_png(output, image, stops, request.encoding.unwrap_or_default())?
            }
            OutputFormat::Exr => save_exr_with_f32_layers(
                output,
                &result.image,
                &metadata,
                vec![
                    rgb_layer("noisy", ["R", "G", "B"], &result.raw.mean_image().pixels),
                    rgb_layer("albedo", ["R", "G", "B"], &result.guides.albedo),
                    rgb_layer("normal", ["X", "Y", "Z"], &result.guides.normal),
                ],
            )?,
        }
    }
    Ok(())
}
