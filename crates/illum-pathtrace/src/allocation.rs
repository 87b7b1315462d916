//! Adaptive sampling: how many samples each block of 8 x 8 pixels takes, decided by a pilot.
//!
//! The error illum measures is the relMSE, the mean over pixels of (estimate - truth)^2 /
//! (truth^2 + eps). A block b of P_b pixels whose samples have the relative variance v_b (per
//! sample, averaged over its pixels and channels) contributes P_b v_b / n_b with n_b samples per
//! pixel. For a fixed budget sum_b P_b n_b = N, a Lagrange multiplier gives the minimum at
//!
//! ```text
//!     n_b = N sqrt(v_b) / sum_c P_c sqrt(v_c),
//!     relMSE_adaptive / relMSE_uniform = (sum_b P_b sqrt(v_b))^2 / (P sum_b P_b v_b) <= 1
//! ```
//!
//! (Cauchy-Schwarz; equality when every block is equally noisy). That is for errors falling as
//! 1 / n (independent samples); the low-discrepancy sequence's fall faster where they can, and
//! take a smaller exponent ([`LOW_DISCREPANCY_EXPONENT`]). On the Cornell box the ceiling, lit
//! only by interreflection, is several times noisier than the walls, and the black outside the
//! box's opening has no noise at all.
//!
//! **No bias.** The v_b come from a pilot render with a seed of its own, whose samples are then
//! discarded ([`plan_adaptive`]): a pixel's sample count is independent of the samples
//! averaged in it, so the mean of its n samples is unbiased for every n, and so is the image.
//! (Letting a pixel stop when its own running estimate looks converged would not be: the count
//! would then depend on the values it averages.) `tests/pathtrace/adaptive.rs` checks the
//! image against the f64 oracle pixel by pixel.
//!
//! **Blocks of 8 x 8** are the compute shader's workgroup: on a CPU driver a SIMD group runs as
//! long as its busiest lane, so a finer allocation would buy little. Every block takes at least
//! one chunk (16 samples, so that every pixel has an error estimate) and at most
//! [`MAX_FACTOR`] times the mean (a single wild pilot sample cannot take the budget); counts
//! are whole chunks, and the total never exceeds the uniform render's.

use crate::Accumulator;
use crate::batch::CHUNK_SAMPLES;
#[cfg(not(target_arch = "wasm32"))]
use crate::{PathTraceError, PathTracer, Sequence};
use illum_image::metrics::REL_MSE_EPSILON;

/// Pixels along each side of a block (the shader's workgroup; `ADAPTIVE_BLOCK` in
/// crates/illum-pathtrace/shaders/pathtrace.wgsl).
pub const BLOCK: u32 = 8;

/// The pilot's samples per pixel: one chunk. Per block that is 1024 samples, enough to rank
/// the blocks' variances; 1.6% of a 1024-spp budget.
pub const PILOT_SPP: u32 = CHUNK_SAMPLES;

/// The exponent of the blocks' variances for independent samples, whose error falls as 1 / n:
/// n_b ~ v_b^(1/2) (module docs).
pub const INDEPENDENT_EXPONENT: f64 = 0.5;

/// The exponent for the low-discrepancy sequence. Its error falls faster than 1 / n where the
/// integrand is smooth in each pair of dimensions (the walls' direct light) and about as 1 / n
/// where it is not (the ceiling's interreflection). For errors v_b n_b^-beta the optimum is
/// n_b ~ v_b^(1 / (1 + beta)); beta = 1.5, the rate of stratified sampling across edges, gives
/// 0.4, and a faster fall a smaller exponent. 0.3 is the exponent of lowest error measured
/// with the bilinear light points, and it also moves fewer samples to the costly ceiling
/// (docs/accuracy.md, "Adaptive sampling", has the relMSE of each exponent tried).
pub const LOW_DISCREPANCY_EXPONENT: f64 = 0.3;

/// No block takes more than this many times the mean spp.
pub const MAX_FACTOR: u32 = 16;

/// XORed into the scene's seed for the pilot: any non-zero key makes its samples independent of
/// the render's.
pub const PILOT_SEED_KEY: u32 = 0x5851_f42d;

