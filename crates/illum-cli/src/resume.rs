//! `render --resume FILE.exr`: the settings a checkpoint supplies, what it must match to be
//! continued as the flags ask, and loading it into the tracer so that the result equals a
//! straight render (`illum_pathtrace::checkpoint`).

use std::path::Path;

use anyhow::bail;
use illum_pathtrace::checkpoint::Checkpoint;
use illum_pathtrace::{PathTracer, Sequence, StopRules, TracerOptions};
use illum_scene::Scene;

use crate::SceneArgs;
use crate::render_args::RenderArgs;

/// Fills the image-changing settings not given on the command line from a checkpoint's
/// metadata, so that `--resume FILE` needs only the scene file and the new target.
pub(crate) fn fill_from_checkpoint(
    checkpoint: &Checkpoint,
    settings: &mut SceneArgs,
    (sequence, replicates): (&mut Option<Sequence>, &mut Option<bool>),
    caustics: &mut Option<bool>,
) {
    let get = |key: &str| checkpoint.metadata.get(key);
    settings.width = settings.width.or(Some(checkpoint.accumulator.width));
    settings.height = settings.height.or(Some(checkpoint.accumulator.height));
    settings.bounces = settings.bounces.or_else(|| get("bounces")?.parse().ok());
    settings.seed = settings.seed.or_else(|| get("seed")?.parse().ok());
    settings.sampling = settings.sampling.or_else(|| get("sampling")?.parse().ok());
    let stored = get("sequence").and_then(TracerOptions::parse_sequence_label);
    *sequence = sequence.or(stored.map(|(sequence, _)| sequence));
    *replicates = replicates.or(stored.map(|(_, replicates)| replicates));
    *caustics = caustics.or_else(|| crate::on_off_arg(get("caustics")?).ok());
}

/// The caustic method a checkpoint's estimators name: `manifold` when its token list holds the
/// solve's token, else none (the scene file's or the flag's then decides, and the estimators'
/// key comparison refuses a mismatch).
pub(crate) fn caustic_method_of(checkpoint: &Checkpoint) -> Option<illum_scene::CausticMethod> {
    let key = checkpoint.metadata.get(illum_pathtrace::metadata::ESTIMATORS)?;
    let manifold = illum_pathtrace::Estimator::ManifoldNee.token();
    key.split_whitespace().any(|t| t == manifold).then_some(illum_scene::CausticMethod::Manifold)
}

/// Checks that `checkpoint`, read from `path`, can be continued as the flags ask.
pub(crate) fn check_resume(
    args: &RenderArgs,
    path: &Path,
    checkpoint: Checkpoint,
    scene: &Scene,
    options: TracerOptions,
    rules: &StopRules,
) -> anyhow::Result<Checkpoint> {
    checkpoint.header().check_matches(path, scene, options).map_err(anyhow::Error::msg)?;
    if let Some(range) = &args.sample_range
        && range.start != checkpoint.sample_start
    {
        bail!(
            "--sample-range {}..{}: {} holds samples from index {}, so a continued range must start there",
            range.start,
            range.end,
            path.display(),
            checkpoint.sample_start
        );
    }
    if let Some(target) = rules.spp
        && target < checkpoint.spp_done
    {
        let asked = if args.sample_range.is_some() || args.settings.spp.is_some() {
            "asked for"
        } else {
            "of the scene file's [pathtrace] spp"
        };
        bail!(
            "{} already holds {} spp, more than the {target} {asked}: nothing to continue (give a larger --spp{})",
            path.display(),
            checkpoint.spp_done,
            if args.sample_range.is_some() { " or a longer --sample-range" } else { "" }
        );
    }
    if checkpoint.sample_start != 0 && args.sample_range.is_none() {
        bail!(
            "{} is a part of a split render (samples from index {}): continue it with --sample-range {}..END",
            path.display(),
            checkpoint.sample_start,
            checkpoint.sample_start
        );
    }
    Ok(checkpoint)
}

/// Loads `checkpoint` (read from `path`) into the tracer, from where the render goes on.
pub(crate) fn restore(
    tracer: &mut PathTracer,
    path: &Path,
    checkpoint: Checkpoint,
    rules: &StopRules,
) -> anyhow::Result<()> {
    tracer.set_sample_offset(checkpoint.sample_start);
    println!(
        "resuming {}: {} spp done{}",
        path.display(),
        checkpoint.spp_done,
        checkpoint
            .partial_pass
            .map_or(String::new(), |(spp, rows)| format!(", and {rows} rows of a pass of {spp} spp"))
    );
    // Going on past the file's spp, to an spp target.
    let continues = rules.spp.is_some_and(|target| target > checkpoint.spp_done);
    match checkpoint.aligned_prefix {
        // The samples end inside a chunk: start again from the last chunk boundary, so that the
        // chunk is summed whole, as a straight render sums it (illum_pathtrace::checkpoint).
        // Only when the render goes on to more spp: otherwise nothing may be taken away.
        Some((prefix, spp)) if checkpoint.partial_pass.is_none() && continues => {
            println!(
                "  (going on from {spp} spp, the last chunk boundary, so that the result equals a straight render)"
            );
            tracer.restore(prefix, spp, None, None)?
        }
        prefix => {
            let chunk = illum_pathtrace::CHUNK_SAMPLES;
            if continues
                && prefix.is_none()
                && !(checkpoint.sample_start + checkpoint.spp_done).is_multiple_of(chunk)
            {
                println!(
                    "  (the file ends inside a chunk of {chunk} samples and has no copy of its statistics at the \
                     chunk boundary: the result will differ from a straight render by f32 rounding, about 1e-7)"
                );
            }
            tracer.restore(checkpoint.accumulator, checkpoint.spp_done, checkpoint.partial_pass, prefix)?
        }
    }
    Ok(())
}
