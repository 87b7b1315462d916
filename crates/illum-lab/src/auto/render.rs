//! How the pilot renders and times a setting as `render` would: the path tracer with its
//! sequence, adaptive sampling (its own pilot of 16 spp, then the spread spp), or kept as two
//! halves and denoised; the rasterizer and the Whitted ray tracer as they are.

use std::time::Instant;

use illum_auto::settings::apply;
use illum_denoise::{Denoiser, SplitRender};
use illum_gpu::GpuContext;
use illum_image::RgbImage32;
use illum_pathtrace::{PathTracer, SampleAllocation, TracerOptions};
use illum_raster::{Options, RasterRenderer, RasterScene};
use illum_scene::{Scene, Sequence};
use illum_whitted::WhittedTracer;

use super::plan::Setting;

/// The spp a path tracer's setting renders in multiples of: a denoised render's two halves
/// take the same samples; a low-discrepancy render's error estimate needs whole replicate runs.
pub(super) fn spp_multiple(setting: &Setting) -> u32 {
    match setting {
        Setting::PathTrace { denoise: Some(_), .. } => 2,
        Setting::PathTrace { sequence: Sequence::LowDiscrepancy, .. } => {
            illum_pathtrace::replicates::REPLICATE_RUN
        }
        _ => 1,
    }
}

/// The path tracer's options for `setting` (its sequence).
pub(super) fn tracer_options(setting: &Setting) -> TracerOptions {
    match setting {
        Setting::PathTrace { sequence, .. } => TracerOptions { sequence: *sequence, ..Default::default() },
        _ => TracerOptions::default(),
    }
}

/// A path tracer's costs at the pilot's size: the set-up (pipelines, buffers), the seconds
/// that scale with the pixels but not the spp (adaptive sampling's pilot, a denoised render's
/// guides and filter runs) and the seconds per spp, timed over `timing_spp` samples per pixel.
pub(super) fn path_tracer_throughput(
    gpu: &GpuContext,
    small: &Scene,
    setting: &Setting,
    timing_spp: u32,
) -> anyhow::Result<(f64, f64, f64)> {
    let Setting::PathTrace { adaptive, denoise, .. } = setting else {
        anyhow::bail!("{setting} is not a path tracer's setting");
    };
    let variant = apply(small, setting);
    let t = Instant::now();
    if let Some(kind) = denoise {
        let filter = Denoiser::new(gpu, *kind)?;
        let mut split = SplitRender::new(gpu, &variant, tracer_options(setting))?;
        let cancel = std::sync::atomic::AtomicBool::new(false);
        split.advance(1, &cancel)?; // the first pass also sets up buffers
        split.a.reset();
        split.b.reset();
        let setup = t.elapsed().as_secs_f64();
        let t = Instant::now();
        split.advance(timing_spp / 2, &cancel)?;
        let per_spp = t.elapsed().as_secs_f64() / f64::from(timing_spp / 2 * 2);
        let t = Instant::now();
        split.denoise(&filter)?;
        return Ok((setup, t.elapsed().as_secs_f64(), per_spp));
    }
    let mut tracer = if *adaptive {
        let (w, h) = (variant.camera.width, variant.camera.height);
        PathTracer::with_sample_allocation(
            gpu,
            &variant,
            tracer_options(setting),
            SampleAllocation::uniform(w, h, u32::MAX),
        )?
    } else {
        PathTracer::with_options(gpu, &variant, tracer_options(setting))?
    };
    tracer.render_to_spp(1)?; // the first pass also sets up buffers
    let setup = t.elapsed().as_secs_f64();
    tracer.reset();
    let t = Instant::now();
    let (adaptive_pilot, until) = if *adaptive {
        let allocation = illum_pathtrace::allocation::plan_adaptive(&mut tracer, timing_spp)?;
        (t.elapsed().as_secs_f64(), allocation.max())
    } else {
        (0.0, timing_spp)
    };
    let t = Instant::now();
    tracer.render_to_spp(until)?;
    Ok((setup, adaptive_pilot, t.elapsed().as_secs_f64() / f64::from(timing_spp)))
}

/// Renders `scene` (with `setting` applied, see [`apply`]) by the setting's renderer, the path
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
