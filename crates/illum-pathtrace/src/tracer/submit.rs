//! One submission of the path tracer: a band of rows of the current pass traced on the GPU,
//! read back, checked for lost samples and folded into the f64 accumulator.
//!
//! The readback is either a blocking wait ([`PathTracer::submit_band`], native tools only) or
//! polled ([`PathTracer::poll_band`], the web viewer, which cannot wait): the band is submitted
//! and its mapping started, and later calls fold it once the browser has mapped it. With the
//! caustic's light tracer, a pass's frames are traced and folded before its first band, the
//! same way: waited for, or polled dispatch by dispatch (`tracer/caustic.rs`).
//!
//! The blocking form keeps the GPU busy while the CPU folds: once a band's results are mapped,
//! the next band of the same pass is submitted (into a second staging buffer, or the second set
//! of batch buffers) before the fold begins. At 1024 x 1024 the fold of one band (a pass over
//! 88 MB of statistics and 32 MB of results) took 5 to 6 ms, during which the GPU had nothing
//! to do.
//!
//! Where the GPU computes in the host's memory (lavapipe, integrated GPUs) the results are not
//! copied at all: the CPU maps the batch buffers the shader wrote ([`Readback::Mapped`]).

#[cfg(not(target_arch = "wasm32"))]
use illum_gpu::readback;
use illum_gpu::readback::PendingRead;
use illum_gpu::wgpu;
use web_time::Instant;

use super::caustic::PassKey;
use super::{PathTracer, StepReport, TIMED_PASS};
use crate::PathTraceError;
use crate::batch::{self, BatchBuffers, SLOT_BYTES};
use crate::options::Traversal;
use crate::planner::PassPlan;

const WORKGROUP: u32 = 8;

/// Longest time a caller may take between two `render_step` calls and still have bands launched
/// ahead for it (see `launch_ahead`): a render loop's progress bar takes microseconds, a
/// viewer's frame tens of milliseconds.
#[cfg(not(target_arch = "wasm32"))]
const AHEAD_MAX_ABSENCE: std::time::Duration = std::time::Duration::from_millis(1);

impl PathTracer {
    /// Shrinks a pass plan to what the device can take: at most `max_chunks` chunks per dispatch
    /// (the z dimension), and a band of at most `max_slots` slots (rows x width x chunks) per
    /// batch buffer, so an image of any size is rendered band by band.
    pub(super) fn fit(&self, plan: PassPlan) -> PassPlan {
        let width = u64::from(self.scene.camera.width);
        let chunk = u64::from(self.chunk_samples);
        // check_row_fits guarantees max_slots >= width, so at least one chunk fits.
        let max_chunks = u64::from(self.max_chunks).min(self.max_slots / width).max(1);
        let spp = u64::from(plan.spp.max(1)).min(max_chunks * chunk);
        // The caustic's statistics of one pass must fit their host memory.
        let spp = match &self.caustic {
            Some(caustic) => spp.min(u64::from(caustic.max_pass_spp(self.chunk_samples))),
            None => spp,
        };
        let chunks = spp.div_ceil(chunk);
        let max_rows = (self.max_slots / (width * chunks)).max(1);
        let rows = u64::from(plan.rows).clamp(1, max_rows);
        PassPlan { spp: spp as u32, rows: rows as u32 }
    }

    /// Makes sure the batch buffers hold at least `slots` slots (growing them, within
    /// `max_slots`, and rebinding).
    fn ensure_batch_capacity(&mut self, slots: u64) -> Result<(), PathTraceError> {
        // Buffers made before `set_mapped_readback(true)` cannot be mapped: made anew.
        let mappable =
            |b: &BatchBuffers| !self.mapped_readback || b.sum.usage().contains(wgpu::BufferUsages::MAP_READ);
        if self.batch.as_ref().is_some_and(|b| b.slots >= slots && mappable(b)) {
            return Ok(());
        }
        // Grow geometrically (within max_slots) so that passes of slowly rising spp do not
        // reallocate every time; never below what this band needs (a pass planned before a
        // lower cap was set still needs its own size).
        let doubled = self.batch.as_ref().map_or(0, |b| 2 * b.slots).min(self.max_slots);
        let slots = slots.max(doubled);
        let layout = self.pipeline.get_bind_group_layout(0);
        let mut inputs = vec![(0, &self.params_buffer)];
        // A specialised pipeline has its objects and materials as literals (specialise.rs).
        if self.options.traversal == Traversal::Generic {
            inputs.extend([(1, &self.objects_buffer), (2, &self.materials_buffer)]);
        }
        // A pipeline without area lights does not declare them.
        if self.base_params.num_lights > 0 {
            inputs.push((3, &self.lights_buffer));
        }
        // Adaptive sampling's block counts (shader def ADAPTIVE).
        if let Some((_, block_samples)) = &self.allocation {
            inputs.push((6, block_samples));
        }
        let mapped_readback = self.mapped_readback.then(|| self.timer.result_size());
        self.batch = Some(BatchBuffers::new(&self.gpu, slots, &layout, &inputs, mapped_readback)?);
        Ok(())
    }

