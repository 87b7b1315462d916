//! Checkpoints: EXR files that a render can be continued from, and partial renders that can be
//! merged.
//!
//! Every EXR the `render` example writes for the path tracer is a checkpoint: besides the mean
//! image (the first layer, what any EXR viewer shows) it has a layer named
//! [`STATISTICS_LAYER`] with, per pixel, the exact f64 sum and sum of squares of the finite
//! samples (each f64 stored as two 32-bit words, since EXR has no 64-bit samples) and the u64
//! count (two words as well). Its metadata ([`crate::metadata::exr_metadata`]) names the scene,
//! every setting that changes the image, a hash of the scene's content
//! ([`scene_content_hash`]), the first sample index (`sample_start`, for `--sample-range`), the
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
//! Over 450 lines with its tests: writing, reading, resuming and merging share one file layout.

use std::path::Path;

use illum_image::{ExrMetadata, U32Layer, load_u32_layers, save_exr_with_layers};
use illum_scene::Scene;

use crate::{Accumulator, PathTracer, TracerOptions};

/// Name of the EXR layer with the exact per-pixel statistics.
pub const STATISTICS_LAYER: &str = "illum.statistics";

/// Name of the layer with the statistics at the last chunk boundary, in files whose samples end
/// inside a chunk (its spp: metadata `aligned_spp`).
pub const ALIGNED_LAYER: &str = "illum.statistics.aligned";

const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// 64-bit FNV-1a of the scene's physical content: the camera's placement and field of view,
/// materials, objects and lights, as parsed (so a comment, a key's order or the `[raster]`
/// section do not change it; every number that changes the path-traced image does). The
/// resolution is compared on its own, like the other settings. Written as 16 hex digits in
/// `illum.scene_hash`.
pub fn scene_content_hash(scene: &Scene) -> String {
    let c = &scene.camera;
    let content = format!(
        "{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}",
        c.eye,
        c.target,
        c.up,
        c.vfov_deg,
        scene.materials,
        scene.objects,
        scene.directional_light,
        scene.environment
    );
    let hash = content
        .bytes()
        .fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3));
    format!("{hash:016x}")
}

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

fn split(bits: u64) -> (u32, u32) {
    ((bits >> 32) as u32, bits as u32)
}

fn join(hi: u32, lo: u32) -> u64 {
    (u64::from(hi) << 32) | u64::from(lo)
}

/// The statistics layer of `accumulator`.
pub fn statistics_layer(accumulator: &Accumulator) -> U32Layer {
    layer_named(STATISTICS_LAYER, accumulator)
}

