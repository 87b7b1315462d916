//! The speed/accuracy ladder: one scene through every renderer, each image timed and compared
//! with the converged path-traced truth, overall and per region.
//!
//! ```text
//! cargo run --release --example ladder -- [SCENE] [--width W --height H] [--truth-spp N]
//!     [--truth-bounces B] [--truth FILE.exr] [--spp-list 1,4,16,64,256,1024] [--depths 1,2,8]
//!     [--bounce-list 0,1,2,4] [--bounce-spp 1024] [--denoise-spp-list 1,4,16,64,256] [--frames 5]
//!     [--tessellate 1,2,3,4] [--tessellate-flat 1,3] [--tessellate-spp N] [--out DIR]
//! ```
//! Rows:
//! - the rasterizer (if it can draw the scene): the `figure` look, the `enhanced` look, and the
//!   enhanced look with each effect off in turn;
//! - the Whitted ray tracer at each depth of `--depths` (the first alone in a scene without a
//!   mirror or glass, where depth changes nothing);
//! - the path tracer at each spp of `--spp-list` (the scene's bounces), without and (where the
//!   scene has a caustic: a sun and a mirror or glass) with the caustic estimator (the light
//!   tracer) and, where the scene is solvable sphere by sphere, with manifold next-event
//!   estimation in its place (docs/caustics-manifold.md), the latter once more with the
//!   low-discrepancy sequence, one randomisation (no error estimate), and at each
//!   bounce count of `--bounce-list` with `--bounce-spp` samples (on the Cornell box this is
//!   the classic "Whitted against path tracing, bounce by bounce");
//! - the path tracer at each spp of `--denoise-spp-list` followed by the à-trous denoiser, and
//!   by Open Image Denoise in builds with `--features illum-denoise/oidn` (illum-denoise, with
//!   its bound on every denoised pixel; the guide pass and the filter are part of its time);
//! - with `--tessellate` (a scene with a sphere, e.g. scenes/cornell-sphere.toml): the path
//!   tracer at `--tessellate-spp` with the scene's spheres, then with icospheres of each
//!   subdivision of `--tessellate` (shaded smoothly) and `--tessellate-flat` (flat) in their
//!   place, against the analytic scene's truth; the sphere's pixels get regions of their own
//!   (rim, shadow terminator, lit and dark side), and ladder.md a section on what the
//!   tessellation costs (`tessellation.rs`).
//!
//! Each row's time is the median of `--frames` frames: the rasterizer's wall time per frame as
//! a viewer pays it (no readback) and its GPU time from timestamp queries; the Whitted ray
//! tracer's wall time per image (dispatch and readback); the path tracer's wall time to render
//! that many samples per pixel from nothing (median of up to 3 runs).
//! (Compute passes get no GPU time: on lavapipe the timestamps around a compute dispatch do not
//! grow with its work, so they do not measure it.)
//!
//! The truth is a path-traced render with `--truth-spp` samples per pixel (`--truth-bounces`,
//! by default unbounded; the caustic estimator where the scene has a caustic; cosine sampling;
//! its own seed), cached in DIR under a name derived from everything that
//! changes it, or the EXR given by `--truth`. The regions come from the Whitted ray tracer's
//! object-ID image (`illum_lab::regions`).
//!
//! Outputs in DIR: ladder.csv (one line per row and region: renderer, settings, times, pixels,
//! relMSE, luminance ratio, FLIP, efficiency), ladder.md (the tables), error-vs-time.png and
//! flip-vs-time.png (log-log, one series per renderer), contact-sheet.png (each image beside
//! its FLIP error map, labelled), regions.png; with `--tessellate`, tessellation-sheet.png (each
//! tessellation row around the sphere, enlarged, beside FLIP's map of its difference from the
//! analytic sphere's image).
//!

mod outputs;
mod rungs;
mod tessellation;

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::Parser;

