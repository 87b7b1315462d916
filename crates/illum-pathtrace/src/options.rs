//! The tracer's pipeline choices: how rays find what they hit, and which sample sequence.

use illum_scene::Sequence;

/// How rays find what they hit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Traversal {
    /// Traversal code generated from the scene: every object's test unrolled with its numbers as
    /// constants (see `specialise.rs`). The default.
    #[default]
    Specialised,
    /// One loop over the object buffer, the same pipeline for every scene.
    Generic,
}

/// Pipeline choices that do not change the expected image, only speed or noise.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TracerOptions {
    pub traversal: Traversal,
    pub sequence: Sequence,
    /// Trace a pixel's samples two at a time, in lockstep (shader def PAIRED_PATHS,
    /// pathtrace.wgsl's `main`), with the specialised traversal (the generic one always traces
    /// one path at a time, see `Specialisation::shader_defs`): the same image bit for bit, and a second,
    /// independent path gives the CPU core of a software driver work to overlap with the first
    /// one's chains of dependent square roots and divisions (docs/performance-levers.md).
    /// The default natively; off in the browser, where Chrome's SwiftShader loses the device
    /// on the paired shader, so the page runs the one-path loop of the same shader.
    pub paired_paths: bool,
    /// With the low-discrepancy sequence: deal each pixel's samples to 4 independently
    /// randomised replicates, whose spread is the render's error estimate (`replicates.rs`;
    /// the default). Off: one randomisation of the sequence, with less error and less work per
    /// sample and no estimate of its error, for renders of a fixed spp that read none (the
    /// trade is measured in docs/performance.md). Independent numbers ignore it.
    pub replicates: bool,
}

impl TracerOptions {
    /// Whether the render keeps replicates: the low-discrepancy sequence with `replicates` on.
    /// Its slots, shader and accumulator follow this one rule.
    pub fn replicated(&self) -> bool {
        self.sequence == Sequence::LowDiscrepancy && self.replicates
    }

    /// Whether the render has an estimate of its error: every one but the low-discrepancy
    /// sequence without replicates (whose per-sample spread overstates its error).
    pub fn estimates_error(&self) -> bool {
        self.sequence != Sequence::LowDiscrepancy || self.replicates
    }

    /// The sample sequence as files and summaries name it: the sequence, and for the
    /// low-discrepancy one without replicates `low-discrepancy (one randomisation)`. Checkpoints
    /// compare it (`illum.sequence`): the two sample the sequence differently.
    pub fn sequence_label(&self) -> String {
        if self.estimates_error() {
            self.sequence.to_string()
        } else {
            format!("{}{UNREPLICATED_SUFFIX}", self.sequence)
        }
    }

    /// Reads [`Self::sequence_label`] back: (sequence, replicates), or `None` for a label that is
    /// neither form.
    pub fn parse_sequence_label(label: &str) -> Option<(Sequence, bool)> {
        match label.strip_suffix(UNREPLICATED_SUFFIX) {
            Some(sequence) => Some((sequence.parse().ok()?, false)),
            None => Some((label.parse().ok()?, true)),
        }
    }
}

/// What [`TracerOptions::sequence_label`] adds for one randomisation.
const UNREPLICATED_SUFFIX: &str = " (one randomisation)";

impl Default for TracerOptions {
    fn default() -> Self {
        TracerOptions {
            traversal: Traversal::default(),
            sequence: Sequence::default(),
            paired_paths: !cfg!(target_arch = "wasm32"),
            replicates: true,
        }
    }
}
