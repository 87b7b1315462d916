//! The pilot of `--renderer auto`: what the planner ([`super::plan`]) needs, measured on this
//! scene and this machine.
//!
//! - Bias and noise: every setting rendered at a low resolution (the scene's aspect,
//!   [`PilotOptions::longer_side`] pixels on the longer side) and compared with a path-traced
//!   truth at that size, as the ladder compares (relMSE, per region). A deterministic renderer's
//!   bias² is its relMSE less the truth's own estimated noise; a path tracer's is its relMSE less
//!   its own and the truth's estimated noise, and its noise curve ([`super::plan::NoiseCurve`])
//!   comes from its own estimate: at the pilot's spp with the 1/N law for independent samples
//!   and adaptive sampling; at a sixteenth, a quarter and all of it for the low-discrepancy
//!   sequence (its estimate from independently randomised replicates), with the law beyond of
//!   [`super::plan::NoiseCurve::with_measured_law`]; and
//!   for a denoised render, the denoised image's relMSE against the truth at 4, 16, 64 and the
//!   pilot's spp, less the bias. The truth and these figures are cached in the pilot's folder
//!   under a key of the scene's content hash and every pilot setting, like the ladder's truth.
//! - Throughput: measured now, every run, per setting. The rasterizer draws one frame at the
//!   size asked for (set-up and first frame, as `render` pays them); the Whitted ray tracer and
//!   the path tracer run at the pilot's size, their set-up counted once and their per-pixel
//!   time scaled by the ratio of pixel counts; adaptive sampling's own pilot and a denoised
//!   render's guides and three filter runs are timed at the pilot's size and scaled the same way.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context as _;
use illum_denoise::{DenoiseInput, Denoiser, OIDN_BUILT};
use illum_gpu::GpuContext;
use illum_image::RgbImage32;
use illum_pathtrace::{PathTracer, SampleAllocation, guide_samples};
use illum_raster::{Options, RasterRenderer, RasterScene};
use illum_scene::{Bounces, DenoiserKind, Overrides, Scene, Sequence};
use illum_whitted::WhittedTracer;

use super::cache::{read_cache, write_cache};
use super::plan::{Candidate, Setting};
pub use super::render::render;
use super::render::{path_tracer_throughput, spp_multiple, tracer_options};
use crate::reference::{cached_reference, reference_settings};
use crate::regions::{Regions, compare};
use illum_auto::measure::{Measured, measured};
pub use illum_auto::settings::{
    Variants, apply, has_caustic, pilot_size, settings, settings_with_variants, truth_scene,
};

/// How the pilot measures.
#[derive(Clone, Debug)]
pub struct PilotOptions {
    /// Pixels on the longer side of the pilot's images (never more than the render's own).
    pub longer_side: u32,
    /// Samples per pixel of the pilot's truth.
    pub truth_spp: u32,
    /// Samples per pixel of each path-tracer setting's bias and noise measurement.
    pub pilot_spp: u32,
    /// Samples per pixel of each path-tracer setting's throughput measurement.
    pub timing_spp: u32,
    /// Where the truth and the measured biases are cached.
    pub folder: PathBuf,
}

impl Default for PilotOptions {
    fn default() -> Self {
        PilotOptions {
            longer_side: 128,
            truth_spp: 8192,
            pilot_spp: 256,
            timing_spp: 32,
            folder: PathBuf::from("out/auto"),
        }
    }
}

/// What the pilot measured.
#[derive(Clone, Debug)]
pub struct Pilot {
    /// Every setting with its bias, noise and cost at the size asked for.
    pub candidates: Vec<Candidate>,
    /// The pilot's image size.
    pub size: (u32, u32),
    /// The truth's samples per pixel and its own estimated relMSE.
    pub truth_spp: u32,
    pub truth_rel_mse: f64,
    /// Seconds spent now on the truth (0 when cached), on the biases (0 when cached) and on
    /// the throughput.
    pub truth_seconds: f64,
    pub bias_seconds: f64,
    pub throughput_seconds: f64,
    /// The cache file of the biases.
    pub bias_file: PathBuf,
}

impl Pilot {
    /// Everything the pilot cost in this run.
    pub fn seconds(&self) -> f64 {
        self.truth_seconds + self.bias_seconds + self.throughput_seconds
    }
}

