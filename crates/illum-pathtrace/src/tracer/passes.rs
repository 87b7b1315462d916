//! The passes of a render: planning the next one (chunk-aligned for exact resumes), tracing it
//! band by band toward a sample target (`render_step`, `render_to_spp`, or exactly
//! `add_samples_in_one_pass`), starting again (`reset`) and going on from a checkpoint
//! (`restore`, `aligned_prefix`).

use super::runner::{ActivePass, Readback};
use super::{PathTracer, StepReport};
use crate::planner::PassPlan;
use crate::{Accumulator, PathTraceError};

impl PathTracer {
    /// With `true`, every pass [`Self::render_step`] plans ends on a multiple of the chunk size in
    /// absolute sample indices (or where the render ends), so each pixel's chunks are always the
    /// same samples, whatever the batching: two renders with the same seed, or one resumed from
    /// a checkpoint, fold the same f32 chunk sums in the same order and agree bit for bit. The
    /// first pass then has a whole chunk (16 spp) rather than the planner's 1-spp probe; the
    /// bands shrink to keep each submission short. The `render` example turns it on.
    pub fn set_chunk_aligned_passes(&mut self, aligned: bool) {
        self.bands.chunk_aligned = aligned;
    }

    /// The pass in progress, if a render stopped inside one: (its spp, rows done from row 0).
    pub fn partial_pass(&self) -> Option<(u32, u32)> {
        self.bands.pass().map(|p| (p.plan.spp, p.next_row))
    }

    /// The statistics at the last chunk boundary and their spp, when the samples taken so far
    /// (or the pass in progress) end inside a chunk: what a checkpoint stores so that a resumed
    /// render can go on from that boundary (see [`Self::set_chunk_aligned_passes`]).
    pub fn aligned_prefix(&self) -> Option<(&Accumulator, u32)> {
        let chunk = self.bands.chunk_samples.max(1);
        let end = self.next_sample() + self.bands.pass().map_or(0, |p| p.plan.spp);
        let (accumulator, spp) = self.accumulation.aligned_prefix.as_ref()?;
        (!end.is_multiple_of(chunk)).then_some((accumulator, *spp))
    }

    /// Continues from a checkpoint: the accumulator, the spp of the completed passes, and a pass
    /// stopped inside (its spp and the rows done), which the next steps finish first. The
    /// accumulator must have this tracer's resolution. `aligned_prefix`: the checkpoint's
    /// statistics at its last chunk boundary (see [`Self::aligned_prefix`]), kept for the next
    /// checkpoint when the pass in progress ends inside a chunk.
    pub fn restore(
        &mut self,
        mut accumulator: Accumulator,
        spp_done: u32,
        partial_pass: Option<(u32, u32)>,
        aligned_prefix: Option<(Accumulator, u32)>,
    ) -> Result<(), PathTraceError> {
        let camera = self.pipeline.scene.camera;
        if (accumulator.width, accumulator.height) != (camera.width, camera.height) {
            return Err(PathTraceError::Unsupported {
                scene: self.pipeline.scene.name.clone(),
                message: format!(
                    "a checkpoint of {} x {} pixels cannot continue a {} x {} render",
                    accumulator.width, accumulator.height, camera.width, camera.height
                ),
            });
        }
        let radiance_exponent = self.pipeline.radiance_exponent;
        accumulator.set_radiance_exponent(radiance_exponent);
        accumulator.set_estimates_error(self.pipeline.options.estimates_error());
        // The glint belongs to this tracer's scene (solved when it was built), not to the file.
        let exact = self.accumulation.accumulator.exact().clone();
        accumulator.set_exact(exact.clone());
        self.reset();
        self.accumulation.accumulator = accumulator;
        self.accumulation.spp_done = spp_done;
        self.accumulation.aligned_prefix = aligned_prefix.map(|(mut prefix, spp)| {
            prefix.set_radiance_exponent(radiance_exponent);
            prefix.set_exact(exact);
            (prefix, spp)
        });
        if let Some((spp, next_row)) = partial_pass.filter(|&(_, rows)| rows > 0 && rows < camera.height) {
            let planned = self.bands.planner.plan(camera.width, camera.height, spp);
            let rows = if planned.spp >= spp { camera.height } else { planned.rows.max(1) };
            let plan = self.fit(PassPlan { spp, rows });
            self.bands.start_pass(ActivePass { plan, sample_base: spp_done, next_row });
        }
        self.accumulation.show_accumulator(&self.pipeline.gpu, radiance_exponent);
        Ok(())
    }

    /// Discards everything accumulated; the next step starts again at sample 0.
    pub fn reset(&mut self) {
        // A band on the GPU is dropped with its pass: it is never folded.
        self.bands.restart();
        if let Some(caustic) = &mut self.pipeline.caustic {
            caustic.discard_pass();
        }
        self.accumulation.reset(&self.pipeline.gpu);
    }