fn layer_named(name: &str, accumulator: &Accumulator) -> U32Layer {
    let state = accumulator.state();
    let mut channels = Vec::new();
    for (prefix, data) in [("sum", state.sum), ("sum_sq", state.sum_sq)] {
        for (c, name) in CHANNELS.iter().enumerate() {
            let (hi, lo): (Vec<u32>, Vec<u32>) = data.iter().map(|v| split(v[c].to_bits())).unzip();
            channels.push((format!("{prefix}.{name}.hi"), hi));
            channels.push((format!("{prefix}.{name}.lo"), lo));
        }
    }
    let (hi, lo): (Vec<u32>, Vec<u32>) = state.count.iter().map(|&n| split(n)).unzip();
    channels.push(("count.hi".to_owned(), hi));
    channels.push(("count.lo".to_owned(), lo));
    U32Layer { name: name.to_owned(), channels }
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
pub fn save_checkpoint(path: &Path, tracer: &PathTracer, metadata: &ExrMetadata) -> Result<(), String> {
    let (metadata, layers) = checkpoint_layers(tracer.accumulator(), tracer.aligned_prefix(), metadata);
    save_exr_with_layers(path, &tracer.accumulator().mean_image(), &metadata, layers)
        .map_err(|e| with_causes(&e))
}

/// Writes a checkpoint read back or merged: its mean image, metadata and statistics layers, to
/// `path`, atomically.
pub fn save_loaded(path: &Path, checkpoint: &Checkpoint) -> Result<(), String> {
    let aligned = checkpoint.aligned_prefix.as_ref().map(|(a, spp)| (a, *spp));
    let (metadata, layers) = checkpoint_layers(&checkpoint.accumulator, aligned, &checkpoint.metadata);
    save_exr_with_layers(path, &checkpoint.accumulator.mean_image(), &metadata, layers)
        .map_err(|e| with_causes(&e))
}

/// [`save_checkpoint`] into memory: the EXR file's bytes (the web viewer's download). `name`
/// labels errors.
pub fn checkpoint_bytes(name: &str, tracer: &PathTracer, metadata: &ExrMetadata) -> Result<Vec<u8>, String> {
    let (metadata, layers) = checkpoint_layers(tracer.accumulator(), tracer.aligned_prefix(), metadata);
    illum_image::exr_bytes_with_layers(name, &tracer.accumulator().mean_image(), &metadata, layers)
        .map_err(|e| with_causes(&e))
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

    /// The value of a setting in the file; width and height come from the image itself.
    fn setting(&self, key: &str) -> Option<String> {
        match key {
            "width" => Some(self.width.to_string()),
            "height" => Some(self.height.to_string()),
            "scene" => Some(self.metadata.scene.clone()),
            // A file without the key was rendered without the caustic's light tracer.
            "caustics" => Some(self.metadata.get(key).unwrap_or("off").to_owned()),
            _ => self.metadata.get(key).map(str::to_owned),
        }
    }
}

/// The checkpoint fields of a file's illum metadata: a path-traced, non-adaptive render with
/// whole-number spp, start and partial pass. `at` prefixes the file's name to a reason.
fn header_fields(
    at: &dyn Fn(String) -> String,
    metadata: ExrMetadata,
    width: u32,
    height: u32,
) -> Result<CheckpointHeader, String> {
    if metadata.renderer != crate::metadata::RENDERER {
        return Err(at(format!(
            "illum.renderer = {}: only path-traced images can be continued",
            metadata.renderer
        )));
    }
    let number = |key: &str| -> Result<u32, String> {
        let text = metadata.get(key).ok_or_else(|| at(format!("illum.{key} is missing")))?;
        text.parse().map_err(|_| at(format!("illum.{key} = {text:?} is not a whole number")))
    };
    if let Some(adaptive) = metadata.get("adaptive").filter(|a| *a != "off") {
        return Err(at(format!(
            "illum.adaptive = {adaptive:?}: an adaptive render's pixels hold different numbers of samples, \
             chosen for its budget, so it cannot be continued or merged (render it again with a larger --spp)"
        )));
    }
    let spp_done = number("spp")?;
    let sample_start = number("sample_start")?;
    let partial = (number("partial_pass_spp")?, number("partial_pass_rows")?);
    let partial_pass = (partial.0 > 0 && partial.1 > 0).then_some(partial);
    Ok(CheckpointHeader { metadata, width, height, spp_done, sample_start, partial_pass })
}

/// Reads a checkpoint's headers only ([`CheckpointHeader`]): every failure of
/// [`load_checkpoint`] that the headers show (not an EXR, not illum's, not the path tracer's,
/// adaptive, a missing or unparsable key, no statistics layer), naming the file. The
/// statistics themselves are checked when the file is read whole.
pub fn load_checkpoint_header(path: &Path) -> Result<CheckpointHeader, String> {
    let at = |reason: String| format!("{}: {reason}", path.display());
    if !path.exists() {
        return Err(at("no such file".into()));
    }
    let header = illum_image::load_exr_header(path)
        .map_err(|e| at(format!("cannot be read as an EXR (truncated or corrupt?): {}", with_causes(&e))))?;
    let metadata = ExrMetadata::from_attributes(path, &header.attributes)
        .map_err(|e| e.to_string())?
        .ok_or_else(|| at("not written by illum (no illum.* metadata), so it cannot be continued".into()))?;
    let fields = header_fields(&at, metadata, header.width, header.height)?;
    if !header.layers.iter().any(|l| l == STATISTICS_LAYER) {
        return Err(at(format!(
            "has no {STATISTICS_LAYER} layer (written without the statistics a render continues from)"
        )));
    }
    Ok(fields)
}

/// Reads a checkpoint. Every failure names the file and what is wrong with it: not an EXR,
/// truncated or corrupt (with the decoder's error), not illum's, not the path tracer's, no
/// statistics layer, a missing or unparsable key, or statistics that do not add up to the spp
/// the metadata claims.
pub fn load_checkpoint(path: &Path) -> Result<Checkpoint, String> {
    let at = |reason: String| format!("{}: {reason}", path.display());
    let CheckpointHeader { metadata, width, height, spp_done, sample_start, partial_pass } =
        load_checkpoint_header(path)?;
    let dropped = match metadata.get("dropped_samples") {
        Some(text) => {
            text.parse().map_err(|_| at(format!("illum.dropped_samples = {text:?} is not a count")))?
        }
        None => 0,
    };
    // One read of the file for both layers (the mean image is recomputed from the statistics).
    let layers = load_u32_layers(path, &[STATISTICS_LAYER, ALIGNED_LAYER])
        .map_err(|e| at(format!("cannot be read as an EXR (truncated or corrupt?): {}", with_causes(&e))))?;
    let mut layers = layers.into_iter().map(|layer| {
        layer.map(|layer| statistics_from_layer(&layer, width, height, dropped).map_err(at)).transpose()
    });
    let accumulator = layers.next().transpose()?.flatten().ok_or_else(|| {
        at(format!(
            "has no {STATISTICS_LAYER} layer (written without the statistics a render continues from)"
        ))
    })?;
    check_counts(&accumulator, spp_done, partial_pass).map_err(at)?;
    let aligned_prefix = match layers.next().transpose()?.flatten() {
        Some(prefix) => {
            let text =
                metadata.get("aligned_spp").ok_or_else(|| at("illum.aligned_spp is missing".into()))?;
            let spp: u32 = text
                .parse()
                .map_err(|_| at(format!("illum.aligned_spp = {text:?} is not a whole number")))?;
            if spp > spp_done || !(sample_start + spp).is_multiple_of(crate::CHUNK_SAMPLES) {
                return Err(at(format!(
                    "illum.aligned_spp = {spp}: must be a chunk boundary (sample_start + it a multiple of {}) \
                     at most illum.spp = {spp_done}",
                    crate::CHUNK_SAMPLES
                )));
            }
            check_counts(&prefix, spp, None).map_err(|e| at(format!("layer {ALIGNED_LAYER}: {e}")))?;
            Some((prefix, spp))
        }
        None => None,
    };
    Ok(Checkpoint { metadata, accumulator, spp_done, sample_start, partial_pass, aligned_prefix })
}

/// Rebuilds an accumulator from a statistics layer of a `width x height` image.
fn statistics_from_layer(
    layer: &U32Layer,
    width: u32,
    height: u32,
    dropped: u64,
) -> Result<Accumulator, String> {
    let pixels = width as usize * height as usize;
    let channel = |name: String| -> Result<&Vec<u32>, String> {
        let values = layer
            .channels
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| v)
            .ok_or_else(|| format!("layer {} has no channel {name}", layer.name))?;
        if values.len() != pixels {
            return Err(format!("channel {name} has {} values for {pixels} pixels", values.len()));
        }
        Ok(values)
    };
    let pair = |prefix: &str| -> Result<Vec<[f64; 3]>, String> {
        let mut out = vec![[0.0; 3]; pixels];
        for (c, name) in CHANNELS.iter().enumerate() {
            let hi = channel(format!("{prefix}.{name}.hi"))?;
            let lo = channel(format!("{prefix}.{name}.lo"))?;
            for (p, v) in out.iter_mut().enumerate() {
                v[c] = f64::from_bits(join(hi[p], lo[p]));
            }
        }
        Ok(out)
    };
    let sum = pair("sum")?;
    let sum_sq = pair("sum_sq")?;
    let (hi, lo) = (channel("count.hi".into())?, channel("count.lo".into())?);
    let count: Vec<u64> = hi.iter().zip(lo).map(|(&h, &l)| join(h, l)).collect();
    if sum.iter().chain(&sum_sq).flatten().any(|v| !v.is_finite()) {
        return Err("the statistics hold a NaN or infinite sum: the file is corrupt".into());
    }
    Accumulator::from_state(width, height, sum, sum_sq, count, dropped)
}

