//! Command-line pieces shared by the examples: the scene flags and device setup.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
pub use illum_scene::resolve_scene_path;
use illum_scene::{Bounces, Overrides, Sampling, Scene};

/// The default scene: the assignment's Cornell box.
pub const DEFAULT_SCENE: &str = "scenes/cornell.toml";

/// Flags that override the scene file's settings (same names in every example).
#[derive(Args, Clone, Debug, Default)]
pub struct SceneArgs {
    /// Samples per pixel (>= 1).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Bounces of indirect light: 0 = direct only, up to 256, or `unbounded` (Russian roulette).
    #[arg(long)]
    pub bounces: Option<Bounces>,
    /// Random seed.
    #[arg(long)]
    pub seed: Option<u32>,
    /// Image width in pixels.
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels.
    #[arg(long)]
    pub height: Option<u32>,
    /// Hemisphere sampling for bounces: `cosine` or `uniform`.
    #[arg(long)]
    pub sampling: Option<Sampling>,
}

impl SceneArgs {
    pub fn overrides(&self) -> Overrides {
        Overrides {
            spp: self.spp,
            bounces: self.bounces,
            seed: self.seed,
            sampling: self.sampling,
            sequence: None,
            width: self.width,
            height: self.height,
        }
    }
}

/// Loads a scene file and applies the command-line overrides.
pub fn load_scene(path: &Path, args: &SceneArgs) -> anyhow::Result<Scene> {
    let mut scene = Scene::load(&resolve_scene_path(path))?;
    scene.apply_overrides(&args.overrides(), "command line")?;
    Ok(scene)
}

/// Creates the GPU context, adding what to do when it fails.
pub fn gpu() -> anyhow::Result<illum_gpu::GpuContext> {
    let gpu = illum_gpu::GpuContext::new().context("setting up the GPU")?;
    log::info!("adapter: {} ({:?})", gpu.adapter_info.name, gpu.adapter_info.backend);
    Ok(gpu)
}

/// Runs an example's `run` with logging set up, printing any error with its causes and exiting
/// with status 1 (never a panic's backtrace for a user mistake).
pub fn main_with<A: clap::Parser>(run: impl FnOnce(A) -> anyhow::Result<()>) {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    if let Err(error) = run(A::parse()) {
        eprintln!("error: {error:#}");
        std::process::exit(1);
    }
}

/// Parses `on` or `off` (for `--caustics`).
pub fn on_off_arg(text: &str) -> Result<bool, String> {
    match text.trim() {
        "on" => Ok(true),
        "off" => Ok(false),
        other => Err(format!("{other:?} is neither on nor off")),
    }
}

/// Parses a number of stops for `--exposure`: any finite number, negative ones as typed
/// (`--exposure -1`; declare the flag with `allow_negative_numbers`).
pub fn exposure_arg(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("{text:?} is not a finite number of stops (for example -1, 0 or 2.5)")),
    }
}

/// Parses `--target-error` (see [`illum_pathtrace::parse_target_error`]).
pub fn target_error_arg(text: &str) -> Result<f64, String> {
    let value = text.trim().parse::<f64>().map_err(|_| format!("{text:?} is not a number"))?;
    illum_pathtrace::parse_target_error("--target-error", value)
}

/// Parses `--time-budget` in seconds (see [`illum_pathtrace::parse_time_budget`]).
pub fn time_budget_arg(text: &str) -> Result<std::time::Duration, String> {
    let value = text.trim().parse::<f64>().map_err(|_| format!("{text:?} is not a number of seconds"))?;
    illum_pathtrace::parse_time_budget("--time-budget", value)
}

/// The names of the flags that were given, from (given, name) pairs, in order.
pub fn given_flags(flags: &[(bool, &'static str)]) -> Vec<&'static str> {
    flags.iter().filter_map(|&(given, flag)| given.then_some(flag)).collect()
}

/// Parses `--sample-range A..B`: sample indices A to B-1, A < B.
pub fn sample_range_arg(text: &str) -> Result<std::ops::Range<u32>, String> {
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| format!("{text:?}: expected A..B, for example 0..256 (sample indices A to B-1)"))?;
    let parse = |part: &str, which: &str| {
        part.trim()
            .parse::<u32>()
            .map_err(|_| format!("{text:?}: {which} {part:?} is not a whole number 0..={}", u32::MAX))
    };
    let (a, b) = (parse(a, "start")?, parse(b, "end")?);
    if a >= b {
        return Err(format!("{text:?}: the range is empty; the end must be above the start"));
    }
    Ok(a..b)
}

/// Checks every output before any rendering, so that a finished render is never lost to a bad
/// name: a known extension, a folder that can take the file, not a directory or a read-only
/// file. `png_flags` are the PNG-only flags given (`--encoding`, `--exposure`): an error when no
/// output is a PNG, since they would do nothing.
pub fn check_outputs(outputs: &[PathBuf], png_flags: &[&str]) -> anyhow::Result<()> {
    let mut any_png = false;
    for output in outputs {
        any_png |= output_format(output)? == OutputFormat::Png;
    }
    if !any_png && !png_flags.is_empty() {
        anyhow::bail!(
            "{} only to PNG output (EXR files are linear and never scaled), and no -o file is a .png",
            png_flags.join(", ").to_owned() + if png_flags.len() == 1 { " applies" } else { " apply" }
        );
    }
    for output in outputs {
        illum_image::check_output(output)?;
    }
    Ok(())
}

/// An output file's format, from its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    Png,
    Exr,
}

/// The format of `path` (.png or .exr, any case), or an error naming what is allowed.
pub fn output_format(path: &Path) -> anyhow::Result<OutputFormat> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("png") => Ok(OutputFormat::Png),
        Some("exr") => Ok(OutputFormat::Exr),
        _ => anyhow::bail!("output {}: unknown extension; allowed: .png or .exr", path.display()),
    }
}
