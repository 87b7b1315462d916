//! Frame timing for the benchmark: wall time per frame and GPU time per pass.
//!
//! A frame is timed from the start of recording to the moment the GPU reports it finished (its
//! pass times are mapped back), without reading the image back: what an interactive viewer
//! pays per frame. Warm-up frames first absorb pipeline and allocation costs.

use std::time::Instant;

use crate::scene::RasterScene;
use illum_gpu::GpuContext;
use illum_image::median;

use crate::{Options, PassTimes, RasterError, RasterRenderer};

/// What [`bench_frames`] measured.
#[derive(Clone, Debug)]
pub struct BenchReport {
    pub width: u32,
    pub height: u32,
    pub options: Options,
    /// Wall time of each measured frame, in milliseconds, in the order they ran.
    pub frame_ms: Vec<f64>,
    /// Per-frame pass times (empty without timestamp queries).
    pub pass_ms: Vec<PassTimes>,
    /// Shadow-map side in texels and cube-map face side, as rendered.
    pub shadow_map_size: u32,
    pub cube_size: u32,
}

impl BenchReport {
    /// The median frame time in milliseconds.
    pub fn median_frame_ms(&self) -> f64 {
        median(&mut self.frame_ms.clone())
    }

    /// Frames per second at the median frame time.
    pub fn fps(&self) -> f64 {
        1000.0 / self.median_frame_ms()
    }

    /// The median of each pass's GPU time, when the adapter has timestamp queries.
    pub fn median_pass_ms(&self) -> Option<PassTimes> {
        if self.pass_ms.is_empty() {
            return None;
        }
        let pick = |f: fn(&PassTimes) -> f64| median(&mut self.pass_ms.iter().map(f).collect::<Vec<_>>());
        Some(PassTimes {
            shadow_ms: pick(|t| t.shadow_ms),
            cube_ms: pick(|t| t.cube_ms),
            main_ms: pick(|t| t.main_ms),
        })
    }
}

/// Renders `warmup` untimed frames, then `frames` timed ones, of `scene` at `width` x `height`.
pub fn bench_frames(
    gpu: &GpuContext,
    scene: &RasterScene,
    width: u32,
    height: u32,
    options: &Options,
    warmup: u32,
    frames: u32,
) -> Result<BenchReport, RasterError> {
    let mut renderer = RasterRenderer::new(gpu, scene, width, height)?;
    for _ in 0..warmup {
        renderer.draw(options)?;
    }
    let mut frame_ms = Vec::with_capacity(frames as usize);
    let mut pass_ms = Vec::with_capacity(frames as usize);
    for _ in 0..frames {
        let started = Instant::now();
        let times = renderer.draw(options)?;
        frame_ms.push(started.elapsed().as_secs_f64() * 1e3);
        pass_ms.extend(times);
    }
    Ok(BenchReport {
        width,
        height,
        options: *options,
        frame_ms,
        pass_ms,
        shadow_map_size: renderer.shadow_map_resolution().0,
        cube_size: renderer.scene().quality.cube_size,
    })
}