fn resized(scene: &Scene, (width, height): (u32, u32)) -> anyhow::Result<Scene> {
    let mut small = scene.clone();
    small.apply_overrides(
        &Overrides { width: Some(width), height: Some(height), ..Default::default() },
        "auto pilot",
    )?;
    Ok(small)
}

/// Measures every setting of [`settings`] for `scene` (at the size it will be rendered) on
/// `gpu`. `overhead_seconds`, what every render pays before its renderer starts (setting up
/// the device), is added to every candidate's fixed cost.
pub fn measure(
    gpu: &GpuContext,
    scene: &Scene,
    overhead_seconds: f64,
    options: &PilotOptions,
) -> anyhow::Result<Pilot> {
    let size = pilot_size(scene, options.longer_side);
    let small = resized(scene, size)?;
    std::fs::create_dir_all(&options.folder)
        .with_context(|| format!("creating {}", options.folder.display()))?;

    // The truth: the converged solution (unbounded bounces, the caustic's light tracer where
    // there is one), cached by content.
    let truth_scene = truth_scene(&small, Bounces::Unbounded);
    let started = Instant::now();
    let truth = cached_reference(gpu, &truth_scene, options.truth_spp, &options.folder, "auto pilot truth")?;
    let truth_seconds =
        if truth.metadata.get("reference_key").is_some() && started.elapsed().as_secs_f64() < 1.0 {
            0.0
        } else {
            started.elapsed().as_secs_f64()
        };
    let truth_rel_mse = if truth.estimated_rel_mse.is_finite() { truth.estimated_rel_mse } else { 0.0 };

    let denoisers: &[DenoiserKind] =
        if OIDN_BUILT { &[DenoiserKind::Atrous, DenoiserKind::Oidn] } else { &[DenoiserKind::Atrous] };
    let all = settings_with_variants(scene, Variants { low_discrepancy: true, adaptive: true, denoisers });
    let (_, truth_key) = reference_settings(&truth_scene, options.truth_spp);
    // The leading version is raised whenever what a cached measurement holds changes (the pilot's
    // rules, or the output of a renderer or denoiser it measures): an older cache then misses.
    let key = format!(
        "auto pilot 5; truth: {truth_key}; pilot spp {}; seed {}; sampling {}; settings: {}",
        options.pilot_spp,
        small.pathtrace.seed,
        small.pathtrace.sampling,
        all.iter().map(ToString::to_string).collect::<Vec<_>>().join("; ")
    );
    let bias_file = options.folder.join(format!(
        "auto-pilot-{}-{:016x}.csv",
        scene.name,
        illum_scene::fnv1a_64(key.as_bytes())
    ));
    let started = Instant::now();
    let (measured, bias_seconds) = match read_cache(&bias_file, &key, all.len()) {
        Some(measured) => (measured, 0.0),
        None => {
            let regions = Regions::from_ids(&small, &WhittedTracer::new(gpu, &small)?.object_ids()?);
            let mut measured = Vec::new();
            for setting in &all {
                measured.push(measure_bias(
                    gpu,
                    &small,
                    setting,
                    &truth.image,
                    truth_rel_mse,
                    &regions,
                    options,
                )?);
            }
            write_cache(&bias_file, &key, &all, &measured)?;
            (measured, started.elapsed().as_secs_f64())
        }
    };

    let started = Instant::now();
    let pixel_ratio = f64::from(scene.camera.width) * f64::from(scene.camera.height)
        / (f64::from(size.0) * f64::from(size.1));
    let mut candidates = Vec::new();
    let mut raster: Option<(RasterRenderer, f64)> = None;
    for (setting, m) in all.iter().zip(measured) {
        let (fixed_seconds, seconds_per_spp) = match setting {
            Setting::Raster { look, effects } => {
                if raster.is_none() {
                    let raster_scene = RasterScene::from_scene(scene)?;
                    let t = Instant::now();
                    let renderer =
                        RasterRenderer::new(gpu, &raster_scene, scene.camera.width, scene.camera.height)?;
                    raster = Some((renderer, t.elapsed().as_secs_f64()));
                }
                let (renderer, setup) = raster.as_mut().expect("made above");
                let t = Instant::now();
                renderer.render(&Options { look: *look, effects: *effects })?;
                (*setup + t.elapsed().as_secs_f64(), 0.0)
            }
            Setting::Whitted { .. } => {
                let variant = apply(&small, setting);
                let t = Instant::now();
                let tracer = WhittedTracer::new(gpu, &variant)?;
                let setup = t.elapsed().as_secs_f64();
                let t = Instant::now();
                tracer.render()?;
                (setup + t.elapsed().as_secs_f64() * pixel_ratio, 0.0)
            }
            Setting::PathTrace { .. } => {
                let (setup, per_pixel_fixed, per_spp) =
                    path_tracer_throughput(gpu, &small, setting, options.timing_spp)?;
                (setup + per_pixel_fixed * pixel_ratio, per_spp * pixel_ratio)
            }
        };
        candidates.push(Candidate {
            setting: setting.clone(),
            bias_rel_mse: m.bias_rel_mse,
            noise: m.noise,
            spp_multiple: spp_multiple(setting),
            fixed_seconds: overhead_seconds + fixed_seconds,
            seconds_per_spp,
            worst_region: m.worst_region,
        });
    }
    Ok(Pilot {
        candidates,
        size,
        truth_spp: options.truth_spp,
        truth_rel_mse,
        truth_seconds,
        bias_seconds,
        throughput_seconds: started.elapsed().as_secs_f64(),
        bias_file,
    })
}

