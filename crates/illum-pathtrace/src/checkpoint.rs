//! Checkpoints: EXR files that a render can be continued from, and partial renders that can be
//! merged.
//!
//! Every EXR the `render` example writes for the path tracer is a checkpoint: besides the mean
//! image (the first layer, what any EXR viewer shows) it has a layer named
//! [`STATISTICS_LAYER`] with, per pixel, the exact f64 sum and sum of squares of the finite
//! samples (each f64 stored as two 32-bit words, since EXR has no 64-bit samples) and the u64
//! count (two words as well). Its metadata ([`crate::metadata::exr_metadata`]) names the scene,
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
//! The statistics layers' encoding is `layers.rs`, merging `merge.rs`; every failure is a
//! [`CheckpointError`] naming the file and, for a bad metadata value, the field, the value and
//! what is allowed.

mod error;
mod layers;
mod merge;

use std::path::Path;

use illum_image::{ExrMetadata, F32Layer, U32Layer, load_u32_layers, save_exr_with_float_layers};
use illum_scene::Scene;

use crate::estimators::{Estimators, KeyMismatch, compare_key};
use crate::{Accumulator, PathTracer, TracerOptions};
pub use error::CheckpointError;
pub use layers::statistics_layer;
use layers::{check_counts, layer_named, statistics_from_layer};
pub use merge::{merge_checkpoint_files, merge_checkpoints};

/// Name of the EXR layer with the exact per-pixel statistics.
pub const STATISTICS_LAYER: &str = "illum.statistics";

/// Name of the f32 layer with each pixel's estimated relative standard error (channel `Y`; see
/// [`crate::error_map`]), written into every checkpoint for people and viewers: a resume reads
/// the statistics, never it.
pub const ERROR_LAYER: &str = "illum.error";

/// The [`ERROR_LAYER`] of `accumulator`.
pub fn error_layer(accumulator: &Accumulator) -> F32Layer {
    let map = crate::error_map::ErrorMap::of(accumulator);
    F32Layer { name: ERROR_LAYER.to_owned(), channels: vec![("Y".to_owned(), map.relative_error())] }
}

/// Name of the layer with the statistics at the last chunk boundary, in files whose samples end
/// inside a chunk (its spp: metadata `aligned_spp`).
pub const ALIGNED_LAYER: &str = "illum.statistics.aligned";

/// An error and its causes on one line ("reading x.exr as EXR failed: unexpected end of file").
fn with_causes(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        text += &format!(": {cause}");
        source = cause.source();
    }
    text
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
        let start = u64::from(self.sample_start);
        start..start + u64::from(self.spp_done)
    }

    /// Checks that these samples were rendered from `scene` with `options`: an error naming
    /// every difference (content hash, resolution, bounces, seed, sampling, sequence, caustics
    /// and their estimators), with both values. The scene is known by its content
    /// (`illum.scene_hash`), not its name: a scene renamed, or a comment edited, goes on.
    pub fn check_matches(
        &self,
        path: &Path,
        scene: &Scene,
        options: TracerOptions,
    ) -> Result<(), CheckpointError> {
        let mut differences: Vec<String> =
            check_estimators(path, self, &Estimators::of(scene))?.into_iter().collect();
        for (key, now) in image_settings(scene, options) {
            let then = self.setting(key);
            if then.as_deref() != Some(now.as_str()) {
                differences.push(if key == "scene_hash" {
                    format!(
                        "scene content (camera, materials, objects, lights; illum.scene_hash): {} ({:?}) in the file, \
                         {now} ({:?}) now",
                        shown(then.as_deref()),
                        self.metadata.scene,
                        scene.name
                    )
                } else {
                    format!("{key}: {} in the file, {} now", shown(then.as_deref()), shown(Some(&now)))
                });
            }
        }
        if differences.is_empty() {
            Ok(())
        } else {
            Err(CheckpointError::OtherSettings { path: path.to_path_buf(), differences })
        }
    }

    /// The value of a setting in the file; width and height come from the image itself.
    fn setting(&self, key: &str) -> Option<String> {
        match key {
            "width" => Some(self.width.to_string()),
            "height" => Some(self.height.to_string()),
            "scene" => Some(self.metadata.scene.clone()),
            // A file without the key was rendered without the caustic's light tracer.
            "caustics" => Some(self.metadata.get(key).unwrap_or("off").to_owned()),
            // A file without the key has no glint in its means.
            "glint" => Some(self.metadata.get(key).unwrap_or("none").to_owned()),
            _ => self.metadata.get(key).map(str::to_owned),
        }
    }
}

/// Longest value a refusal shows whole: every setting's but a glint's (the caustic estimators'
/// description is about 160 characters).
const SHOWN_CHARS: usize = 200;