    /// The caustic's pass that the active pass pairs with, when the light tracer runs.
    fn caustic_key(&self) -> Option<PassKey> {
        let pass = self.pass.as_ref()?;
        self.caustic.as_ref()?;
        Some(PassKey {
            first_sample: self.sample_offset + pass.sample_base,
            spp: pass.plan.spp,
            chunk: self.chunk_samples,
        })
    }

    /// Traces one band and folds it, waiting for the readback (the band launched ahead by the
    /// previous call, if there is one), and launches the pass's next band before folding.
    #[cfg(not(target_arch = "wasm32"))]
    pub(super) fn submit_band(&mut self) -> Result<StepReport, PathTraceError> {
        let AheadBand { band } = match self.ahead.take() {
            Some(ahead) => ahead,
            None => {
                // The caustic's frames of this pass, traced once, before its first band.
                if let Some(key) = self.caustic_key() {
                    self.caustic.as_mut().expect("keyed above").prepare_pass(&self.gpu, key)?;
                }
                AheadBand { band: self.begin_band(self.mapped_readback)? }
            }
        };
        // Folded straight from the mapping: at 1024 x 1024 a band is many megabytes, and
        // copying it out first (allocating and faulting in fresh pages) cost time for nothing.
        let context = "reading back a path-tracing batch";
        let gpu = self.gpu.clone();
        let bytes = band.bytes;
        let folded = match &band.readback {
            Readback::Staging(staging) => {
                readback::with_mapped(&gpu, staging, band.staging_size, context, |data| {
                    self.launch_ahead_and_finish(&band, BandBytes::split(data, bytes as usize))
                })
            }
            Readback::Mapped { sum, sum_sq, timestamps } => {
                readback::with_mapped(&gpu, sum, bytes, context, |sums| {
                    readback::with_mapped(&gpu, sum_sq, bytes, context, |sums_sq| match timestamps {
                        Some(t) => readback::with_mapped(&gpu, t, t.size(), context, |timestamps| {
                            self.launch_ahead_and_finish(&band, BandBytes { sums, sums_sq, timestamps })
                        }),
                        None => {
                            Ok(self
                                .launch_ahead_and_finish(&band, BandBytes { sums, sums_sq, timestamps: &[] }))
                        }
                    })
                })
                .and_then(|mapped| mapped)
                .and_then(|mapped| mapped)
            }
        };
        // The staging buffer just read becomes the one the next band (launched later) copies into.
        if let Readback::Staging(staging) = band.readback {
            self.staging = Some(staging);
        }
        let folded = folded.map_err(PathTraceError::from).and_then(|r| r);
        if folded.is_err() {
            // This band's rows were not folded: the band ahead of it may not be either.
            self.ahead = None;
            if let Some(pass) = self.pass.as_mut() {
                pass.launched_row = pass.next_row;
            }
        }
        folded
    }

    /// Launches the pass's next band, then folds `band` from its read-back bytes.
    #[cfg(not(target_arch = "wasm32"))]
    fn launch_ahead_and_finish(
        &mut self,
        band: &Band,
        bytes: BandBytes,
    ) -> Result<StepReport, PathTraceError> {
        let launched = self.launch_ahead(band);
        // Folded even when the next band could not be launched: its error comes after.
        let folded = self.finish_band(band, bytes);
        folded.and_then(|report| launched.map(|()| report))
    }