/// Checks that the per-pixel sample counts are what `spp_done` complete passes and a pass
/// stopped inside (`partial`: its spp and the rows done from row 0) give: no pixel has more,
/// and the samples missing in all are at most the dropped (NaN or infinite) ones.
fn check_counts(accumulator: &Accumulator, spp_done: u32, partial: Option<(u32, u32)>) -> Result<(), String> {
    let width = accumulator.width as usize;
    let mut missing = 0u64;
    for p in 0..width * accumulator.height as usize {
        let row = (p / width) as u32;
        let expected = u64::from(spp_done)
            + partial.filter(|&(_, rows)| row < rows).map_or(0, |(spp, _)| u64::from(spp));
        let count = accumulator.pixel_count(p);
        if count > expected {
            return Err(format!(
                "pixel ({}, {row}) has {count} samples, more than the {expected} the metadata's spp gives: the file is \
                 corrupt or was edited",
                p % width
            ));
        }
        missing += expected - count;
    }
    if missing > accumulator.dropped_samples() {
        return Err(format!(
            "the statistics hold {missing} samples fewer than illum.spp = {spp_done} gives, and only {} were dropped: \
             the file is corrupt or was edited",
            accumulator.dropped_samples()
        ));
    }
    Ok(())
}

/// The settings that change the image, as stored in a checkpoint and as `scene` and `options`
/// would store them: (key, value). Compared one by one so that a refusal names what differs.
pub fn image_settings(scene: &Scene, options: TracerOptions) -> Vec<(&'static str, String)> {
    vec![
        ("scene_hash", scene_content_hash(scene)),
        ("width", scene.camera.width.to_string()),
        ("height", scene.camera.height.to_string()),
        ("bounces", scene.pathtrace.bounces.to_string()),
        ("seed", scene.pathtrace.seed.to_string()),
        ("sampling", scene.pathtrace.sampling.to_string()),
        ("sequence", options.sequence.to_string()),
        ("caustics", crate::gpu_scene::caustics_label(scene).to_owned()),
    ]
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

    /// Checks that this checkpoint was rendered from `scene` with `options`: an error naming
    /// every difference (scene name, content hash, resolution, bounces, seed, sampling,
    /// sequence, caustics), with both values.
    pub fn check_matches(&self, path: &Path, scene: &Scene, options: TracerOptions) -> Result<(), String> {
        let header = self.header();
        let mut differences = Vec::new();
        if self.metadata.scene != scene.name {
            differences.push(format!("scene: {:?} in the file, {:?} now", self.metadata.scene, scene.name));
        }
        for (key, now) in image_settings(scene, options) {
            let then = header.setting(key).unwrap_or_else(|| "(missing)".to_owned());
            if then != now {
                let what = if key == "scene_hash" {
                    "scene content (camera, materials, objects: the file was edited)".to_owned()
                } else {
                    key.to_owned()
                };
                differences.push(format!("{what}: {then} in the file, {now} now"));
            }
        }
        if differences.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "{}: rendered with other settings, so its samples cannot be combined with these: {}",
                path.display(),
                differences.join("; ")
            ))
        }
    }

    /// The sample indices this file holds: `sample_start .. sample_start + spp_done`.
    pub fn sample_range(&self) -> std::ops::Range<u64> {
        let start = u64::from(self.sample_start);
        start..start + u64::from(self.spp_done)
    }
}

