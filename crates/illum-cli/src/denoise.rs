//! `render --denoise`: a path-traced render kept as two independent halves, denoised, with the
//! denoised image's error estimated from the halves (illum-denoise, docs/denoising.md).
//!
//! With an error target or a time budget the halves advance in rounds; after each round the
//! image is denoised and the stop rules are checked with the denoised image's estimated error,
//! so `--target-error` stops at the error of what is written. Each round pays the filter three
//! times, so rounds are few: each is sized to land on the rules ([`next_half`]): the spp that
//! the error's fall over the last two rounds predicts for the target, or, when the time budget
//! ends the render first, the rest of the budget in one round. An spp target alone is one round.
//! An spp target is rounded up to an even number (both halves take the same samples).
//!
//! The time budget counts the sampling, and the filter's time comes on top (the summary says how
//! much); a round that runs into the budget samples in shrinking steps and ends there. A
//! denoised render then has about the samples a raw render of the same budget has, so its image
//! is the nearer the truth, which a budget that also paid the filter could not promise (on
//! lavapipe the filter of a 512 x 512 image takes longer than the default 5 s budget).

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

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
    if let Some(budget) = rules.time_budget {
        println!(
            "the time budget ({} s) counts the sampling; each round's filter adds its own time",
            budget.as_secs_f64()
        );
    }
    let mut last: Option<Denoised> = None;
    let mut rounds: Vec<Round> = Vec::new();
    // Seconds spent sampling, over the rounds: what the time budget counts.
    let mut sampling = 0.0;
    let reason = loop {
        let target = half_target.map_or(half, |t| half.min(t));
        let started = Instant::now();
        if !advance(&mut split, target, rules.time_budget.map(|b| b.as_secs_f64() - sampling), cancel)? {
            break StopReason::Cancelled;
        }
        let tracing = started.elapsed().as_secs_f64();
        sampling += tracing;
        let denoised = split.denoise(&filter)?;
        let error = denoised.estimate.relative_error();
        let status = Status {
            spp_done: split.spp_done(),
            samples: denoised.raw.total_samples(),
            run_samples: denoised.raw.total_samples(),
            elapsed: Duration::from_secs_f64(sampling),
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
        rounds.push(Round { half: target, error: status.relative_error, tracing });
        last = Some(denoised);
        if let Some(reason) = rules.check(&status) {
            break reason;
        }
        half = next_half(&rounds, rules, sampling);
    };
    let Some(result) = last else {
        eprintln!("error: stopped before the first round of the denoised render: nothing was written");
        return Ok(None);
    };
    let seconds = clock.elapsed().as_secs_f64();
    write(request, &split, &result, reason, seconds)?;
    println!(
        "{}: {}x{}, {} spp in two halves in {} round{}, denoised ({}), {:.2} s (sampling {:.2} s; the last \
         round's filter {:.3} s, guides {:.3} s), estimated relative error {:.4} denoised, {:.4} raw",
        scene.name,
        scene.camera.width,
        scene.camera.height,
        split.spp_done(),
        rounds.len(),
        if rounds.len() == 1 { "" } else { "s" },
        denoiser,
        seconds,
        sampling,
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

/// Advances both halves to `half` samples per pixel each; with `seconds` (what is left of the
/// time budget), in steps that each take about half of what is left at the pace measured so far
/// (one sample per half while nothing is measured or little is left), ending once the sampling
/// has taken them: a round ends at the budget however the last round misjudged the cost per
/// sample (the filter, the costly part, runs once per round). False when cancelled.
fn advance(
    split: &mut SplitRender,
    half: u32,
    seconds: Option<f64>,
    cancel: &AtomicBool,
) -> anyhow::Result<bool> {
    let Some(seconds) = seconds else { return Ok(split.advance(half, cancel)?) };
    let started = Instant::now();
    let first = split.spp_done() / 2;
    loop {
        let (done, elapsed) = (split.spp_done() / 2, started.elapsed().as_secs_f64());
        if done >= half || elapsed >= seconds {
            return Ok(true);
        }
        let per_sample = (done > first).then(|| elapsed / f64::from(done - first));
        let step = per_sample.map_or(1.0, |p| (0.5 * (seconds - elapsed) / p).floor().max(1.0));
        let next = (f64::from(done) + step).min(f64::from(half)) as u32;
        if !split.advance(next, cancel)? {
            return Ok(false);
        }
    }
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

/// One round of a denoised render: its samples per half after it, the denoised image's
/// estimated error then (`None` while unknown), and its seconds tracing.
#[derive(Clone, Copy, Debug)]
struct Round {
    half: u32,
    error: Option<f64>,
    tracing: f64,
}

/// The samples per half the next round aims at, after `rounds` (at least one), `sampling`
/// seconds of sampling into the render:
/// - for an error target, the spp at which the error reaches it: the error falls as
///   spp^-slope, the slope measured over the last two rounds (between 1/2, the raw image's, and
///   1, a denoised image's fall where the filter's bias shrinks with its noise), 1/2 before two
///   rounds are known, with a tenth to spare, so that one round usually lands on the target;
///   at most 8 times the last round's (a prediction from few samples can be far off);
/// - for a time budget, when the sampling reaches it (at the last round's cost per sample)
///   before the error target's spp, or there is no error target: the rest of the budget, in one
///   round ([`advance`] ends it at the budget), so `u32::MAX`;
/// - else, or while the error is unknown, twice the last round's.
///
/// Always more than the last round's (a round of nothing would loop).
fn next_half(rounds: &[Round], rules: &StopRules, sampling: f64) -> u32 {
    let last = *rounds.last().expect("a round before the next");
    let before = rounds.iter().rev().nth(1).map_or(0, |r| r.half);
    let doubled = f64::from(last.half) * 2.0;
    let most = f64::from(last.half.saturating_mul(8));
    let predicted = match (rules.target_error, last.error) {
        (Some(target), Some(error)) => {
            let earlier = rounds.iter().rev().nth(1).and_then(|r| r.error.map(|e| (r.half, e)));
            let slope = earlier
                .filter(|&(h, e)| h < last.half && e > error && error > 0.0)
                .map(|(h, e)| ((e / error).ln() / (f64::from(last.half) / f64::from(h)).ln()).clamp(0.5, 1.0))
                .unwrap_or(0.5);
            Some(f64::from(last.half) * (error / target).powf(1.0 / slope) * 1.1)
        }
        _ => None,
    };
    let budgeted = rules.time_budget.and_then(|budget| {
        let per_sample = last.tracing / f64::from(last.half.saturating_sub(before).max(1));
        (per_sample > 0.0).then(|| f64::from(last.half) + (budget.as_secs_f64() - sampling) / per_sample)
    });
    let half = match (predicted, budgeted) {
        (Some(p), Some(b)) if b <= p => f64::from(u32::MAX),
        (Some(p), _) => p.min(most),
        (None, Some(_)) if rules.target_error.is_none() => f64::from(u32::MAX),
        _ => doubled,
    };
    (half.ceil().min(f64::from(u32::MAX)) as u32).max(last.half.saturating_add(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn round(half: u32, error: f64) -> Round {
        Round { half, error: Some(error), tracing: f64::from(half) * 0.1 }
    }

    /// The error target: one round from the measured fall lands on it, where doubling took
    /// three (the Cornell box's denoised errors at 4, 8, 16 and 32 spp fell from 0.105 to
    /// 0.022, about spp^-0.8; the target 0.03).
    #[test]
    fn a_round_aims_at_the_spp_that_reaches_the_error_target() {
        let rules = StopRules { target_error: Some(0.03), ..Default::default() };
        let rounds = [round(2, 0.1048), round(4, 0.0574)];
        let next = next_half(&rounds, &rules, 0.0);
        // Slope ln(0.1048 / 0.0574) / ln 2 = 0.87: 4 (0.0574 / 0.03)^(1 / 0.87) 1.1 = 9.8.
        assert_eq!(next, 10);
        let reached = 0.0574 * (f64::from(next) / 4.0).powf(-0.87);
        assert!(reached <= 0.03, "{reached}");
        // One round known: the raw image's slope, 1/2 (more samples than needed, never fewer).
        assert_eq!(next_half(&rounds[..1], &rules, 0.0), 16);
        // No error yet: doubling; an error already far above the target: at most 8 times.
        let unknown = [Round { error: None, ..round(2, 0.0) }];
        assert_eq!(next_half(&unknown, &rules, 0.0), 4);
        assert_eq!(next_half(&[round(2, 10.0)], &rules, 0.0), 16);
        // An error that rose (noise in the estimate) does not make a slope: 1/2.
        let rose = [round(2, 0.05), round(4, 0.06)];
        assert_eq!(next_half(&rose, &rules, 0.0), 18);
    }

    /// With a time budget, the next round samples the rest of it ([`advance`] ends the round at
    /// the budget) when the error target would come later or there is none; and a round always
    /// advances by at least one sample.
    #[test]
    fn a_round_samples_the_rest_of_the_time_budget() {
        let rules = StopRules { time_budget: Some(Duration::from_secs(10)), ..Default::default() };
        assert_eq!(next_half(&[round(4, 0.1)], &rules, 5.8), u32::MAX);
        // With an error target, the budget's end at 0.1 s a sample per half (2 + 9.8 / 0.1 = 100)
        // comes before the target's 2 (0.1048 / 0.01)^2 1.1 = 242...
        let far = StopRules { target_error: Some(0.01), ..rules };
        assert_eq!(next_half(&[round(2, 0.1048)], &far, 0.2), u32::MAX);
        // ... and the target when it comes first (2 (0.1048 / 0.09)^2 1.1 = 3.0), capped at 8
        // times the last round (0.02: 60, capped at 16).
        let near = StopRules { target_error: Some(0.09), ..rules };
        assert_eq!(next_half(&[round(2, 0.1048)], &near, 0.2), 3);
        let default = StopRules { target_error: Some(0.02), ..rules };
        assert_eq!(next_half(&[round(2, 0.1048)], &default, 0.2), 16);
        // The cost per sample is the last round's own: 36 samples in 3.6 s after 4 in 0.4 s, so
        // the budget's end (40 + 6 / 0.1 = 100) comes before the target's 40 (0.05 / 0.02)^2 1.1.
        let rounds = [round(4, 0.1), Round { half: 40, error: Some(0.05), tracing: 3.6 }];
        assert_eq!(next_half(&rounds, &default, 4.0), u32::MAX);
    }
}
