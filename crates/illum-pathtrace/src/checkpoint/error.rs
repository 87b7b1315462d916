//! What can go wrong with a checkpoint: writing it, reading it, continuing it or merging it.

use std::ops::Range;
use std::path::PathBuf;

/// Why a checkpoint could not be written, read, continued or merged. Every variant names the
/// file (a refused merge, each file involved); a bad metadata value also names the field, the
/// value and what is allowed, as `FILE: illum.FIELD = VALUE: ALLOWED`.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// Writing the file (or its bytes, for a download) failed: the image writer's error with its
    /// causes, which names the file.
    #[error("{reason}")]
    Write { path: PathBuf, reason: String },
    #[error("{}: no such file", path.display())]
    NoSuchFile { path: PathBuf },
    /// Not an EXR, or a truncated or corrupt one: the decoder's error with its causes.
    #[error("{}: cannot be read as an EXR (truncated or corrupt?): {reason}", path.display())]
    Unreadable { path: PathBuf, reason: String },
    /// Read, but not an image a checkpoint can be (a PNG, an EXR without R, G and B):
    /// the reader's reason.
    #[error("{}: {reason}; a checkpoint is an EXR the path tracer wrote", path.display())]
    NotAnExr { path: PathBuf, reason: String },
    #[error("{}: not written by illum (no illum.* metadata), so it cannot be continued", path.display())]
    NotIllum { path: PathBuf },
    /// illum's metadata is there but an attribute does not parse (the error names the file and
    /// the attribute).
    #[error("{0}")]
    Metadata(illum_image::ImageError),
    #[error("{}: illum.{field} is missing", path.display())]
    MissingField { path: PathBuf, field: &'static str },
    #[error("{}: illum.{field} = {value}: {allowed}", path.display())]
    InvalidField { path: PathBuf, field: &'static str, value: String, allowed: String },
    #[error("{}: has no {layer} layer (written without the statistics a render continues from)", path.display())]
    NoStatistics { path: PathBuf, layer: &'static str },
    /// The statistics contradict themselves or the metadata (a corrupt or edited file);
    /// `reason` says which numbers disagree.
    #[error("{}: {reason}", path.display())]
    Corrupt { path: PathBuf, reason: String },
    /// The file names its estimators in an older form than this build's token list
    /// (`estimators.rs`): it cannot be resumed or merged, whatever its settings.
    #[error("{}: illum.estimators: {reason}", path.display())]
    OlderEstimators { path: PathBuf, reason: String },
    /// A file that keeps the sun's glint as text in its metadata (`illum.glint`), written before
    /// the glint had a layer of its own ([`super::GLINT_LAYER`]).
    #[error(
        "{}: illum.glint: the sun's glint is stored as metadata text, the form before it moved to its own layer \
         ({}); this build reads only the layer, so the file cannot be resumed or merged: render it again",
        path.display(),
        super::GLINT_LAYER
    )]
    OlderGlint { path: PathBuf },
    /// Resuming with settings other than the file's: each difference, with both values.
    #[error(
        "{}: rendered with other settings, so its samples cannot be combined with these: {}",
        path.display(),
        differences.join("; ")
    )]
    OtherSettings { path: PathBuf, differences: Vec<String> },
    #[error("nothing to merge: give at least one EXR file")]
    NothingToMerge,
    /// A part that may not hold its whole range yet (stopped inside a pass, or stopped early by
    /// a signal or a time budget); `finish` is the command that completes it.
    #[error("{}: {reason}; {finish}", path.display())]
    Unfinished { path: PathBuf, reason: String, finish: String },
    #[error("{}: holds no complete pass", path.display())]
    NoCompletePass { path: PathBuf },
    /// A part whose samples start inside a chunk: merged, it would differ from one render by f32
    /// rounding.
    #[error(
        "{}: its samples start at index {start}, not a multiple of {chunk} (the chunk the GPU sums in), so merged \
         it would differ from one render by f32 rounding; render the ranges with starts on multiples of {chunk}",
        path.display()
    )]
    OffChunk { path: PathBuf, start: u64, chunk: u32 },
    /// Parts rendered with different settings: each difference, naming both files.
    #[error("these files are renders of different images: {}", differences.join("; "))]
    DifferentImages { differences: Vec<String> },
    #[error(
        "{} (samples {}..{}) and {} (samples {}..{}) overlap: each sample index may be merged once",
        first.display(),
        first_range.start,
        first_range.end,
        second.display(),
        second_range.start,
        second_range.end
    )]
    Overlap { first: PathBuf, first_range: Range<u64>, second: PathBuf, second_range: Range<u64> },
    #[error(
        "samples {}..{} are missing between {} (ending at {}) and {} (starting at {}): render that range too",
        missing.start,
        missing.end,
        before.display(),
        missing.start,
        after.display(),
        missing.end
    )]
    Gap { before: PathBuf, after: PathBuf, missing: Range<u64> },
    #[error("the merged render would have {total} spp, above {}", u32::MAX)]
    TooManySamples { total: u64 },
    #[error(
        "{}: changed while being merged (its samples or settings differ from when it was first read); merge again \
         once nothing writes to it",
        path.display()
    )]
    Changed { path: PathBuf },
}

/// For callers whose errors are text (the viewer's status line).
impl From<CheckpointError> for String {
    fn from(error: CheckpointError) -> String {
        error.to_string()
    }
}

/// An error and its causes on one line ("reading x.exr as EXR failed: unexpected end of file").
pub(super) fn with_causes(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        text += &format!(": {cause}");
        source = cause.source();
    }
    text
}