/// The keys two partial renders must agree on to be merged.
const MERGE_KEYS: [&str; 9] =
    ["scene", "scene_hash", "width", "height", "bounces", "seed", "sampling", "sequence", "caustics"];

/// Checks that partial renders can be merged, from their headers alone, and sorts them into
/// sample order (the order the merge adds them in). Refused, with the files named: a file
/// stopped inside a pass or stopped early (resume it first: the message gives the command), a
/// range not starting on a chunk, a setting that differs, overlapping ranges (the same samples
/// twice would count double) and gaps (the result would not be one range that can be
/// continued). Returns the merged spp.
fn check_mergeable<T>(parts: &mut [(std::path::PathBuf, CheckpointHeader, T)]) -> Result<u32, String> {
    if parts.is_empty() {
        return Err("nothing to merge: give at least one EXR file".to_owned());
    }
    for (path, c, _) in parts.iter() {
        let range = c.sample_range();
        let resume = || match c.metadata.get(crate::metadata::SAMPLE_END) {
            Some(end) => format!(
                "finish it first with `render SCENE.toml --resume {} --sample-range {}..{end}`",
                path.display(),
                range.start
            ),
            None => format!(
                "finish it first with `render SCENE.toml --resume {} --sample-range {}..END` (END: the end of its range)",
                path.display(),
                range.start
            ),
        };
        if let Some((spp, rows)) = c.partial_pass {
            return Err(format!(
                "{}: stopped inside a pass ({rows} rows of {spp} spp done after {} complete spp); {}",
                path.display(),
                c.spp_done,
                resume()
            ));
        }
        if c.spp_done == 0 {
            return Err(format!("{}: holds no complete pass", path.display()));
        }
        if let Some(reason @ ("cancelled" | "time_budget")) = c.metadata.get("stopped_by") {
            return Err(format!(
                "{}: stopped early (illum.stopped_by = {reason}) at sample {} of its range, so it may not hold the \
                 whole range; {}",
                path.display(),
                range.end,
                resume()
            ));
        }
        if !range.start.is_multiple_of(u64::from(crate::CHUNK_SAMPLES)) {
            return Err(format!(
                "{}: its samples start at index {}, not a multiple of {} (the chunk the GPU sums in), so merged it \
                 would differ from one render by f32 rounding; render the ranges with starts on multiples of {}",
                path.display(),
                range.start,
                crate::CHUNK_SAMPLES,
                crate::CHUNK_SAMPLES
            ));
        }
    }
    let (first_path, first, _) = &parts[0];
    for (path, c, _) in &parts[1..] {
        let differences: Vec<String> = MERGE_KEYS
            .iter()
            .filter_map(|key| {
                let (a, b) = (first.setting(key), c.setting(key));
                (a != b).then(|| {
                    let show = |v: Option<String>| v.unwrap_or_else(|| "(missing)".to_owned());
                    format!(
                        "{key}: {} in {}, {} in {}",
                        show(a),
                        first_path.display(),
                        show(b),
                        path.display()
                    )
                })
            })
            .collect();
        if !differences.is_empty() {
            return Err(format!("these files are renders of different images: {}", differences.join("; ")));
        }
    }
    parts.sort_by_key(|(_, c, _)| c.sample_start);
    for pair in parts.windows(2) {
        let ((pa, a, _), (pb, b, _)) = (&pair[0], &pair[1]);
        let (ra, rb) = (a.sample_range(), b.sample_range());
        if rb.start < ra.end {
            return Err(format!(
                "{} (samples {}..{}) and {} (samples {}..{}) overlap: each sample index may be merged once",
                pa.display(),
                ra.start,
                ra.end,
                pb.display(),
                rb.start,
                rb.end
            ));
        }
        if rb.start > ra.end {
            return Err(format!(
                "samples {}..{} are missing between {} (ending at {}) and {} (starting at {}): render that range too",
                ra.end,
                rb.start,
                pa.display(),
                ra.end,
                pb.display(),
                rb.start
            ));
        }
    }
    let total = parts.iter().map(|(_, c, _)| u64::from(c.spp_done)).sum::<u64>();
    u32::try_from(total).map_err(|_| format!("the merged render would have {total} spp, above {}", u32::MAX))
}

