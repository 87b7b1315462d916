//! Writing checkpoints: the mean image, the statistics layers (with, where the samples end
//! inside a chunk, those at the last chunk boundary), the glint's layer, the error layer and the
//! metadata, to a file atomically or to bytes.

use std::path::Path;

use illum_image::{ExrMetadata, F32Layer, U32Layer, save_exr_with_float_layers};

use super::error::with_causes;
use super::layers::{exact_layer, layer_named, statistics_layer};
use super::{ALIGNED_LAYER, Checkpoint, CheckpointError, ERROR_LAYER};
use crate::{Accumulator, PathTracer};

/// The [`ERROR_LAYER`] of `accumulator`.
pub fn error_layer(accumulator: &Accumulator) -> F32Layer {
    let map = crate::error_map::ErrorMap::of(accumulator);
    F32Layer { name: ERROR_LAYER.to_owned(), channels: vec![("Y".to_owned(), map.relative_error())] }
}

/// The layers and metadata of a checkpoint of `accumulator`: the statistics, and where the
/// samples end inside a chunk, the statistics at the last chunk boundary (`aligned`: them and
/// their spp) with `aligned_spp` added to the metadata.
fn checkpoint_layers(
    accumulator: &Accumulator,
    aligned: Option<(&Accumulator, u32)>,
    metadata: &ExrMetadata,
) -> (ExrMetadata, Vec<U32Layer>) {
    let mut metadata = metadata.clone();
    metadata.fields.retain(|(k, _)| k != "aligned_spp");
    let mut layers = vec![statistics_layer(accumulator)];
    if let Some((prefix, spp)) = aligned {
        metadata.fields.push(("aligned_spp".to_owned(), spp.to_string()));
        layers.push(layer_named(ALIGNED_LAYER, prefix));
    }
    // The prefix holds the same glint: the image's, stored once.
    layers.extend(exact_layer(accumulator));
    (metadata, layers)
}

/// Writes the tracer's mean image, `metadata` and the statistics layer to `path`, atomically.
pub fn save_checkpoint(
    path: &Path,
    tracer: &PathTracer,
    metadata: &ExrMetadata,
) -> Result<(), CheckpointError> {
    let (metadata, layers) = checkpoint_layers(tracer.accumulator(), tracer.aligned_prefix(), metadata);
    let errors = vec![error_layer(tracer.accumulator())];
    save_exr_with_float_layers(path, &tracer.accumulator().mean_image(), &metadata, layers, errors)
        .map_err(|e| write_error(path, &e))
}

fn write_error(path: &Path, error: &illum_image::ImageError) -> CheckpointError {
    CheckpointError::Write { path: path.to_path_buf(), reason: with_causes(error) }
}

/// Writes a checkpoint read back or merged: its mean image, metadata and statistics layers, to
/// `path`, atomically.
pub fn save_loaded(path: &Path, checkpoint: &Checkpoint) -> Result<(), CheckpointError> {
    let aligned = checkpoint.aligned_prefix.as_ref().map(|(a, spp)| (a, *spp));
    let (metadata, layers) = checkpoint_layers(&checkpoint.accumulator, aligned, &checkpoint.metadata);
    let errors = vec![error_layer(&checkpoint.accumulator)];
    save_exr_with_float_layers(path, &checkpoint.accumulator.mean_image(), &metadata, layers, errors)
        .map_err(|e| write_error(path, &e))
}

/// [`save_checkpoint`] into memory: the EXR file's bytes (the web viewer's download). `name`
/// labels errors.
pub fn checkpoint_bytes(
    name: &str,
    tracer: &PathTracer,
    metadata: &ExrMetadata,
) -> Result<Vec<u8>, CheckpointError> {
    let (metadata, layers) = checkpoint_layers(tracer.accumulator(), tracer.aligned_prefix(), metadata);
    let errors = vec![error_layer(tracer.accumulator())];
    illum_image::exr_bytes_with_layers(name, &tracer.accumulator().mean_image(), &metadata, layers, errors)
        .map_err(|e| write_error(Path::new(name), &e))
}
