//! The tracer's pipeline choices: how rays find what they hit, and which sample sequence.

use illum_gpu::shader::Def;
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
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct TracerOptions {
    pub traversal: Traversal,
    pub sequence: Sequence,
}

impl TracerOptions {
    /// naga_oil shader defs for these options.
    pub fn shader_defs(&self) -> Vec<(&'static str, Def)> {
        match self.sequence {
            Sequence::Independent => Vec::new(),
            Sequence::LowDiscrepancy => vec![("LOW_DISCREPANCY", Def::Bool(true))],
        }
    }
}
