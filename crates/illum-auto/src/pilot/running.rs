//! A path tracer the pilot runs to a number of samples over steps, and its timing.

use illum_gpu::GpuContext;
use illum_pathtrace::{PathTracer, Readback, SampleAllocation, TracerOptions};
use illum_scene::Scene;
use web_time::Instant;

/// A path tracer being run to a number of samples over steps, with its timing.
pub(super) struct Running {
    pub(super) tracer: PathTracer,
    started: Instant,
    /// Seconds to create it and have its first sample per pixel back (pipeline, buffers).
    pub(super) setup_seconds: Option<f64>,
    /// Seconds of adaptive sampling's own pilot (0 without adaptive sampling).
    pub(super) adaptive_seconds: f64,
    /// With adaptive sampling, the mean spp its allocation spreads (its spp done counts the
    /// busiest block's).
    mean_spp: Option<u32>,
    /// Seconds of the submissions after the first sample, and the spp they added.
    step_seconds: f64,
    step_spp: u32,
}

impl Running {
    /// A tracer of `scene` with `options`; with `adaptive`, its samples spread by adaptive
    /// sampling (planned once the first sample is in, see [`Self::step`]).
    pub(super) fn start(
        gpu: &GpuContext,
        scene: &Scene,
        options: TracerOptions,
        adaptive: bool,
        slice: f64,
    ) -> Result<Running, String> {
        let started = Instant::now();
        let (w, h) = (scene.camera.width, scene.camera.height);
        let mut tracer = if adaptive {
            // The adaptive pipeline from the start, so that its set-up is counted here.
            let unlimited = SampleAllocation::uniform(w, h, u32::MAX);
            PathTracer::with_sample_allocation(gpu, scene, options, unlimited)
        } else {
            PathTracer::with_options(gpu, scene, options)
        }
        .map_err(|e| e.to_string())?;
        tracer.set_target_seconds(slice);
        Ok(Running {
            tracer,
            started,
            setup_seconds: None,
            adaptive_seconds: 0.0,
            mean_spp: None,
            step_seconds: 0.0,
            step_spp: 0,
        })
    }

    /// One submission of about `slice` seconds toward `spp` (the first sample per pixel first,
    /// which counts in the set-up and is then discarded), or a poll of the one under way; true
    /// once `spp` is reached.
    pub(super) fn step(&mut self, spp: u32, slice: f64) -> Result<bool, String> {
        if self.setup_seconds.is_none() {
            self.tracer.render_step(Some(1)).map_err(|e| e.to_string())?;
            if self.tracer.spp_done() >= 1 {
                self.setup_seconds = Some(self.started.elapsed().as_secs_f64());
                self.tracer.reset();
                if self.tracer.sample_allocation().is_some() {
                    self.plan_adaptive(spp)?;
                }
            }
            return Ok(false);
        }
        let until = self.until(spp);
        if self.tracer.spp_done() >= until {
            return Ok(true);
        }
        self.tracer.set_target_seconds(slice);
        let before = self.tracer.spp_done();
        let caustic_before = self.tracer.caustic_seconds();
        let report = self.tracer.render_step(Some(until)).map_err(|e| e.to_string())?;
        // As the tracer's own planner counts a submission: a polled one's wall time includes
        // the frames drawn while it was read back, its GPU time (where there is one) does not.
        // The caustic's frames are traced in steps of their own, whose reports are empty, and
        // timed apart (PathTracer::caustic_seconds), whatever the readback.
        let seconds = match self.tracer.readback() {
            Readback::Polled => report.gpu_seconds.unwrap_or(report.wall_seconds),
            _ => report.wall_seconds,
        };
        self.step_seconds += seconds + self.tracer.caustic_seconds() - caustic_before;
        self.step_spp += self.tracer.spp_done() - before;
        Ok(self.tracer.spp_done() >= until)
    }

    /// The spp done at which a run to a mean of `spp` ends: `spp`, or with adaptive sampling
    /// its busiest block's.
    fn until(&self, spp: u32) -> u32 {
        match (self.mean_spp, self.tracer.sample_allocation()) {
            (Some(_), Some(allocation)) => allocation.max(),
            _ => spp,
        }
    }

    /// Adaptive sampling's own pilot for a mean of `spp` (it waits for its readback).
    #[cfg(not(target_arch = "wasm32"))]
    fn plan_adaptive(&mut self, spp: u32) -> Result<(), String> {
        let t = Instant::now();
        illum_pathtrace::allocation::plan_adaptive(&mut self.tracer, spp).map_err(|e| e.to_string())?;
        self.adaptive_seconds = t.elapsed().as_secs_f64();
        self.mean_spp = Some(spp);
        Ok(())
    }

    #[cfg(target_arch = "wasm32")]
    fn plan_adaptive(&mut self, _: u32) -> Result<(), String> {
        Err("adaptive sampling's pilot waits for the GPU: the command line's Auto measures it, a web page's cannot"
            .to_owned())
    }

    /// Seconds per spp over the whole image (the first sample, counted in the set-up, aside).
    pub(super) fn seconds_per_spp(&self) -> f64 {
        let setup = self.setup_seconds.unwrap_or(0.0);
        let spp = self.mean_spp.unwrap_or(self.step_spp);
        if self.step_spp == 0 { setup } else { self.step_seconds / f64::from(spp) }
    }
}
