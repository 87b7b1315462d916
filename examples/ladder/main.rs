//! The speed/accuracy ladder: one scene through every renderer, each image timed and compared
//! with the converged path-traced truth, overall and per region.
//!
//! ```text
//! cargo run --release --example ladder -- [SCENE] [--width W --height H] [--truth-spp N]
//!     [--truth-bounces B] [--truth FILE.exr] [--spp-list 1,4,16,64,256,1024] [--depths 1,2,8]
//!     [--bounce-list 0,1,2,4] [--bounce-spp 1024] [--denoise-spp-list 1,4,16,64,256] [--frames 5]
//!     [--out DIR]
//! ```
//! Rows:
//! - the rasterizer (if it can draw the scene): the `figure` look, the `enhanced` look, and the
//!   enhanced look with each effect off in turn;
//! - the Whitted ray tracer at each depth of `--depths` (the first alone in a scene without a
//!   mirror or glass, where depth changes nothing);
//! - the path tracer at each spp of `--spp-list` (the scene's bounces), without and (where the
//!   scene has a caustic: a sun and a mirror or glass) with the caustic estimator, and at each
//!   bounce count of `--bounce-list` with `--bounce-spp` samples (on the Cornell box this is
//!   the classic "Whitted against path tracing, bounce by bounce");
//! - the path tracer at each spp of `--denoise-spp-list` followed by the à-trous denoiser, and
//!   by Open Image Denoise in builds with `--features illum-denoise/oidn` (illum-denoise, with
//!   its bound on every denoised pixel; the guide pass and the filter are part of its time).
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
//! relMSE, luminance ratio, FLIP), ladder.md (the tables), error-vs-time.png and
//! flip-vs-time.png (log-log, one series per renderer), contact-sheet.png (each image beside
//! its FLIP error map, labelled), regions.png.
//!
//! Over 450 lines: one study from its rows to its tables (shared parts are library modules).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, bail};
use clap::Parser;

use illum::gpu::GpuContext;
use illum::image::{Encoding, RgbImage32, median, save_exr, save_rgba8_png, to_rgba8};
use illum::pathtrace::PathTracer;
use illum::raster::{Options, RasterRenderer, RasterScene};
use illum::scene::{Bounces, Effects, Look, MAX_WHITTED_DEPTH, MaterialKind, Scene};
use illum::whitted::WhittedTracer;
use illum_auto::settings::{has_caustic, truth_scene};
use illum_denoise::{DenoiseInput, Denoiser, DenoiserKind};
use illum_lab::contact_sheet::contact_sheet;
use illum_lab::plot::{self, Line, Style};
use illum_lab::reference::{Reference, cached_reference, load_reference};
use illum_lab::regions::{Comparison, Regions, compare, flip_heat_map};
use illum_lab::report::{csv_text, host_cpu, markdown_table, write_text};

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
    /// Folder for the tables, plots, images and the cached truth.
    #[arg(long, default_value = "out/ladder")]
    out: PathBuf,
}

/// Which of the plots' series a rung belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Series {
    Raster,
    Whitted,
    /// The path tracer at the scene's bounces, more samples per pixel each rung, without the
    /// caustic estimator.
    PathTraceSpp,
    /// The same with the caustic estimator (light tracing, `[pathtrace] caustics`).
    PathTraceCaustics,
    /// The path tracer at a fixed spp, more bounces each rung.
    PathTraceBounces,
    /// The path tracer at the scene's bounces followed by the à-trous denoiser, more spp each rung.
    PathTraceAtrous,
    /// The same followed by Open Image Denoise (builds with the feature `oidn`).
    PathTraceOidn,
}

/// One rung: an image made by one renderer with one setting, and how long it took.
struct Rung {
    renderer: &'static str,
    series: Series,
    settings: String,
    /// Median wall time per frame, in milliseconds.
    wall_ms: f64,
    /// Median GPU time per frame (timestamp queries), where the renderer has them.
    gpu_ms: Option<f64>,
    image: RgbImage32,
}

