//! One submission of the path tracer: a band of rows of the current pass traced on the GPU,
//! read back, checked for lost samples and folded into the f64 accumulator.
//!
//! The readback (`runner.rs`, [`Readback`]) is either waited for ([`PathTracer::submit_band`],
//! native tools only) or polled ([`PathTracer::poll_band`], the web viewer, which cannot wait):
//! the band is submitted and its mapping started, and later calls fold it once the browser has
//! mapped it. With the caustic's light tracer, a pass's frames are traced and folded before its
//! first band, the same way: waited for, or polled dispatch by dispatch (`tracer/caustic.rs`).
//!
//! The waited form keeps the GPU busy while the CPU folds: once a band's results are mapped,
//! the next band of the same pass is submitted (into a second staging buffer, or the second set
//! of batch buffers) before the fold begins, since a large band's fold (a pass over its
//! statistics and results in host memory) would otherwise leave the GPU idle.
//!
//! Where the GPU computes in the host's memory (lavapipe, integrated GPUs) the results are not
//! copied at all: the CPU maps the batch buffers the shader wrote ([`Readback::Mapped`]).

#[cfg(not(target_arch = "wasm32"))]
use illum_gpu::readback;
use illum_gpu::readback::PendingRead;
use illum_gpu::wgpu;
use web_time::Instant;

use super::caustic::PassKey;
use super::runner::{ActivePass, Band, Submitted, TIMED_PASS, Written};
#[cfg(not(target_arch = "wasm32"))]
use super::runner::{Readback, Results};
use super::{PathTracer, StepReport};
use crate::PathTraceError;
use crate::batch::{self, Layers, SLOT_BYTES};
use crate::planner::PassPlan;

const WORKGROUP: u32 = 8;

const READING: &str = "reading back a path-tracing batch";

/// Pixels folded together across all of a band's slot layers: their statistics (56 bytes a
/// pixel) and replicates (128) fill about 370 KB, within a core's L2 cache.
const FOLD_TILE_PIXELS: usize = 2048;

impl PathTracer {
    /// The slot layout of the next pass: [`crate::batch::Layers`] of this tracer's chunk, one
    /// layer per replicate when the render keeps them ([`crate::TracerOptions::replicated`]).
    pub(super) fn layers(&self) -> Layers {
        Layers { chunk: self.bands.chunk_samples, replicated: self.pipeline.options.replicated() }
    }

    /// Shrinks a pass plan to what the device can take: at most `max_chunks` chunks per dispatch
    /// (the z dimension), and a band of at most `max_slots` slots (rows x width x slot layers)
    /// per batch buffer, so an image of any size is rendered band by band.
    pub(super) fn fit(&self, plan: PassPlan) -> PassPlan {
        let width = u64::from(self.pipeline.scene.camera.width);
        let layers = self.layers();
        let chunk = u64::from(layers.chunk);
        let row_slots = width * u64::from(layers.per_chunk());
        let max_slots = self.bands.max_slots;
        // check_row_fits guarantees max_slots >= one row's slots, so at least one chunk fits.
        let max_chunks = u64::from(self.bands.max_chunks).min(max_slots / row_slots).max(1);
        let spp = u64::from(plan.spp.max(1)).min(max_chunks * chunk);
        // The caustic's statistics of one pass must fit their host memory.
        let spp = match &self.pipeline.caustic {
            Some(caustic) => spp.min(u64::from(caustic.max_pass_spp(layers))),
            None => spp,
        };
        let chunks = spp.div_ceil(chunk);
        let max_rows = (max_slots / (row_slots * chunks)).max(1);
        let rows = u64::from(plan.rows).clamp(1, max_rows);
        PassPlan { spp: spp as u32, rows: rows as u32 }
    }

    /// The caustic's pass that `pass` pairs with (when the light tracer runs).
    pub(super) fn caustic_key(&self, pass: &ActivePass) -> PassKey {
        PassKey {
            first_sample: self.bands.sample_offset + pass.sample_base,
            spp: pass.plan.spp,
            layers: self.layers(),
            origin: self.bands.sample_offset,
        }
    }

