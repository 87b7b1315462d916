//! The pilot of `--renderer auto`: what the planner ([`super::plan`]) needs, measured on this
//! scene and this machine.
//!
//! - Bias and noise: every setting rendered at a low resolution (the scene's aspect,
//!   [`PilotOptions::longer_side`] pixels on the longer side) and compared with a path-traced
//!   truth at that size, as the ladder compares (relMSE, per region). A deterministic renderer's
//!   bias² is its relMSE less the truth's own estimated noise; a path tracer's is its relMSE less
//!   its own and the truth's estimated noise, and its noise per sample is its estimated relMSE
//!   times its spp. The truth and these figures are cached in the pilot's folder under a key of
//!   the scene's content hash and every pilot setting, like the ladder's truth.
//! - Throughput: measured now, every run, per setting. The rasterizer draws one frame at the
//!   size asked for (set-up and first frame, as `render` pays them); the Whitted ray tracer and
//!   the path tracer run at the pilot's size, their set-up counted once and their per-pixel
//!   time scaled by the ratio of pixel counts.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context as _;
use illum_gpu::GpuContext;
use illum_image::RgbImage32;
use illum_pathtrace::PathTracer;
use illum_raster::{Options, RasterRenderer, RasterScene};
use illum_scene::{Bounces, Overrides, Scene};
use illum_whitted::WhittedTracer;

use super::plan::{Candidate, Setting};
use crate::reference::{cached_reference, reference_settings};
use crate::regions::{Regions, compare};
use crate::report::{csv_text, write_text};
use illum_auto::measure::{Measured, measured};
pub use illum_auto::settings::{apply, has_caustic, pilot_size, settings};

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
    let mut truth_scene = small.clone();
    truth_scene.pathtrace.bounces = Bounces::Unbounded;
    truth_scene.pathtrace.caustics = has_caustic(&small);
    let started = Instant::now();
    let truth = cached_reference(gpu, &truth_scene, options.truth_spp, &options.folder, "auto pilot truth")?;
    let truth_seconds =
        if truth.metadata.get("reference_key").is_some() && started.elapsed().as_secs_f64() < 1.0 {
            0.0
        } else {
            started.elapsed().as_secs_f64()
        };
    let truth_rel_mse = if truth.estimated_rel_mse.is_finite() { truth.estimated_rel_mse } else { 0.0 };

    let all = settings(scene);
    let (_, truth_key) = reference_settings(&truth_scene, options.truth_spp);
    let key = format!(
        "auto pilot 2; truth: {truth_key}; pilot spp {}; seed {}; sampling {}; settings: {}",
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
                let variant = apply(&small, setting);
                let t = Instant::now();
                let mut tracer = PathTracer::new(gpu, &variant)?;
                tracer.render_to_spp(1)?; // the first pass also sets up buffers
                let setup = t.elapsed().as_secs_f64();
                tracer.reset();
                let t = Instant::now();
                tracer.render_to_spp(options.timing_spp)?;
                let per_spp = t.elapsed().as_secs_f64() / f64::from(options.timing_spp) * pixel_ratio;
                (setup, per_spp)
            }
        };
        candidates.push(Candidate {
            setting: setting.clone(),
            bias_rel_mse: m.bias_rel_mse,
            noise_per_sample: m.noise_per_sample,
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
    let (image, own_noise) = render(gpu, &apply(small, setting), setting, options.pilot_spp)?;
    let errors = compare(&image, truth, regions);
    Ok(measured(&errors, regions, truth_rel_mse, own_noise, options.pilot_spp))
}

/// Renders `scene` (with `setting` applied, see [`apply`]) by the setting's renderer, the path
/// tracer at `spp`; returns the image and, for the path tracer, its estimated relMSE from noise.
pub fn render(
    gpu: &GpuContext,
    scene: &Scene,
    setting: &Setting,
    spp: u32,
) -> anyhow::Result<(RgbImage32, Option<f64>)> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    Ok(match setting {
        Setting::Raster { look, effects } => {
            let mut renderer = RasterRenderer::new(gpu, &RasterScene::from_scene(scene)?, w, h)?;
            (renderer.render(&Options { look: *look, effects: *effects })?, None)
        }
        Setting::Whitted { .. } => (WhittedTracer::new(gpu, scene)?.render()?, None),
        Setting::PathTrace { .. } => {
            let mut tracer = PathTracer::new(gpu, scene)?;
            tracer.render_to_spp(spp)?;
            let accumulator = tracer.accumulator();
            (accumulator.mean_image(), Some(accumulator.estimated_rel_mse()))
        }
    })
}

/// The cached measurements, if `path` holds them for exactly `key`.
fn read_cache(path: &Path, key: &str, expected: usize) -> Option<Vec<Measured>> {
    let text = std::fs::read_to_string(path).ok()?;
    let (first, rest) = text.split_once('\n')?;
    if first.strip_prefix("# ")? != key {
        return None;
    }
    let mut reader = csv::Reader::from_reader(rest.as_bytes());
    let mut measured = Vec::new();
    for record in reader.records() {
        let record = record.ok()?;
        let number = |i: usize| record.get(i)?.parse::<f64>().ok();
        let noise = record.get(2)?;
        let region = record.get(3)?;
        measured.push(Measured {
            bias_rel_mse: number(1)?,
            noise_per_sample: if noise.is_empty() { None } else { Some(noise.parse().ok()?) },
            worst_region: if region.is_empty() { None } else { Some((region.to_owned(), number(4)?)) },
        });
    }
    (measured.len() == expected).then_some(measured)
}

fn write_cache(path: &Path, key: &str, settings: &[Setting], measured: &[Measured]) -> anyhow::Result<()> {
    let rows: Vec<Vec<String>> = settings
        .iter()
        .zip(measured)
        .map(|(s, m)| {
            vec![
                s.to_string(),
                format!("{:e}", m.bias_rel_mse),
                m.noise_per_sample.map_or(String::new(), |n| format!("{n:e}")),
                m.worst_region.as_ref().map_or(String::new(), |(r, _)| r.clone()),
                m.worst_region.as_ref().map_or(String::new(), |(_, ratio)| format!("{ratio:e}")),
            ]
        })
        .collect();
    let header =
        ["setting", "bias_rel_mse", "noise_per_sample", "worst_region", "worst_region_luminance_ratio"];
    write_text(path, &format!("# {key}\n{}", csv_text(&header, &rows)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cache_reads_back_what_it_wrote_and_refuses_another_key() {
        let folder = std::env::temp_dir().join(format!("illum-auto-cache-{}", std::process::id()));
        std::fs::create_dir_all(&folder).unwrap();
        let path = folder.join("pilot.csv");
        let settings = [
            Setting::Whitted { depth: 8, aa: 2 },
            Setting::PathTrace { bounces: Bounces::Unbounded, caustics: true },
        ];
        let measured = vec![
            Measured {
                bias_rel_mse: 0.06,
                noise_per_sample: None,
                worst_region: Some(("floor in the glass sphere's shadow, a \"quoted\" name".into(), 0.27)),
            },
            Measured { bias_rel_mse: 1.5e-6, noise_per_sample: Some(0.11), worst_region: None },
        ];
        write_cache(&path, "key 1", &settings, &measured).unwrap();
        assert_eq!(read_cache(&path, "key 1", 2), Some(measured));
        assert_eq!(read_cache(&path, "key 2", 2), None);
        assert_eq!(read_cache(&path, "key 1", 3), None);
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