    /// Submits the pass's next band, if `band` is not its last, into the spare staging buffer or,
    /// with mapped readback, the other set of batch buffers (the caustic's passes fold frames
    /// traced per pass and are left serial).
    ///
    /// Only for a caller that came straight back last time (a render loop): a band launched
    /// ahead is timed from the last fold to its own, and a caller that goes away in between (a
    /// viewer drawing its window) would have that time counted as the band's cost. The planner
    /// would then shrink every later band toward one row, a feedback that once cut the viewer's
    /// throughput to about 1/500 of `render`'s.
    #[cfg(not(target_arch = "wasm32"))]
    fn launch_ahead(&mut self, band: &Band) -> Result<(), PathTraceError> {
        if self.caustic.is_some()
            || self.caller_absence > AHEAD_MAX_ABSENCE
            || self.active_rows(band.row_offset + band.rows, band.sample_start).is_none()
        {
            return Ok(());
        }
        self.ahead = Some(AheadBand { band: self.begin_band(self.mapped_readback)? });
        Ok(())
    }

    /// The polled form of [`Self::submit_band`]: submits a band when none is in flight, and
    /// folds the one in flight once its mapping is done. `None` while it is not; never waits.
    pub(super) fn poll_band(&mut self) -> Result<Option<StepReport>, PathTraceError> {
        if self.in_flight.is_none() {
            // The caustic's frames of this pass come first, read back dispatch by dispatch over
            // as many calls as it takes.
            if let Some(key) = self.caustic_key()
                && !self.caustic.as_mut().expect("keyed above").poll_pass(&self.gpu, key)?
            {
                return Ok(None);
            }
            self.launch_band()?;
        }
        let Some(result) = self.in_flight.as_ref().and_then(|f| f.read.poll(&self.gpu)) else {
            return Ok(None);
        };
        let flight = self.in_flight.take().expect("polled above");
        let data = result?;
        self.staging = Some(flight.read.into_buffer());
        let bytes = flight.band.bytes as usize;
        let report = self.finish_band(&flight.band, BandBytes::split(&data, bytes))?;
        // The next band of this pass goes to the GPU now, so that it works while the page
        // draws its next frame (a new pass waits for the next call, which checks the target).
        if self.pass.is_some() {
            self.launch_band()?;
        }
        Ok(Some(report))
    }

    /// Submits a band and starts its polled readback.
    fn launch_band(&mut self) -> Result<(), PathTraceError> {
        // Through a staging copy: the polled read maps one buffer.
        let band = self.begin_band(false)?;
        let Readback::Staging(staging) = band.readback.clone() else {
            unreachable!("begun with a staging copy")
        };
        let read = PendingRead::start(staging, band.staging_size, "reading back a path-tracing batch");
        self.in_flight = Some(InFlightBand { band, read });
        Ok(())
    }