    /// Traces one band of `pass` and folds it, waiting for the readback (of the band launched
    /// ahead by the previous call, if there is one), and launches the pass's next band before
    /// folding. `None`: the call made one submission of the pass's caustic frames instead, sized
    /// like a band to the step's time target (see `CausticTracer::prepare_pass`).
    #[cfg(not(target_arch = "wasm32"))]
    pub(super) fn submit_band(&mut self, pass: ActivePass) -> Result<Option<StepReport>, PathTraceError> {
        let readback = self.bands.readback().waited();
        let (band, results) = match self.bands.take_submitted() {
            Submitted::Ahead { band, results } => (band, results),
            // A polled band (left by a change of readback) is dropped: its rows are traced again.
            Submitted::Nothing | Submitted::Polled { .. } => {
                // The caustic's frames of this pass, traced once, before its first band.
                let key = self.caustic_key(&pass);
                let target = self.bands.planner.target_seconds();
                if let Some(caustic) = &mut self.pipeline.caustic
                    && !caustic.prepare_pass(&self.pipeline.gpu, key, target)?
                {
                    return Ok(None);
                }
                self.begin_band(&pass, pass.next_row, readback)?
            }
        };
        // Folded straight from the mapping: a large band is many megabytes, and copying it out
        // first (allocating and faulting in fresh pages) costs time for nothing.
        let gpu = self.pipeline.gpu.clone();
        let bytes = band.bytes;
        let folded = match &results {
            Results::Staging(staging) => {
                readback::with_mapped(&gpu, staging, band.staging_size, READING, |data| {
                    self.launch_ahead_and_finish(
                        &pass,
                        &band,
                        readback,
                        BandBytes::split(data, bytes as usize),
                    )
                })
            }
            Results::Mapped(Written { sum, sum_sq, timestamps }) => {
                readback::with_mapped(&gpu, sum, bytes, READING, |sums| {
                    readback::with_mapped(&gpu, sum_sq, bytes, READING, |sums_sq| match timestamps {
                        Some(t) => readback::with_mapped(&gpu, t, t.size(), READING, |timestamps| {
                            let bytes = BandBytes { sums, sums_sq, timestamps };
                            self.launch_ahead_and_finish(&pass, &band, readback, bytes)
                        }),
                        None => {
                            let bytes = BandBytes { sums, sums_sq, timestamps: &[] };
                            Ok(self.launch_ahead_and_finish(&pass, &band, readback, bytes))
                        }
                    })
                })
                .and_then(|mapped| mapped)
                .and_then(|mapped| mapped)
            }
        };
        // The staging buffer just read becomes the one the next band (launched later) copies into.
        if let Results::Staging(staging) = results {
            self.bands.buffers.put_staging(staging);
        }
        let folded = folded.map_err(PathTraceError::from).and_then(|r| r);
        if folded.is_err() {
            // This band's rows were not folded: the band ahead of it may not be either. Both are
            // traced again from the pass's `next_row`.
            self.bands.take_submitted();
        }
        folded.map(Some)
    }

    /// Launches the pass's next band, then folds `band` from its read-back bytes.
    #[cfg(not(target_arch = "wasm32"))]
    fn launch_ahead_and_finish(
        &mut self,
        pass: &ActivePass,
        band: &Band,
        readback: Readback,
        bytes: BandBytes,
    ) -> Result<StepReport, PathTraceError> {
        let launched = self.launch_ahead(pass, band, readback);
        // Folded even when the next band could not be launched: its error comes after.
        let folded = self.finish_band(band, bytes);
        folded.and_then(|report| launched.map(|()| report))
    }

    /// Submits the pass's next band, if `band` is not its last, into the spare staging buffer or,
    /// with mapped readback, the other set of batch buffers (the caustic's passes fold frames
    /// traced per pass and are left serial). Only for a caller that came straight back last
    /// time: a band launched ahead is timed from the last fold to its own (see
    /// `runner.rs`, [`super::runner::Pacing::may_launch_ahead`]).
    #[cfg(not(target_arch = "wasm32"))]
    fn launch_ahead(
        &mut self,
        pass: &ActivePass,
        band: &Band,
        readback: Readback,
    ) -> Result<(), PathTraceError> {
        if self.pipeline.caustic.is_some()
            || !self.bands.pacing.may_launch_ahead()
            || self.pipeline.active_rows(band.end(), band.sample_start).is_none()
        {
            return Ok(());
        }
        let (band, results) = self.begin_band(pass, band.end(), readback)?;
        self.bands.put_submitted(Submitted::Ahead { band, results });
        Ok(())
    }

