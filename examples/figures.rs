//! Renders the assignment's reference figures of the Cornell box.
//!
//! ```text
//! cargo run --release --example figures -- [SCENE] [--out DIR] [--width W --height H] [--seed S]
//! ```
//! - Figure 2: bounces 0, 1 and 2 at 20 spp (direct light, one bounce, two bounces).
//! - Figure 3: bounces 2 at 1, 4 and 16 spp.
//!
//! Each panel is written as a PNG (gamma 2.2, as the assignment's shader wrote it), and all six
//! are assembled into one labelled contact sheet, `DIR/contact-sheet.png`.

use std::path::PathBuf;

use clap::Parser;
use illum::image::{Encoding, save_png, save_rgba8_png, to_rgba8};
use illum::pathtrace::PathTracer;
use illum::scene::{Bounces, Overrides};
use illum_cli::SceneArgs;
use illum_lab::contact_sheet::contact_sheet;

#[derive(Parser, Debug)]
#[command(about = "Render the assignment's figures 2 and 3")]
struct Args {
    /// Scene file (TOML).
    #[arg(default_value = illum_cli::DEFAULT_SCENE)]
    scene: PathBuf,
    /// Output directory.
    #[arg(long, default_value = "out/figures")]
    out: PathBuf,
    /// Image width in pixels (default: the scene's).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (default: the scene's).
    #[arg(long)]
    height: Option<u32>,
    /// Random seed (default: the scene's).
    #[arg(long)]
    seed: Option<u32>,
}

/// (file stem, label, bounces, spp)
const PANELS: [(&str, &str, u32, u32); 6] = [
    ("figure2a", "Fig. 2a: direct light, 20 spp", 0, 20),
    ("figure2b", "Fig. 2b: 1 bounce, 20 spp", 1, 20),
    ("figure2c", "Fig. 2c: 2 bounces, 20 spp", 2, 20),
    ("figure3a", "Fig. 3a: 2 bounces, 1 spp", 2, 1),
    ("figure3b", "Fig. 3b: 2 bounces, 4 spp", 2, 4),
    ("figure3c", "Fig. 3c: 2 bounces, 16 spp", 2, 16),
];

fn main() {
    illum_cli::main_with(run);
}

fn run(args: Args) -> anyhow::Result<()> {
    let gpu = illum_cli::gpu()?;
    let base = SceneArgs { width: args.width, height: args.height, seed: args.seed, ..Default::default() };
    let mut sheet_panels = Vec::new();
    for (stem, label, bounces, spp) in PANELS {
        let mut scene = illum_cli::load_scene(&args.scene, &base)?;
        scene.apply_overrides(
            &Overrides { bounces: Some(Bounces::Fixed(bounces)), spp: Some(spp), ..Default::default() },
            "figure settings",
        )?;
        let mut tracer = PathTracer::new(&gpu, &scene)?;
        tracer.render_to_spp(spp)?;
        let image = tracer.accumulator().mean_image();
        let path = args.out.join(format!("{stem}.png"));
        save_png(&path, &image, 0.0, Encoding::Gamma22)?;
        println!("wrote {} ({label})", path.display());
        sheet_panels.push((label.to_owned(), to_rgba8(&image, 0.0, Encoding::Gamma22)));
    }
    let sheet = contact_sheet(&sheet_panels, 3);
    let path = args.out.join("contact-sheet.png");
    save_rgba8_png(&path, &sheet)?;
    println!("wrote {}", path.display());
    Ok(())
}
