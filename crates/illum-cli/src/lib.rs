//! illum-cli: the command-line front end the examples share (`render`, `merge`, and the flags
//! and device setup of every tool), kept out of the renderer crates and the `illum` facade so
//! that a program linking a renderer does not link clap, indicatif or signal handling.
//!
//! - this module: the scene flags ([`SceneArgs`]), loading, device setup, output files and
//!   [`main_with`], which runs an example's `run` and prints its error;
//! - [`interrupt`]: Ctrl-C and SIGTERM for long renders;
//! - [`progress`]: progress bars and log lines;
//! - [`render`]: the `render` command's flags and the choice of renderer; [`pathtrace`],
//!   [`raster`], [`whitted`]: each renderer's path of it, [`denoise`] the path tracer's with
//!   `--denoise`, `resume` its `--resume`, [`auto`] `--renderer auto` (its flags, pilot and plan).

pub mod auto;
pub mod denoise;
pub mod interrupt;
pub mod pathtrace;
pub mod progress;
pub mod raster;
pub mod reference;
pub mod render;
mod render_args;
mod resume;
mod summary;
pub mod whitted;

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use illum_image::{Encoding, Exposure, ExrMetadata, RgbImage32, save_exr, save_png};
pub use illum_scene::resolve_scene_path;
use illum_scene::{Bounces, Overrides, Sampling, Scene};

/// The default scene: the assignment's Cornell box.
pub const DEFAULT_SCENE: &str = "scenes/cornell.toml";

/// Flags that override the scene file's settings (same names in every example).
#[derive(Args, Clone, Debug, Default)]
pub struct SceneArgs {
    /// Samples per pixel (>= 1).
    #[arg(long, allow_negative_numbers = true, value_parser = spp_arg)]
    pub spp: Option<u32>,
    /// Bounces of indirect light: 0 = direct only, up to 256, or `unbounded` (Russian roulette).
    #[arg(long, allow_negative_numbers = true)]
    pub bounces: Option<Bounces>,
    /// Random seed, 0 to 4294967295.
    #[arg(long, allow_negative_numbers = true, value_parser = seed_arg)]
    pub seed: Option<u32>,
    /// Image width in pixels (>= 1).
    #[arg(long, allow_negative_numbers = true, value_parser = width_arg)]
    pub width: Option<u32>,
    /// Image height in pixels (>= 1).
    #[arg(long, allow_negative_numbers = true, value_parser = height_arg)]
    pub height: Option<u32>,
    /// Hemisphere sampling for bounces: `cosine` or `uniform`.
    #[arg(long)]
    pub sampling: Option<Sampling>,
}

impl SceneArgs {
    /// The path tracer's flags among these that were given: an error for the other renderers.
    pub fn path_tracer_flags(&self) -> Vec<&'static str> {
        given_flags(&[
            (self.spp.is_some(), "--spp"),
            (self.bounces.is_some(), "--bounces"),
            (self.seed.is_some(), "--seed"),
            (self.sampling.is_some(), "--sampling"),
        ])
    }

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
    for note in scene.notes() {
        eprintln!("{note}");
    }
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

/// Largest `--exposure` in stops either way: 2^64 (about 1.8e19) scales any radiance the
/// scene model gives from black to white or back; beyond it the scale factor only overflows.
pub const MAX_EXPOSURE_STOPS: f32 = 64.0;

/// Parses `--exposure`: `auto` (chosen from the image, see [`Exposure::Auto`]) or a finite
/// number of stops within +-[`MAX_EXPOSURE_STOPS`], negative ones as typed (`--exposure -1`;
/// declare the flag with `allow_hyphen_values`, so that `-inf` reaches this parser too).
pub fn exposure_arg(text: &str) -> Result<Exposure, String> {
    if text.trim() == "auto" {
        return Ok(Exposure::Auto);
    }
    match text.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v.abs() <= MAX_EXPOSURE_STOPS => Ok(Exposure::Stops(v)),
        Ok(v) if v.is_finite() => Err(format!(
            "{text:?}: at most {MAX_EXPOSURE_STOPS} stops either way (a factor of 2^{MAX_EXPOSURE_STOPS}); {v} \
             would turn every pixel black or white"
        )),
        _ => Err(format!("{text:?} is neither auto nor a finite number of stops (for example -1, 0 or 2.5)")),
    }
}