    /// Runs one short submission (one band of rows of the current pass; about 0.15 s, see
    /// [`Self::set_target_seconds`]) toward `target_spp` samples per pixel (`None`: no limit).
    /// Returns a report with `samples == 0` once the target is reached. Progressive renderers
    /// call it in a loop, between frames or checks of their stop rules.
    ///
    /// With [`Readback::Polled`] it never waits: a call submits a band, and later calls
    /// report `samples == 0` until its results are back, then fold it and report it.
    pub fn render_step(&mut self, target_spp: Option<u32>) -> Result<StepReport, PathTraceError> {
        self.bands.pacing.enter();
        let result = self.step_once(target_spp);
        self.bands.last_step = *result.as_ref().unwrap_or(&StepReport::default());
        self.bands.pacing.leave();
        result
    }

    /// [`Self::render_step`]'s work.
    fn step_once(&mut self, target_spp: Option<u32>) -> Result<StepReport, PathTraceError> {
        let camera = self.pipeline.scene.camera;
        let pass = match self.bands.pass() {
            Some(pass) => *pass,
            None => {
                let spp_done = self.accumulation.spp_done;
                let remaining = match target_spp {
                    Some(t) if t <= spp_done => return Ok(StepReport::default()),
                    Some(t) => t - spp_done,
                    None => u32::MAX - spp_done,
                };
                let start = self.next_sample();
                let planned =
                    self.bands.planner.plan(camera.width, self.pipeline.active_height(start), remaining);
                let mut plan =
                    self.fit(PassPlan { rows: self.pipeline.spread_rows(planned.rows, start), ..planned });
                if self.bands.chunk_aligned {
                    let chunk = self.bands.chunk_samples;
                    plan = align_pass(plan, start, remaining, chunk);
                    if start.is_multiple_of(chunk.max(1)) {
                        self.keep_aligned_prefix(start + plan.spp);
                    }
                }
                let pass = ActivePass { plan, sample_base: spp_done, next_row: 0 };
                self.bands.start_pass(pass);
                pass
            }
        };
        let Some(report) = self.next_band(pass)? else { return Ok(StepReport::default()) };
        // A polled band's wall time includes the frames drawn while it was read back; its GPU
        // time (timestamp queries), where the adapter has them, is what it cost.
        let seconds = if self.bands.readback() == Readback::Polled {
            report.gpu_seconds.unwrap_or(report.wall_seconds)
        } else {
            report.wall_seconds
        };
        self.bands.planner.record(report.samples, seconds);
        // Later bands of the pass follow what the planner has learnt: a pass planned before
        // the first measurement (a large image with chunk-aligned passes: bands of one row)
        // would otherwise be a thousand tiny submissions, each paying the driver's fixed cost.
        // Bands are rows, so their size never changes which samples a pixel's chunks hold.
        if let Some(spp) = self.bands.pass().map(|p| p.plan.spp) {
            let start = self.next_sample();
            let planned = self.bands.planner.rows_for(camera.width, self.pipeline.active_height(start), spp);
            let fitted = self.fit(PassPlan { spp, rows: self.pipeline.spread_rows(planned, start) });
            if let Some(pass) = self.bands.pass_mut().filter(|_| fitted.spp == spp) {
                pass.plan.rows = fitted.rows;
            }
        }
        Ok(report)
    }

    /// At a chunk boundary before a pass that ends at `end` (absolute sample index): when that
    /// is inside a chunk (the last pass of a render that ends inside one), keeps the statistics
    /// at this boundary (see `aligned_prefix`), if the host has the memory for the copy with a
    /// fifth to spare (a render too large for it, resumed, then differs from a straight one by
    /// f32 rounding, and the resume says so).
    fn keep_aligned_prefix(&mut self, end: u32) {
        let accumulation = &mut self.accumulation;
        let copy_fits = || {
            use crate::accumulator::{ALIGNED_COPY_BYTES_PER_PIXEL, RENDER_HOST_BYTES_PER_PIXEL};
            let accumulator = &accumulation.accumulator;
            let pixels = u64::from(accumulator.width) * u64::from(accumulator.height);
            // Replicates (low-discrepancy): in the statistics and the copy, each with its EXR layer.
            let replicates =
                accumulator.replicates().map_or(0, |_| 4 * crate::replicates::Replicates::BYTES_PER_PIXEL);
            let peak = pixels * (RENDER_HOST_BYTES_PER_PIXEL + ALIGNED_COPY_BYTES_PER_PIXEL + replicates);
            crate::accumulator::available_host_memory().is_none_or(|available| peak <= available / 5 * 4)
        };
        let kept = (!end.is_multiple_of(self.bands.chunk_samples.max(1)) && copy_fits())
            .then(|| (accumulation.accumulator.clone(), accumulation.spp_done));
        accumulation.aligned_prefix = kept;
    }

    /// One band of the active pass: polled (`None` while its results, or the caustic's frames
    /// before it, are not back) or waited for.
    #[cfg(not(target_arch = "wasm32"))]
    fn next_band(&mut self, pass: ActivePass) -> Result<Option<StepReport>, PathTraceError> {
        match self.bands.readback() {
            Readback::Polled => self.poll_band(pass),
            Readback::Staging | Readback::Mapped => self.submit_band(pass),
        }
    }

