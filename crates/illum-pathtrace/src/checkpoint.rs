//! Checkpoints: EXR files that a render can be continued from, and partial renders that can be
//! merged.
//!
//! Every EXR the `render` example writes for the path tracer is a checkpoint: besides the mean
//! image (the first layer, what any EXR viewer shows) it has a layer named
//! [`STATISTICS_LAYER`] with, per pixel, the exact f64 sum and sum of squares of the finite
//! samples (each f64 stored as two 32-bit words, since EXR has no 64-bit samples) and the u64
//! count (two words as well); where the image has an exact part (the sun's glint), a layer
//! [`GLINT_LAYER`] holds it the same way. Its metadata ([`crate::metadata::exr_metadata`]) names the scene,
//! every setting that changes the image, a hash of the scene's content
//! ([`crate::metadata::scene_hash`]), the first sample index (`sample_start`, for `--sample-range`), the
//! completed spp and a pass stopped inside (`partial_pass_spp`, `partial_pass_rows`).
//!
//! Why a resumed render equals a straight one: a sample's random numbers depend only on (seed,
//! pixel, sample index); with chunk-aligned passes
//! ([`crate::PathTracer::set_chunk_aligned_passes`]) every pixel's f32 chunk sums are the same
//! samples in every run, and the f64 fold adds them in sample order. Restoring the f64 sums
//! exactly and going on from the same sample index therefore repeats the straight render's
//! arithmetic: the result is bit-identical. A merge adds whole partial sums instead
//! ((a + b) + c against a + (b + c) per pixel), so it differs from one render only by f64
//! rounding: within 1e-12 relative for ranges on chunk boundaries (multiples of 16).
//!
//! A render whose spp is not a multiple of the chunk ends inside a chunk: its last f32 chunk sum
//! holds fewer samples than a longer render's would. Continuing from there would split that
//! chunk in two and differ by f32 rounding (about 1e-7 relative). So such a file also stores the
//! statistics at its last chunk boundary (layer [`ALIGNED_LAYER`], spp `aligned_spp`), and a
//! resumed render starts again from that boundary: the few samples after it are traced again,
//! with the same random numbers, and the result is bit-identical to a straight render. For the
//! same reason `--sample-range A..B` must start on a chunk boundary, so only the last of a set of
//! ranges can end inside a chunk.
//!
//! Writing is `checkpoint/save.rs`, reading `checkpoint/load.rs`, the settings a file must share
//! with a scene to be continued `checkpoint/settings.rs`, the statistics layers' encoding
//! `checkpoint/layers.rs`, merging `checkpoint/merge.rs`; every failure is a [`CheckpointError`]
//! naming the file and, for a bad metadata value, the field, the value and what is allowed.

mod error;
mod layers;
mod load;
mod merge;
mod save;
mod settings;

use illum_image::ExrMetadata;

use crate::Accumulator;
pub use error::CheckpointError;
pub use layers::statistics_layer;
pub use load::{load_checkpoint, load_checkpoint_header};
pub use merge::{merge_checkpoint_files, merge_checkpoints};
pub use save::{checkpoint_bytes, error_layer, save_checkpoint, save_loaded};
pub use settings::image_settings;

/// Name of the EXR layer with the exact per-pixel statistics.
pub const STATISTICS_LAYER: &str = "illum.statistics";

/// Name of the f32 layer with each pixel's estimated relative standard error (channel `Y`; see
/// [`crate::error_map`]), written into every checkpoint for people and viewers: a resume reads
/// the statistics, never it.
pub const ERROR_LAYER: &str = "illum.error";

/// Name of the layer with the statistics at the last chunk boundary, in files whose samples end
/// inside a chunk (its spp: metadata `aligned_spp`).
pub const ALIGNED_LAYER: &str = "illum.statistics.aligned";

/// Name of the layer with the exact part of the image, the sun's glint (`glint.rs`,
/// [`Accumulator::exact`]): per pixel its f64 radiance, each as two 32-bit words; written only
/// when the image has one. The mean image adds it to the samples' means.
pub const GLINT_LAYER: &str = "illum.exact";

/// A render read back from a checkpoint file.
#[derive(Clone, Debug)]
pub struct Checkpoint {
    pub metadata: ExrMetadata,
    pub accumulator: Accumulator,
    /// Samples per pixel of the completed passes.
    pub spp_done: u32,
    /// The first sample index (0 unless rendered with `--sample-range`).
    pub sample_start: u32,
    /// A pass stopped inside: (its spp, rows done from row 0).
    pub partial_pass: Option<(u32, u32)>,
    /// Where the samples end inside a chunk: the statistics at the last chunk boundary and their
    /// spp, from which a resumed render starts again (see the module's documentation).
    pub aligned_prefix: Option<(Accumulator, u32)>,
}

/// What a checkpoint's headers say about its samples, read without its pixels: enough to check
/// a merge of many files before reading any of their statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckpointHeader {
    pub metadata: ExrMetadata,
    pub width: u32,
    pub height: u32,
    /// Samples per pixel of the completed passes.
    pub spp_done: u32,
    /// The first sample index (0 unless rendered with `--sample-range`).
    pub sample_start: u32,
    /// A pass stopped inside: (its spp, rows done from row 0).
    pub partial_pass: Option<(u32, u32)>,
}

impl CheckpointHeader {
    /// The sample indices the file holds: `sample_start .. sample_start + spp_done`.
    pub fn sample_range(&self) -> std::ops::Range<u64> {
        sample_range(self.sample_start, self.spp_done)
    }
}

impl Checkpoint {
    /// What the file's headers say about these samples (the metadata is copied).
    pub fn header(&self) -> CheckpointHeader {
        CheckpointHeader {
            metadata: self.metadata.clone(),
            width: self.accumulator.width,
            height: self.accumulator.height,
            spp_done: self.spp_done,
            sample_start: self.sample_start,
            partial_pass: self.partial_pass,
        }
    }

    /// The sample indices this file holds: `sample_start .. sample_start + spp_done`.
    pub fn sample_range(&self) -> std::ops::Range<u64> {
        sample_range(self.sample_start, self.spp_done)
    }
}

/// The sample indices of `spp_done` samples per pixel from `sample_start`.
fn sample_range(sample_start: u32, spp_done: u32) -> std::ops::Range<u64> {
    let start = u64::from(sample_start);
    start..start + u64::from(spp_done)
}
