//! `bench --parts`: where a path-traced render's time goes with every estimator on, one row per
//! part, so that no part grows unmeasured. Each configuration renders the scene with the
//! caustic's estimators off and on, the runs alternated, and each row is a median over the runs
//! of the part's seconds per spp, beside the same figure of the camera paths alone (estimators
//! off) on the same clock: GPU rows against the camera paths' GPU time, host and wall rows
//! against their wall time. Where the scene allows it, a third configuration renders with
//! manifold next-event estimation instead of the light tracer (`caustic_method = "manifold"`).

use illum::gpu::GpuContext;
use illum::image::median;
use illum::pathtrace::Estimators;
use illum::pathtrace::{CausticParts, PathTracer};
use illum::scene::{CausticMethod, Scene};

/// What one render measured, its times in seconds.
struct Run {
    setup: f64,
    wall: f64,
    /// The camera bands' GPU time (0 without timestamps).
    camera_gpu: f64,
    /// The light tracer's time as the tracer counts it (its submissions, waits and folds).
    caustic: f64,
    parts: CausticParts,
}

fn render(gpu: &GpuContext, scene: &Scene, spp: u32) -> anyhow::Result<Run> {
    let started = std::time::Instant::now();
    let mut tracer = PathTracer::new(gpu, scene)?;
    let setup = started.elapsed().as_secs_f64();
    let started = std::time::Instant::now();
    tracer.render_to_spp(spp)?;
    Ok(Run {
        setup,
        wall: started.elapsed().as_secs_f64(),
        camera_gpu: tracer.gpu_seconds(),
        caustic: tracer.caustic_seconds(),
        parts: tracer.caustic_parts().unwrap_or_default(),
    })
}

/// `scene` with its caustic on, found by `method`.
fn caustic_scene(scene: &Scene, method: CausticMethod) -> Scene {
    let mut on = scene.clone();
    on.pathtrace.caustics = true;
    on.pathtrace.caustic_method = method;
    on
}

/// The median over `runs` of `f`.
fn med(runs: &[Run], f: impl Fn(&Run) -> f64) -> f64 {
    median(&mut runs.iter().map(f).collect::<Vec<_>>())
}

/// Prints the parts' table of `scene` at each (width, height, spp), `runs` times each.
pub fn bench_parts(gpu: &GpuContext, scene: &Scene, runs: u32, load: &str) -> anyhow::Result<()> {
    println!("the parts of a path-traced render of {} with its caustic estimators on{load}\n", scene.name);
    let solves = Estimators::of(&caustic_scene(scene, CausticMethod::Manifold)).manifold();
    let configurations =
        if solves { "caustics off, light tracer and manifold" } else { "caustics off and on" };
    for (width, height, spp) in [(320, 180, 64), (1280, 720, 16)] {
        let mut off_scene = scene.clone();
        (off_scene.camera.width, off_scene.camera.height) = (width, height);
        off_scene.pathtrace.caustics = false;
        let on_scene = caustic_scene(&off_scene, CausticMethod::LightTracer);
        let solved_scene = caustic_scene(&off_scene, CausticMethod::Manifold);
        let (mut off, mut on, mut solved) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..runs {
            off.push(render(gpu, &off_scene, spp)?);
            on.push(render(gpu, &on_scene, spp)?);
            if solves {
                solved.push(render(gpu, &solved_scene, spp)?);
            }
        }
        let n = f64::from(spp);
        let (camera_wall, camera_gpu) = (med(&off, |r| r.wall) / n, med(&off, |r| r.camera_gpu) / n);
        // The stages' times cover the frames whose stages were timed; scaled to all of them.
        let timed = |r: &Run, seconds: f64| {
            (r.parts.timed_frames > 0).then(|| seconds * r.parts.frames as f64 / r.parts.timed_frames as f64)
        };
        let particles = med(&on, |r| timed(r, r.parts.particles).unwrap_or(f64::NAN)) / n;
        let gather = med(&on, |r| timed(r, r.parts.gather).unwrap_or(f64::NAN)) / n;
        let fold = med(&on, |r| r.parts.fold_host) / n;
        let rest = med(&on, |r| {
            (r.caustic - r.parts.fold_host - timed(r, r.parts.particles + r.parts.gather).unwrap_or(f64::NAN))
                .max(0.0)
        }) / n;
        let row = |part: &str, clock: &str, seconds: f64, base: f64| {
            let ratio =
                if seconds.is_finite() && base > 0.0 { format!("{:.2}", seconds / base) } else { "-".into() };
            let ms = if seconds.is_finite() { format!("{:.3}", seconds * 1e3) } else { "-".into() };
            println!("| {part} | {clock} | {ms} | {ratio} |");
        };
        println!("{width} x {height}, {spp} spp, median of {runs} runs ({configurations} alternated):\n");
        println!("| part | clock | ms per spp | x the camera paths alone |");
        println!("|---|---|---|---|");
        row("camera paths alone (caustics off)", "GPU", camera_gpu, camera_gpu);
        row(
            "camera paths with the estimators on (glint, gather lookups)",
            "GPU",
            med(&on, |r| r.camera_gpu) / n,
            camera_gpu,
        );
        row("light tracer: particles and their photon storage", "GPU or waited", particles, camera_gpu);
        row("photon gather", "GPU or waited", gather, camera_gpu);
        row("camera paths alone (caustics off)", "wall", camera_wall, camera_wall);
        row("fold of the light tracer's frames", "host", fold, camera_wall);
        row("the light tracer's readback and waits", "wall", rest, camera_wall);
        row("whole render, caustics on", "wall", med(&on, |r| r.wall) / n, camera_wall);
        if solves {
            // Manifold next-event estimation replaces the light tracer and the gather: its time is
            // the camera paths' own (docs/caustics-manifold.md).
            row(
                "camera paths with manifold next-event estimation",
                "GPU",
                med(&solved, |r| r.camera_gpu) / n,
                camera_gpu,
            );
            row("whole render, caustic method manifold", "wall", med(&solved, |r| r.wall) / n, camera_wall);
        }
        // A difference within rounding of the printed figure prints as 0.00, not -0.00.
        let setup =
            Some(med(&on, |r| r.setup) - med(&off, |r| r.setup)).filter(|s| s.abs() >= 0.005).unwrap_or(0.0);
        println!(
            "\nset-up before the first sample with the estimators on (the glint's solve started beside the first \
             samples, the light tracer's buffers and pipelines): {setup:.2} s more than without\n"
        );
    }
    Ok(())
}
