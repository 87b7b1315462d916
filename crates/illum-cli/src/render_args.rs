//! The `render` command's flags ([`RenderArgs`]) and the values only they parse: the renderer
//! (`--renderer`, [`RendererChoice`]) and `--error-percentile`. The command itself is
//! `render.rs`; `auto.rs` adds what `--renderer auto` checks and how the flags follow its choice.

use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;
use std::time::Duration;

use clap::Parser;
use illum_image::Encoding;
use illum_pathtrace::Sequence;
use illum_scene::RendererKind;

use crate::raster::RasterArgs;
use crate::whitted::WhittedArgs;
use crate::{DEFAULT_SCENE, SceneArgs};

#[derive(Parser, Clone, Debug)]
#[command(
    name = "render",
    about = "Render a scene file to PNG and/or EXR with the path tracer, the rasterizer or the Whitted ray tracer",
    after_help = "Stopping: Ctrl-C or SIGTERM stops a render and exits with status 130 or 143. The path tracer \
writes what has accumulated (a checkpoint that --resume continues), or, before its first complete pass, \
nothing, and says so. The Whitted ray tracer and a raster frame above 4 Mpixels render in parts and stop \
between them; their images are deterministic, so an interrupted one writes nothing and says so (a complete \
one is written). Copies of the signal within a second of the first (timeout, Slurm and systemd signal the \
whole process group) are the same request; a signal after that ends the process at once.\n\n\
Progress: a bar on a terminal; in a job log (standard error not a terminal), lines starting with \
\"progress: \" every --progress-seconds and at every tenth of the way."
)]
pub struct RenderArgs {
    /// Scene file (TOML).
    #[arg(default_value = DEFAULT_SCENE)]
    pub scene: PathBuf,
    /// Renderer: `pathtrace`, `raster`, `whitted`, or `auto`: the fastest renderer and settings
    /// predicted to reach --target-error, or the most accurate predicted to finish within
    /// --time-budget, from a pilot of this scene on this machine (docs/auto.md). Default: the
    /// scene file's `renderer`.
    #[arg(long)]
    pub renderer: Option<RendererChoice>,
    #[command(flatten)]
    pub settings: SceneArgs,
    #[command(flatten)]
    pub raster: RasterArgs,
    #[command(flatten)]
    pub whitted: WhittedArgs,
    /// Output file(s); the extension (.png or .exr) picks the format. Default: out/NAME.png and
    /// out/NAME.exr.
    #[arg(short = 'o', long = "output")]
    pub outputs: Vec<PathBuf>,
    /// Stop once the estimated relative standard error falls to this value (e.g. 0.01). Lifts
    /// the scene's spp; with --spp too, the first rule that holds wins.
    #[arg(long, allow_negative_numbers = true, value_parser = crate::target_error_arg)]
    pub target_error: Option<f64>,
    /// Stop after this many seconds of wall-clock time (after one complete pass at least).
    /// Lifts the scene's spp; with --spp too, the first rule that holds wins.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = crate::time_budget_arg)]
    pub time_budget: Option<Duration>,
    /// With --target-error: stop when this percentile of the pixels' estimated errors reaches
    /// the target (95: 95% of pixels at or under it), instead of the whole image's error.
    #[arg(long, value_name = "PERCENT", allow_negative_numbers = true, value_parser = error_percentile_arg)]
    pub error_percentile: Option<f64>,
    /// With --target-error: measure the error over one region only: an object's name in the
    /// scene file (e.g. "glass sphere") or one of the ladder's regions (e.g. "floor, lit"),
    /// found through the Whitted tracer's object-ID image. An unknown name lists the valid ones.
    #[arg(long, value_name = "NAME")]
    pub region: Option<String>,
    /// Rasterizer and Whitted ray tracer: a converged EXR of the same scene (by illum.scene_hash)
    /// and size; the EXR outputs get the layer illum.difference, image minus reference, and the
    /// summary its relMSE.
    #[arg(long, value_name = "FILE.exr")]
    pub reference: Option<PathBuf>,
    /// PNG encoding: gamma2.2, srgb or linear. Default: gamma2.2 (the assignment's) for
    /// path-traced scenes, linear for rasterizer scenes (the assignment's figure 1 is linear).
    #[arg(long)]
    pub encoding: Option<Encoding>,
    /// Path-tracer scenes: `independent` (default) or `low-discrepancy` sample values (lower
    /// error for the same spp; its error is estimated from 4 independently randomised
    /// replicates: see docs/accuracy.md).
    #[arg(long)]
    pub sequence: Option<Sequence>,
    /// With --sequence low-discrepancy: `on` (default) deals the samples to 4 independently
    /// randomised replicates, whose spread is the error estimate; `off` renders one
    /// randomisation, with less error and less time per sample and no error estimate, so it
    /// needs a fixed sample count (--spp, --sample-range or --time-budget) and no rule that
    /// reads the estimate (docs/accuracy-estimate.md, "Without replicates").
    #[arg(long, value_name = "on|off", value_parser = crate::on_off_arg)]
    pub replicates: Option<bool>,
    /// Path-tracer scenes: the caustic's light tracer `on` or `off` (default: the file's
    /// `[pathtrace] caustics`). It runs only on a scene with a directional light and a mirror
    /// or glass object (docs/caustics.md).
    #[arg(long, value_name = "on|off", value_parser = crate::on_off_arg)]
    pub caustics: Option<bool>,
    /// Path-tracer scenes: how the caustic is found (default: the file's `[pathtrace]
    /// caustic_method`): `light-tracer` (particles from the sun, every specular chain) or
    /// `manifold` (solved through each specular sphere at every diffuse vertex; chains through
    /// two objects are left out, docs/caustics-manifold.md). A scene the solve cannot take
    /// falls back to the light tracer and says why.
    #[arg(long, value_name = "light-tracer|manifold")]
    pub caustic_method: Option<illum_scene::CausticMethod>,
    /// PNG exposure in stops, e.g. -1 or 2, at most 64 either way, or `auto`: the stops that
    /// bring the median luminance to mid-grey (0.18), for scenes of any brightness. EXR output
    /// is never scaled. Default 0.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::exposure_arg)]
    pub exposure: Option<illum_image::Exposure>,
    /// Continue the path-traced render saved in this EXR (a checkpoint) to --spp N samples per
    /// pixel (or to the end of --sample-range). Give the same scene file; the settings that
    /// change the image (size, bounces, seed, sampling, sequence, caustics) default to the
    /// file's, and one given that differs is refused. Default output: the same file.
    #[arg(long, value_name = "FILE.exr")]
    pub resume: Option<PathBuf>,
    /// Render only sample indices A to B-1 of every pixel (B - A spp), for the merge example
    /// to combine with other ranges. A must be a multiple of 16 (the chunk the GPU sums in), so
    /// that merged ranges give the image of one render.
    #[arg(long, value_name = "A..B", value_parser = crate::sample_range_arg)]
    pub sample_range: Option<std::ops::Range<u32>>,
    /// Path-tracer scenes: denoise the image (`atrous`: the edge-avoiding à-trous filter on the
    /// GPU; `oidn`: Intel Open Image Denoise's RT filter on the CPU, only in builds with
    /// `--features illum-denoise/oidn`, docs/denoising.md). The render is kept as two
    /// independent halves, and the denoised image's error is estimated from them
    /// (docs/denoising.md): it is the `illum.estimated_relative_error` written and the one
    /// --target-error stops at. The EXR holds the denoised image, and layers `noisy`, `albedo`
    /// and `normal`. --spp is rounded up to an even number. Not with --resume, --sample-range,
    /// --adaptive or --checkpoint-seconds.
    #[arg(long, value_name = "atrous|oidn", value_parser = crate::denoise::denoiser_arg)]
    pub denoise: Option<crate::denoise::DenoiserKind>,
    /// Path-tracer scenes: adaptive sampling. A pilot of 16 spp (another seed, then discarded)
    /// measures the noise of every 8 x 8 block of pixels, and the --spp budget is spread over
    /// the blocks in proportion to it: the spp is then the mean over the image (docs/accuracy.md, "Adaptive sampling").
    /// Needs --spp; not with --resume, --sample-range or the caustic's light tracer.
    #[arg(long)]
    pub adaptive: bool,
    /// Write the EXR outputs (checkpoints, see --resume) every this many seconds while
    /// rendering. Default 60.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = crate::checkpoint_seconds_arg)]
    pub checkpoint_seconds: Option<Duration>,
    /// When standard error is not a terminal (a job log, `> log 2>&1`): print a line starting
    /// with `progress: ` this often (0.1 to 86400 seconds; default 10), and at every tenth of the
    /// way, with every renderer. On a terminal a progress bar shows the same.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = crate::progress::period_arg)]
    pub progress_seconds: Option<Duration>,
}