/// Plans adaptive sampling on `tracer` for a budget of `mean_spp` samples per pixel and sets
/// it ([`PathTracer::set_sample_allocation`]): a pilot of [`PILOT_SPP`] samples per pixel with
/// another seed (the scene's XOR [`PILOT_SEED_KEY`]) gives each block's noise, then its samples
/// are discarded and the tracer starts again with the scene's own seed. Returns the allocation.
/// Waits for the pilot's readback: native only.
#[cfg(not(target_arch = "wasm32"))]
pub fn plan_adaptive(tracer: &mut PathTracer, mean_spp: u32) -> Result<SampleAllocation, PathTraceError> {
    let scene = tracer.scene().clone();
    let camera = scene.camera;
    // The adaptive pipeline from the start (no block limited), so that it compiles once.
    tracer.set_sample_allocation(Some(SampleAllocation::uniform(camera.width, camera.height, u32::MAX)))?;
    let mut pilot = scene.clone();
    pilot.pathtrace.seed = scene.pathtrace.seed ^ PILOT_SEED_KEY;
    tracer.update_scene(&pilot)?;
    tracer.add_samples_in_one_pass(PILOT_SPP)?;
    let exponent = match tracer.options().sequence {
        Sequence::Independent => INDEPENDENT_EXPONENT,
        Sequence::LowDiscrepancy => LOW_DISCREPANCY_EXPONENT,
    };
    let allocation = SampleAllocation::from_pilot(tracer.accumulator(), mean_spp, exponent);
    tracer.update_scene(&scene)?;
    tracer.set_sample_allocation(Some(allocation.clone()))?;
    Ok(allocation)
}

/// Samples per pixel of every block of an image, row-major over blocks (the last row and column
/// of blocks may be cut by the image's edge).
#[derive(Clone, Debug, PartialEq)]
pub struct SampleAllocation {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel of each block: absolute sample indices `0..n` of each of its pixels.
    pub samples: Vec<u32>,
}

impl SampleAllocation {
    /// Blocks across and down an image of `width x height`.
    pub fn blocks(width: u32, height: u32) -> (u32, u32) {
        (width.div_ceil(BLOCK), height.div_ceil(BLOCK))
    }

    /// The pixels of each block of an image of `width x height`, row-major over blocks (the last
    /// row and column of blocks are cut by the image's edge).
    pub fn block_pixels(width: u32, height: u32) -> Vec<u64> {
        let (bx, by) = Self::blocks(width, height);
        let side = |i: u32, size: u32| u64::from(BLOCK.min(size - i * BLOCK));
        (0..by).flat_map(|j| (0..bx).map(move |i| side(i, width) * side(j, height))).collect()
    }

    /// Every block `spp` samples per pixel.
    pub fn uniform(width: u32, height: u32, spp: u32) -> Self {
        let (bx, by) = Self::blocks(width, height);
        SampleAllocation { width, height, samples: vec![spp; bx as usize * by as usize] }
    }

    /// The allocation minimizing the expected relMSE for a budget of `mean_spp` samples per pixel
    /// over the image (module docs), from the per-pixel statistics of a pilot render: counts
    /// proportional to v_b^`exponent` ([`INDEPENDENT_EXPONENT`], [`LOW_DISCREPANCY_EXPONENT`]). Every
    /// block gets whole chunks, from one chunk to [`MAX_FACTOR`] x `mean_spp`; a pilot with no
    /// noise anywhere (or a budget of one chunk) gives the uniform allocation.
    pub fn from_pilot(pilot: &Accumulator, mean_spp: u32, exponent: f64) -> Self {
        let (width, height) = (pilot.width, pilot.height);
        let (bx, by) = Self::blocks(width, height);
        let mut noise = vec![0.0f64; bx as usize * by as usize];
        let pixels = Self::block_pixels(width, height);
        for y in 0..height {
            for x in 0..width {
                let b = (y / BLOCK * bx + x / BLOCK) as usize;
                let p = (y * width + x) as usize;
                let n = pilot.pixel_count(p) as f64;
                if n < 2.0 {
                    continue;
                }
                let mean = pilot.pixel_mean(p);
                // The per-sample variance: n times s^2 / n (the spread of the samples, which the
                // exponents were fitted to, not the low-discrepancy mean's replicate variance).
                let var = pilot.pixel_sample_variance_over_n(p);
                noise[b] +=
                    (0..3).map(|c| n * var[c] / (mean[c] * mean[c] + REL_MSE_EPSILON)).sum::<f64>() / 3.0;
            }
        }
        let weights: Vec<f64> = noise
            .iter()
            .zip(&pixels)
            .map(|(&v, &p)| if p > 0 && !v.is_nan() { (v / p as f64).powf(exponent) } else { 0.0 })
            .collect();
        Self::from_weights(width, height, &weights, &pixels, mean_spp)
    }