/// A setting's value as a refusal shows it: whole when short, else its start and its length
/// (an `illum.glint` value holds thousands of characters, and only its difference matters).
fn shown(value: Option<&str>) -> String {
    match value {
        None => "(missing)".to_owned(),
        Some(v) if v.chars().count() <= SHOWN_CHARS => v.to_owned(),
        Some(v) => format!(
            "{}... ({} characters)",
            v.chars().take(SHOWN_CHARS).collect::<String>(),
            v.chars().count()
        ),
    }
}

/// A whole number in illum metadata field `field` of the file at `path`.
fn whole_number<T: std::str::FromStr>(
    path: &Path,
    metadata: &ExrMetadata,
    field: &'static str,
) -> Result<T, CheckpointError> {
    let text = metadata
        .get(field)
        .ok_or_else(|| CheckpointError::MissingField { path: path.to_path_buf(), field })?;
    text.parse().map_err(|_| CheckpointError::InvalidField {
        path: path.to_path_buf(),
        field,
        value: format!("{text:?}"),
        allowed: "must be a whole number".to_owned(),
    })
}

/// The checkpoint fields of the illum metadata of the file at `path`: a path-traced,
/// non-adaptive render with whole-number spp, start and partial pass.
fn header_fields(
    path: &Path,
    metadata: ExrMetadata,
    width: u32,
    height: u32,
) -> Result<CheckpointHeader, CheckpointError> {
    let invalid = |field: &'static str, value: String, allowed: &str| CheckpointError::InvalidField {
        path: path.to_path_buf(),
        field,
        value,
        allowed: allowed.to_owned(),
    };
    if metadata.renderer != crate::metadata::RENDERER {
        return Err(invalid(
            "renderer",
            metadata.renderer.clone(),
            "only path-traced images can be continued",
        ));
    }
    if let Some(denoiser) = metadata.get("denoiser") {
        return Err(invalid(
            "denoiser",
            denoiser.to_owned(),
            "a denoised image is not a checkpoint: it holds the denoised pixels, not the sums of the samples a \
             render goes on from, so it cannot be continued or merged (render again with a larger --spp)",
        ));
    }
    if let Some(adaptive) = metadata.get("adaptive").filter(|a| *a != "off") {
        return Err(invalid(
            "adaptive",
            format!("{adaptive:?}"),
            "must be \"off\": an adaptive render's pixels hold different numbers of samples, chosen for its \
             budget, so it cannot be continued or merged (render it again with a larger --spp)",
        ));
    }
    let spp_done = whole_number(path, &metadata, "spp")?;
    let sample_start = whole_number(path, &metadata, "sample_start")?;
    let partial: (u32, u32) = (
        whole_number(path, &metadata, "partial_pass_spp")?,
        whole_number(path, &metadata, "partial_pass_rows")?,
    );
    let partial_pass = (partial.0 > 0 && partial.1 > 0).then_some(partial);
    Ok(CheckpointHeader { metadata, width, height, spp_done, sample_start, partial_pass })
}

fn unreadable(path: &Path, error: &illum_image::ImageError) -> CheckpointError {
    match error {
        illum_image::ImageError::BadContent { reason, .. } => {
            CheckpointError::NotAnExr { path: path.to_path_buf(), reason: reason.clone() }
        }
        _ => CheckpointError::Unreadable { path: path.to_path_buf(), reason: with_causes(error) },
    }
}

fn no_statistics(path: &Path) -> CheckpointError {
    CheckpointError::NoStatistics { path: path.to_path_buf(), layer: STATISTICS_LAYER }
}

/// Reads a checkpoint's headers only ([`CheckpointHeader`]): every failure of
/// [`load_checkpoint`] that the headers show (not an EXR, not illum's, not the path tracer's,
/// adaptive, a missing or unparsable key, no statistics layer), naming the file. The
/// statistics themselves are checked when the file is read whole.
pub fn load_checkpoint_header(path: &Path) -> Result<CheckpointHeader, CheckpointError> {
    if !path.exists() {
        return Err(CheckpointError::NoSuchFile { path: path.to_path_buf() });
    }
    let header = illum_image::load_exr_header(path).map_err(|e| unreadable(path, &e))?;
    let metadata = ExrMetadata::from_attributes(path, &header.attributes)
        .map_err(CheckpointError::Metadata)?
        .ok_or_else(|| CheckpointError::NotIllum { path: path.to_path_buf() })?;
    let fields = header_fields(path, metadata, header.width, header.height)?;
    if !header.layers.iter().any(|l| l == STATISTICS_LAYER) {
        return Err(no_statistics(path));
    }
    Ok(fields)
}