    /// The polled form of [`Self::submit_band`]: submits a band of `pass` when none is in
    /// flight, and folds the one in flight once its mapping is done. `None` while it is not;
    /// never waits.
    pub(super) fn poll_band(&mut self, pass: ActivePass) -> Result<Option<StepReport>, PathTraceError> {
        let (band, read) = match self.bands.take_submitted() {
            Submitted::Polled { band, read } => (band, read),
            // Nothing in flight, or a band launched ahead for a waited readback (left by a
            // change of readback), which is dropped: its rows are traced again.
            _ => {
                // The caustic's frames of this pass come first, read back dispatch by dispatch
                // over as many calls as it takes.
                let key = self.caustic_key(&pass);
                let target = self.bands.planner.target_seconds();
                if let Some(caustic) = &mut self.pipeline.caustic
                    && !caustic.poll_pass(&self.pipeline.gpu, key, target)?
                {
                    return Ok(None);
                }
                self.begin_polled_band(&pass, pass.next_row)?
            }
        };
        let Some(result) = read.poll(&self.pipeline.gpu) else {
            self.bands.put_submitted(Submitted::Polled { band, read });
            return Ok(None);
        };
        let data = result?;
        self.bands.buffers.put_staging(read.into_buffer());
        let report = self.finish_band(&band, BandBytes::split(&data, band.bytes as usize))?;
        // The next band of this pass goes to the GPU now, so that it works while the page
        // draws its next frame (a new pass waits for the next call, which checks the target).
        if let Some(pass) = self.bands.pass().copied() {
            let (band, read) = self.begin_polled_band(&pass, pass.next_row)?;
            self.bands.put_submitted(Submitted::Polled { band, read });
        }
        Ok(Some(report))
    }

    /// Submits a band of `pass` from row `from` and starts its polled readback (of a staging
    /// copy: the polled read maps one buffer).
    fn begin_polled_band(
        &mut self,
        pass: &ActivePass,
        from: u32,
    ) -> Result<(Band, PendingRead), PathTraceError> {
        let band = self.band_of(pass, from, false);
        let staging = self.bands.buffers.take_staging(&self.pipeline.gpu, band.staging_size);
        self.record_band(&band, Some(&staging))?;
        Ok((band, PendingRead::start(staging, band.staging_size, READING)))
    }

    /// Submits a band of `pass` from row `from`, to be waited for: read where the GPU wrote it
    /// with [`Readback::Mapped`], else from a staging copy.
    #[cfg(not(target_arch = "wasm32"))]
    fn begin_band(
        &mut self,
        pass: &ActivePass,
        from: u32,
        readback: Readback,
    ) -> Result<(Band, Results), PathTraceError> {
        let mapped = readback == Readback::Mapped;
        let band = self.band_of(pass, from, mapped);
        if mapped {
            let written = self.record_band(&band, None)?;
            return Ok((band, Results::Mapped(written)));
        }
        let staging = self.bands.buffers.take_staging(&self.pipeline.gpu, band.staging_size);
        self.record_band(&band, Some(&staging))?;
        Ok((band, Results::Staging(staging)))
    }