impl RenderArgs {
    /// The PNG-only flags given (`--encoding`, `--exposure`).
    pub fn png_flags(&self) -> Vec<&'static str> {
        crate::given_flags(&[
            (self.encoding.is_some(), "--encoding"),
            (self.exposure.is_some(), "--exposure"),
        ])
    }

    /// The flags only the path tracer takes that were given.
    pub(crate) fn path_tracer_only_flags(&self) -> Vec<&'static str> {
        crate::given_flags(&[
            (self.target_error.is_some(), "--target-error"),
            (self.time_budget.is_some(), "--time-budget"),
            (self.error_percentile.is_some(), "--error-percentile"),
            (self.region.is_some(), "--region"),
            (self.sequence.is_some(), "--sequence"),
            (self.replicates.is_some(), "--replicates"),
            (self.caustics.is_some(), "--caustics"),
            (self.caustic_method.is_some(), "--caustic-method"),
            (self.resume.is_some(), "--resume"),
            (self.sample_range.is_some(), "--sample-range"),
            (self.checkpoint_seconds.is_some(), "--checkpoint-seconds"),
            (self.adaptive, "--adaptive"),
            (self.denoise.is_some(), "--denoise"),
        ])
    }
}

/// `--renderer pathtrace|raster|whitted|auto`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RendererChoice {
    Kind(RendererKind),
    Auto,
}