    /// Records and submits one band of the active pass (trace, display sum, and with `mapped`
    /// false the copies into the staging buffer; with `mapped` true the band takes the other set
    /// of batch buffers, and the CPU will map them).
    fn begin_band(&mut self, mapped: bool) -> Result<Band, PathTraceError> {
        let started = Instant::now();
        let width = self.scene.camera.width;
        let height = self.scene.camera.height;
        let pass = self.pass.as_ref().expect("submit_band needs an active pass");
        let spp = pass.plan.spp;
        let sample_base = pass.sample_base;
        // Rows with nothing to trace (adaptive sampling's finished blocks) are skipped.
        let (row_offset, end) = self
            .active_rows(pass.launched_row, self.sample_offset + sample_base)
            .unwrap_or((pass.launched_row.min(height - 1), height));
        let rows = pass.plan.rows.min(end - row_offset);
        let chunk = self.chunk_samples;
        let chunks = spp.div_ceil(chunk);
        let band_pixels = rows as usize * width as usize;
        let slots = band_pixels as u64 * u64::from(chunks);
        if mapped {
            // The set the previous band wrote may still be mapped, or about to be.
            std::mem::swap(&mut self.batch, &mut self.spare_batch);
        }
        self.ensure_batch_capacity(slots)?;

        let mut params = self.base_params;
        params.row_offset = row_offset;
        params.rows = rows;
        params.sample_base = self.sample_offset + sample_base;
        params.sample_count = spp;
        params.chunk_samples = chunk;
        self.gpu.queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
        // The caustic's frames of this pass were folded before its first band (the callers
        // above): `finish_band` pairs them with the band's chunks.
        if let Some(key) = self.caustic_key() {
            debug_assert!(
                self.caustic.as_ref().is_some_and(|c| c.holds(key)),
                "caustic pass {key:?} not ready"
            );
        }

        let bytes = slots * SLOT_BYTES;
        let staging_size = if mapped { 0 } else { 2 * bytes + self.timer.result_size() };
        if !mapped && self.staging.as_ref().is_none_or(|s| s.size() < staging_size) {
            self.staging = Some(self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pathtrace staging"),
                size: staging_size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        let batch = self.batch.as_ref().expect("allocated above");

        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pathtrace band") });
        {
            let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("pathtrace"),
                timestamp_writes: self.timer.compute_writes(TIMED_PASS),
            });
            compute.set_pipeline(&self.pipeline);
            compute.set_bind_group(0, &batch.bind_group, &[]);
            compute.dispatch_workgroups(width.div_ceil(WORKGROUP), rows.div_ceil(WORKGROUP), chunks);
        }
        // The display sum reads the slots on the GPU in the same submission (wgpu orders the two
        // passes); the copies below for the f64 fold are unchanged.
        if let Some(display) = &mut self.display_sum {
            display.record(&self.gpu, &mut encoder, &batch.sum, rows, row_offset, chunks);
        }
        let readback = if mapped {
            if let Some(timestamps) = &batch.timestamps {
                self.timer.copy_results(&mut encoder, timestamps, 0);
            }
            Readback::Mapped {
                sum: batch.sum.clone(),
                sum_sq: batch.sum_sq.clone(),
                timestamps: batch.timestamps.clone(),
            }
        } else {
            // Taken: the band holds it until its bytes are read (nothing may copy into it then).
            let staging = self.staging.take().expect("allocated above");
            encoder.copy_buffer_to_buffer(&batch.sum, 0, &staging, 0, bytes);
            encoder.copy_buffer_to_buffer(&batch.sum_sq, 0, &staging, bytes, bytes);
            self.timer.copy_results(&mut encoder, &staging, 2 * bytes);
            Readback::Staging(staging)
        };
        self.gpu.queue.submit([encoder.finish()]);
        if let Some(pass) = self.pass.as_mut() {
            pass.launched_row = row_offset + rows;
        }
        let sample_start = params.sample_base;
        let scheduled = match &self.allocation {
            None => band_pixels as u64 * u64::from(spp),
            Some((allocation, _)) => (row_offset..row_offset + rows)
                .flat_map(|y| (0..width).map(move |x| (x, y)))
                .map(|(x, y)| u64::from(allocation.at(x, y).saturating_sub(sample_start).min(spp)))
                .sum(),
        };
        Ok(Band {
            scheduled,
            started,
            row_offset,
            rows,
            spp,
            sample_start,
            chunk,
            chunks,
            band_pixels,
            bytes,
            staging_size,
            readback,
        })
    }

