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
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TracerOptions {
    pub traversal: Traversal,
    pub sequence: Sequence,
    /// Trace a pixel's samples two at a time, in lockstep (shader def PAIRED_PATHS,
    /// pathtrace.wgsl's `main`), with the specialised traversal (the generic one always traces
    /// one path at a time, see `shader_defs`): the same image bit for bit, and a second,
    /// independent path gives the CPU core of a software driver work to overlap with the first
    /// one's chains of dependent square roots and divisions (docs/performance.md, "Levers").
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

impl TracerOptions {
    /// naga_oil shader defs for these options.
    ///
    /// The low-discrepancy sequence also draws light points from the bilinear fit of the
    /// geometric term (`BILINEAR_LIGHT`, sampling.wgsl's `sample_light_bilinear`): it lowers the
    /// error by more than it adds time there. Independent numbers keep uniform points: their
    /// error is mostly in the bounce directions, so the better light point buys less than it
    /// costs (docs/performance.md, "Levers").
    pub fn shader_defs(&self) -> Vec<(&'static str, Def)> {
        let mut defs = match self.sequence {
            Sequence::Independent => Vec::new(),
            Sequence::LowDiscrepancy => {
                vec![("LOW_DISCREPANCY", Def::Bool(true)), ("BILINEAR_LIGHT", Def::Bool(true))]
            }
        };
        // Pairs pay with the specialised traversal only: with the generic one's loop over the
        // object buffer they are slower than one path at a time (docs/performance.md, "Levers").
        if self.paired_paths && self.traversal == Traversal::Specialised {
            defs.push(("PAIRED_PATHS", Def::Bool(true)));
        }
        defs
    }
}