use illum::pathtrace::Estimators;
use illum::scene::{Bounces, CausticMethod, MAX_WHITTED_DEPTH, MaterialKind, Scene};
use illum::whitted::WhittedTracer;
use illum_auto::settings::{has_caustic, truth_scene};
use illum_denoise::{Denoiser, DenoiserKind};
use illum_lab::reference::{Reference, cached_reference, load_reference};
use illum_lab::regions::{Regions, compare};

use outputs::{Header, Row, write_outputs};
use rungs::{Series, denoised_rung, pathtrace_rung, print_rung, raster_rungs, whitted_rung};

#[derive(Parser, Debug)]
#[command(
    about = "The speed/accuracy ladder: the scene through the rasterizer, the Whitted ray tracer and the \
             path tracer, each timed and compared with the converged path-traced truth, overall and per region"
)]
struct Args {
    /// Scene file (TOML).
    #[arg(default_value = "scenes/whitted.toml")]
    scene: PathBuf,
    /// Image width in pixels (default: the scene's aspect, 320 on the longer side).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (default: the scene's aspect, 320 on the longer side).
    #[arg(long)]
    height: Option<u32>,
    /// Samples per pixel of the rendered (and cached) truth.
    #[arg(long, default_value_t = 16384)]
    truth_spp: u32,
    /// Bounces of the truth: the converged solution of the rendering equation is `unbounded`
    /// (Russian roulette); the rows at the scene's own bounce count then show that count's bias.
    #[arg(long, default_value = "unbounded")]
    truth_bounces: Bounces,
    /// A truth EXR (linear, the same size) instead of rendering one.
    #[arg(long)]
    truth: Option<PathBuf>,
    /// The path tracer's rows: samples per pixel (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "1,4,16,64,256,1024")]
    spp_list: Vec<u32>,
    /// The Whitted ray tracer's rows: recursion depths (comma-separated, 0 to 64).
    #[arg(long, value_delimiter = ',', default_value = "1,2,8")]
    depths: Vec<u32>,
    /// The path tracer's rows by bounce count (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "0,1,2,4")]
    bounce_list: Vec<Bounces>,
    /// Samples per pixel of the rows by bounce count (0 skips them).
    #[arg(long, default_value_t = 1024)]
    bounce_spp: u32,
    /// The path tracer + à-trous rows: samples per pixel (comma-separated; the flag with no value
    /// skips them).
    #[arg(long, value_delimiter = ',', num_args = 0.., default_value = "1,4,16,64,256")]
    denoise_spp_list: Vec<u32>,
    /// Frames timed per row (the median is reported).
    #[arg(long, default_value_t = 5)]
    frames: u32,
    /// Tessellation rows: the scene's spheres replaced by the icosphere of each of these
    /// subdivisions (0 to 4), shaded smoothly (comma-separated; none by default).
    #[arg(long, value_delimiter = ',')]
    tessellate: Vec<u32>,
    /// Tessellation rows shaded flat, by subdivision (comma-separated; none by default).
    #[arg(long, value_delimiter = ',')]
    tessellate_flat: Vec<u32>,
    /// Samples per pixel of the tessellation rows (default: the largest of --spp-list).
    #[arg(long)]
    tessellate_spp: Option<u32>,
    /// Folder for the tables, plots, images and the cached truth.
    #[arg(long, default_value = "out/ladder")]
    out: PathBuf,
}

fn main() {
    illum_cli::main_with(run);
}

