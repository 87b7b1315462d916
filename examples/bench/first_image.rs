//! `bench --first-image`: the time to the first image, part of the speed/accuracy trade that a
//! per-pixel figure hides: the whole `render` process (start, device, the pipeline's compile by
//! the driver, one frame, the PNG) for each scene given, at 320 x 180, the path tracer at 1 spp
//! with the caustic's estimators off and the Whitted ray tracer at the scene's depth. Each is
//! timed cold, with Mesa's shader cache disabled (`MESA_SHADER_CACHE_DISABLE=true`: a new
//! scene, a fresh machine, or an edit that changes the shader), and warm, after an untimed run
//! that fills the cache. Beside them, the path tracer's throughput at 16 spp once compiled.
//! `scripts/many-spheres.py` writes scenes with many objects for it.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use illum::gpu::GpuContext;
use illum::image::median;
use illum::pathtrace::PathTracer;
use illum::scene::{Scene, Shape};
use illum_cli::SceneArgs;

const WIDTH: u32 = 320;
const HEIGHT: u32 = 180;
/// The samples per pixel of the throughput column.
const SPP: u32 = 16;

/// The `render` example beside this binary.
pub(crate) fn render_binary() -> anyhow::Result<PathBuf> {
    let exe = std::env::current_exe()?;
    exe.parent()
        .map(|dir| dir.join(format!("render{}", std::env::consts::EXE_SUFFIX)))
        .filter(|path| path.exists())
        .ok_or_else(|| {
            anyhow::anyhow!(
                "the render example is missing beside the bench: build it with `cargo build --release --example render`"
            )
        })
}

/// Wall seconds of one `render` process drawing `scene` with `renderer`, Mesa's shader cache
/// disabled when `cold`.
fn process_seconds(
    render: &Path,
    scene: &Path,
    renderer: &str,
    caustics: bool,
    cold: bool,
) -> anyhow::Result<f64> {
    let out = std::env::temp_dir().join(format!("illum-bench-first-image-{}.png", std::process::id()));
    let mut command = Command::new(render);
    command.arg(scene).args([
        "--renderer",
        renderer,
        "--width",
        &WIDTH.to_string(),
        "--height",
        &HEIGHT.to_string(),
    ]);
    if renderer == "pathtrace" {
        command.args(["--spp", "1"]);
        if caustics {
            command.args(["--caustics", "off"]);
        }
    }
    command.arg("-o").arg(&out);
    if cold {
        command.env("MESA_SHADER_CACHE_DISABLE", "true");
    } else {
        command.env_remove("MESA_SHADER_CACHE_DISABLE");
    }
    let started = Instant::now();
    let output = command.output()?;
    let seconds = started.elapsed().as_secs_f64();
    let _ = std::fs::remove_file(&out);
    anyhow::ensure!(
        output.status.success(),
        "render {} --renderer {renderer} failed ({}): {}{}",
        scene.display(),
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    Ok(seconds)
}

/// The path tracer's samples/s at 16 spp once its pipeline is compiled: the median of `runs`.
fn throughput(gpu: &GpuContext, scene: &Scene, runs: u32) -> anyhow::Result<f64> {
    let mut tracer = PathTracer::new(gpu, scene)?;
    // Warm-up: compiles the pipeline and teaches the planner the cost (as the other rows).
    tracer.render_to_spp(SPP)?;
    let samples = f64::from(WIDTH) * f64::from(HEIGHT) * f64::from(SPP);
    let mut rates = Vec::new();
    for _ in 0..runs {
        tracer.reset();
        tracer.render_to_spp(SPP)?;
        rates.push(samples / tracer.wall_seconds());
    }
    Ok(median(&mut rates))
}

pub fn bench_first_image(gpu: &GpuContext, scenes: &[PathBuf], runs: u32, load: &str) -> anyhow::Result<()> {
    let render = render_binary()?;
    println!(
        "time to the first image: the whole `render` process at {WIDTH} x {HEIGHT} (path tracer: 1 spp, caustics off), \
         median of {runs} runs{load}\n"
    );
    println!(
        "| scene | objects | spheres | objects under a BVH | path tracer cold s | path tracer warm s | Whitted cold s | Whitted warm s | Msamples/s at {SPP} spp |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for path in scenes {
        let settings =
            SceneArgs { spp: Some(SPP), width: Some(WIDTH), height: Some(HEIGHT), ..Default::default() };
        let mut scene: Scene = illum_cli::load_scene(path, &settings)?;
        let caustics = scene.pathtrace.caustics;
        scene.pathtrace.caustics = false;
        let spheres = scene.objects.iter().filter(|o| matches!(o.shape, Shape::Sphere(_))).count();
        let under_bvh = illum::rtcore::Geometry::new(&scene).analytic.map_or(0, |bvh| bvh.objects.len());
        let mut columns = Vec::new();
        for renderer in ["pathtrace", "whitted"] {
            let (mut cold, mut warm) = (Vec::new(), Vec::new());
            for _ in 0..runs {
                cold.push(process_seconds(&render, path, renderer, caustics, true)?);
                // Untimed: fills the shader cache.
                process_seconds(&render, path, renderer, caustics, false)?;
                warm.push(process_seconds(&render, path, renderer, caustics, false)?);
            }
            columns.push(median(&mut cold));
            columns.push(median(&mut warm));
        }
        let rate = throughput(gpu, &scene, runs)?;
        println!(
            "| {} | {} | {spheres} | {under_bvh} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
            path.display(),
            scene.objects.len(),
            columns[0],
            columns[1],
            columns[2],
            columns[3],
            rate * 1e-6
        );
    }
    Ok(())
}