    /// The next band of `pass` from row `from`: its rows (rows with nothing to trace, adaptive
    /// sampling's finished blocks, are skipped), samples and sizes; `mapped`: read where the GPU
    /// writes it, without a staging copy.
    fn band_of(&self, pass: &ActivePass, from: u32, mapped: bool) -> Band {
        let started = Instant::now();
        let camera = self.pipeline.scene.camera;
        let (width, height) = (camera.width, camera.height);
        let spp = pass.plan.spp;
        let sample_start = self.bands.sample_offset + pass.sample_base;
        let (row_offset, end) =
            self.pipeline.active_rows(from, sample_start).unwrap_or((from.min(height - 1), height));
        let rows = pass.plan.rows.min(end - row_offset);
        let layers = self.layers();
        let chunks = spp.div_ceil(layers.chunk);
        let slot_layers = layers.count(spp);
        let band_pixels = rows as usize * width as usize;
        let bytes = band_pixels as u64 * u64::from(slot_layers) * SLOT_BYTES;
        let scheduled = match &self.pipeline.allocation {
            None => band_pixels as u64 * u64::from(spp),
            Some((allocation, _)) => (row_offset..row_offset + rows)
                .flat_map(|y| (0..width).map(move |x| (x, y)))
                .map(|(x, y)| u64::from(allocation.at(x, y).saturating_sub(sample_start).min(spp)))
                .sum(),
        };
        Band {
            started,
            row_offset,
            rows,
            spp,
            sample_start,
            layers,
            chunks,
            slot_layers,
            band_pixels,
            bytes,
            scheduled,
            staging_size: if mapped { 0 } else { 2 * bytes + self.bands.timer.result_size() },
        }
    }