    /// Checks and folds a band's read-back bytes (its sums, sums of squares and timestamps), and
    /// moves the pass on.
    fn finish_band(&mut self, band: &Band, bytes: BandBytes) -> Result<StepReport, PathTraceError> {
        let Band { started, row_offset, rows, spp, sample_start, chunk, chunks, band_pixels, .. } = *band;
        let width = self.scene.camera.width;
        let height = self.scene.camera.height;
        let (sums, sums_sq) = (batch::slots(bytes.sums), batch::slots(bytes.sums_sq));
        let (sums, sums_sq) = (&sums[..], &sums_sq[..]);
        let uniform = batch::uniform_chunk(spp, chunk);
        let checked = match &self.allocation {
            None => batch::check_complete(sums, sums_sq, chunks, band_pixels, uniform),
            // A block takes the part of each chunk below its count (the shader's ADAPTIVE code).
            Some((allocation, _)) => batch::check_complete(sums, sums_sq, chunks, band_pixels, |k, i| {
                let (x, y) = (i as u32 % width, row_offset + i as u32 / width);
                let start = sample_start + k * chunk;
                allocation.at(x, y).saturating_sub(start).min(uniform(k, i))
            }),
        };
        let samples = match checked {
            Ok(samples) => samples,
            Err(error) => {
                // The accumulator drops this band, but the display pass already added it: set
                // the display sum back to the accumulator's samples.
                if let Some(display) = &self.display_sum {
                    display.seed(&self.gpu, &self.accumulator, self.radiance_exponent);
                }
                return Err(error);
            }
        };
        for k in 0..chunks as usize {
            let range = k * band_pixels..(k + 1) * band_pixels;
            self.accumulator.fold(
                row_offset as usize * width as usize,
                &sums[range.clone()],
                &sums_sq[range.clone()],
            );
            if let Some(caustic) = &self.caustic {
                caustic.fold(&mut self.accumulator, k, row_offset as usize * width as usize, &sums[range]);
            }
        }
        // The display pass added the camera's samples only: show the accumulator's image.
        if let (Some(display), Some(_)) = (&self.display_sum, &self.caustic) {
            display.seed(&self.gpu, &self.accumulator, self.radiance_exponent);
        }
        let gpu_seconds = self.timer.decode(bytes.timestamps).map(|timings| timings[0].1 * 1e-3);

        let pass = self.pass.as_mut().expect("still active");
        pass.next_row = row_offset + rows;
        let start = self.sample_offset + pass.sample_base;
        if self.active_rows(row_offset + rows, start).is_none() {
            // Nothing left to trace below: the pass is complete.
            self.pass.as_mut().expect("still active").next_row = height;
        }
        let pass = self.pass.as_mut().expect("still active");
        let pass_completed = pass.next_row >= height;
        if pass_completed {
            self.spp_done += spp;
            self.pass = None;
            if let Some(caustic) = &mut self.caustic {
                caustic.finish_pass(&mut self.accumulator);
            }
        }
        // A band launched ahead ran while the previous one was folded: its wall time starts
        // where that fold ended, so that the bands' times add up to the elapsed time.
        let now = Instant::now();
        let from = self.last_fold.filter(|&t| t > started).unwrap_or(started);
        let wall_seconds = now.duration_since(from).as_secs_f64();
        self.last_fold = Some(now);
        self.wall_seconds += wall_seconds;
        self.gpu_seconds += gpu_seconds.unwrap_or(0.0);
        Ok(StepReport {
            samples,
            wall_seconds,
            gpu_seconds,
            pass_completed,
            scheduled_samples: band.scheduled,
        })
    }
}

/// What a submitted band covers, for folding it when its bytes are back.
pub(super) struct Band {
    started: Instant,
    row_offset: u32,
    rows: u32,
    spp: u32,
    /// The pass's first sample index (absolute: the sample offset included).
    sample_start: u32,
    /// Samples per chunk when it was recorded (a later `set_chunk_samples` must not change it).
    chunk: u32,
    chunks: u32,
    band_pixels: usize,
    /// Bytes of each of the two slot arrays (sums, sums of squares).
    bytes: u64,
    /// Paths the band traces: its pixels x spp, or with adaptive sampling what the blocks'
    /// counts leave in its sample range.
    scheduled: u64,
    /// Bytes of the staging copy (0 when mapped where the GPU wrote them).
    staging_size: u64,
    readback: Readback,
}

/// A band's read-back bytes: its sums, its sums of squares (slot by slot, as the shader wrote
/// them) and its timestamps (empty when the device has none).
pub(super) struct BandBytes<'a> {
    sums: &'a [u8],
    sums_sq: &'a [u8],
    timestamps: &'a [u8],
}

impl<'a> BandBytes<'a> {
    /// The staging copy's layout: `bytes` of sums, `bytes` of sums of squares, the timestamps.
    fn split(data: &'a [u8], bytes: usize) -> Self {
        let (sums, rest) = data.split_at(bytes);
        let (sums_sq, timestamps) = rest.split_at(bytes);
        BandBytes { sums, sums_sq, timestamps }
    }
}

/// Where a band's results are read.
#[derive(Clone)]
pub(super) enum Readback {
    /// A staging buffer they were copied into: the sums, then the sums of squares, then the
    /// timestamps.
    Staging(wgpu::Buffer),
    /// The batch buffers the shader wrote, and the band's timestamps (when timed). Read only by
    /// the blocking readback, which the web build has not.
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    Mapped { sum: wgpu::Buffer, sum_sq: wgpu::Buffer, timestamps: Option<wgpu::Buffer> },
}

/// A band submitted while the one before it is folded (blocking readback: native only).
#[cfg(not(target_arch = "wasm32"))]
pub(super) struct AheadBand {
    band: Band,
}

/// A band submitted with polled readback, whose staging buffer is being mapped.
pub(super) struct InFlightBand {
    band: Band,
    read: PendingRead,
}
