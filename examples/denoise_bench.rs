//! What denoising costs on this machine: the à-trous filter alone, Open Image Denoise's RT
//! filter on the CPU (in builds with `--features illum-denoise/oidn`; "-" otherwise) and the
//! guide pass, per megapixel, at a few image sizes (median of `--runs` after a warm-up), beside
//! the path tracer's own time per sample per pixel at that size.
//!
//! ```text
//! cargo run --release --example denoise_bench -- [SCENE] [--sizes 256,512,1024] [--runs 5]
//! ```

use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use illum::image::median;
use illum::pathtrace::{GUIDE_SAMPLES_MIN, PathTracer};
use illum::scene::{Overrides, Scene};
use illum_denoise::{AtrousDenoiser, AtrousSettings, DenoiseInput, Denoiser, DenoiserKind};

#[derive(Parser, Debug)]
#[command(about = "The à-trous denoiser's and the guide pass's cost in ms per megapixel")]
struct Args {
    #[arg(default_value = "scenes/cornell.toml")]
    scene: PathBuf,
    /// Square image sizes in pixels (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "256,512,1024")]
    sizes: Vec<u32>,
    /// Timed runs per measurement (the median is reported).
    #[arg(long, default_value_t = 5)]
    runs: u32,
}

fn main() {
    illum_cli::main_with(run);
}

fn run(args: Args) -> anyhow::Result<()> {
    let gpu = illum_cli::gpu()?;
    let filter = AtrousDenoiser::new(&gpu)?;
    let settings = AtrousSettings::default();
    let oidn = match Denoiser::new(&gpu, DenoiserKind::Oidn) {
        Ok(oidn) => Some(oidn),
        Err(e) => {
            println!("no OIDN column: {e}");
            None
        }
    };
    println!("{} on {}; à-trous {settings:?}", args.scene.display(), gpu.adapter_info.name);
    println!(
        "| size | à-trous ms | à-trous ms/Mpixel | OIDN ms/Mpixel | guides ({GUIDE_SAMPLES_MIN} spp) ms/Mpixel | path tracing ms/Mpixel per spp |"
    );
    println!("|---|---|---|---|---|---|");
    for &size in &args.sizes {
        let mut scene = Scene::load(&illum_cli::resolve_scene_path(&args.scene))?;
        let overrides =
            Overrides { width: Some(size), height: Some(size), spp: Some(4), ..Default::default() };
        scene.apply_overrides(&overrides, "--sizes")?;
        let mut tracer = PathTracer::new(&gpu, &scene)?;
        tracer.render_to_spp(1)?;
        let time = |f: &mut dyn FnMut() -> anyhow::Result<()>| -> anyhow::Result<f64> {
            f()?; // warm-up
            let mut ms = Vec::new();
            for _ in 0..args.runs.max(1) {
                let started = Instant::now();
                f()?;
                ms.push(started.elapsed().as_secs_f64() * 1e3);
            }
            Ok(median(&mut ms))
        };
        let trace_ms = time(&mut || {
            tracer.reset();
            tracer.render_to_spp(4)?;
            Ok(())
        })? / 4.0;
        let guides_ms = time(&mut || {
            tracer.guides(GUIDE_SAMPLES_MIN)?;
            Ok(())
        })?;
        let guides = tracer.guides(GUIDE_SAMPLES_MIN)?;
        let input = DenoiseInput::from_render(tracer.accumulator(), &guides);
        let filter_ms = time(&mut || {
            filter.denoise(&input, &settings)?;
            Ok(())
        })?;
        let mp = f64::from(size) * f64::from(size) / 1e6;
        let oidn_ms = match &oidn {
            Some(oidn) => format!(
                "{:.0}",
                time(&mut || {
                    oidn.denoise(&input)?;
                    Ok(())
                })? / mp
            ),
            None => "-".to_owned(),
        };
        println!(
            "| {size} x {size} | {filter_ms:.1} | {:.0} | {oidn_ms} | {:.0} | {:.0} |",
            filter_ms / mp,
            guides_ms / mp,
            trace_ms / mp
        );
    }
    Ok(())
}
