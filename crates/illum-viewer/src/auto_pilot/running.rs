//! A path tracer the pilot runs to a number of samples over frames, and its timing.

use illum_gpu::GpuContext;
use illum_pathtrace::{PathTracer, Readback};
use illum_scene::Scene;
use web_time::Instant;

/// A path tracer being run to a number of samples over frames, with its timing.
pub(super) struct Running {
    pub(super) tracer: PathTracer,
    started: Instant,
    /// Seconds to create it and have its first sample per pixel back (pipeline, buffers).
    pub(super) setup_seconds: Option<f64>,
    /// Seconds of the bands after the first sample, and the spp they added.
    step_seconds: f64,
    step_spp: u32,
}

impl Running {
    pub(super) fn start(gpu: &GpuContext, scene: &Scene) -> Result<Running, String> {
        let started = Instant::now();
        let mut tracer = PathTracer::new(gpu, scene).map_err(|e| e.to_string())?;
        tracer.set_target_seconds(crate::pacer::MOVING_SECONDS);
        Ok(Running { tracer, started, setup_seconds: None, step_seconds: 0.0, step_spp: 0 })
    }

    /// One submission of about `seconds` toward `spp` (the first sample per pixel first),
    /// or a poll of the one under way; true once `spp` is reached.
    pub(super) fn step(&mut self, spp: u32, seconds: f64) -> Result<bool, String> {
        if self.setup_seconds.is_none() {
            self.tracer.render_step(Some(1)).map_err(|e| e.to_string())?;
            if self.tracer.spp_done() >= 1 {
                self.setup_seconds = Some(self.started.elapsed().as_secs_f64());
            }
            return Ok(false);
        }
        if self.tracer.spp_done() >= spp {
            return Ok(true);
        }
        self.tracer.set_target_seconds(seconds);
        let before = self.tracer.spp_done();
        let caustic_before = self.tracer.caustic_seconds();
        let report = self.tracer.render_step(Some(spp)).map_err(|e| e.to_string())?;
        // As the tracer's own planner counts a band: a polled band's wall time includes the
        // frames drawn while it was read back, its GPU time (where there is one) does not.
        // The caustic's frames are traced in steps of their own, whose reports are empty,
        // and timed apart from the bands (PathTracer::caustic_seconds), whatever the readback.
        let band_seconds = match self.tracer.readback() {
            Readback::Polled => report.gpu_seconds.unwrap_or(report.wall_seconds),
            _ => report.wall_seconds,
        };
        self.step_seconds += band_seconds + self.tracer.caustic_seconds() - caustic_before;
        self.step_spp += self.tracer.spp_done() - before;
        Ok(self.tracer.spp_done() >= spp)
    }

    /// Seconds per spp over the whole pilot image (the first sample, counted in the set-up,
    /// aside).
    pub(super) fn seconds_per_spp(&self) -> f64 {
        let setup = self.setup_seconds.unwrap_or(0.0);
        if self.step_spp == 0 { setup } else { self.step_seconds / f64::from(self.step_spp) }
    }
}
