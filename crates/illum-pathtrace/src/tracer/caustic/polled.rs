//! The polled form of a caustic pass, for a caller that cannot wait (a web page): each call looks
//! whether the submission in flight is done, folds it if so, and submits the next, so that a
//! submission's cost is known only up to the time between looks.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use illum_gpu::readback::PendingRead;
use illum_gpu::{GpuContext, wgpu};
use web_time::Instant;

use super::CausticTracer;
use super::dispatch::Launched;
use super::flight::{Flight, InFlight, seen_done};
use super::pass::PassKey;
use super::schedule::{Submission, Took};
use crate::PathTraceError;

impl CausticTracer {
    /// The polled form of [`Self::prepare_pass`]: true once the frames of pass `key` are all
    /// folded. Each call folds the frames in flight if their mapping is done, or sees whether
    /// the piece in flight is done, and then submits the next work; it never waits. A
    /// submission's cost is its GPU time where the device timed it (whole frames), else the time
    /// from its submission to the call that sees it done, which counts the frames a page drew
    /// meanwhile and the browser's delay in telling it: only a bound on the cost ([`Took`]).
    pub(crate) fn poll_pass(
        &mut self,
        gpu: &GpuContext,
        key: PassKey,
        target: f64,
    ) -> Result<bool, PathTraceError> {
        let mut pass = self.take_pass(key);
        if let Some(flight) = pass.in_flight.take() {
            let seconds = flight.launched.elapsed().as_secs_f64();
            match flight.what {
                Flight::Read { read, bytes, count } => {
                    let Some(result) = read.poll(gpu) else {
                        pass.in_flight = Some(InFlight {
                            what: Flight::Read { read, bytes, count },
                            looks: flight.looks + 1,
                            ..flight
                        });
                        self.pass = Some(pass);
                        return Ok(false);
                    };
                    let data = result?;
                    let frames = bytes.frames as usize;
                    let fold = Instant::now();
                    pass.fold_frames(bytemuck::cast_slice(&data[..frames]), count, self.pixels, self.unit);
                    self.record_parts(
                        flight.submission,
                        count,
                        &data[frames..],
                        fold.elapsed().as_secs_f64(),
                        None,
                    );
                    let gpu_seconds = matches!(flight.submission, Submission::Frames { .. })
                        .then(|| self.timer.decode(&data[frames..]))
                        .flatten()
                        .map(|passes| passes.iter().map(|p| p.1).sum::<f64>() * 1e-3);
                    let took = match gpu_seconds {
                        Some(gpu) => Took::Seconds(gpu),
                        None => seen_done(flight.looks, seconds),
                    };
                    let seconds = gpu_seconds.unwrap_or(seconds);
                    self.record(&mut pass, flight.submission, seconds, took);
                    self.staging = Some(read.into_buffer());
                }
                Flight::Piece(done) => {
                    // One piece on the GPU at a time: the queue never holds more than a step's work.
                    if let Err(e) = gpu.device.poll(wgpu::PollType::Poll) {
                        return Err(illum_gpu::GpuError::DeviceLost { message: e.to_string() }.into());
                    }
                    if !done.load(Ordering::Acquire) {
                        pass.in_flight =
                            Some(InFlight { what: Flight::Piece(done), looks: flight.looks + 1, ..flight });
                        self.pass = Some(pass);
                        return Ok(false);
                    }
                    let took = seen_done(flight.looks, seconds);
                    self.record(&mut pass, flight.submission, seconds, took);
                }
            }
        }
        let launched = self.launch(gpu, &mut pass, target)?;
        let complete = launched.is_none();
        let now = Instant::now();
        pass.in_flight = match launched {
            Some(Launched::Frames { staging, bytes, count, submission }) => Some(InFlight {
                what: Flight::Read {
                    read: PendingRead::start(staging, bytes.total, "reading back caustic frames"),
                    bytes,
                    count,
                },
                submission,
                launched: now,
                looks: 0,
            }),
            Some(Launched::Piece(submission)) => {
                pass.polled_frame = true;
                let done = Arc::new(AtomicBool::new(false));
                let flag = done.clone();
                gpu.queue.on_submitted_work_done(move || flag.store(true, Ordering::Release));
                Some(InFlight { what: Flight::Piece(done), submission, launched: now, looks: 0 })
            }
            None => None,
        };
        self.pass = Some(pass);
        Ok(complete)
    }
}