/// Renders `setting` at the pilot's size and measures its bias (and noise) against the truth.
fn measure_bias(
    gpu: &GpuContext,
    small: &Scene,
    setting: &Setting,
    truth: &RgbImage32,
    truth_rel_mse: f64,
    regions: &Regions,
    options: &PilotOptions,
) -> anyhow::Result<Measured> {
    let variant = apply(small, setting);
    let spp = options.pilot_spp;
    let Setting::PathTrace { sequence, adaptive, denoise, .. } = setting else {
        let (image, _) = render(gpu, &variant, setting, spp)?;
        return Ok(measured(&compare(&image, truth, regions), regions, truth_rel_mse, None, spp));
    };
    let mut tracer = if *adaptive {
        let (w, h) = (variant.camera.width, variant.camera.height);
        let unlimited = SampleAllocation::uniform(w, h, u32::MAX);
        let mut tracer =
            PathTracer::with_sample_allocation(gpu, &variant, tracer_options(setting), unlimited)?;
        illum_pathtrace::allocation::plan_adaptive(&mut tracer, spp)?;
        tracer
    } else {
        PathTracer::with_options(gpu, &variant, tracer_options(setting))?
    };
    // From one render continued: the denoised image's relMSE at these spp, and the
    // low-discrepancy render's own estimate at those.
    let denoised_at = illum_auto::measure::denoised_spps(spp);
    let estimated_at = illum_auto::measure::low_discrepancy_spps(spp);
    let mut stops: Vec<u32> = denoised_at.iter().chain(&estimated_at).copied().collect();
    stops.sort_unstable();
    stops.dedup();
    let filter = match denoise {
        Some(kind) => Some(Denoiser::new(gpu, *kind)?),
        None => None,
    };
    let mut denoised = Vec::new();
    let mut estimates = Vec::new();
    for &n in &stops {
        let until = match tracer.sample_allocation() {
            Some(allocation) => allocation.max(),
            None => n,
        };
        tracer.render_to_spp(until)?;
        if estimated_at.contains(&n) {
            estimates.push((n, tracer.accumulator().estimated_rel_mse()));
        }
        if let Some(filter) = &filter
            && denoised_at.contains(&n)
        {
            // The guides a render of n spp would have (`render --denoise`, illum-denoise's split).
            let guides = tracer.guides(guide_samples(n))?;
            let image = filter.denoise(&DenoiseInput::from_render(tracer.accumulator(), &guides))?;
            // As a deterministic image: its relMSE less the truth's noise, and its worst region.
            denoised.push((n, measured(&compare(&image, truth, regions), regions, truth_rel_mse, None, n)));
        }
    }
    let accumulator = tracer.accumulator();
    let own = accumulator.estimated_rel_mse();
    let raw =
        measured(&compare(&accumulator.mean_image(), truth, regions), regions, truth_rel_mse, Some(own), spp);
    Ok(match (sequence, denoise) {
        (_, Some(_)) => illum_auto::measure::denoised(raw, &denoised),
        (Sequence::LowDiscrepancy, None) => illum_auto::measure::low_discrepancy(raw, &estimates),
        (Sequence::Independent, None) => raw,
    })
}
