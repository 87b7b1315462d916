//! The speed/accuracy trade, measured: error against time and samples per pixel.
//!
//! ```text
//! cargo run --release --example convergence -- [SCENE] [--width W --height H] [--bounces B]
//!     [--seed S] [--spp-list 1,2,4,...,4096] [--time-budgets 0.5,1,2] [--reference FILE.exr]
//!     [--reference-factor 64] [--bounces-spp 1024] [--out DIR]
//! ```
//! For each option (cosine or uniform hemisphere sampling; independent or low-discrepancy
//! numbers) and each spp count or time budget it records: spp, wall time, samples/s, RMSE,
//! relMSE and mean-luminance bias against a reference, the relMSE *estimated without the
//! reference* from the per-pixel variance, and efficiency 1 / (relMSE x time).
//!
//! The reference is the given EXR, or a render with `reference-factor` times the largest spp
//! any row reached (default 64x; time-budget rows included), made once and kept in the output
//! folder for later runs, under a name derived from everything that changes it (the scene's
//! content after the flags, the seed, the spp). A second table gives
//! the mean radiance per bounce count (0 to 8 and unbounded): how the series converges.
//!
//! Outputs in DIR: convergence.csv, convergence.md, bounces.csv, and the plots
//! error-vs-time-sampling.png, error-vs-time-sequence.png, error-vs-spp.png, bounces.png.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use anyhow::{Context, bail};
use clap::Parser;
use illum::gpu::GpuContext;
use illum::image::{RgbImage32, mean_luminance_bias, rel_mse, rmse};
use illum::pathtrace::{
    PathTracer, Sequence, StopRules, TracerOptions, parse_time_budget, render_progressive,
};
use illum::scene::{Bounces, Sampling, Scene};
use illum_cli::SceneArgs;
use illum_lab::plot::{self, Line, Style};
use illum_lab::reference::{Reference, cached_reference, load_reference};
use illum_lab::report::{csv_text, write_text};

#[derive(Parser, Debug)]
#[command(about = "Measure error against time and spp for the path tracer's options (cosine or uniform \
             sampling, independent or low-discrepancy numbers), against a reference image")]
struct Args {
    /// Scene file (TOML).
    #[arg(default_value = illum_cli::DEFAULT_SCENE)]
    scene: PathBuf,
    #[command(flatten)]
    settings: SceneFlags,
    /// Samples per pixel at which to record a row (comma-separated).
    #[arg(
        long = "spp-list",
        value_delimiter = ',',
        default_value = "1,2,4,8,16,32,64,128,256,512,1024,2048,4096"
    )]
    spp_list: Vec<u32>,
    /// Time budgets in seconds at which to record a row (comma-separated).
    #[arg(long, value_delimiter = ',')]
    time_budgets: Vec<f64>,
    /// A reference EXR (linear, same size); by default one is rendered and cached.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// The rendered reference has this many times the largest spp.
    #[arg(long, default_value_t = 64)]
    reference_factor: u32,
    /// Samples per pixel for the bounce-count table (0 skips it).
    #[arg(long, default_value_t = 1024)]
    bounces_spp: u32,
    /// Folder for the tables, plots and the cached reference.
    #[arg(long, default_value = "out/convergence")]
    out: PathBuf,
}

/// The scene flags this tool takes. Not `--spp` (the rows' counts are `--spp-list`) nor
/// `--sampling` (the tool measures both), so `--help` lists neither.
#[derive(clap::Args, Debug)]
struct SceneFlags {
    /// Bounces of indirect light: 0 = direct only, up to 256, or `unbounded` (Russian roulette).
    #[arg(long)]
    bounces: Option<Bounces>,
    /// Random seed.
    #[arg(long)]
    seed: Option<u32>,
    /// Image width in pixels (default 64).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (default 64).
    #[arg(long)]
    height: Option<u32>,
}

impl SceneFlags {
    fn scene_args(&self) -> SceneArgs {
        SceneArgs {
            bounces: self.bounces,
            seed: self.seed,
            width: Some(self.width.unwrap_or(64)),
            height: Some(self.height.unwrap_or(64)),
            ..Default::default()
        }
    }
}

