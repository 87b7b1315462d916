//! Renders a scene file to PNG and/or EXR with the path tracer, the rasterizer or the Whitted
//! ray tracer, or with `--renderer auto` the one a pilot of the scene predicts best for a goal.
//!
//! ```text
//! cargo run --release --example render -- [SCENE] [--renderer pathtrace|raster|whitted|auto]
//!     [--spp N] [--target-error X] [--time-budget SECONDS] [-o FILE.png|FILE.exr]... [--help]
//! ```
//! With no arguments it renders `scenes/cornell.toml` to `out/cornell.png` and `out/cornell.exr`.
//! The command is library code: its flags and renderers are `illum_cli::render`, the path
//! tracer's stop rules, checkpoints and split renders `illum_cli::pathtrace`, `--renderer auto`
//! `illum_cli::auto`.

use illum_cli::auto::RendererChoice;
use illum_cli::render::{RenderArgs, render};

fn main() {
    illum_cli::main_with(|args: RenderArgs| match args.renderer {
        Some(RendererChoice::Auto) => illum_cli::auto::run(args),
        _ => render(&args).map(|_| ()),
    });
}
