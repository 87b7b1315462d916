//! Recording and submitting the caustic's work: the next submission of a pass as the schedule
//! plans it, its dispatches (the light tracer's, then the photon gather's) and the copy of its
//! frames to a staging buffer.

use illum_gpu::{GpuContext, wgpu};

use super::flight::DispatchBytes;
use super::params::WORDS_PER_PIXEL;
use super::pass::CausticPass;
use super::schedule::{Cursor, FrameShape, Stage, Submission, WORKGROUP, next_submission};
use super::{CausticParams, CausticTracer};
use crate::PathTraceError;

/// What [`CausticTracer::launch`] submitted.
pub(super) enum Launched {
    /// A piece of a frame, not read back.
    Piece(Submission),
    /// Frames to read back: whole ones, or a frame's last piece.
    Frames { staging: wgpu::Buffer, bytes: DispatchBytes, count: u32, submission: Submission },
}

/// The timer's names of the light tracer's and the photon gather's passes.
pub(super) const CAUSTIC_PASS: &str = "caustic";
pub(super) const GATHER_PASS: &str = "photon gather";

impl CausticTracer {
    /// The shape of this tracer's frames, for `schedule.rs`.
    fn frame_shape(&self) -> FrameShape {
        FrameShape {
            invocations: self.base.particles,
            gather: self.gather.is_some(),
            max_frames: self.max_frames_per_dispatch,
        }
    }

    /// The staging buffer for a dispatch's frames (the one read last, or a new one).
    fn take_staging(&mut self, gpu: &GpuContext) -> Result<wgpu::Buffer, PathTraceError> {
        match self.staging.take() {
            Some(staging) => Ok(staging),
            None => Ok(gpu.scoped("allocating the caustic's staging buffer", || {
                gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("caustic staging"),
                    size: self.splat_size + self.timer.result_size(),
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            })?),
        }
    }

    /// Submits the next work of `pass`, as [`next_submission`] plans it at the measured costs
    /// and `target` seconds, and moves the pass's cursor past it. `None` when the pass is
    /// complete.
    pub(super) fn launch(
        &mut self,
        gpu: &GpuContext,
        pass: &mut CausticPass,
        target: f64,
    ) -> Result<Option<Launched>, PathTraceError> {
        if pass.complete() {
            return Ok(None);
        }
        let shape = self.frame_shape();
        let submission =
            next_submission(shape, &self.costs, target, pass.cursor, pass.key.spp - pass.frames_done);
        let frame = pass.key.first_sample + pass.frames_done;
        let read = self.submit(gpu, frame, pass.key.origin, submission)?;
        if pass.cursor == Cursor::FrameStart {
            pass.polled_frame = false;
        }
        pass.cursor = submission.cursor_after(shape.invocations, shape.gather);
        Ok(Some(match (read, submission) {
            (Some((staging, bytes)), Submission::Frames { count }) => {
                Launched::Frames { staging, bytes, count, submission }
            }
            (Some((staging, bytes)), Submission::Piece { .. }) => {
                Launched::Frames { staging, bytes, count: 1, submission }
            }
            (None, _) => Launched::Piece(submission),
        }))
    }

    /// Workgroups (x, y) and the invocations per row for a dispatch of `count` invocations.
    fn layout(&self, count: u32) -> (u32, u32, u32) {
        let groups = count.div_ceil(WORKGROUP).max(1);
        let gx = groups.min(self.max_groups_x.max(1));
        (gx, groups.div_ceil(gx), gx * WORKGROUP)
    }

    /// Records and submits `submission` from sample index `frame` of a render whose first is
    /// `origin`. Returns the staging buffer and what to read from it when it completes frames
    /// (whole ones, or a frame's last piece).
    fn submit(
        &mut self,
        gpu: &GpuContext,
        frame: u32,
        origin: u32,
        submission: Submission,
    ) -> Result<Option<(wgpu::Buffer, DispatchBytes)>, PathTraceError> {
        let n = self.base.particles;
        let (frames, first, count, clear, particles, gather, read) = match submission {
            Submission::Frames { count } => (count, 0, n, true, true, true, true),
            Submission::Piece { stage, first, count, clear, read } => {
                let particles = stage == Stage::Particles;
                (1, first, count, clear, particles, !particles, read)
            }
        };
        let (gx, gy, row_stride) = self.layout(count);
        let params = CausticParams {
            frame_base: frame,
            frame_count: frames,
            first_index: first,
            index_end: first + count,
            row_stride,
            radius_origin: origin,
            ..self.base
        };
        let words_per_frame = WORDS_PER_PIXEL * self.pixels as u64;
        let bytes = (words_per_frame + 1) * 4 * u64::from(frames);
        // Whole frames are timed; a piece is timed by its caller.
        let timed = matches!(submission, Submission::Frames { .. });
        let staging = if read { Some(self.take_staging(gpu)?) } else { None };
        gpu.queue.write_buffer(&self.scene_params_buffer, 0, bytemuck::bytes_of(&self.scene_params));
        gpu.queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("caustic frames") });
        if clear {
            encoder.clear_buffer(&self.splat, 0, Some(bytes));
            if let Some(gather) = &self.gather {
                encoder.clear_buffer(&gather.heads, 0, Some(gather.heads_frame_bytes * u64::from(frames)));
            }
        }
        if particles {
            let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("caustic"),
                timestamp_writes: if timed { self.timer.compute_writes(CAUSTIC_PASS) } else { None },
            });
            compute.set_pipeline(&self.pipeline);
            compute.set_bind_group(0, &self.bind_group, &[]);
            if let Some(bvh) = &self.bvh {
                bvh.set(&mut compute);
            }
            compute.dispatch_workgroups(gx, gy, frames);
        }
        // Its own pass: the gather reads what every particle of the frames stored.
        if let Some(gather) = self.gather.as_ref().filter(|_| gather) {
            let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("photon gather"),
                timestamp_writes: if timed { self.timer.compute_writes(GATHER_PASS) } else { None },
            });
            compute.set_pipeline(&gather.pipeline);
            compute.set_bind_group(0, &gather.bind_group, &[]);
            if let Some(bvh) = &gather.bvh {
                bvh.set(&mut compute);
            }
            compute.dispatch_workgroups(gx, gy, frames);
        }
        let result = staging.map(|staging| {
            encoder.copy_buffer_to_buffer(&self.splat, 0, &staging, 0, bytes);
            let timestamps = if timed && self.timer.enabled() {
                self.timer.copy_results(&mut encoder, &staging, bytes);
                self.timer.result_size()
            } else {
                0
            };
            (staging, DispatchBytes { frames: bytes, total: bytes + timestamps })
        });
        gpu.queue.submit([encoder.finish()]);
        Ok(result)
    }
}
