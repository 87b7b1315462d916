//! The ladder's rungs: each renderer's images at each setting, and how long each took.

use std::time::Instant;

use illum::gpu::GpuContext;
use illum::image::{RgbImage32, median};
use illum::pathtrace::{Estimators, PathTracer, Sequence, TracerOptions};
use illum::raster::{Options, RasterRenderer, RasterScene};
use illum::scene::{Bounces, Effects, Look, Scene};
use illum::whitted::WhittedTracer;
use illum_denoise::{DenoiseInput, Denoiser, DenoiserKind};

/// Which of the plots' series a rung belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Series {
    Raster,
    Whitted,
    /// The path tracer at the scene's bounces, more samples per pixel each rung, without the
    /// caustic estimator.
    PathTraceSpp,
    /// The same with the caustic estimator (light tracing, `[pathtrace] caustics`).
    PathTraceCaustics,
    /// The same with manifold next-event estimation in the light tracer's place
    /// (`caustic_method = "manifold"`).
    PathTraceManifold,
    /// The same with the low-discrepancy sequence, one randomisation (`render --sequence
    /// low-discrepancy --replicates off`: no error estimate, less error per sample).
    PathTraceManifoldLowDiscrepancy,
    /// The path tracer at a fixed spp, more bounces each rung.
    PathTraceBounces,
    /// The path tracer at the scene's bounces followed by the à-trous denoiser, more spp each rung.
    PathTraceAtrous,
    /// The same followed by Open Image Denoise (builds with the feature `oidn`).
    PathTraceOidn,
    /// The path tracer with the scene's spheres, then icospheres in their place
    /// (`tessellation.rs`).
    Tessellation,
}

/// One rung: an image made by one renderer with one setting, and how long it took.
pub(crate) struct Rung {
    pub(crate) renderer: &'static str,
    pub(crate) series: Series,
    pub(crate) settings: String,
    /// Median wall time per frame, in milliseconds.
    pub(crate) wall_ms: f64,
    /// Median GPU time per frame (timestamp queries), where the renderer has them.
    pub(crate) gpu_ms: Option<f64>,
    pub(crate) image: RgbImage32,
}

/// The path tracer at `spp` (the scene's bounces and caustic estimator) followed by `filter`
/// with its default settings and the bound of every denoised image: the time is the render's,
/// the guide pass's and the filter's (median of `runs`, after a warm-up that compiles the
/// pipelines).
pub(crate) fn denoised_rung(
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
        settings: format!("{spp} spp, bounces {}{}, {name}", scene.pathtrace.bounces, caustic_label(&scene)),
        wall_ms: median(&mut ms),
        gpu_ms: None,
        image: image.expect("at least one run"),
    })
}

/// What a row's settings say of the caustic's estimators (`Estimators::of`, the rule every
/// renderer follows): nothing without them, "caustic estimator" for the light tracer and its
/// gather, "manifold NEE" for the solve.
fn caustic_label(scene: &Scene) -> &'static str {
    let estimators = Estimators::of(scene);
    if estimators.manifold() {
        ", manifold NEE"
    } else if estimators.light_tracer() {
        ", caustic estimator"
    } else {
        ""
    }
}

pub(crate) fn print_rung(r: &Rung) {
    let gpu = r.gpu_ms.map_or(String::new(), |g| format!(" (GPU {g:.2} ms)"));
    println!("{:9} {:34} {:10.2} ms{gpu}", r.renderer, r.settings, r.wall_ms);
}

/// The rasterizer's rows: both looks with every effect, then the enhanced look with each effect
/// off in turn. A scene the rasterizer cannot draw (the Cornell box) has none; the reason is
/// printed.
pub(crate) fn raster_rungs(
    gpu: &GpuContext,
    scene: &Scene,
    frames: u32,
    rungs: &mut Vec<Rung>,
) -> anyhow::Result<()> {
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

pub(crate) fn whitted_rung(gpu: &GpuContext, scene: &Scene, depth: u32, frames: u32) -> anyhow::Result<Rung> {
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

/// The path tracer set up for one row: `scene` at `spp` and `bounces`, warmed up (the pipeline
/// compiled, the buffers made), each timed run rendering those samples from nothing.
pub(crate) struct PathTraceRow {
    tracer: PathTracer,
    spp: u32,
    settings: String,
    ms: Vec<f64>,
}

impl PathTraceRow {
    pub(crate) fn new(
        gpu: &GpuContext,
        scene: &Scene,
        (spp, bounces): (u32, Bounces),
        options: TracerOptions,
    ) -> anyhow::Result<Self> {
        let mut scene = scene.clone();
        scene.pathtrace.bounces = bounces;
        scene.pathtrace.spp = spp;
        let mut tracer = PathTracer::with_options(gpu, &scene, options)?;
        tracer.render_to_spp(1)?; // warm-up: the pipeline and buffers
        let sequence = match options.sequence {
            Sequence::LowDiscrepancy => format!(", {}", options.sequence_label()),
            _ => String::new(),
        };
        let settings = format!("{spp} spp, bounces {bounces}{}{sequence}", caustic_label(&scene));
        Ok(PathTraceRow { tracer, spp, settings, ms: Vec::new() })
    }

    /// One timed run.
    pub(crate) fn run(&mut self) -> anyhow::Result<()> {
        self.tracer.reset();
        let started = Instant::now();
        self.tracer.render_to_spp(self.spp)?;
        self.ms.push(started.elapsed().as_secs_f64() * 1e3);
        Ok(())
    }

    /// The rung: the median of the runs' times, the last run's image.
    pub(crate) fn rung(mut self, series: Series) -> Rung {
        Rung {
            renderer: "pathtrace",
            series,
            settings: self.settings,
            wall_ms: median(&mut self.ms),
            gpu_ms: None,
            image: self.tracer.accumulator().mean_image(),
        }
    }
}

pub(crate) fn pathtrace_rung(
    gpu: &GpuContext,
    scene: &Scene,
    setting: (u32, Bounces),
    series: Series,
    runs: u32,
) -> anyhow::Result<Rung> {
    let options = match series {
        Series::PathTraceManifoldLowDiscrepancy => TracerOptions {
            sequence: Sequence::LowDiscrepancy,
            replicates: false,
            ..TracerOptions::default()
        },
        _ => TracerOptions::default(),
    };
    let mut row = PathTraceRow::new(gpu, scene, setting, options)?;
    for _ in 0..runs.max(1) {
        row.run()?;
    }
    Ok(row.rung(series))
}