/// Reads a checkpoint. Every failure names the file and what is wrong with it: not an EXR,
/// truncated or corrupt (with the decoder's error), not illum's, not the path tracer's, no
/// statistics layer, a missing or unparsable key, or statistics that do not add up to the spp
/// the metadata claims.
pub fn load_checkpoint(path: &Path) -> Result<Checkpoint, CheckpointError> {
    let corrupt = |reason: String| CheckpointError::Corrupt { path: path.to_path_buf(), reason };
    let CheckpointHeader { metadata, width, height, spp_done, sample_start, partial_pass } =
        load_checkpoint_header(path)?;
    let dropped = match metadata.get("dropped_samples") {
        Some(_) => whole_number(path, &metadata, "dropped_samples")?,
        None => 0,
    };
    // One read of the file for both layers (the mean image is recomputed from the statistics).
    let layers =
        load_u32_layers(path, &[STATISTICS_LAYER, ALIGNED_LAYER]).map_err(|e| unreadable(path, &e))?;
    let mut layers = layers.into_iter().map(|layer| {
        layer.map(|layer| statistics_from_layer(&layer, width, height, dropped).map_err(corrupt)).transpose()
    });
    let mut accumulator = layers.next().transpose()?.flatten().ok_or_else(|| no_statistics(path))?;
    let glint = crate::metadata::parse_glint_field(metadata.get("glint").unwrap_or("none"))
        .and_then(|glint| accumulator.set_glint(&glint).map(|()| glint))
        .map_err(|reason| CheckpointError::InvalidField {
            path: path.to_path_buf(),
            field: "glint",
            value: metadata.get("glint").unwrap_or_default().chars().take(80).collect(),
            allowed: format!("none, or pixel:r,g,b entries joined by ';' inside the image ({reason})"),
        })?;
    check_counts(&accumulator, spp_done, partial_pass).map_err(corrupt)?;
    let aligned_prefix = match layers.next().transpose()?.flatten() {
        Some(prefix) => {
            let spp: u32 = whole_number(path, &metadata, "aligned_spp")?;
            let chunk = crate::CHUNK_SAMPLES;
            if spp > spp_done || !(sample_start + spp).is_multiple_of(chunk) {
                return Err(CheckpointError::InvalidField {
                    path: path.to_path_buf(),
                    field: "aligned_spp",
                    value: spp.to_string(),
                    allowed: format!(
                        "must be a chunk boundary (sample_start + it a multiple of {chunk}) at most illum.spp = {spp_done}"
                    ),
                });
            }
            check_counts(&prefix, spp, None).map_err(|e| corrupt(format!("layer {ALIGNED_LAYER}: {e}")))?;
            let mut prefix = prefix;
            prefix.set_glint(&glint).map_err(corrupt)?;
            Some((prefix, spp))
        }
        None => None,
    };
    Ok(Checkpoint { metadata, accumulator, spp_done, sample_start, partial_pass, aligned_prefix })
}

/// The settings that change the image, as stored in a checkpoint and as `scene` and `options`
/// would store them: (key, value). Compared one by one so that a refusal names what differs.
pub fn image_settings(scene: &Scene, options: TracerOptions) -> Vec<(&'static str, String)> {
    vec![
        ("scene_hash", crate::metadata::scene_hash(scene)),
        ("width", scene.camera.width.to_string()),
        ("height", scene.camera.height.to_string()),
        ("bounces", scene.pathtrace.bounces.to_string()),
        ("seed", scene.pathtrace.seed.to_string()),
        ("sampling", scene.pathtrace.sampling.to_string()),
        ("sequence", options.sequence.to_string()),
        ("caustics", Estimators::of(scene).caustics_label().to_owned()),
    ]
}