/// One option of the comparison.
#[derive(Clone, Copy)]
struct Variant {
    name: &'static str,
    sampling: Sampling,
    sequence: Sequence,
}

const VARIANTS: [Variant; 3] = [
    Variant { name: "cosine, independent", sampling: Sampling::Cosine, sequence: Sequence::Independent },
    Variant { name: "uniform, independent", sampling: Sampling::Uniform, sequence: Sequence::Independent },
    Variant {
        name: "cosine, low-discrepancy",
        sampling: Sampling::Cosine,
        sequence: Sequence::LowDiscrepancy,
    },
];

/// A render taken for a row, before the reference is known.
struct Taken {
    variant: &'static str,
    image: RgbImage32,
    spp: u64,
    seconds: f64,
    samples_per_second: f64,
    estimated_rel_mse: f64,
}

struct Row {
    variant: &'static str,
    spp: u64,
    seconds: f64,
    samples_per_second: f64,
    rmse: f64,
    rel_mse: f64,
    bias: f64,
    estimated_rel_mse: f64,
}

impl Row {
    fn efficiency(&self) -> f64 {
        1.0 / (self.rel_mse * self.seconds)
    }
}

fn main() {
    illum_cli::main_with(run);
}

fn run(mut args: Args) -> anyhow::Result<()> {
    if args.spp_list.is_empty() || args.spp_list.contains(&0) {
        bail!("--spp-list = {:?}: give one or more counts, each at least 1", args.spp_list);
    }
    args.spp_list.sort_unstable();
    args.spp_list.dedup();
    let budgets = args
        .time_budgets
        .iter()
        .map(|&t| parse_time_budget("--time-budgets", t))
        .collect::<Result<Vec<_>, String>>()
        .map_err(anyhow::Error::msg)?;
    if args.reference_factor < 1 {
        bail!("--reference-factor = 0: must be at least 1");
    }
    let scene = illum_cli::load_scene(&args.scene, &args.settings.scene_args())?;
    // The user's reference is checked (size, scene) before any row is rendered.
    let given_reference = args.reference.as_ref().map(|path| load_reference(path, &scene)).transpose()?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let gpu = illum_cli::gpu()?;
    println!(
        "scene {} at {}x{}, bounces {}",
        scene.name, scene.camera.width, scene.camera.height, scene.pathtrace.bounces
    );

    let mut taken = Vec::new();
    for variant in VARIANTS {
        let mut variant_scene = scene.clone();
        variant_scene.pathtrace.sampling = variant.sampling;
        let options = TracerOptions { sequence: variant.sequence, ..Default::default() };
        let mut tracer = PathTracer::with_options(&gpu, &variant_scene, options)?;
        // The driver compiles a pipeline on its first dispatch: keep that out of the timings.
        tracer.render_to_spp(1)?;
        tracer.reset();
        for &spp in &args.spp_list {
            tracer.render_to_spp(spp)?;
            // Time in submissions (readback and f64 fold included), not the measuring between rows.
            taken.push(take(variant.name, &tracer, tracer.wall_seconds()));
        }
        for &budget in &budgets {
            let mut tracer = PathTracer::with_options(&gpu, &variant_scene, options)?;
            tracer.render_to_spp(1)?;
            tracer.reset();
            let rules = StopRules { time_budget: Some(budget), ..Default::default() };
            let (_, progressive) =
                render_progressive(&mut tracer, &rules, &AtomicBool::new(false), |_, _| {})?;
            taken.push(take(variant.name, &tracer, progressive.clock().elapsed().as_secs_f64()));
        }
    }
    // The reference must out-sample every row it judges, time-budget rows included.
    let max_spp = taken.iter().map(|t| t.spp).max().unwrap_or(1).min(u64::from(u32::MAX)) as u32;
    let Reference { image: reference, .. } = match given_reference {
        Some(reference) => reference,
        None => {
            let progress = illum_cli::progress::RenderProgress::new();
            let reference = cached_reference(
                &gpu,
                &scene,
                max_spp.saturating_mul(args.reference_factor),
                &args.out,
                "convergence reference",
                &mut |t, p| progress.update(t, p),
            )?;
            progress.finish();
            reference
        }
    };
    println!("reference mean luminance {:.5}", reference.mean_luminance());
    let mut rows = Vec::new();
    for t in taken {
        rows.push(measure(t, &reference)?);
        print_row(rows.last().expect("just pushed"));
    }
    write_tables(&args.out, &rows)?;
    plot_rows(&args.out, &rows)?;
    if args.bounces_spp > 0 {
        bounce_table(&gpu, &scene, args.bounces_spp, &args.out)?;
    }
    println!("wrote {}", args.out.display());
    Ok(())
}