/// A whole number of at least `min` for `flag`, with a message that says what is allowed (a
/// negative value reaches it as typed: the flags are declared with `allow_negative_numbers`,
/// so that clap does not take `-1` for another flag and suggest `-- -1`).
fn whole_number(flag: &str, text: &str, min: u32) -> Result<u32, String> {
    match text.trim().parse::<i128>() {
        Ok(v) if v >= i128::from(min) && v <= i128::from(u32::MAX) => Ok(v as u32),
        _ => Err(format!("{flag} = {text}: must be a whole number from {min} to {}", u32::MAX)),
    }
}

pub fn spp_arg(text: &str) -> Result<u32, String> {
    whole_number("--spp", text, 1)
}

pub fn seed_arg(text: &str) -> Result<u32, String> {
    whole_number("--seed", text, 0)
}

pub fn width_arg(text: &str) -> Result<u32, String> {
    whole_number("--width", text, 1)
}

pub fn height_arg(text: &str) -> Result<u32, String> {
    whole_number("--height", text, 1)
}

/// Parses `--target-error` (see [`illum_pathtrace::parse_target_error`]).
pub fn target_error_arg(text: &str) -> Result<f64, String> {
    let value = text.trim().parse::<f64>().map_err(|_| format!("{text:?} is not a number"))?;
    illum_pathtrace::parse_target_error("--target-error", value)
}

/// Parses `--time-budget` in seconds (see [`illum_pathtrace::parse_time_budget`]).
pub fn time_budget_arg(text: &str) -> Result<std::time::Duration, String> {
    seconds_arg("--time-budget", text)
}

/// Parses `--checkpoint-seconds` (a positive, finite number of seconds, as `--time-budget`).
pub fn checkpoint_seconds_arg(text: &str) -> Result<std::time::Duration, String> {
    seconds_arg("--checkpoint-seconds", text)
}

fn seconds_arg(flag: &str, text: &str) -> Result<std::time::Duration, String> {
    let value = text.trim().parse::<f64>().map_err(|_| format!("{text:?} is not a number of seconds"))?;
    illum_pathtrace::parse_time_budget(flag, value)
}

/// The names of the flags that were given, from (given, name) pairs, in order.
pub fn given_flags(flags: &[(bool, &'static str)]) -> Vec<&'static str> {
    flags.iter().filter_map(|&(given, flag)| given.then_some(flag)).collect()
}

/// "applies" for one flag, "apply" for several.
pub fn verb(flags: usize) -> &'static str {
    if flags == 1 { "applies" } else { "apply" }
}

/// What the `render` example passes to the path of a renderer that draws one image (the
/// rasterizer, the Whitted ray tracer): the scene, the shared flags, the renderer's own flags
/// `A`, the outputs and the PNG settings.
pub struct RenderRequest<'a, A> {
    pub scene: &'a Path,
    pub settings: &'a SceneArgs,
    /// The renderer's own flags.
    pub args: &'a A,
    /// Output files; empty: `out/NAME-SUFFIX.png` (see [`RenderRequest::checked_outputs`]).
    pub outputs: &'a [PathBuf],
    /// PNG encoding; `None`: linear, as the assignment's figure 1 was written.
    pub encoding: Option<Encoding>,
    /// PNG exposure; `None`: 0 stops.
    pub exposure: Option<Exposure>,
    /// Flags of the other renderers that were given (e.g. "--target-error", "--look"): an error.
    pub other_flags: Vec<&'static str>,
    /// How the render reports progress and reacts to Ctrl-C / SIGTERM.
    pub long: LongRender<'a>,
    /// `--reference FILE.exr`: a truth of the same scene; the EXRs get the signed difference
    /// from it (see [`reference`]).
    pub reference: Option<&'a Path>,
}

/// How a long render reports its progress and learns that it should stop.
#[derive(Clone, Copy)]
pub struct LongRender<'a> {
    /// The installed SIGINT / SIGTERM handlers (`None`: nothing stops the render).
    pub interrupt: Option<&'a crate::interrupt::Interrupt>,
    /// Time between `progress: ` lines when standard error is not a terminal.
    pub progress_period: std::time::Duration,
}

impl Default for LongRender<'_> {
    fn default() -> Self {
        LongRender { interrupt: None, progress_period: crate::progress::DEFAULT_PERIOD }
    }
}

