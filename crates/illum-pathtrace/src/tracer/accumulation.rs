//! What the folded bands add up to: the f64 statistics, the running image on the GPU for
//! viewers, the samples per pixel of the completed passes, the statistics kept at the last
//! chunk boundary for an exact resume, and the time spent.

use illum_gpu::GpuContext;

use crate::Accumulator;
use crate::display_sum::DisplaySum;

pub(super) struct Accumulation {
    pub(super) accumulator: Accumulator,
    /// The GPU-resident running image for viewers, when enabled (see `display_sum.rs`).
    pub(super) display_sum: Option<DisplaySum>,
    /// Samples per pixel of all completed passes.
    pub(super) spp_done: u32,
    /// With chunk-aligned passes, the statistics at the last chunk boundary before a pass that
    /// ends inside a chunk (the last pass of a render whose spp is not a multiple of the chunk),
    /// and their spp. A checkpoint stores them so that a resumed render can start again from that
    /// boundary: splitting the final chunk's f32 sum in two would differ from a straight render
    /// by f32 rounding.
    pub(super) aligned_prefix: Option<(Accumulator, u32)>,
    /// Wall and GPU seconds spent on submissions since the last reset.
    pub(super) wall_seconds: f64,
    pub(super) gpu_seconds: f64,
}

impl Accumulation {
    pub(super) fn new(accumulator: Accumulator) -> Self {
        Accumulation {
            accumulator,
            display_sum: None,
            spp_done: 0,
            aligned_prefix: None,
            wall_seconds: 0.0,
            gpu_seconds: 0.0,
        }
    }

    /// Discards everything accumulated.
    pub(super) fn reset(&mut self, gpu: &GpuContext) {
        self.accumulator.reset();
        if let Some(display) = &self.display_sum {
            display.clear(gpu);
        }
        self.spp_done = 0;
        self.aligned_prefix = None;
        self.wall_seconds = 0.0;
        self.gpu_seconds = 0.0;
    }

    /// Sets the display sum, if there is one, to the accumulator's samples (emission uploaded
    /// at 2^-`radiance_exponent`): after a restore, or where the GPU's display pass added what
    /// the f64 statistics did not (a band dropped) or not all they did (the caustic's frames).
    pub(super) fn show_accumulator(&self, gpu: &GpuContext, radiance_exponent: i32) {
        if let Some(display) = &self.display_sum {
            display.seed(gpu, &self.accumulator, radiance_exponent);
        }
    }
}
