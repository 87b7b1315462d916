//! `bench --viewer`: the viewer's path tracer as a user meets it, the real window under
//! `xvfb-run` with the view still (`illum-viewer --mode pathtrace --screenshot`, which prints its
//! statistics on exit), beside `render`'s loop on the same scene at the viewer's resolution for
//! the same wall time, run after it, `runs` times.

use std::path::PathBuf;

use illum::image::median;
use illum::pathtrace::PathTracer;
use illum::scene::Scene;
use illum_cli::SceneArgs;
use illum_lab::report::load_average;

use crate::Args;

/// What a `--screenshot` run of the viewer printed about its path tracer.
struct ViewerRun {
    width: u32,
    height: u32,
    samples_per_second: f64,
    elapsed: f64,
    fps: f64,
    /// Share of the wall time the viewer spent in its path tracer's steps.
    stepping: f64,
}

/// The number after `name ` in the viewer's statistics line.
fn statistic(line: &str, name: &str) -> anyhow::Result<f64> {
    let rest = line
        .split(&format!("{name} "))
        .nth(1)
        .ok_or_else(|| anyhow::anyhow!("the viewer's statistics lack {name:?}: {line}"))?;
    let number: String = rest.chars().take_while(|c| c.is_ascii_digit() || *c == '.').collect();
    number.parse().map_err(|_| anyhow::anyhow!("{name:?} is not followed by a number in: {line}"))
}

/// Runs the viewer binary (next to this example's folder) in a 960 x 600 window under
/// `xvfb-run` for `frames` frames, and reads its statistics line.
fn run_viewer(scene: &std::path::Path, frames: u32) -> anyhow::Result<ViewerRun> {
    use anyhow::Context;
    let exe = std::env::current_exe()?;
    let viewer = exe
        .parent()
        .and_then(std::path::Path::parent)
        .map(|dir| dir.join(format!("illum-viewer{}", std::env::consts::EXE_SUFFIX)))
        .filter(|path| path.exists())
        .ok_or_else(|| {
            anyhow::anyhow!(
                "the viewer binary is missing: build it with `cargo build --release -p illum-viewer`"
            )
        })?;
    let dir = tempfile_dir()?;
    let output = std::process::Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24"])
        .arg(&viewer)
        .arg(scene)
        .args(["--mode", "pathtrace", "--frames", &frames.to_string(), "--screenshot"])
        .arg(dir.join("viewer.png"))
        .output()
        .context("starting xvfb-run (apt-get install xvfb xauth)")?;
    let _ = std::fs::remove_dir_all(&dir);
    let stdout = String::from_utf8_lossy(&output.stdout);
    anyhow::ensure!(
        output.status.success(),
        "the viewer failed ({}): {}{}",
        output.status,
        stdout,
        String::from_utf8_lossy(&output.stderr)
    );
    let line = stdout
        .lines()
        .find_map(|l| l.strip_prefix("statistics: pathtrace: "))
        .ok_or_else(|| anyhow::anyhow!("the viewer printed no path-tracer statistics: {stdout}"))?;
    let size = line.split(',').next().unwrap_or_default();
    let (width, height) = size
        .split_once(" x ")
        .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
        .ok_or_else(|| anyhow::anyhow!("no resolution in the viewer's statistics: {line}"))?;
    Ok(ViewerRun {
        width,
        height,
        samples_per_second: statistic(line, "samples/s (wall)")? * 1e6,
        elapsed: statistic(line, "elapsed")?,
        fps: statistic(line, "window")?,
        stepping: statistic(line, "stepping")? / 100.0,
    })
}

/// A fresh folder for the viewer's screenshot.
fn tempfile_dir() -> anyhow::Result<PathBuf> {
    let dir = std::env::temp_dir().join(format!("illum-bench-viewer-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

/// The viewer's path tracer against `render`'s loop at the viewer's resolution, side by side.
pub(crate) fn bench_viewer(gpu: &illum::gpu::GpuContext, args: &Args) -> anyhow::Result<()> {
    use illum::pathtrace::{StopRules, render_progressive};
    let path = illum_cli::resolve_scene_path(&args.scene);
    println!(
        "| run | resolution | viewer Msamples/s (wall) | window fps | viewer's share of wall time in the path tracer | render Msamples/s (wall), same size and time | viewer / render |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut ratios = Vec::new();
    for run in 1..=args.runs {
        let viewer = run_viewer(&path, args.frames)?;
        let settings =
            SceneArgs { width: Some(viewer.width), height: Some(viewer.height), ..Default::default() };
        let scene: Scene = illum_cli::load_scene(&path, &settings)?;
        let mut tracer = PathTracer::new(gpu, &scene)?;
        tracer.set_chunk_aligned_passes(true);
        let rules = StopRules {
            time_budget: Some(std::time::Duration::from_secs_f64(viewer.elapsed.max(0.5))),
            ..Default::default()
        };
        let never = std::sync::atomic::AtomicBool::new(false);
        let (_, progressive) = render_progressive(&mut tracer, &rules, &never, |_, _| {})?;
        let render = progressive.status(&tracer).samples_per_second();
        let ratio = viewer.samples_per_second / render;
        ratios.push(ratio);
        println!(
            "| {run} | {} x {} | {:.2} | {:.1} | {:.0}% | {:.2} | {:.2} |",
            viewer.width,
            viewer.height,
            viewer.samples_per_second * 1e-6,
            viewer.fps,
            100.0 * viewer.stepping,
            render * 1e-6,
            ratio
        );
    }
    let load = load_average().map_or(String::new(), |l| format!(" (load average {l} at the end)"));
    println!("\nviewer / render, median of {} runs: {:.2}{load}", ratios.len(), median(&mut ratios));
    Ok(())
}
