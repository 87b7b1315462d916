//! How a measuring tool renders a setting as `render` would (the auto check's and the tests'
//! renders of a plan's choice): the path tracer with its sequence, adaptive sampling (its own
//! pilot of 16 spp, then the spread spp), or kept as two halves and denoised; the rasterizer and
//! the Whitted ray tracer as they are.

use illum_auto::settings::tracer_options;
use illum_denoise::{Denoiser, SplitRender};
use illum_gpu::GpuContext;
use illum_image::RgbImage32;
use illum_pathtrace::{PathTracer, SampleAllocation};
use illum_raster::{Options, RasterRenderer, RasterScene};
use illum_scene::Scene;
use illum_whitted::WhittedTracer;

use illum_auto::plan::Setting;

/// Renders `scene` (with `setting` applied, see [`illum_auto::settings::apply`]) by the setting's renderer, the path
/// tracer at `spp` as `render` would (its sequence, adaptive sampling, a denoised render kept as
/// two halves of `spp / 2`); returns the image and, for the path tracer, its estimated relMSE
/// (from its noise, or for a denoised image the halves' estimate).
pub fn render(
    gpu: &GpuContext,
    scene: &Scene,
    setting: &Setting,
    spp: u32,
) -> anyhow::Result<(RgbImage32, Option<f64>)> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    Ok(match setting {
        Setting::Raster { look, effects } => {
            let mut renderer = RasterRenderer::new(gpu, &RasterScene::from_scene(scene)?, w, h)?;
            (renderer.render(&Options { look: *look, effects: *effects })?, None)
        }
        Setting::Whitted { .. } => (WhittedTracer::new(gpu, scene)?.render()?, None),
        Setting::PathTrace { denoise: Some(kind), .. } => {
            let filter = Denoiser::new(gpu, *kind)?;
            let mut split = SplitRender::new(gpu, scene, tracer_options(setting))?;
            split.advance(spp.div_ceil(2), &std::sync::atomic::AtomicBool::new(false))?;
            let denoised = split.denoise(&filter)?;
            (denoised.image, Some(denoised.estimate.rel_mse))
        }
        Setting::PathTrace { adaptive, .. } => {
            let tracer = if *adaptive {
                let unlimited = SampleAllocation::uniform(w, h, u32::MAX);
                let mut tracer =
                    PathTracer::with_sample_allocation(gpu, scene, tracer_options(setting), unlimited)?;
                let allocation = illum_pathtrace::allocation::plan_adaptive(&mut tracer, spp)?;
                tracer.render_to_spp(allocation.max())?;
                tracer
            } else {
                let mut tracer = PathTracer::with_options(gpu, scene, tracer_options(setting))?;
                tracer.render_to_spp(spp)?;
                tracer
            };
            let accumulator = tracer.accumulator();
            (accumulator.mean_image(), Some(accumulator.estimated_rel_mse()))
        }
    })
}