    /// Records and submits `band`: traced into the batch buffers (the set its predecessor did not
    /// use when it is read in place), added to the display sum, and copied into `staging` when
    /// given. Returns the batch buffers it was traced into.
    fn record_band(
        &mut self,
        band: &Band,
        staging: Option<&wgpu::Buffer>,
    ) -> Result<Written, PathTraceError> {
        let slots = band.band_pixels as u64 * u64::from(band.slot_layers);
        let bands = &mut self.bands;
        let batch = bands.buffers.batch_for(
            &self.pipeline,
            slots,
            staging.is_none(),
            bands.max_slots,
            &bands.timer,
        )?;
        let gpu = &self.pipeline.gpu;

        let mut params = self.pipeline.base_params;
        params.row_offset = band.row_offset;
        params.rows = band.rows;
        params.sample_base = band.sample_start;
        params.sample_count = band.spp;
        params.chunk_samples = band.layers.chunk;
        gpu.queue.write_buffer(&self.pipeline.params_buffer, 0, bytemuck::bytes_of(&params));
        // The caustic's frames of this pass were folded before its first band (`submit_band`,
        // `poll_band`): `finish_band` pairs them with the band's chunks.
        if let Some(caustic) = &self.pipeline.caustic {
            let key = PassKey {
                first_sample: band.sample_start,
                spp: band.spp,
                layers: band.layers,
                origin: bands.sample_offset,
            };
            debug_assert!(caustic.holds(key), "caustic pass {key:?} not ready");
        }

        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pathtrace band") });
        {
            let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("pathtrace"),
                timestamp_writes: bands.timer.compute_writes(TIMED_PASS),
            });
            compute.set_pipeline(&self.pipeline.compute);
            compute.set_bind_group(0, &batch.bind_group, &[]);
            if let Some(bvh) = &self.pipeline.bvh {
                bvh.set(&mut compute);
            }
            let width = self.pipeline.scene.camera.width;
            compute.dispatch_workgroups(
                width.div_ceil(WORKGROUP),
                band.rows.div_ceil(WORKGROUP),
                band.chunks,
            );
        }
        // The display sum reads the slots on the GPU in the same submission (wgpu orders the two
        // passes); the copies below for the f64 fold are unchanged.
        if let Some(display) = &mut self.accumulation.display_sum {
            display.record(gpu, &mut encoder, &batch.sum, band.rows, band.row_offset, band.slot_layers);
        }
        match staging {
            None => {
                if let Some(timestamps) = &batch.timestamps {
                    bands.timer.copy_results(&mut encoder, timestamps, 0);
                }
            }
            Some(staging) => {
                encoder.copy_buffer_to_buffer(&batch.sum, 0, staging, 0, band.bytes);
                encoder.copy_buffer_to_buffer(&batch.sum_sq, 0, staging, band.bytes, band.bytes);
                bands.timer.copy_results(&mut encoder, staging, 2 * band.bytes);
            }
        }
        gpu.queue.submit([encoder.finish()]);
        Ok(Written {
            sum: batch.sum.clone(),
            sum_sq: batch.sum_sq.clone(),
            timestamps: batch.timestamps.clone(),
        })
    }

    /// Checks and folds a band's read-back bytes (its sums, sums of squares and timestamps), and
    /// moves the pass on.
    fn finish_band(&mut self, band: &Band, bytes: BandBytes) -> Result<StepReport, PathTraceError> {
        let Band { row_offset, spp, sample_start, layers, slot_layers, band_pixels, .. } = *band;
        let width = self.pipeline.scene.camera.width;
        let (sums, sums_sq) = (batch::slots(bytes.sums), batch::slots(bytes.sums_sq));
        let (sums, sums_sq) = (&sums[..], &sums_sq[..]);
        let uniform = batch::uniform_chunk(layers, sample_start, spp);
        let checked = match &self.pipeline.allocation {
            None => batch::check_complete(sums, sums_sq, slot_layers, band_pixels, uniform),
            // A block takes the part of each chunk below its count (the shader's ADAPTIVE code).
            Some((allocation, _)) => {
                batch::check_complete(sums, sums_sq, slot_layers, band_pixels, |l, i| {
                    let (x, y) = (i as u32 % width, row_offset + i as u32 / width);
                    let start = sample_start + layers.chunk_of(l) * layers.chunk;
                    let taken =
                        allocation.at(x, y).saturating_sub(start).min(batch::chunk_taken(layers, spp, l));
                    layers.samples(sample_start, l, taken)
                })
            }
        };
        let radiance_exponent = self.pipeline.radiance_exponent;
        let gpu = &self.pipeline.gpu;
        let samples = match checked {
            Ok(samples) => samples,
            Err(error) => {
                // The accumulator drops this band, but the display pass already added it: set
                // the display sum back to the accumulator's samples.
                self.accumulation.show_accumulator(gpu, radiance_exponent);
                return Err(error);
            }
        };
        let accumulator = &mut self.accumulation.accumulator;
        let first_pixel = row_offset as usize * width as usize;
        // Tile by tile, every layer of a tile before the next tile: the tile's statistics (and
        // replicates) stay in the cache while its layers are added, where layer by layer over the
        // whole band they would be fetched from memory once per layer (a 256 x 256 band of 64
        // chunks x 4 replicate layers: 14 MB, 256 times). Each pixel still adds its layers in
        // order, so the sums are the same bit for bit.
        for tile in (0..band_pixels).step_by(FOLD_TILE_PIXELS) {
            let tile = tile..(tile + FOLD_TILE_PIXELS).min(band_pixels);
            for l in 0..slot_layers {
                let layer_start = l as usize * band_pixels;
                let range = layer_start + tile.start..layer_start + tile.end;
                accumulator.fold_slots(
                    first_pixel + tile.start,
                    layers.replicate(l),
                    &sums[range.clone()],
                    &sums_sq[range.clone()],
                );
                if let Some(caustic) = &self.pipeline.caustic {
                    caustic.fold(accumulator, l, first_pixel + tile.start, &sums[range]);
                }
            }
        }
        // The display pass added the camera's samples only: show the accumulator's image.
        if self.pipeline.caustic.is_some() {
            self.accumulation.show_accumulator(gpu, radiance_exponent);
        }
        let gpu_seconds = self.bands.timer.decode(bytes.timestamps).map(|timings| timings[0].1 * 1e-3);

        // Nothing left to trace below the band (every row, or every block still busy, is done):
        // the pass is complete.
        let end = band.end();
        let pass_completed = self.pipeline.active_rows(end, sample_start).is_none();
        self.bands.band_folded(end, pass_completed);
        if pass_completed {
            self.accumulation.spp_done += spp;
            if let Some(caustic) = &mut self.pipeline.caustic {
                caustic.finish_pass(&mut self.accumulation.accumulator);
            }
        }
        let wall_seconds = self.bands.pacing.band_folded(band.started);
        self.accumulation.wall_seconds += wall_seconds;
        self.accumulation.gpu_seconds += gpu_seconds.unwrap_or(0.0);
        Ok(StepReport {
            samples,
            wall_seconds,
            gpu_seconds,
            pass_completed,
            scheduled_samples: band.scheduled,
        })
    }
}

/// A band's read-back bytes: its sums, its sums of squares (slot by slot, as the shader wrote
/// them) and its timestamps (empty when the device has none).
struct BandBytes<'a> {
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