    /// Counts proportional to `weights` (one per block; `pixels` each), scaled so that they
    /// spend at most `mean_spp` per pixel on average, in whole chunks within the floor and cap.
    fn from_weights(width: u32, height: u32, weights: &[f64], pixels: &[u64], mean_spp: u32) -> Self {
        let chunk = u64::from(CHUNK_SAMPLES);
        let total_pixels: u64 = pixels.iter().sum();
        let budget = total_pixels * u64::from(mean_spp);
        let floor = chunk;
        // Counts are u32 sample indices: the cap is also the largest whole chunk a u32 holds.
        let cap =
            (u64::from(mean_spp) * u64::from(MAX_FACTOR)).max(floor).min(u64::from(u32::MAX) / chunk * chunk);
        let counts = |scale: f64| -> Vec<u64> {
            weights
                .iter()
                .map(|&w| {
                    let ideal = if w.is_nan() { 0.0 } else { scale * w };
                    let chunks = if ideal.is_finite() { (ideal / chunk as f64).round() } else { f64::MAX };
                    (chunks.min((cap / chunk) as f64) as u64 * chunk).clamp(floor, cap)
                })
                .collect()
        };
        let spent = |c: &[u64]| c.iter().zip(pixels).map(|(&n, &p)| n * p).sum::<u64>();
        // Below one chunk per pixel there is nothing to move around.
        let uniform = || {
            let mean = u64::from(mean_spp);
            vec![if mean < chunk { mean } else { mean / chunk * chunk }; weights.len()]
        };
        let positive = weights.iter().any(|&w| w > 0.0 && w.is_finite());
        let chosen = if !positive || spent(&counts(0.0)) > budget {
            uniform()
        } else {
            // The largest scale whose rounded counts fit the budget: bisection on a
            // non-decreasing function of the scale.
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            while spent(&counts(hi)) <= budget && hi < 1e300 {
                hi *= 2.0;
            }
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if spent(&counts(mid)) <= budget {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            counts(lo)
        };
        SampleAllocation { width, height, samples: chosen.into_iter().map(|n| n as u32).collect() }
    }

    /// A line for people and metadata: `8x8 blocks, 16 to 4096 spp, mean 1023.5, pilot 16 spp`.
    pub fn describe(&self) -> String {
        format!(
            "{BLOCK}x{BLOCK} blocks, {} to {} spp, mean {:.1}, pilot {PILOT_SPP} spp",
            self.min(),
            self.max(),
            self.mean_spp()
        )
    }

    /// Samples per pixel at pixel (x, y).
    pub fn at(&self, x: u32, y: u32) -> u32 {
        let (bx, _) = Self::blocks(self.width, self.height);
        self.samples[(y / BLOCK * bx + x / BLOCK) as usize]
    }

    /// The largest count: the sample index a render must reach for every block to be done.
    pub fn max(&self) -> u32 {
        self.samples.iter().copied().max().unwrap_or(0)
    }

    pub fn min(&self) -> u32 {
        self.samples.iter().copied().min().unwrap_or(0)
    }

    /// Samples over the whole image.
    pub fn total(&self) -> u64 {
        let pixels = Self::block_pixels(self.width, self.height);
        pixels.iter().zip(&self.samples).map(|(&p, &n)| p * u64::from(n)).sum()
    }

    /// Mean samples per pixel.
    pub fn mean_spp(&self) -> f64 {
        self.total() as f64 / (f64::from(self.width) * f64::from(self.height)).max(1.0)
    }

    /// Pixels of the image whose blocks take more than `index` samples: the pixels a pass
    /// starting at sample index `index` still traces.
    pub fn pixels_beyond(&self, index: u32) -> u64 {
        let pixels = Self::block_pixels(self.width, self.height);
        pixels.iter().zip(&self.samples).filter(|&(_, &n)| n > index).map(|(&p, _)| p).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn allocate(weights: &[f64], mean_spp: u32) -> SampleAllocation {
        // One row of whole blocks, one per weight.
        let width = BLOCK * weights.len() as u32;
        let pixels = vec![u64::from(BLOCK * BLOCK); weights.len()];
        SampleAllocation::from_weights(width, BLOCK, weights, &pixels, mean_spp)
    }

    /// Counts follow sqrt(v) (here the weights), spend no more than the uniform budget and
    /// nearly all of it, and stay whole chunks within the floor and cap.
    #[test]
    fn counts_follow_the_weights_within_the_budget() {
        let a = allocate(&[1.0, 2.0, 4.0, 1.0], 1024);
        assert!(a.total() <= 4 * 64 * 1024, "{a:?}");
        assert!(a.total() >= 4 * 64 * (1024 - 16), "most of the budget is spent: {a:?}");
        assert!(a.samples.iter().all(|n| n % CHUNK_SAMPLES == 0), "{a:?}");
        // 8 / 4 = 2048 each unit: 512, 1024, 2048, 512 exactly.
        assert_eq!(a.samples, [512, 1024, 2048, 512]);
        assert_eq!(a.mean_spp(), 1024.0);
    }

    /// The extremes: no noise anywhere, a budget of one chunk or less, a block with all the
    /// noise (capped), a block with none (floored), and an infinite weight.
    #[test]
    fn extremes_stay_inside_the_floor_the_cap_and_the_budget() {
        assert_eq!(allocate(&[0.0, 0.0], 64).samples, [64, 64]);
        assert_eq!(allocate(&[1.0, 9.0], 16).samples, [16, 16]);
        assert_eq!(allocate(&[1.0, 9.0], 5).samples, [5, 5], "below one chunk: uniform");
        assert_eq!(allocate(&[1.0, 9.0], 100).samples.iter().sum::<u32>() % CHUNK_SAMPLES, 0);
        // All the noise in one block: it takes what the floor of the others leaves.
        let hot = allocate(&[1e-9, 1e-9, 1e-9, 1e9], 64);
        assert_eq!(hot.samples, [16, 16, 16, 4 * 64 - 3 * 16], "{hot:?}");
        // ... and no more than the cap when the budget would allow more.
        let mut weights = vec![1e-9; 40];
        weights[0] = 1e9;
        let capped = allocate(&weights, 32);
        assert_eq!(capped.samples[0], 32 * MAX_FACTOR, "{capped:?}");
        let dark = allocate(&[0.0, 1.0], 256);
        assert_eq!(dark.samples[0], CHUNK_SAMPLES, "a black block takes one chunk");
        assert!(dark.total() <= 2 * 64 * 256);
        let inf = allocate(&[f64::INFINITY, 1.0], 256);
        assert!(inf.total() <= 2 * 64 * 256 && inf.samples[1] >= CHUNK_SAMPLES, "{inf:?}");
        // The largest budget: no count wraps past u32 (16 x the mean would).
        let huge = allocate(&[1.0, 9.0], u32::MAX);
        assert!(huge.samples.iter().all(|&n| n >= u32::MAX - 2 * CHUNK_SAMPLES), "{huge:?}");
        assert!(huge.total() <= 2 * 64 * u64::from(u32::MAX), "{huge:?}");
        let nan = allocate(&[f64::NAN, 1.0], 256);
        assert!(nan.total() <= 2 * 64 * 256 && nan.samples.iter().all(|&n| n >= CHUNK_SAMPLES), "{nan:?}");
    }

    /// Edge blocks cut by the image count only their pixels.
    #[test]
    fn totals_count_the_pixels_of_cut_blocks() {
        let a = SampleAllocation::uniform(10, 9, 32);
        assert_eq!(SampleAllocation::blocks(10, 9), (2, 2));
        assert_eq!(a.total(), 10 * 9 * 32);
        assert_eq!(a.pixels_beyond(31), 90);
        assert_eq!(a.pixels_beyond(32), 0);
        assert_eq!(a.at(9, 8), 32);
        assert_eq!(SampleAllocation::block_pixels(10, 9), [64, 16, 8, 2]);
    }
}