    /// One band of the active pass, polled: a web page cannot wait.
    #[cfg(target_arch = "wasm32")]
    fn next_band(&mut self, pass: ActivePass) -> Result<Option<StepReport>, PathTraceError> {
        self.poll_band(pass)
    }

    /// Renders until every pixel has `spp` samples in all (those already taken count), in
    /// submissions sized by the measured speed. Waits for the GPU: native only.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn render_to_spp(&mut self, spp: u32) -> Result<(), PathTraceError> {
        while self.accumulation.spp_done < spp {
            self.render_step(Some(spp))?;
        }
        Ok(())
    }

    /// Adds exactly `spp` samples per pixel in one pass over the image when the device allows
    /// (split into bands only if the image is too large for one short submission or one storage
    /// binding, and into several passes only if one dispatch cannot carry `spp` chunks). Unlike
    /// [`Self::render_to_spp`], the grouping of samples into f32 chunk sums then depends on the
    /// call alone, never on measured speed: tests use it to compare renders bit for bit and to
    /// control batching. Waits for the GPU: native only.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn add_samples_in_one_pass(&mut self, spp: u32) -> Result<(), PathTraceError> {
        assert!(self.bands.pass().is_none(), "add_samples_in_one_pass called in the middle of a pass");
        let camera = self.pipeline.scene.camera;
        let mut remaining = spp;
        while remaining > 0 {
            let planned = self.bands.planner.plan(camera.width, camera.height, remaining);
            let rows = if planned.spp >= remaining { camera.height } else { planned.rows.max(1) };
            let plan = self.fit(PassPlan { spp: remaining, rows });
            self.bands.start_pass(ActivePass { plan, sample_base: self.accumulation.spp_done, next_row: 0 });
            while let Some(pass) = self.bands.pass().copied() {
                if let Some(report) = self.submit_band(pass)? {
                    self.bands.planner.record(report.samples, report.wall_seconds);
                }
            }
            remaining -= plan.spp;
        }
        Ok(())
    }
}
impl PathTracer {
    /// The absolute sample index the next pass starts at.
    pub(super) fn next_sample(&self) -> u32 {
        self.bands.sample_offset + self.accumulation.spp_done
    }
}

/// A pass plan changed so that the pass ends on a multiple of `chunk` in absolute sample indices
/// (`start` is the pass's first index), or at the end of the render (`remaining` samples): one
/// chunk more when the plan would end inside the first chunk, fewer when it ends past a chunk
/// boundary. The rows shrink or grow with the spp so that a submission keeps its size.
fn align_pass(plan: PassPlan, start: u32, remaining: u32, chunk: u32) -> PassPlan {
    let chunk = chunk.max(1);
    if plan.spp >= remaining {
        // The last pass. Where the render ends inside a chunk, the whole chunks come first and
        // the rest in a pass of its own, so that the statistics at the last chunk boundary can be
        // kept for a resumed render (see `PathTracer::aligned_prefix`).
        let end = start.saturating_add(remaining);
        let boundary = end / chunk * chunk;
        let spp = if !end.is_multiple_of(chunk) && boundary > start { boundary - start } else { remaining };
        return PassPlan { spp, ..plan };
    }
    let end = start.saturating_add(plan.spp) / chunk * chunk;
    let spp = if end > start { end - start } else { chunk - start % chunk }.min(remaining);
    let rows = (u64::from(plan.rows) * u64::from(plan.spp) / u64::from(spp)).clamp(1, u64::from(u32::MAX));
    PassPlan { spp, rows: rows as u32 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pass ends on a chunk boundary or at the render's end, and a render that ends inside
    /// a chunk gets its whole chunks first and the rest in a last pass of its own.
    #[test]
    fn passes_end_on_chunk_boundaries_and_the_tail_comes_alone() {
        let ends = |start: u32, target: u32, plan_spp: u32| {
            let mut ends = Vec::new();
            let mut at = start;
            while at < target {
                let plan = align_pass(PassPlan { spp: plan_spp, rows: 8 }, at, target - at, 16);
                assert!(plan.spp >= 1 && plan.rows >= 1);
                at += plan.spp;
                ends.push(at);
            }
            ends
        };
        assert_eq!(ends(0, 50, 1000), [48, 50]);
        assert_eq!(ends(0, 50, 20), [16, 32, 48, 50]);
        assert_eq!(ends(0, 10, 1000), [10]);
        assert_eq!(ends(0, 64, 1000), [64]);
        assert_eq!(ends(16, 100, 1000), [96, 100]);
        assert_eq!(ends(0, 100, 1), [16, 32, 48, 64, 80, 96, 100]);
        // A resumed render going on from an unaligned count reaches the next boundary first.
        assert_eq!(ends(50, 100, 1000), [96, 100]);
        assert_eq!(ends(50, 100, 4), [64, 80, 96, 100]);
    }
}
