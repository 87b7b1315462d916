//! The waited form of a caustic pass, for a caller that can block (the native tools): each call
//! submits the next work and waits for it, so that a submission's cost is measured whole.

use illum_gpu::GpuContext;
use web_time::Instant;

use super::CausticTracer;
use super::dispatch::Launched;
use super::pass::{CausticPass, PassKey};
use super::schedule::Took;
use crate::PathTraceError;

/// A step goes on with the next frame's pieces while at least this share of its target is left:
/// a submission holds whole frames, so a frame of 0.6 times the target would otherwise leave 40%
/// of every step unused (a viewer's frame, whose share of the window's frame time it is).
const FILL_FROM: f64 = 0.2;

impl CausticTracer {
    /// Traces the frames of pass `key` (absolute sample indices `key.first_sample..`, grouped
    /// in the slot layers `key.layers`) and folds them, in submissions sized to what is left of
    /// `target` seconds (`schedule.rs`), each waited for, until the target is spent (within
    /// [`FILL_FROM`] of it) or the pass's frames are all traced. Returns true only when the
    /// pass's frames were all folded before this call (so a step is caustic work or one band,
    /// never both).
    pub(crate) fn prepare_pass(
        &mut self,
        gpu: &GpuContext,
        key: PassKey,
        target: f64,
    ) -> Result<bool, PathTraceError> {
        let mut pass = self.take_pass(key);
        // A polled submission left in flight is abandoned, and so is a frame begun by polling
        // (its last piece may not be done): the frame is traced again from its start here.
        if pass.in_flight.take().is_some() || pass.polled_frame {
            pass.restart_frame();
        }
        let ready = pass.complete();
        let step = Instant::now();
        let mut left = target;
        loop {
            // On an error the pass is dropped, as a submission of it may be half done: the
            // next call traces its frames again.
            let traced = self.submit_waited(gpu, &mut pass, left)?;
            left = target - step.elapsed().as_secs_f64();
            if !traced || pass.complete() || left < FILL_FROM * target {
                break;
            }
        }
        self.pass = Some(pass);
        Ok(ready)
    }

    /// Submits the pass's next work, sized to `target` seconds, waits for it and folds what it
    /// completes. False when the pass had nothing left to trace.
    fn submit_waited(
        &mut self,
        gpu: &GpuContext,
        pass: &mut CausticPass,
        target: f64,
    ) -> Result<bool, PathTraceError> {
        let (pixels, unit) = (self.pixels, self.unit);
        let started = Instant::now();
        match self.launch(gpu, pass, target)? {
            None => return Ok(false),
            Some(Launched::Piece(submission)) => {
                gpu.wait_idle("tracing a piece of a caustic frame")?;
                let seconds = started.elapsed().as_secs_f64();
                self.record_parts(submission, 0, &[], 0.0, Some(seconds));
                self.record(pass, submission, seconds, Took::Seconds(seconds));
            }
            Some(Launched::Frames { staging, bytes, count, submission }) => {
                let (mut fold_seconds, mut timestamps) = (0.0, Vec::new());
                illum_gpu::readback::with_mapped(
                    gpu,
                    &staging,
                    bytes.total,
                    "reading back caustic frames",
                    |data| {
                        let fold = Instant::now();
                        pass.fold_frames(
                            bytemuck::cast_slice(&data[..bytes.frames as usize]),
                            count,
                            pixels,
                            unit,
                        );
                        fold_seconds = fold.elapsed().as_secs_f64();
                        timestamps = data[bytes.frames as usize..].to_vec();
                    },
                )?;
                self.staging = Some(staging);
                let seconds = started.elapsed().as_secs_f64();
                self.record_parts(submission, count, &timestamps, fold_seconds, Some(seconds - fold_seconds));
                self.record(pass, submission, seconds, Took::Seconds(seconds - fold_seconds));
            }
        }
        Ok(true)
    }
}