impl FromStr for RendererChoice {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "auto" {
            return Ok(RendererChoice::Auto);
        }
        s.parse::<RendererKind>().map(RendererChoice::Kind).map_err(|_| {
            format!("{s:?} is not a renderer: must be \"pathtrace\", \"raster\", \"whitted\" or \"auto\"")
        })
    }
}

impl fmt::Display for RendererChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RendererChoice::Kind(kind) => kind.fmt(f),
            RendererChoice::Auto => f.write_str("auto"),
        }
    }
}

/// Parses `--error-percentile` (see [`illum_pathtrace::error_map::parse_error_percentile`]).
pub fn error_percentile_arg(text: &str) -> Result<f64, String> {
    illum_pathtrace::error_map::parse_error_percentile("--error-percentile", text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_and_every_renderer_parse_and_anything_else_is_refused_by_name() {
        assert_eq!("auto".parse(), Ok(RendererChoice::Auto));
        for kind in RendererKind::ALL {
            assert_eq!(kind.to_string().parse(), Ok(RendererChoice::Kind(kind)));
            assert_eq!(RendererChoice::Kind(kind).to_string(), kind.to_string());
        }
        let error = "opengl".parse::<RendererChoice>().unwrap_err();
        assert!(error.contains("\"opengl\"") && error.contains("\"auto\""), "{error}");
    }
}
