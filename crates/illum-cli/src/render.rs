//! The `render` command (`cargo run --example render`): its flags ([`RenderArgs`]) and
//! [`render`], which picks the renderer and runs its path: [`crate::raster`],
//! [`crate::whitted`] or [`crate::pathtrace`]. `--renderer auto` measures first (`auto::run`),
//! then renders its plan with [`render`].
//!
//! With no arguments it renders `scenes/cornell.toml` to `out/cornell.png` and `out/cornell.exr`.
//! `--renderer pathtrace|raster|whitted|auto` picks the renderer; the default is the scene
//! file's `renderer` (`scenes/whitted.toml` says `raster`). A renderer given a scene it cannot
//! render, or a flag of another renderer, says what it lacks.
//!
//! Ctrl-C or SIGTERM stops a render early, exiting with status 130 (SIGINT) or 143 (SIGTERM).
//! Copies of the signal within a second of the first (`timeout`, Slurm and systemd signal the
//! whole process group) are the same request; a signal after that ends the process at once
//! ([`crate::interrupt`]). What each renderer writes when stopped is in its module. Every output
//! is checked before rendering.
//!
//! Progress: a bar on a terminal; when standard error is not one (a job log), a line starting
//! with `progress: ` every `--progress-seconds` (default 10) and at every tenth of the way.

use illum_scene::{RendererKind, Scene};

use crate::LongRender;
use crate::interrupt::Interrupt;
use crate::raster::{RasterRequest, render_raster};
pub use crate::render_args::RenderArgs;
use crate::render_args::RendererChoice;
use crate::whitted::{WhittedRequest, render_whitted};

/// Renders with the renderer and settings the flags name; for the path tracer, returns its
/// estimated relative error from noise.
pub fn render(args: &RenderArgs) -> anyhow::Result<Option<f64>> {
    // First, so that a stop during the (slow on lavapipe) setup is handled like one during the
    // render: a message and the signal's status, never the default silent death.
    let interrupt = Interrupt::install()?;
    interrupt
        .set_note(&crate::interrupt::note("nothing (no file was written yet)", "the render and its setup"));
    let long = LongRender {
        interrupt: Some(&interrupt),
        progress_period: args.progress_seconds.unwrap_or(crate::progress::DEFAULT_PERIOD),
    };
    let renderer = match args.renderer {
        Some(RendererChoice::Kind(renderer)) => renderer,
        Some(RendererChoice::Auto) | None => Scene::load(&crate::resolve_scene_path(&args.scene))?.renderer,
    };
    let path_tracer_only = args.path_tracer_only_flags();
    if renderer == RendererKind::Whitted {
        let mut other_flags = path_tracer_only;
        other_flags.extend(args.raster.given());
        return render_whitted(&WhittedRequest {
            scene: &args.scene,
            settings: &args.settings,
            args: &args.whitted,
            outputs: &args.outputs,
            encoding: args.encoding,
            exposure: args.exposure,
            other_flags,
            long,
            reference: args.reference.as_deref(),
        })
        .map(|()| None);
    }
    let whitted_flags = args.whitted.given();
    if !whitted_flags.is_empty() {
        anyhow::bail!(
            "{}: {} {} only to the Whitted ray tracer (--renderer whitted)",
            args.scene.display(),
            whitted_flags.join(", "),
            crate::verb(whitted_flags.len())
        );
    }
    if renderer == RendererKind::Raster {
        return render_raster(&RasterRequest {
            scene: &args.scene,
            settings: &args.settings,
            args: &args.raster,
            outputs: &args.outputs,
            encoding: args.encoding,
            exposure: args.exposure,
            other_flags: path_tracer_only,
            long,
            reference: args.reference.as_deref(),
        })
        .map(|()| None);
    }
    crate::pathtrace::render_pathtrace(args, &interrupt, long)
}