/// Adds checked parts (in sample order) one at a time: per pixel, the f64 sums and counts in
/// the order of their ranges, so that only the running total and the part being added are in
/// memory. The merged metadata is the first part's, with the union's spp, the summed times and
/// dropped samples, and the error of the merged statistics.
fn fold_parts(
    parts: impl ExactSizeIterator<Item = Result<Checkpoint, String>>,
    spp_done: u32,
) -> Result<Checkpoint, String> {
    let last = parts.len() - 1;
    let mut merged: Option<Checkpoint> = None;
    let mut aligned_prefix = None;
    for (i, part) in parts.enumerate() {
        let part = part?;
        if i == last {
            // Every range but the last ends where the next starts, on a chunk boundary; the last
            // may end inside a chunk, and then its statistics at its last boundary, added to the
            // others' (in the same order as the merge), are the merged render's (what
            // `render --resume` goes on from).
            aligned_prefix = part.aligned_prefix.as_ref().map(|(prefix, spp)| match &merged {
                Some(earlier) => {
                    let mut sum = earlier.accumulator.clone();
                    sum.merge(prefix);
                    (sum, earlier.spp_done + spp)
                }
                None => (prefix.clone(), *spp),
            });
        }
        match &mut merged {
            None => merged = Some(part),
            Some(merged) => {
                merged.accumulator.merge(&part.accumulator);
                merged.metadata.render_seconds += part.metadata.render_seconds;
                merged.spp_done += part.spp_done;
            }
        }
    }
    let mut merged = merged.expect("at least one part (checked)");
    merged.spp_done = spp_done;
    merged.aligned_prefix = aligned_prefix;
    let accumulator = &merged.accumulator;
    let union_end = u64::from(merged.sample_start) + u64::from(spp_done);
    for (key, value) in [
        (crate::metadata::SAMPLE_END, union_end.to_string()),
        ("spp", spp_done.to_string()),
        ("estimated_relative_error", accumulator.estimated_relative_error().to_string()),
        ("dropped_samples", accumulator.dropped_samples().to_string()),
        ("stopped_by", "spp".to_owned()),
        ("source", "merge example".to_owned()),
    ] {
        match merged.metadata.fields.iter_mut().find(|(k, _)| k == key) {
            Some(field) => field.1 = value,
            None => merged.metadata.fields.push((key.to_owned(), value)),
        }
    }
    Ok(merged)
}

