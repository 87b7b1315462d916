//! Renders the pictures of docs/theory-whitted.md: both looks of the rasterizer (which fakes
//! Whitted's look), and a contact sheet of the effect toggles.
//!
//! ```text
//! cargo run --release --example raster_figures -- [--out out/raster-figures]
//! ```
//! The default folder is under `out/`, like every example's; `--out docs/images` replaces the
//! pictures the docs show.
//! Writes `whitted-figure.png` and `whitted-enhanced.png` (640 x 360) and `whitted-effects.png`
//! (eight labelled 400 x 225 panels). PNGs are linear, as the assignment's figure 1.

use std::path::PathBuf;

use anyhow::Context;
use clap::Parser;

use illum::image::{Encoding, save_png, save_rgba8_png, to_rgba8};
use illum::raster::{Effects, Look, Options, RasterRenderer, RasterScene};
use illum_lab::contact_sheet::contact_sheet;

#[derive(Parser, Debug)]
#[command(about = "Render the rasterizer's pictures: both looks, and a contact sheet of the \
             effect toggles (use --out docs/images to update the docs' copies)")]
struct Args {
    /// Output folder.
    #[arg(long, default_value = "out/raster-figures")]
    out: PathBuf,
}

fn main() {
    illum_cli::main_with(run);
}

fn with(look: Look, change: impl FnOnce(&mut Effects)) -> Options {
    let mut options = Options::all_on(look);
    change(&mut options.effects);
    options
}

fn run(args: Args) -> anyhow::Result<()> {
    let scene = RasterScene::load(&illum_cli::resolve_scene_path("scenes/whitted.toml".as_ref()))?;
    let gpu = illum_cli::gpu()?;

    let mut large = RasterRenderer::new(&gpu, &scene, 640, 360)?;
    for look in Look::ALL {
        let path = args.out.join(format!("whitted-{look}.png"));
        save_png(&path, &large.render(&Options::all_on(look))?, 0.0, Encoding::Linear)?;
        println!("wrote {}", path.display());
    }

    let panels = [
        ("figure (the fake)", Options::all_on(Look::Figure)),
        ("enhanced look", Options::all_on(Look::Enhanced)),
        ("figure, no refraction", with(Look::Figure, |e| e.refraction = false)),
        ("enhanced, no reflection", with(Look::Enhanced, |e| e.reflection = false)),
        ("enhanced, no Fresnel", with(Look::Enhanced, |e| e.fresnel = false)),
        ("figure, no shadows", with(Look::Figure, |e| e.shadows = false)),
        ("figure, no PCF", with(Look::Figure, |e| e.pcf = false)),
        ("figure, no anti-aliasing", with(Look::Figure, |e| e.antialiasing = false)),
    ];
    let mut small = RasterRenderer::new(&gpu, &scene, 400, 225)?;
    let mut images = Vec::new();
    for (label, options) in panels {
        let image = small.render(&options).with_context(|| format!("rendering {label}"))?;
        images.push((label.to_owned(), to_rgba8(&image, 0.0, Encoding::Linear)));
    }
    let path = args.out.join("whitted-effects.png");
    save_rgba8_png(&path, &contact_sheet(&images, 4))?;
    println!("wrote {}", path.display());
    Ok(())
}
