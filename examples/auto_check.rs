//! The ladder's check of `render --renderer auto`: for each scene and each target error, runs
//! `render --renderer auto --target-error E` as a user does, then measures the relative error of
//! the image it wrote against a converged path-traced truth and the wall time it took, and
//! prints predicted against measured.
//!
//! ```text
//! cargo run --release --example auto_check -- [--targets 0.3,0.1,0.03,0.01] [--scenes whitted,cornell]
//!     [--truth-spp 8192] [--out out/auto-check]
//! ```
//! Scenes: `scenes/whitted.toml` at 320x180 (the ladder's size) and `scenes/cornell.toml` at
//! 192x192, both larger than the planner's 128-pixel pilot, so the check covers its scaling
//! from the pilot's size to the render's. The truth is rendered once per scene and cached in
//! OUT (as the ladder's). The measured error is the square root of the image's relMSE against
//! the truth less the truth's own estimated relMSE (its noise, which the image does not have).
//!
//! Output: OUT/auto-check.md (the table, with the machine and the truth), and the images.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, bail};
use clap::Parser;
use illum::image::{load_exr, rel_mse};
use illum::scene::{Bounces, Overrides, Scene};
use illum_lab::reference::{Reference, cached_reference, load_reference};
use illum_lab::report::{host_cpu, markdown_table, write_text};

#[derive(Parser, Debug)]
#[command(
    about = "Checks render --renderer auto: predicted against measured error and time, per scene and target"
)]
struct Args {
    /// Target relative errors (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "0.3,0.1,0.03,0.01")]
    targets: Vec<f64>,
    /// The scenes to check, by name (comma-separated; `whitted`, `cornell`).
    #[arg(long, value_delimiter = ',', default_value = "whitted,cornell")]
    scenes: Vec<String>,
    /// Samples per pixel of each scene's truth.
    #[arg(long, default_value_t = 8192)]
    truth_spp: u32,
    /// A truth EXR (repeatable) to use instead of rendering one: a path-traced render of one of
    /// the scenes at its size with bounces unbounded (and the caustic's light tracer where the
    /// scene has one), e.g. made with `render --resume` in steps on a busy machine.
    #[arg(long)]
    truth: Vec<PathBuf>,
    /// Folder for the truths, the images and the table.
    #[arg(long, default_value = "out/auto-check")]
    out: PathBuf,
}

/// The scenes checked and their sizes.
const SCENES: [(&str, u32, u32); 2] = [("scenes/whitted.toml", 320, 180), ("scenes/cornell.toml", 192, 192)];

fn main() {
    illum_cli::main_with(run);
}

/// The value of `key=` in the `auto plan:` line `render` prints.
fn field<'a>(output: &'a str, key: &str) -> Option<&'a str> {
    let line = output.lines().find(|l| l.starts_with("auto plan:"))?;
    line.split_whitespace().find_map(|f| f.strip_prefix(key)?.strip_prefix('='))
}

/// The text after `prefix` on the first line starting with it.
fn line_after<'a>(output: &'a str, prefix: &str) -> Option<&'a str> {
    output.lines().find_map(|l| l.trim_start().strip_prefix(prefix))
}

/// The truth among `files` that shows `truth_scene` (by its EXR's scene name), checked to be
/// a converged render of it: its size and content (`load_reference`), unbounded bounces and the
/// caustic's light tracer as the truth scene has it.
fn given_truth(files: &[PathBuf], truth_scene: &Scene) -> anyhow::Result<Option<Reference>> {
    for path in files {
        let (_, attributes) = load_exr(path)?;
        let shows = illum::image::ExrMetadata::from_attributes(path, &attributes)?.map(|m| m.scene);
        if shows.as_deref() != Some(truth_scene.name.as_str()) {
            continue;
        }
        let reference = load_reference(path, truth_scene)?;
        let caustics = if truth_scene.pathtrace.caustics { "on" } else { "off" };
        for (key, want) in [("bounces", "unbounded"), ("caustics", caustics)] {
            if reference.metadata.get(key) != Some(want) {
                bail!(
                    "{}: a truth needs illum.{key} = {want}, not {:?}",
                    path.display(),
                    reference.metadata.get(key)
                );
            }
        }
        return Ok(Some(reference));
    }
    Ok(None)
}