/// Combines partial renders of the same scene and settings (files from `render --sample-range`)
/// into one, all already in memory: see [`merge_checkpoint_files`], which reads them one at a
/// time, for what is refused and how they are added.
pub fn merge_checkpoints(inputs: Vec<(std::path::PathBuf, Checkpoint)>) -> Result<Checkpoint, String> {
    let mut parts: Vec<_> = inputs.into_iter().map(|(path, c)| (path, c.header(), c)).collect();
    let spp_done = check_mergeable(&mut parts)?;
    fold_parts(parts.into_iter().map(|(_, _, c)| Ok(c)), spp_done)
}

/// Merges the partial renders in `paths` into one, holding one part and the running total in
/// memory, never all parts (256 parts of a 1024 x 1024 render are 14 GB of statistics). First
/// every file's headers are read and checked together ([`check_mergeable`]: nothing is read in
/// full if, say, the last file is of another scene); then the files are read and added in
/// sample order, each checked whole ([`load_checkpoint`]) and against what its header said.
/// `on_part` is called with each file as it is added (progress for a long merge).
pub fn merge_checkpoint_files(
    paths: &[std::path::PathBuf],
    mut on_part: impl FnMut(&Path, &CheckpointHeader),
) -> Result<Checkpoint, String> {
    let mut parts = Vec::with_capacity(paths.len());
    for path in paths {
        parts.push((path.clone(), load_checkpoint_header(path)?, ()));
    }
    let spp_done = check_mergeable(&mut parts)?;
    let loaded = parts.into_iter().map(|(path, header, ())| {
        let part = load_checkpoint(&path)?;
        if part.header() != header {
            return Err(format!(
                "{}: changed while being merged (its samples or settings differ from when it was first read); \
                 merge again once nothing writes to it",
                path.display()
            ));
        }
        on_part(&path, &header);
        Ok(part)
    });
    fold_parts(loaded, spp_done)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f64_and_u64_survive_the_two_word_split() {
        for v in [0.0f64, -0.0, 1.0 / 3.0, f64::MAX, f64::MIN_POSITIVE, 5e-324] {
            let (hi, lo) = split(v.to_bits());
            assert_eq!(f64::from_bits(join(hi, lo)).to_bits(), v.to_bits());
        }
        let (hi, lo) = split(u64::MAX - 7);
        assert_eq!(join(hi, lo), u64::MAX - 7);
    }

    #[test]
    fn the_hash_follows_content_not_settings() {
        let scene = Scene::load(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell.toml")))
            .unwrap();
        let mut other = scene.clone();
        other.pathtrace.spp = 4096;
        other.raster.pcf_radius = 1.0;
        assert_eq!(scene_content_hash(&scene), scene_content_hash(&other));
        other.camera.vfov_deg += 1.0;
        assert_ne!(scene_content_hash(&scene), scene_content_hash(&other));
    }
}