struct Row {
    rung: Rung,
    errors: Comparison,
}

fn main() {
    illum_cli::main_with(run);
}

fn run(args: Args) -> anyhow::Result<()> {
    if args.frames == 0 {
        bail!("--frames 0: at least one frame must be timed");
    }
    if args.truth_spp == 0 || args.spp_list.contains(&0) || args.denoise_spp_list.contains(&0) {
        bail!("samples per pixel must be at least 1 (--truth-spp, --spp-list, --denoise-spp-list)");
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
    let regions = Regions::from_ids(&scene, &WhittedTracer::new(&gpu, &scene)?.object_ids()?);

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
    // or glass to focus it); the truth has it.
    let caustic_options: &[bool] = if has_caustic(&scene) { &[false, true] } else { &[false] };
    for &caustics in caustic_options {
        let mut variant = scene.clone();
        variant.pathtrace.caustics = caustics;
        let series = if caustics { Series::PathTraceCaustics } else { Series::PathTraceSpp };
        for &spp in &args.spp_list {
            let setting = (spp, scene.pathtrace.bounces);
            rungs.push(pathtrace_rung(&gpu, &variant, setting, series, args.frames.min(3))?);
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
    let rows: Vec<Row> = rungs
        .into_iter()
        .map(|rung| {
            let errors = compare(&rung.image, &truth, &regions);
            Row { rung, errors }
        })
        .collect();

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
    write_outputs(&args, &header, &truth, &regions, &rows)?;
    Ok(())
}

/// The path tracer at `spp` (the scene's bounces and caustic estimator) followed by `filter`
/// with its default settings and the bound of every denoised image: the time is the render's,
/// the guide pass's and the filter's (median of `runs`, after a warm-up that compiles the
/// pipelines).
fn denoised_rung(
    gpu: &GpuContext,
    scene: &Scene,
    spp: u32,
    filter: &Denoiser,
    runs: u32,
) -> anyhow::Result<Rung> {
    let mut scene = scene.clone();
    scene.pathtrace.spp = spp;
    let mut tracer = PathTracer::new(gpu, &scene)?;
    let denoise = |tracer: &PathTracer| -> anyhow::Result<RgbImage32> {
        let guides = tracer.guides(illum::pathtrace::guide_samples(tracer.spp_done()))?;
        Ok(filter.denoise(&DenoiseInput::from_render(tracer.accumulator(), &guides))?)
    };
    tracer.render_to_spp(1)?; // warm-up: the pipelines and buffers
    denoise(&tracer)?;
    let mut ms = Vec::new();
    let mut image = None;
    for _ in 0..runs.max(1) {
        tracer.reset();
        let started = Instant::now();
        tracer.render_to_spp(spp)?;
        image = Some(denoise(&tracer)?);
        ms.push(started.elapsed().as_secs_f64() * 1e3);
    }
    let (renderer, series, name) = match filter.kind() {
        DenoiserKind::Atrous => ("pathtrace + à-trous", Series::PathTraceAtrous, "à-trous"),
        DenoiserKind::Oidn => ("pathtrace + OIDN", Series::PathTraceOidn, "OIDN"),
    };
    Ok(Rung {
        renderer,
        series,
        settings: format!(
            "{spp} spp, bounces {}{}, {name}",
            scene.pathtrace.bounces,
            if scene.pathtrace.caustics { ", caustic estimator" } else { "" }
        ),
        wall_ms: median(&mut ms),
        gpu_ms: None,
        image: image.expect("at least one run"),
    })
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

fn print_rung(r: &Rung) {
    let gpu = r.gpu_ms.map_or(String::new(), |g| format!(" (GPU {g:.2} ms)"));
    println!("{:9} {:34} {:10.2} ms{gpu}", r.renderer, r.settings, r.wall_ms);
}

/// The rasterizer's rows: both looks with every effect, then the enhanced look with each effect
/// off in turn. A scene the rasterizer cannot draw (the Cornell box) has none; the reason is
/// printed.
fn raster_rungs(gpu: &GpuContext, scene: &Scene, frames: u32, rungs: &mut Vec<Rung>) -> anyhow::Result<()> {
    let raster_scene = match RasterScene::from_scene(scene) {
        Ok(s) => s,
        Err(e) => {
            println!("no rasterizer rows: {e}");
            return Ok(());
        }
    };
    let (w, h) = (scene.camera.width, scene.camera.height);
    let mut settings = vec![
        ("figure look".to_owned(), Options::all_on(Look::Figure)),
        ("enhanced look".to_owned(), Options::all_on(Look::Enhanced)),
    ];
    for (name, off) in Effects::TOGGLES {
        let mut options = Options::all_on(Look::Enhanced);
        off(&mut options.effects);
        settings.push((format!("enhanced, {name} off"), options));
    }
    let mut renderer = RasterRenderer::new(gpu, &raster_scene, w, h)?;
    for (label, options) in settings {
        let image = renderer.render(&options)?;
        // The whole frame, every map made again: what the ray tracers pay too.
        let motion = illum::raster::Motion::SceneChange;
        let report = illum::raster::bench_frames(gpu, &raster_scene, w, h, &options, motion, 2, frames)?;
        rungs.push(Rung {
            renderer: "raster",
            series: Series::Raster,
            settings: label,
            wall_ms: report.median_frame_ms(),
            gpu_ms: report.median_pass_ms().map(|t| t.total_ms()),
            image,
        });
        print_rung(rungs.last().expect("pushed"));
    }
    Ok(())
}

fn whitted_rung(gpu: &GpuContext, scene: &Scene, depth: u32, frames: u32) -> anyhow::Result<Rung> {
    let mut scene = scene.clone();
    scene.whitted.depth = depth;
    let tracer = WhittedTracer::new(gpu, &scene)?;
    let image = tracer.render()?; // also the warm-up
    let mut ms = Vec::new();
    for _ in 0..frames {
        let started = Instant::now();
        tracer.render()?;
        ms.push(started.elapsed().as_secs_f64() * 1e3);
    }
    Ok(Rung {
        renderer: "whitted",
        series: Series::Whitted,
        settings: format!("depth {depth}, {0}x{0} rays per pixel", scene.whitted.aa),
        wall_ms: median(&mut ms),
        gpu_ms: None,
        image,
    })
}

fn pathtrace_rung(
    gpu: &GpuContext,
    scene: &Scene,
    (spp, bounces): (u32, Bounces),
    series: Series,
    runs: u32,
) -> anyhow::Result<Rung> {
    let mut scene = scene.clone();
    scene.pathtrace.bounces = bounces;
    scene.pathtrace.spp = spp;
    let mut tracer = PathTracer::new(gpu, &scene)?;
    tracer.render_to_spp(1)?; // warm-up: the pipeline and buffers
    let mut ms = Vec::new();
    for _ in 0..runs.max(1) {
        tracer.reset();
        let started = Instant::now();
        tracer.render_to_spp(spp)?;
        ms.push(started.elapsed().as_secs_f64() * 1e3);
    }
    Ok(Rung {
        renderer: "pathtrace",
        series,
        settings: format!(
            "{spp} spp, bounces {bounces}{}",
            if scene.pathtrace.caustics { ", caustic estimator" } else { "" }
        ),
        wall_ms: median(&mut ms),
        gpu_ms: None,
        image: tracer.accumulator().mean_image(),
    })
}

struct Header<'a> {
    scene: &'a Scene,
    adapter: &'a str,
    truth_spp: u64,
    truth_bounces: String,
    truth_error: f64,
    /// The truth's own metadata, written with its copy `truth.exr`.
    truth_metadata: illum::image::ExrMetadata,
}

fn number(x: f64) -> String {
    if x.is_nan() { "n/a".to_owned() } else { format!("{x:.3e}") }
}

fn ratio(x: f64) -> String {
    if x.is_nan() { "n/a".to_owned() } else { format!("{x:.3}") }
}

fn write_outputs(
    args: &Args,
    header: &Header,
    truth: &RgbImage32,
    regions: &Regions,
    rows: &[Row],
) -> anyhow::Result<()> {
    let out = &args.out;
    let sizes = regions.sizes();
    // CSV: one line per row and region ("all" for the whole image).
    let mut lines = Vec::new();
    for row in rows {
        let r = &row.rung;
        let all = std::iter::once(("all", &row.errors.overall));
        let each = regions.names.iter().map(String::as_str).zip(&row.errors.regions);
        for (region, e) in all.chain(each) {
            lines.push(vec![
                r.renderer.to_owned(),
                r.settings.clone(),
                format!("{:.4}", r.wall_ms),
                r.gpu_ms.map_or(String::new(), |g| format!("{g:.4}")),
                region.to_owned(),
                e.pixels.to_string(),
                format!("{:e}", e.rel_mse),
                format!("{}", e.luminance_ratio),
                format!("{}", e.flip),
            ]);
        }
    }
    let csv_header = [
        "renderer",
        "settings",
        "wall_ms",
        "gpu_ms",
        "region",
        "pixels",
        "rel_mse",
        "luminance_ratio",
        "flip",
    ];
    write_text(&out.join("ladder.csv"), &csv_text(&csv_header, &lines)?)?;

    // Markdown: the overall table, then one table per metric with a column per region.
    let s = header.scene;
    // The command that made the page, less where its files went.
    let mut command = vec!["cargo run --release --example ladder --".to_owned()];
    let mut given = std::env::args().skip(1);
    while let Some(arg) = given.next() {
        match arg.as_str() {
            "--out" => _ = given.next(),
            a if a.starts_with("--out=") => {}
            _ => command.push(arg),
        }
    }
    let mut md = format!(
        "# The ladder: `{}`\n\n\
         Every renderer and setting on one scene, timed, and compared with a converged path-traced \
         truth, overall and per region. Made by `{}`.\n\n\
         Scene `{}` at {}x{}, {} on {}. Truth: path traced, {} spp, bounces {}, its own estimated relMSE {}. \
         Times are medians over frames; errors are against the truth (relMSE with epsilon 0.01; \
         luminance ratio = mean luminance / the truth's; FLIP = mean LDR-FLIP, sRGB, exposure 0).\n\n",
        s.name,
        command.join(" "),
        s.name,
        s.camera.width,
        s.camera.height,
        header.adapter,
        host_cpu(),
        header.truth_spp,
        header.truth_bounces,
        number(header.truth_error)
    );
    let overall: Vec<Vec<String>> = rows
        .iter()
        .map(|row| {
            let (r, e) = (&row.rung, &row.errors.overall);
            vec![
                r.renderer.to_owned(),
                r.settings.clone(),
                format!("{:.2}", r.wall_ms),
                r.gpu_ms.map_or("-".to_owned(), |g| format!("{g:.2}")),
                number(e.rel_mse),
                ratio(e.luminance_ratio),
                ratio(e.flip),
            ]
        })
        .collect();
    md.push_str(&markdown_table(
        &["renderer", "settings", "wall ms", "GPU ms", "relMSE", "luminance ratio", "FLIP"],
        &overall,
    ));
    let region_header: Vec<String> = std::iter::once("renderer, settings".to_owned())
        .chain(regions.names.iter().zip(&sizes).map(|(n, px)| format!("{n} ({px} px)")))
        .collect();
    let region_header: Vec<&str> = region_header.iter().map(String::as_str).collect();
    type Metric = (&'static str, fn(&illum_lab::regions::Errors) -> String);
    let metrics: [Metric; 3] = [
        ("relMSE per region", |e| number(e.rel_mse)),
        ("Luminance ratio per region (1 = the truth's brightness)", |e| ratio(e.luminance_ratio)),
        ("FLIP per region", |e| ratio(e.flip)),
    ];
    for (title, show) in metrics {
        let table: Vec<Vec<String>> = rows
            .iter()
            .map(|row| {
                std::iter::once(format!("{}, {}", row.rung.renderer, row.rung.settings))
                    .chain(row.errors.regions.iter().map(show))
                    .collect()
            })
            .collect();
        md.push_str(&format!("\n{title}:\n\n"));
        md.push_str(&markdown_table(&region_header, &table));
    }
    write_text(&out.join("ladder.md"), &md)?;

    // Plots: error against time, one series per renderer.
    for (file, title, label, value) in [
        ("error-vs-time.png", "relMSE against time per frame", "relMSE", 0),
        ("flip-vs-time.png", "FLIP against time per frame", "mean FLIP", 1),
    ] {
        let series = [
            ("rasterizer", Series::Raster, Style::Markers),
            ("Whitted ray tracer", Series::Whitted, Style::Markers),
            ("path tracer, more spp", Series::PathTraceSpp, Style::Joined),
            ("path tracer + caustic estimator, more spp", Series::PathTraceCaustics, Style::Joined),
            ("path tracer, more bounces", Series::PathTraceBounces, Style::Joined),
            ("path tracer + à-trous, more spp", Series::PathTraceAtrous, Style::Joined),
            ("path tracer + OIDN, more spp", Series::PathTraceOidn, Style::Joined),
        ];
        let lines: Vec<Line> = series
            .iter()
            .map(|&(label, series, style)| Line {
                label: label.to_owned(),
                points: rows
                    .iter()
                    .filter(|r| r.rung.series == series)
                    .map(|r| {
                        let e = &r.errors.overall;
                        (r.rung.wall_ms, if value == 0 { e.rel_mse } else { e.flip })
                    })
                    .collect(),
                style,
            })
            .filter(|l| !l.points.is_empty())
            .collect();
        plot::log_log(&out.join(file), title, "wall time per frame (ms)", label, &lines)?;
    }

    // Images: the truth, the regions, then each row's image and FLIP map.
    let (w, h) = (truth.width, truth.height);
    let png = |i: &RgbImage32| to_rgba8(i, 0.0, Encoding::Srgb);
    let region_map = region_colours(regions, w, h);
    save_rgba8_png(out.join("regions.png"), &region_map)?;
    // With the metadata of the render it is (renderer, scene, time, spp, settings).
    save_exr(out.join("truth.exr"), truth, &header.truth_metadata)?;
    let legend = regions.names.join("; ");
    let mut panels = vec![
        (format!("truth: path traced, {} spp", header.truth_spp), png(truth)),
        (format!("regions: {legend}"), region_map),
    ];
    for row in rows {
        let (r, e) = (&row.rung, &row.errors.overall);
        panels.push((format!("{} {}: {:.2} ms", r.renderer, r.settings, r.wall_ms), png(&r.image)));
        panels.push((
            format!("FLIP {:.3}, relMSE {}, luminance x{:.3}", e.flip, number(e.rel_mse), e.luminance_ratio),
            flip_heat_map(&row.errors.flip_map, w, h),
        ));
    }
    save_rgba8_png(out.join("contact-sheet.png"), &contact_sheet(&panels, 4))?;
    println!(
        "wrote {}/ladder.csv, ladder.md, error-vs-time.png, flip-vs-time.png, contact-sheet.png",
        out.display()
    );
    Ok(())
}

/// The regions drawn in distinct colours, in the order of their names.
fn region_colours(regions: &Regions, w: u32, h: u32) -> image::RgbaImage {
    const PALETTE: [[u8; 3]; 8] = [
        [120, 170, 230],
        [230, 200, 60],
        [120, 60, 160],
        [200, 80, 60],
        [80, 180, 120],
        [220, 220, 220],
        [160, 100, 40],
        [60, 60, 60],
    ];
    image::RgbaImage::from_fn(w, h, |x, y| {
        let c = PALETTE[regions.of_pixel[(y * w + x) as usize] % PALETTE.len()];
        image::Rgba([c[0], c[1], c[2], 255])
    })
}