fn run(args: Args) -> anyhow::Result<()> {
    if args.targets.iter().any(|t| !(*t > 0.0 && t.is_finite())) {
        bail!("--targets {:?}: every target must be a finite number above 0", args.targets);
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let render = std::env::current_exe()?.with_file_name(format!("render{}", std::env::consts::EXE_SUFFIX));
    if !render.exists() {
        bail!("{} is missing: build it first (cargo build --release --examples)", render.display());
    }
    let name = |file: &str| Path::new(file).file_stem().map(|s| s.to_string_lossy().into_owned());
    let known: Vec<String> = SCENES.iter().filter_map(|(file, _, _)| name(file)).collect();
    if let Some(unknown) = args.scenes.iter().find(|s| !known.contains(s)) {
        bail!("--scenes {unknown}: not a scene this check knows; it knows {}", known.join(", "));
    }
    let mut rows = Vec::new();
    let mut truths = Vec::new();
    let mut adapter = String::new();
    for (file, width, height) in SCENES {
        if !name(file).is_some_and(|n| args.scenes.contains(&n)) {
            continue;
        }
        let mut scene = Scene::load(Path::new(file))?;
        scene.apply_overrides(
            &Overrides { width: Some(width), height: Some(height), ..Default::default() },
            "auto check",
        )?;
        let truth_scene = illum_auto::settings::truth_scene(&scene, Bounces::Unbounded);
        let gpu = illum_cli::gpu()?;
        adapter = gpu.adapter_info.name.clone();
        let truth = match given_truth(&args.truth, &truth_scene)? {
            Some(truth) => truth,
            None => {
                let progress = illum_cli::progress::RenderProgress::new();
                let on_step = &mut |t: &_, p: &_| progress.update(t, p);
                let truth = cached_reference(
                    &gpu,
                    &truth_scene,
                    args.truth_spp,
                    &args.out,
                    "auto check truth",
                    on_step,
                )?;
                progress.finish();
                truth
            }
        };
        drop(gpu);
        // The cache's truths carry their estimated relMSE; a `render` EXR its estimated relative error.
        let truth_noise = [
            truth.estimated_rel_mse,
            truth.metadata.get("estimated_relative_error").and_then(|v| v.parse::<f64>().ok()).map_or(f64::NAN, |e| e * e),
        ]
        .into_iter()
        .find(|v| v.is_finite())
        .context("the truth does not say its own error (illum.estimated_rel_mse or illum.estimated_relative_error)")?;
        truths.push(format!(
            "{} at {width}x{height}: {} spp, bounces unbounded, caustic light tracer {}, its own estimated relative \
             error {:.4}",
            scene.name,
            truth.spp,
            if truth_scene.pathtrace.caustics { "on" } else { "off" },
            truth_noise.sqrt()
        ));
        for &target in &args.targets {
            let image_path = args.out.join(format!("{}-{target}.exr", scene.name));
            let started = Instant::now();
            let output = Command::new(&render)
                .args([file, "--renderer", "auto", "--target-error", &target.to_string()])
                .args(["--width", &width.to_string(), "--height", &height.to_string()])
                .arg("-o")
                .arg(&image_path)
                .env("RUST_LOG", "warn")
                .output()
                .with_context(|| format!("running {}", render.display()))?;
            let wall = started.elapsed().as_secs_f64();
            let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
            let stderr = String::from_utf8_lossy(&output.stderr);
            if !output.status.success() {
                // A refused target is a result too: its reason goes in the table.
                let reason =
                    stderr.lines().filter(|l| !l.starts_with("progress")).collect::<Vec<_>>().join(" ");
                println!("{} {target}: refused: {reason}", scene.name);
                rows.push(vec![
                    scene.name.clone(),
                    target.to_string(),
                    format!("refused: {}", reason.trim_start_matches("error: ")),
                    "-".into(),
                    "-".into(),
                    "-".into(),
                    "-".into(),
                    "-".into(),
                    format!("{wall:.1}"),
                ]);
                continue;
            }
            let number = |key: &str| -> anyhow::Result<f64> {
                field(&stdout, key)
                    .and_then(|v| v.parse().ok())
                    .with_context(|| format!("render printed no {key} in its `auto plan:` line:\n{stdout}"))
            };
            let predicted_error = number("predicted_error")?;
            let predicted_seconds = number("predicted_seconds")?;
            let pilot_seconds = number("pilot_seconds")?;
            let choice = line_after(&stdout, "choice: ")
                .and_then(|l| l.split(": predicted").next())
                .unwrap_or("?")
                .to_owned();
            let rendered = line_after(&stdout, "auto: rendered in ")
                .and_then(|l| l.split(' ').next())
                .and_then(|v| v.parse::<f64>().ok())
                .context("render printed no `auto: rendered in` line")?;
            let (image, _) = load_exr(&image_path)?;
            let measured = (rel_mse(&image, &truth.image)? - truth_noise).max(0.0).sqrt();
            println!(
                "{} {target}: {choice}: error predicted {predicted_error:.4}, measured {measured:.4} (x{:.2}); render \
                 predicted {predicted_seconds:.2} s, took {rendered:.2} s; pilot {pilot_seconds:.1} s, wall {wall:.1} s",
                scene.name,
                measured / predicted_error
            );
            rows.push(vec![
                scene.name.clone(),
                target.to_string(),
                choice,
                format!("{predicted_error:.4}"),
                format!("{measured:.4}"),
                format!("{:.2}", measured / predicted_error),
                format!("{predicted_seconds:.2}"),
                format!("{rendered:.2}"),
                format!("{wall:.1}"),
            ]);
        }
    }
    let mut md = format!(
        "`render --renderer auto --target-error E` against the truth, on {}, {adapter}, generated by \
         `cargo run --release --example auto_check` (scripts/readme-figures.sh). Truths: {}.\n\n\
         Measured error: the square root of the image's relMSE against the truth, less the truth's own \
         estimated relMSE. Render seconds: the rendering step as `render` timed it (device, set-up, samples, \
         files), against the plan's prediction; wall seconds: the whole command, pilot included (its truth \
         and biases cached, its throughput measured every run).\n\n",
        host_cpu(),
        truths.join("; ")
    );
    md.push_str(&markdown_table(
        &[
            "scene",
            "target",
            "choice",
            "predicted error",
            "measured error",
            "measured / predicted",
            "predicted render s",
            "render s",
            "wall s",
        ],
        &rows,
    ));
    let table = args.out.join("auto-check.md");
    write_text(&table, &md)?;
    println!("wrote {}", table.display());
    Ok(())
}