fn take(variant: &'static str, tracer: &PathTracer, seconds: f64) -> Taken {
    let acc = tracer.accumulator();
    Taken {
        variant,
        image: acc.mean_image(),
        spp: acc.min_samples(),
        seconds,
        samples_per_second: acc.total_samples() as f64 / seconds,
        estimated_rel_mse: acc.estimated_rel_mse(),
    }
}

fn measure(t: Taken, reference: &RgbImage32) -> anyhow::Result<Row> {
    Ok(Row {
        variant: t.variant,
        spp: t.spp,
        seconds: t.seconds,
        samples_per_second: t.samples_per_second,
        rmse: rmse(&t.image, reference)?,
        rel_mse: rel_mse(&t.image, reference)?,
        bias: mean_luminance_bias(&t.image, reference)?,
        estimated_rel_mse: t.estimated_rel_mse,
    })
}

fn print_row(r: &Row) {
    println!(
        "{:26} {:6} spp {:8.3} s  relMSE {:.3e} (estimated {:.3e})  efficiency {:.3e}",
        r.variant,
        r.spp,
        r.seconds,
        r.rel_mse,
        r.estimated_rel_mse,
        r.efficiency()
    );
}

fn write_tables(out: &Path, rows: &[Row]) -> anyhow::Result<()> {
    let header = [
        "variant",
        "spp",
        "seconds",
        "samples_per_second",
        "rmse",
        "rel_mse",
        "mean_luminance_bias",
        "estimated_rel_mse",
        "estimated_over_true",
        "efficiency",
    ];
    let mut csv_rows = Vec::new();
    let mut md = String::from(
        "| option | spp | time (s) | Msamples/s | RMSE | relMSE | bias | estimated relMSE | est./true | efficiency |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let ratio = r.estimated_rel_mse / r.rel_mse;
        csv_rows.push(vec![
            r.variant.to_owned(),
            r.spp.to_string(),
            r.seconds.to_string(),
            r.samples_per_second.to_string(),
            r.rmse.to_string(),
            r.rel_mse.to_string(),
            r.bias.to_string(),
            r.estimated_rel_mse.to_string(),
            ratio.to_string(),
            r.efficiency().to_string(),
        ]);
        writeln!(
            md,
            "| {} | {} | {:.3} | {:.2} | {:.4} | {:.3e} | {:+.4} | {:.3e} | {:.2} | {:.3e} |",
            r.variant,
            r.spp,
            r.seconds,
            r.samples_per_second * 1e-6,
            r.rmse,
            r.rel_mse,
            r.bias,
            r.estimated_rel_mse,
            ratio,
            r.efficiency()
        )?;
    }
    write_text(&out.join("convergence.csv"), &csv_text(&header, &csv_rows)?)?;
    write_text(&out.join("convergence.md"), &md)
}

fn series(rows: &[Row], variant: &str, x: impl Fn(&Row) -> f64, y: impl Fn(&Row) -> f64) -> Vec<(f64, f64)> {
    let mut points: Vec<(f64, f64)> =
        rows.iter().filter(|r| r.variant == variant).map(|r| (x(r), y(r))).collect();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    points
}