/// Checks that the file at `path` (its `header`) was made by the estimators `now` names, by the
/// same rules (`estimators.rs`): samples of another set hold other light. A file that names its
/// estimators in an older form (the sentence of `illum.caustic_estimators`, or no key) is
/// refused with that reason; one whose tokens differ gives the difference to report beside the
/// other settings that differ.
pub(crate) fn check_estimators(
    path: &Path,
    header: &CheckpointHeader,
    now: &Estimators,
) -> Result<Option<String>, CheckpointError> {
    let stored = header.metadata.get(crate::metadata::ESTIMATORS);
    let legacy = header.metadata.get(crate::metadata::LEGACY_ESTIMATORS);
    match compare_key(stored, legacy, now) {
        Ok(()) => Ok(None),
        Err(mismatch @ KeyMismatch::OlderForm { .. }) => {
            Err(CheckpointError::OlderEstimators { path: path.to_path_buf(), reason: mismatch.to_string() })
        }
        Err(mismatch) => Ok(Some(format!("{}: {mismatch}", crate::metadata::ESTIMATORS))),
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
        let start = u64::from(self.sample_start);
        start..start + u64::from(self.spp_done)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn metadata(fields: &[(&str, &str)]) -> ExrMetadata {
        ExrMetadata {
            renderer: crate::metadata::RENDERER.to_owned(),
            scene: "cornell".to_owned(),
            render_seconds: 1.0,
            fields: fields.iter().map(|&(k, v)| (k.to_owned(), v.to_owned())).collect(),
        }
    }

    /// A checkpoint is of a scene by content: renamed, it goes on; of edited content, it is
    /// refused naming both hashes and both names.
    #[test]
    fn a_renamed_scene_resumes_and_other_content_is_refused_by_hash_and_name() {
        let mut scene = Scene::load(&illum_scene::resolve_scene_path(Path::new("scenes/cornell.toml")))
            .expect("the Cornell box");
        let options = TracerOptions::default();
        let header = |scene: &Scene| CheckpointHeader {
            metadata: ExrMetadata {
                scene: scene.name.clone(),
                ..metadata(
                    &image_settings(scene, options)
                        .iter()
                        .map(|(k, v)| (*k, v.as_str()))
                        .filter(|(k, _)| !matches!(*k, "width" | "height"))
                        .chain([(crate::metadata::ESTIMATORS, Estimators::of(scene).key().as_str())])
                        .collect::<Vec<_>>(),
                )
            },
            width: scene.camera.width,
            height: scene.camera.height,
            spp_done: 16,
            sample_start: 0,
            partial_pass: None,
        };
        let file = header(&scene);
        scene.name = "cornell-renamed".to_owned();
        assert!(file.check_matches(Path::new("long.exr"), &scene, options).is_ok());
        scene.camera.vfov_deg += 1.0;
        let error = file.check_matches(Path::new("long.exr"), &scene, options).unwrap_err().to_string();
        let (then, now) = (file.metadata.get("scene_hash").unwrap(), crate::metadata::scene_hash(&scene));
        for part in ["long.exr", "illum.scene_hash", then, &now, "\"cornell\"", "\"cornell-renamed\""] {
            assert!(error.contains(part), "the refusal lacks {part:?}: {error}");
        }
    }

    #[test]
    fn errors_name_the_file_the_field_the_value_and_what_is_allowed() {
        let path = Path::new("out/part.exr");
        let good =
            [("spp", "32"), ("sample_start", "0"), ("partial_pass_spp", "0"), ("partial_pass_rows", "0")];
        let header = header_fields(path, metadata(&good), 4, 4).expect("a good header");
        assert_eq!((header.spp_done, header.sample_start, header.partial_pass), (32, 0, None));

        let mut bad = good;
        bad[0].1 = "3.5";
        let error = header_fields(path, metadata(&bad), 4, 4).unwrap_err();
        assert!(
            matches!(&error, CheckpointError::InvalidField { field: "spp", value, .. } if value == "\"3.5\""),
            "{error:?}"
        );
        assert_eq!(error.to_string(), "out/part.exr: illum.spp = \"3.5\": must be a whole number");

        let error = header_fields(path, metadata(&good[1..]), 4, 4).unwrap_err();
        assert!(matches!(error, CheckpointError::MissingField { field: "spp", .. }), "{error:?}");
        assert_eq!(error.to_string(), "out/part.exr: illum.spp is missing");

        let mut raster = metadata(&good);
        raster.renderer = "raster".to_owned();
        let error = header_fields(path, raster, 4, 4).unwrap_err().to_string();
        assert_eq!(error, "out/part.exr: illum.renderer = raster: only path-traced images can be continued");

        let mut adaptive = good.to_vec();
        adaptive.push(("adaptive", "8x8 blocks"));
        let error = header_fields(path, metadata(&adaptive), 4, 4).unwrap_err().to_string();
        assert!(
            error.starts_with("out/part.exr: illum.adaptive = \"8x8 blocks\": must be \"off\""),
            "{error}"
        );

        let mut denoised = good.to_vec();
        denoised.push(("denoiser", "atrous"));
        denoised[1].1 = "0 and 2147483648 (two halves)";
        let error = header_fields(path, metadata(&denoised), 4, 4).unwrap_err().to_string();
        assert!(
            error.starts_with("out/part.exr: illum.denoiser = atrous: a denoised image is not a checkpoint"),
            "{error}"
        );

        let missing = Path::new("no/such/checkpoint.exr");
        let error = load_checkpoint(missing).unwrap_err();
        assert!(matches!(error, CheckpointError::NoSuchFile { .. }), "{error:?}");
        assert_eq!(error.to_string(), "no/such/checkpoint.exr: no such file");
        // The viewer shows errors as text.
        assert_eq!(String::from(error), "no/such/checkpoint.exr: no such file");
    }
}