impl LongRender<'_> {
    /// Whether a stop was asked for.
    pub fn stop_requested(&self) -> bool {
        self.interrupt.is_some_and(|i| i.requested())
    }

    /// Ends the process with the signal's status, saying that nothing was written and what was
    /// under way, when a stop was asked for.
    pub fn exit_if_requested(&self, what: &str) {
        if let Some(interrupt) = self.interrupt {
            interrupt.exit_if_requested(what);
        }
    }

    /// After a complete image was written: when a stop was asked for meanwhile, says so and
    /// exits with the signal's status (so that `render && next-step` stops there too).
    pub fn exit_after_complete_image(&self) {
        if let Some((signal, code)) = self.interrupt.and_then(|i| i.exit_status()) {
            eprintln!(
                "stopped by {signal} after the image was complete (it was written): exiting with status {code}"
            );
            std::process::exit(code);
        }
    }
}

impl<A> RenderRequest<'_, A> {
    /// The flags this renderer refuses that were given: the path tracer's scene settings, then
    /// `other_flags`.
    pub fn refused_flags(&self) -> Vec<&'static str> {
        let mut flags = self.settings.path_tracer_flags();
        flags.extend(&self.other_flags);
        flags
    }

    /// The outputs (`out/NAME-SUFFIX.png` when none is given), each checked before any
    /// rendering (see [`check_outputs`]).
    pub fn checked_outputs(&self, name: &str, suffix: &str) -> anyhow::Result<Vec<PathBuf>> {
        let outputs = if self.outputs.is_empty() {
            vec![PathBuf::from(format!("out/{name}-{suffix}.png"))]
        } else {
            self.outputs.to_vec()
        };
        let png_flags =
            given_flags(&[(self.encoding.is_some(), "--encoding"), (self.exposure.is_some(), "--exposure")]);
        check_outputs(&outputs, &png_flags)?;
        Ok(outputs)
    }

    /// The `--reference` image, read and checked against the request's scene file at the
    /// request's size (before rendering).
    pub fn reference_image(&self) -> anyhow::Result<Option<RgbImage32>> {
        let Some(path) = self.reference else { return Ok(None) };
        let mut scene = Scene::load(&resolve_scene_path(self.scene))?;
        let sizes =
            Overrides { width: self.settings.width, height: self.settings.height, ..Default::default() };
        scene.apply_overrides(&sizes, "command line")?;
        reference::load_reference(path, &scene).map(Some)
    }

    /// Writes `image` to every output (PNG with the request's exposure and encoding, linear by
    /// default; EXR with `metadata`, and with a `reference` the layer of the signed difference
    /// from it), then prints `summary` (and the relMSE against the reference) and the files written.
    pub fn write(
        &self,
        outputs: &[PathBuf],
        image: &RgbImage32,
        metadata: &ExrMetadata,
        summary: &str,
        reference: Option<&RgbImage32>,
    ) -> anyhow::Result<()> {
        let encoding = self.encoding.unwrap_or(Encoding::Linear);
        let exposure = self.exposure.unwrap_or_default().stops_for(image);
        for output in outputs {
            match (output_format(output)?, reference) {
                (OutputFormat::Png, _) => save_png(output, image, exposure, encoding)?,
                (OutputFormat::Exr, None) => save_exr(output, image, metadata)?,
                (OutputFormat::Exr, Some(truth)) => illum_image::save_exr_with_float_layers(
                    output,
                    image,
                    metadata,
                    Vec::new(),
                    vec![reference::difference_layer(image, truth)],
                )?,
            }
        }
        println!("{summary}");
        if let Some(truth) = reference {
            println!("against the reference: relMSE {:.4e}", illum_image::rel_mse(image, truth)?);
        }
        for output in outputs {
            println!("wrote {}", output.display());
        }
        Ok(())
    }
}

/// The outputs' paths, comma-separated (for messages).
pub fn describe_outputs(outputs: &[PathBuf]) -> String {
    outputs.iter().map(|o| o.display().to_string()).collect::<Vec<_>>().join(", ")
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
    let chunk = illum_pathtrace::CHUNK_SAMPLES;
    if !a.is_multiple_of(chunk) {
        return Err(format!(
            "{text:?}: the start must be a multiple of {chunk} (the GPU sums samples in chunks of {chunk}; ranges \
             that start on a chunk merge into exactly the image of one render), for example {}..{b}",
            a / chunk * chunk
        ));
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
            "{} {} only to PNG output (EXR files are linear and never scaled), and no -o file is a .png",
            png_flags.join(", "),
            verb(png_flags.len())
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
