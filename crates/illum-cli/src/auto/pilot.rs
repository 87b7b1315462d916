//! The command line's pilot of `--renderer auto`: [`illum_auto::pilot`] (what it measures and
//! how) looped to its end, with the command line's options, and its truth and its measured
//! biases cached in a folder under a key of the scene's content hash and every pilot setting,
//! like the ladder's truth; the throughput is measured every run.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context as _;
use illum_auto::pilot::{self as polled, Progress, Sizes, Unpaced};
use illum_gpu::GpuContext;
use illum_scene::Scene;

use super::cache::{read_cache, write_cache};
use illum_auto::plan::Candidate;
use illum_lab::reference::{OnStep, cached_reference, reference_settings};

/// How the command line's pilot measures, and where it caches.
#[derive(Clone, Debug)]
pub struct PilotOptions {
    pub pilot: polled::PilotOptions,
    /// Where the truth and the measured biases are cached.
    pub folder: PathBuf,
}

impl Default for PilotOptions {
    fn default() -> Self {
        PilotOptions { pilot: polled::PilotOptions::COMMAND_LINE, folder: PathBuf::from("out/auto") }
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
    /// the throughput (the truth's regions included).
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

/// Measures every setting for `scene` (at the size it will be rendered) on `gpu`.
/// `overhead_seconds`, what every render pays before its renderer starts (setting up the
/// device), is added to every candidate's fixed cost; `on_step` is told how far the truth is
/// when it has to be rendered.
pub fn measure(
    gpu: &GpuContext,
    scene: &Scene,
    overhead_seconds: f64,
    options: &PilotOptions,
    on_step: OnStep,
) -> anyhow::Result<Pilot> {
    let pilot_options = polled::PilotOptions { overhead_seconds, ..options.pilot };
    let sizes = Sizes::all(scene.camera.width, scene.camera.height);
    let mut pilot = polled::Pilot::new(scene, sizes, pilot_options).map_err(anyhow::Error::msg)?;
    std::fs::create_dir_all(&options.folder)
        .with_context(|| format!("creating {}", options.folder.display()))?;

    // The truth, rendered as the measuring tools' references are, cached by content.
    let truth_scene = pilot.truth_scene();
    let spp = pilot_options.truth_spp;
    let started = Instant::now();
    let truth = cached_reference(gpu, &truth_scene, spp, &options.folder, "auto pilot truth", on_step)?;
    let truth_seconds =
        if truth.metadata.get("reference_key").is_some() && started.elapsed().as_secs_f64() < 1.0 {
            0.0
        } else {
            started.elapsed().as_secs_f64()
        };
    let truth_rel_mse = if truth.estimated_rel_mse.is_finite() { truth.estimated_rel_mse } else { 0.0 };
    pilot = pilot.with_truth(truth.image, truth_rel_mse);

    let (_, truth_key) = reference_settings(&truth_scene, spp);
    // The leading version is raised whenever what a cached measurement holds changes (the pilot's
    // rules, or the output of a renderer or denoiser it measures): an older cache then misses.
    let key = format!(
        "auto pilot 6; truth: {truth_key}; pilot spp {}; seed {}; sampling {}; settings: {}",
        pilot_options.pilot_spp,
        scene.pathtrace.seed,
        scene.pathtrace.sampling,
        pilot.settings().iter().map(ToString::to_string).collect::<Vec<_>>().join("; ")
    );
    let bias_file = options.folder.join(format!(
        "auto-pilot-{}-{:016x}.csv",
        scene.name,
        illum_scene::fnv1a_64(key.as_bytes())
    ));
    let cached = read_cache(&bias_file, &key, pilot.settings().len());
    let was_cached = cached.is_some();
    if let Some(measured) = cached {
        pilot = pilot.with_measured(measured);
    }
    loop {
        match pilot.step(gpu, &mut Unpaced) {
            Progress::Working { .. } => {}
            Progress::Done => break,
            Progress::Failed(why) => anyhow::bail!("the auto pilot of {}: {why}", scene.name),
        }
    }
    let measured = pilot.measured().expect("done");
    if !was_cached {
        write_cache(&bias_file, &key, pilot.settings(), measured)?;
    }
    let [regions, bias_seconds, throughput_seconds] = pilot.phase_seconds();
    Ok(Pilot {
        candidates: pilot.candidates().expect("done").to_vec(),
        size: pilot.size(),
        truth_spp: spp,
        truth_rel_mse,
        truth_seconds,
        bias_seconds,
        throughput_seconds: regions + throughput_seconds,
        bias_file,
    })
}