fn plot_rows(out: &Path, rows: &[Row]) -> anyhow::Result<()> {
    let time = |r: &Row| r.seconds;
    let measured = |r: &Row| r.rel_mse;
    let estimated = |r: &Row| r.estimated_rel_mse;
    let pair = |names: [&str; 2]| -> Vec<Line> {
        names
            .iter()
            .flat_map(|name| {
                [
                    Line {
                        label: format!("{name}: relMSE"),
                        points: series(rows, name, time, measured),
                        style: Style::Joined,
                    },
                    Line {
                        label: format!("{name}: estimated"),
                        points: series(rows, name, time, estimated),
                        style: Style::MarkersOfPrevious,
                    },
                ]
            })
            .collect()
    };
    for (file, title, other) in [
        ("error-vs-time-sampling.png", "Cosine vs uniform hemisphere sampling", VARIANTS[1].name),
        ("error-vs-time-sequence.png", "Independent vs low-discrepancy numbers", VARIANTS[2].name),
    ] {
        plot::log_log(&out.join(file), title, "wall time (s)", "relMSE", &pair([VARIANTS[0].name, other]))?;
    }
    let spp = |r: &Row| r.spp as f64;
    let mut lines: Vec<Line> = VARIANTS
        .iter()
        .map(|v| Line {
            label: v.name.to_owned(),
            points: series(rows, v.name, spp, measured),
            style: Style::Joined,
        })
        .collect();
    // The 1/N line through the first baseline point: Monte Carlo's convergence rate.
    if let Some(&(n0, e0)) = lines[0].points.first() {
        let last = lines[0].points.last().map_or(n0, |p| p.0);
        lines.push(Line {
            label: "1/N (relMSE of an O(1/sqrt N) error)".into(),
            points: vec![(n0, e0), (last, e0 * n0 / last)],
            style: Style::Joined,
        });
    }
    plot::log_log(&out.join("error-vs-spp.png"), "Error against samples per pixel", "spp", "relMSE", &lines)
}

/// Mean radiance of the image per bounce count: each bounce adds a term of the Neumann series.
fn bounce_table(gpu: &GpuContext, scene: &Scene, spp: u32, out: &Path) -> anyhow::Result<()> {
    let mut csv_rows = Vec::new();
    let mut md = String::from(
        "| bounces | mean luminance | standard error | added by this bounce |\n|---|---|---|---|\n",
    );
    let mut previous = 0.0;
    let mut points = Vec::new();
    let settings: Vec<Bounces> = (0..=8).map(Bounces::Fixed).chain([Bounces::Unbounded]).collect();
    for bounces in settings {
        let mut s = scene.clone();
        s.pathtrace.bounces = bounces;
        let mut tracer = PathTracer::new(gpu, &s)?;
        tracer.render_to_spp(spp)?;
        let acc = tracer.accumulator();
        let n = (acc.width * acc.height) as usize;
        let weights = [0.2126, 0.7152, 0.0722];
        let (mut mean, mut variance) = (0.0, 0.0);
        for p in 0..n {
            let (m, v) = (acc.pixel_mean(p), acc.pixel_variance_of_mean(p));
            for c in 0..3 {
                mean += weights[c] * m[c];
                variance += weights[c] * weights[c] * v[c];
            }
        }
        mean /= n as f64;
        let standard_error = variance.sqrt() / n as f64;
        let increment = mean - previous;
        csv_rows.push(vec![
            bounces.to_string(),
            mean.to_string(),
            standard_error.to_string(),
            increment.to_string(),
        ]);
        writeln!(md, "| {bounces} | {mean:.5} | {standard_error:.5} | {increment:+.5} |")?;
        if let Bounces::Fixed(b) = bounces {
            points.push(((b + 1) as f64, increment.max(1e-12)));
        }
        previous = mean;
        println!("bounces {bounces:>9}: mean luminance {mean:.5} +- {standard_error:.5}");
    }
    let header = ["bounces", "mean_luminance", "standard_error", "increment"];
    write_text(&out.join("bounces.csv"), &csv_text(&header, &csv_rows)?)?;
    write_text(&out.join("bounces.md"), &md)?;
    plot::log_log(
        &out.join("bounces.png"),
        "Light added by each bounce",
        "bounce index + 1",
        "added mean luminance",
        &[Line { label: "increment".into(), points, style: Style::Joined }],
    )
}
