//! One pass's caustic statistics, gathered frame by frame: per slot layer and pixel the f64 sum
//! and sum of squares of the frames' values (see the parent module for how they join the
//! camera's), and where the frame in progress stands.

use super::flight::InFlight;
use super::params::WORDS_PER_PIXEL;
use super::schedule::Cursor;
use crate::batch::Layers;

/// Which pass a caustic pass belongs to: its first absolute sample index, its spp, the slot
/// layers of the camera's sums that its statistics are grouped by, and the render's first
/// sample index (which the gather's radius counts from).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct PassKey {
    pub first_sample: u32,
    pub spp: u32,
    pub layers: Layers,
    pub origin: u32,
}

/// One pass's caustic statistics: per slot layer and pixel, S1 and S2 of its frames, complete once
/// `frames_done` reaches the pass's spp.
pub(super) struct CausticPass {
    pub(super) key: PassKey,
    pub(super) sum: Vec<[f64; 3]>,
    pub(super) sum_sq: Vec<[f64; 3]>,
    pub(super) dropped: u64,
    /// Frames folded so far: frames `key.first_sample..key.first_sample + frames_done`.
    pub(super) frames_done: u32,
    /// Where the next frame stands (traced in pieces, see `schedule.rs`).
    pub(super) cursor: Cursor,
    /// Seconds the pieces of the frame at `cursor` took so far.
    pub(super) frame_seconds: f64,
    /// Whether the frame at `cursor` was begun by polling (a waiting caller starts it again:
    /// its last polled piece may not be done).
    pub(super) polled_frame: bool,
    /// The submission whose polled readback, or polled completion, is under way.
    pub(super) in_flight: Option<InFlight>,
}

impl CausticPass {
    pub(super) fn new(key: PassKey, pixels: usize) -> Self {
        let layers = key.layers.count(key.spp) as usize;
        CausticPass {
            key,
            sum: vec![[0.0; 3]; layers * pixels],
            sum_sq: vec![[0.0; 3]; layers * pixels],
            dropped: 0,
            frames_done: 0,
            cursor: Cursor::FrameStart,
            frame_seconds: 0.0,
            polled_frame: false,
            in_flight: None,
        }
    }

    pub(super) fn complete(&self) -> bool {
        self.frames_done >= self.key.spp
    }

    /// Forgets the pieces of the frame in progress: it is traced again from its start (by the
    /// blocking `prepare_pass`, which a browser does not have).
    #[cfg(not(target_arch = "wasm32"))]
    pub(super) fn restart_frame(&mut self) {
        self.cursor = Cursor::FrameStart;
        self.frame_seconds = 0.0;
        self.polled_frame = false;
    }

    /// Folds `count` frames of `pixels` pixels read back from a dispatch (the splat buffer's
    /// words, frames first, then one dropped-particle counter per frame): they are the pass's
    /// next frames. A fixed-point unit is worth `unit` in true radiance.
    pub(super) fn fold_frames(&mut self, words: &[u32], count: u32, pixels: usize, unit: f64) {
        let words_per_frame = WORDS_PER_PIXEL as usize * pixels;
        for f in 0..count as usize {
            let relative = self.frames_done as usize + f;
            let offset = self.key.layers.layer_of(self.key.first_sample, relative as u32) as usize * pixels;
            let frame = &words[f * words_per_frame..(f + 1) * words_per_frame];
            for (p, w) in frame.chunks_exact(WORDS_PER_PIXEL as usize).enumerate() {
                for c in 0..3 {
                    let q = (u64::from(w[2 * c + 1]) << 32) | u64::from(w[2 * c]);
                    if q != 0 {
                        let v = q as f64 * unit;
                        self.sum[offset + p][c] += v;
                        self.sum_sq[offset + p][c] += v * v;
                    }
                }
            }
            self.dropped += u64::from(words[count as usize * words_per_frame + f]);
        }
        self.frames_done += count;
    }
}
