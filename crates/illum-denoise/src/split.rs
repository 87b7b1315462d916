//! A path-traced render kept as two independent halves (two [`PathTracer`]s over disjoint
//! sample indices of the same seed), so that a denoised image's error can be estimated
//! ([`crate::estimate`]): the whole image is the halves merged, bit for bit the f64 sum of
//! their samples.

use std::sync::atomic::{AtomicBool, Ordering};

use illum_gpu::GpuContext;
use illum_image::RgbImage32;
use illum_pathtrace::{Accumulator, Guides, PathTracer, TracerOptions, guide_samples};
use illum_scene::Scene;

use crate::DenoiseError;
use crate::denoiser::Denoiser;
use crate::estimate::HalvesError;
use crate::input::DenoiseInput;

/// The second half's first sample index: far beyond any render's samples of the first half.
pub const SECOND_HALF: u32 = 1 << 31;

pub struct SplitRender {
    pub a: PathTracer,
    pub b: PathTracer,
}

/// A denoised render and what is known of its error.
pub struct Denoised {
    /// The denoised image of both halves' samples.
    pub image: RgbImage32,
    /// The halves' estimate (of a denoised half's error: conservative for `image`).
    pub estimate: HalvesError,
    /// The raw (noisy) whole: both halves merged.
    pub raw: Accumulator,
    pub guides: Guides,
    /// Wall seconds the three filter runs took (both halves and the whole).
    pub filter_seconds: f64,
    /// Wall seconds of the guide pass.
    pub guide_seconds: f64,
}

impl SplitRender {
    pub fn new(gpu: &GpuContext, scene: &Scene, options: TracerOptions) -> Result<Self, DenoiseError> {
        let a = PathTracer::with_options(gpu, scene, options)?;
        let mut b = PathTracer::with_options(gpu, scene, options)?;
        b.set_sample_offset(SECOND_HALF);
        Ok(SplitRender { a, b })
    }

    /// Samples per pixel of the whole (both halves, each complete to its own spp).
    pub fn spp_done(&self) -> u32 {
        self.a.spp_done().min(self.b.spp_done()).saturating_mul(2)
    }

    /// Renders each half to `half_spp` samples per pixel, A then B. Returns false when `cancel`
    /// was set (the halves may then differ in spp; [`Self::spp_done`] counts the smaller).
    pub fn advance(&mut self, half_spp: u32, cancel: &AtomicBool) -> Result<bool, DenoiseError> {
        for tracer in [&mut self.a, &mut self.b] {
            while tracer.spp_done() < half_spp {
                if cancel.load(Ordering::Relaxed) {
                    return Ok(false);
                }
                tracer.render_step(Some(half_spp))?;
            }
        }
        Ok(true)
    }

    /// Both halves merged: the raw image's statistics.
    pub fn merged(&self) -> Accumulator {
        let mut whole = self.a.accumulator().clone();
        whole.merge(self.b.accumulator());
        whole
    }

    /// Denoises both halves and the whole with `filter`, and estimates the error.
    pub fn denoise(&self, filter: &Denoiser) -> Result<Denoised, DenoiseError> {
        let clock = std::time::Instant::now();
        // As many guide samples as the whole image has (within guide_samples' bounds), over the
        // first half's sample indices, rendered or not: the guides see those camera rays.
        let guides = self.a.guides(guide_samples(self.spp_done()))?;
        let guide_seconds = clock.elapsed().as_secs_f64();
        let clock = std::time::Instant::now();
        let (a, b) = (self.a.accumulator(), self.b.accumulator());
        let da = filter.denoise(&DenoiseInput::from_render(a, &guides))?;
        let db = filter.denoise(&DenoiseInput::from_render(b, &guides))?;
        let raw = self.merged();
        let image = filter.denoise(&DenoiseInput::from_render(&raw, &guides))?;
        let filter_seconds = clock.elapsed().as_secs_f64();
        let estimate = HalvesError::new(
            (&a.mean_image(), &a.variance_image(), &da),
            (&b.mean_image(), &b.variance_image(), &db),
            &image,
        );
        Ok(Denoised { image, estimate, raw, guides, filter_seconds, guide_seconds })
    }
}
