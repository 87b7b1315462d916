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
}

impl Default for TracerOptions {
    fn default() -> Self {
        TracerOptions {
            traversal: Traversal::default(),
            sequence: Sequence::default(),
            paired_paths: !cfg!(target_arch = "wasm32"),
        }
    }
}
