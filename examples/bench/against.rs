//! `bench --against OLD_RENDER --truth TRUTH.exr SCENE`: the efficiency of this build's caustic
//! estimators and sequences against another build's `render` (an older commit's, built in a
//! worktree: `scripts/readme-figures.sh --against REV` does both), side by side in one run.
//!
//! Each configuration renders `SCENE` at 320 x 180 and 64 spp with seeds 1 to `runs`, the
//! configurations alternated seed by seed (A B C D E, then again), so that the host's drift
//! falls on all of them alike. A row's time is the median whole-process wall time of its runs
//! after the first (which may compile shaders); its relMSE is the mean over every run against
//! `TRUTH.exr`, one truth for every row (illum_image's rel_mse); efficiency is 1 / (relMSE x
//! seconds), and the last column its ratio to the other build's.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use illum::image::{median, metrics::rel_mse};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 180;
const SPP: u32 = 64;

/// One row: which binary, with which flags beyond the common ones.
struct Config {
    label: &'static str,
    this_build: bool,
    flags: &'static [&'static str],
}

const CONFIGS: [Config; 5] = [
    Config { label: "the other build, the scene's caustic estimator", this_build: false, flags: &[] },
    Config {
        label: "light tracer and photon gather",
        this_build: true,
        flags: &["--caustic-method", "light-tracer"],
    },
    Config { label: "manifold NEE", this_build: true, flags: &["--caustic-method", "manifold"] },
    Config {
        label: "manifold NEE, low-discrepancy (4 replicates: with an error estimate)",
        this_build: true,
        flags: &["--caustic-method", "manifold", "--sequence", "low-discrepancy"],
    },
    Config {
        label: "manifold NEE, low-discrepancy (one randomisation: no error estimate)",
        this_build: true,
        flags: &["--caustic-method", "manifold", "--sequence", "low-discrepancy", "--replicates", "off"],
    },
];

/// Renders `scene` with `render` and `flags` at `seed` into `out`; its whole-process seconds.
fn process_seconds(
    render: &Path,
    scene: &Path,
    flags: &[&str],
    seed: u32,
    out: &Path,
) -> anyhow::Result<f64> {
    let mut command = Command::new(render);
    command.arg(scene).args(["--renderer", "pathtrace"]).args(flags);
    command.args(["--width", &WIDTH.to_string(), "--height", &HEIGHT.to_string(), "--spp", &SPP.to_string()]);
    command.args(["--seed", &seed.to_string()]).arg("-o").arg(out);
    let started = Instant::now();
    let output = command.output()?;
    let seconds = started.elapsed().as_secs_f64();
    anyhow::ensure!(
        output.status.success(),
        "{} {} {} failed ({}): {}",
        render.display(),
        scene.display(),
        flags.join(" "),
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    Ok(seconds)
}

pub(crate) fn bench_against(other: &Path, truth_path: &Path, scene: &Path, runs: u32) -> anyhow::Result<()> {
    anyhow::ensure!(
        other.is_file(),
        "--against {}: no such file (a render binary of another build)",
        other.display()
    );
    let this = crate::first_image::render_binary()?;
    let (truth, _) = illum::image::load_exr(truth_path)
        .map_err(|e| anyhow::anyhow!("--truth {}: {e}", truth_path.display()))?;
    anyhow::ensure!(
        (truth.width, truth.height) == (WIDTH, HEIGHT),
        "--truth {}: {} x {} pixels, the rows are {WIDTH} x {HEIGHT}",
        truth_path.display(),
        truth.width,
        truth.height
    );
    let runs = runs.max(2);
    let dir = std::env::temp_dir().join(format!("illum-bench-against-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let mut seconds = vec![Vec::new(); CONFIGS.len()];
    let mut errors = vec![Vec::new(); CONFIGS.len()];
    for seed in 1..=runs {
        for (i, config) in CONFIGS.iter().enumerate() {
            let binary: PathBuf = if config.this_build { this.clone() } else { other.to_path_buf() };
            let out = dir.join(format!("row{i}-seed{seed}.exr"));
            let s = process_seconds(&binary, scene, config.flags, seed, &out)?;
            if seed > 1 {
                seconds[i].push(s);
            }
            let (image, _) = illum::image::load_exr(&out)?;
            errors[i].push(rel_mse(&image, &truth)?);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    println!("{} at {WIDTH} x {HEIGHT}, {SPP} spp, seeds 1 to {runs} alternated\n", scene.display());
    println!(
        "| build, caustic, sequence | whole process s | relMSE | efficiency, 1 / (relMSE x s) | against the other build |"
    );
    println!("|---|---|---|---|---|");
    let rows: Vec<(f64, f64)> = seconds
        .iter_mut()
        .zip(&errors)
        .map(|(s, e)| (median(s), e.iter().sum::<f64>() / e.len() as f64))
        .collect();
    let base = 1.0 / (rows[0].0 * rows[0].1);
    for (config, &(s, e)) in CONFIGS.iter().zip(&rows) {
        let efficiency = 1.0 / (s * e);
        println!(
            "| {} | {s:.2} | {e:.3e} | {efficiency:.0} | {:.2}x |",
            if config.this_build { format!("this build, {}", config.label) } else { config.label.to_owned() },
            efficiency / base
        );
    }
    Ok(())
}
