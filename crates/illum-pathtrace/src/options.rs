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
    /// one path at a time, see `shader_defs`): the same image bit for bit; on lavapipe 14%
    /// faster at bounces 2 with 16 samples per invocation (docs/performance.md, "Levers of
    /// 2026-12-02, midday"). The default natively; off in the browser, where Chrome's
    /// SwiftShader lost the device on the paired shader (a blank page and failed readbacks in
    /// the web test, 2026-12-02) and runs the one-path loop.
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
    /// geometric term (`BILINEAR_LIGHT`, sampling.wgsl's `sample_light_bilinear`). Measured on
    /// the Cornell box (256 x 256, 1024 spp, bounces 2, docs/performance.md): with it, 22% less
    /// error for 11 to 15% more time; with independent numbers, whose error is mostly in the
    /// bounce directions, 11% less error for 15 to 20% more time, a loss, so they keep uniform
    /// points.
    pub fn shader_defs(&self) -> Vec<(&'static str, Def)> {
        let mut defs = match self.sequence {
            Sequence::Independent => Vec::new(),
            Sequence::LowDiscrepancy => {
                vec![("LOW_DISCREPANCY", Def::Bool(true)), ("BILINEAR_LIGHT", Def::Bool(true))]
            }
        };
        // Pairs pay with the specialised traversal only: with the generic one's loop over the
        // object buffer they were slower (bench, 256 x 256, bounces 2: 2.45 / 2.48 against
        // 2.83 / 2.62 Msamples/s one path at a time; bounces 8: 0.73 / 0.82 against 0.95 / 1.03).
        if self.paired_paths && self.traversal == Traversal::Specialised {
            defs.push(("PAIRED_PATHS", Def::Bool(true)));
        }
        defs
    }
}
