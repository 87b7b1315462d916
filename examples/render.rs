//! Renders a scene file to PNG and/or EXR with the path tracer, the rasterizer or the Whitted
//! ray tracer, or with `--renderer auto` the one a pilot of the scene predicts best for a goal.
//!
//! ```text
//! cargo run --release --example render -- [SCENE] [--renderer pathtrace|raster|whitted|auto]
//!     [--spp N] [--target-error X] [--time-budget SECONDS] [-o FILE.png|FILE.exr]... [--help]
//! ```
//! With no arguments it renders `scenes/cornell.toml` to `out/cornell.png` and `out/cornell.exr`.
//! The command is library code: its flags and renderers are `illum_cli::render`, the path
//! tracer's stop rules, checkpoints and split renders `illum_cli::pathtrace`. The pilot of
//! `--renderer auto` is a measuring tool (`illum_lab::auto`), wired here.

use illum_cli::auto::RendererChoice;
use illum_cli::render::{RenderArgs, render};
use illum_lab::auto::pilot::PilotOptions;
use illum_lab::auto::plan::Goal;

fn main() {
    illum_cli::main_with(run);
}

fn run(args: RenderArgs) -> anyhow::Result<()> {
    if args.renderer == Some(RendererChoice::Auto) {
        return run_auto(args);
    }
    render(&args).map(|_| ())
}

/// `--renderer auto`: checks the flags, runs the pilot, prints the plan, then renders it as the
/// flags naming its renderer and settings would, and compares what it reached with what was
/// predicted.
fn run_auto(mut args: RenderArgs) -> anyhow::Result<()> {
    let goal = args.auto_goal()?;
    let scene = illum_cli::load_scene(&args.scene, &args.settings)?;
    illum_cli::check_outputs(&args.outputs, &args.png_flags())?;
    let started = std::time::Instant::now();
    let gpu = illum_cli::gpu()?;
    let device_seconds = started.elapsed().as_secs_f64();
    let progress = illum_cli::progress::RenderProgress::new();
    let on_step = &mut |t: &_, p: &_| progress.update(t, p);
    let pilot =
        illum_lab::auto::pilot::measure(&gpu, &scene, device_seconds, &PilotOptions::default(), on_step)?;
    progress.finish();
    drop(gpu);
    let pilot_seconds = started.elapsed().as_secs_f64();
    let left = illum_cli::auto::goal_left(goal, pilot_seconds).map_err(anyhow::Error::msg)?;
    let plan = illum_lab::auto::plan::plan(&pilot.candidates, left)
        .map_err(|why| anyhow::anyhow!("{}: {why}", args.scene.display()))?;
    if let (Goal::Seconds(budget), Goal::Seconds(rest)) = (goal, left) {
        println!(
            "auto: the pilot took {pilot_seconds:.1} s of the {budget} s budget; the render gets the {rest:.1} s left"
        );
    }
    print!("{}", illum_lab::auto::describe(&scene, &pilot, left, &plan));
    args.follow(&plan.choice, &scene, left);
    let rendering = std::time::Instant::now();
    let noise = render(&args)?;
    println!("{}", illum_lab::auto::reached(&plan.choice, noise, rendering.elapsed().as_secs_f64()));
    if let Goal::Seconds(budget) = goal {
        println!(
            "auto: the whole command took {:.1} s of its {budget} s budget (the device and the pilot {pilot_seconds:.1} s)",
            started.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