fn run(args: Args) -> anyhow::Result<()> {
    if args.frames == 0 {
        bail!("--frames 0: at least one frame must be timed");
    }
    if args.truth_spp == 0
        || args.spp_list.contains(&0)
        || args.denoise_spp_list.contains(&0)
        || args.tessellate_spp == Some(0)
    {
        bail!(
            "samples per pixel must be at least 1 (--truth-spp, --spp-list, --denoise-spp-list, --tessellate-spp)"
        );
    }
    let mut scene = Scene::load(&illum_cli::resolve_scene_path(&args.scene))?;
    let (w, h) = default_size(&scene, args.width, args.height);
    scene.apply_overrides(
        &illum::scene::Overrides { width: Some(w), height: Some(h), ..Default::default() },
        "command line",
    )?;
    if let Some(depth) = args.depths.iter().find(|&&d| d > MAX_WHITTED_DEPTH) {
        bail!("--depths {depth}: a Whitted depth must be 0 to {MAX_WHITTED_DEPTH}");
    }
    let tessellating = !args.tessellate.is_empty() || !args.tessellate_flat.is_empty();
    let geometries = if tessellating {
        tessellation::geometries(&scene, &args.tessellate, &args.tessellate_flat)?
    } else {
        Vec::new()
    };
    illum::image::check_output(args.out.join("ladder.csv"))?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let gpu = illum_cli::gpu()?;
    println!("scene {} at {w}x{h} on {}", scene.name, gpu.adapter_info.name);

    let Reference {
        image: truth,
        spp: truth_spp,
        estimated_rel_mse: truth_error,
        metadata: truth_metadata,
        ..
    } = match &args.truth {
        Some(path) => load_reference(path, &scene)?,
        None => {
            let truth_scene = truth_scene(&scene, args.truth_bounces);
            let progress = illum_cli::progress::RenderProgress::new();
            let truth = cached_reference(
                &gpu,
                &truth_scene,
                args.truth_spp,
                &args.out,
                "ladder truth",
                &mut |t, p| progress.update(t, p),
            )?;
            progress.finish();
            truth
        }
    };
    println!("truth: {truth_spp} spp, its own estimated relMSE {truth_error:.2e}");
    let most = args.spp_list.iter().copied().chain([args.bounce_spp]).max().unwrap_or(0);
    if truth_spp < 16 * u64::from(most) {
        println!(
            "warning: the truth has {truth_spp} spp, under 16 times the {most} spp of the largest row: \
             that row's error includes a sixteenth or more of the truth's own"
        );
    }
    let ids = WhittedTracer::new(&gpu, &scene)?.object_ids()?;
    let regions = Regions::from_ids(&scene, &ids);
    let regions =
        if tessellating { tessellation::with_sphere_bands(&scene, &regions, &ids) } else { regions };

    let mut rungs = Vec::new();
    raster_rungs(&gpu, &scene, args.frames, &mut rungs)?;
    // Without a mirror or glass no ray is ever reflected or refracted: every depth gives the
    // same image, so only the first is rendered.
    let depths =
        if has_specular(&scene) { &args.depths[..] } else { &args.depths[..args.depths.len().min(1)] };
    if depths.len() < args.depths.len() {
        println!("no mirror or glass: the Whitted ray tracer's depth changes nothing, one row only");
    }
    for &depth in depths {
        rungs.push(whitted_rung(&gpu, &scene, depth, args.frames)?);
        print_rung(rungs.last().expect("pushed"));
    }
    // Without and with the caustic estimator, where the scene has a caustic (a sun and a mirror
    // or glass to focus it; the truth has it), and with the manifold solve in the light
    // tracer's place where the scene is solvable sphere by sphere.
    let mut variants = vec![(scene.clone(), Series::PathTraceSpp)];
    variants[0].0.pathtrace.caustics = false;
    if has_caustic(&scene) {
        let mut light_tracer = scene.clone();
        light_tracer.pathtrace.caustics = true;
        light_tracer.pathtrace.caustic_method = CausticMethod::LightTracer;
        let mut manifold = light_tracer.clone();
        manifold.pathtrace.caustic_method = CausticMethod::Manifold;
        let solvable = Estimators::of(&manifold).manifold();
        variants.push((light_tracer, Series::PathTraceCaustics));
        if solvable {
            variants.push((manifold.clone(), Series::PathTraceManifold));
            variants.push((manifold, Series::PathTraceManifoldLowDiscrepancy));
        }
    }
    for (variant, series) in &variants {
        let series = *series;
        for &spp in &args.spp_list {
            let setting = (spp, scene.pathtrace.bounces);
            rungs.push(pathtrace_rung(&gpu, variant, setting, series, args.frames.min(3))?);
            print_rung(rungs.last().expect("pushed"));
        }
    }
    let mut with_caustic = scene.clone();
    with_caustic.pathtrace.caustics = has_caustic(&scene);
    for &bounces in args.bounce_list.iter().filter(|_| args.bounce_spp > 0) {
        let setting = (args.bounce_spp, bounces);
        rungs.push(pathtrace_rung(&gpu, &with_caustic, setting, Series::PathTraceBounces, 1)?);
        print_rung(rungs.last().expect("pushed"));
    }
    let denoisers: &[DenoiserKind] = if illum_denoise::OIDN_BUILT {
        &[DenoiserKind::Atrous, DenoiserKind::Oidn]
    } else {
        &[DenoiserKind::Atrous]
    };
    for &kind in denoisers.iter().filter(|_| !args.denoise_spp_list.is_empty()) {
        let filter = Denoiser::new(&gpu, kind)?;
        for &spp in &args.denoise_spp_list {
            rungs.push(denoised_rung(&gpu, &with_caustic, spp, &filter, args.frames.min(3))?);
            print_rung(rungs.last().expect("pushed"));
        }
    }
    let tessellate_spp = args.tessellate_spp.unwrap_or(args.spp_list.iter().copied().max().unwrap_or(1));
    let (tessellated, timing) = if tessellating {
        tessellation::tessellation_rungs(&gpu, &scene, &geometries, tessellate_spp, args.frames.min(3))?
    } else {
        (Vec::new(), String::new())
    };
    let first_tessellated = rungs.len();
    let row_geometries: Vec<_> = tessellated.iter().map(|(g, _)| *g).collect();
    rungs.extend(tessellated.into_iter().map(|(_, rung)| rung));
    let rows: Vec<Row> = rungs
        .into_iter()
        .map(|rung| {
            let errors = compare(&rung.image, &truth, &regions);
            Row { rung, errors }
        })
        .collect();
    let tessellation_rows: Vec<_> = row_geometries
        .iter()
        .zip(&rows[first_tessellated..])
        .map(|(&g, row)| (g, &row.rung, &row.errors))
        .collect();
    let tessellation_rows = tessellation::compared(&tessellation_rows, &regions);
    let tessellation_md = tessellation::section(&tessellation_rows, &regions, &timing);
    if let Some(crop) = tessellation::sphere_crop(&scene, &ids).filter(|_| !tessellation_rows.is_empty()) {
        let sheet = tessellation::sheet(&tessellation_rows, crop);
        illum::image::save_rgba8_png(args.out.join(tessellation::SHEET), &sheet)?;
        println!("wrote {}/{}", args.out.display(), tessellation::SHEET);
    }

    let truth_bounces =
        if args.truth.is_some() { "as in the given file".to_owned() } else { args.truth_bounces.to_string() };
    let header = Header {
        scene: &scene,
        adapter: &gpu.adapter_info.name,
        truth_spp,
        truth_bounces,
        truth_error,
        truth_metadata,
    };
    write_outputs(&args.out, &header, &truth, &regions, &rows, &tessellation_md)?;
    Ok(())
}

/// Whether the scene has a mirror or glass.
fn has_specular(scene: &Scene) -> bool {
    scene
        .materials
        .iter()
        .any(|m| matches!(m.kind, MaterialKind::Dielectric { .. } | MaterialKind::Mirror { .. }))
}

/// The scene's aspect with 320 pixels on the longer side, unless the flags say otherwise.
fn default_size(scene: &Scene, width: Option<u32>, height: Option<u32>) -> (u32, u32) {
    let (sw, sh) = (f64::from(scene.camera.width), f64::from(scene.camera.height));
    let scale = 320.0 / sw.max(sh);
    let w = width.unwrap_or_else(|| match height {
        Some(h) => (f64::from(h) * sw / sh).round().max(1.0) as u32,
        None => (sw * scale).round().max(1.0) as u32,
    });
    let h = height.unwrap_or_else(|| (f64::from(w) * sh / sw).round().max(1.0) as u32);
    (w, h)
}
