//! Per-pixel statistics folded in f64.
//!
//! The GPU returns, per pixel and batch, the f32 sum and sum of squares of its finite samples, the
//! number of finite samples, and the number of dropped (NaN/Inf) ones. Folding those batch sums in
//! f64 keeps 10^6 spp free of drift: f32 only ever sums one short batch.
//!
//! Over 450 lines with its tests: the statistics, their fold and their estimates are one type.

use illum_image::RgbImage32;
// The epsilon of `illum_image::metrics::rel_mse` itself, so that the estimated and the measured
// relMSE are the same quantity.
use illum_image::metrics::REL_MSE_EPSILON;

use crate::replicates::Replicates;

#[derive(Clone, Debug)]
pub struct Accumulator {
    pub width: u32,
    pub height: u32,
    sum: Vec<[f64; 3]>,
    sum_sq: Vec<[f64; 3]>,
    count: Vec<u64>,
    /// Sum of `count`, kept as batches are folded so that reading it does not cost a pass over
    /// the image (progress reports read it after every band).
    total: u64,
    dropped: u64,
    /// 2^k: what the GPU's values are multiplied by when folded (see [`radiance_exponent`]).
    sum_scale: f64,
    /// Per-replicate sums of a low-discrepancy render (see `replicates.rs`): when present, the
    /// variance of each pixel's mean comes from their spread instead of s^2 / n.
    replicates: Option<Replicates>,
    /// The sun's glint (`glint.rs`): (pixel, radiance) sorted by pixel, added to those pixels'
    /// means and to nothing else. A point mass solved exactly has no variance: the statistics,
    /// the error estimate and the checkpoints' layers hold the samples alone.
    glint: Vec<(usize, [f64; 3])>,
}

/// Largest emitted radiance the GPU traces unscaled: 2^16. Above it the scene's emission is
/// divided by a power of two 2^k on upload (so that the brightest light is below 2^17) and the
/// fold multiplies the sums back by 2^k and the sums of squares by 2^(2k), in f64.
///
/// Why: a sample is at most about the brightest emission times a geometric factor of the
/// next-event estimator (light area / distance^2), and the GPU squares it in f32 and sums 16 such
/// squares. Unscaled, `emission = 1e30` would give squares of 1e60, past f32's 3.4e38: an
/// infinite variance while the image is still finite. Scaled, a sample squares in range unless that
/// geometric factor exceeds about 1e13, so every radiance the validator accepts (up to f32::MAX)
/// keeps a finite error estimate. Multiplying by a power of two is exact in binary floating point
/// (short of subnormal numbers), so the scaled render is the unscaled one, bit for bit, times 2^-k;
/// and scenes whose lights are below 2^16 (every scene in scenes/) are not scaled at all.
pub const UNSCALED_RADIANCE_LIMIT: f32 = 65536.0;

/// The exponent k by which the GPU's radiance is scaled down (2^-k) for a scene whose brightest
/// emission component is `max_emission` (0 for every emission up to [`UNSCALED_RADIANCE_LIMIT`]).
pub fn radiance_exponent(max_emission: f32) -> i32 {
    if max_emission.is_nan() || max_emission <= UNSCALED_RADIANCE_LIMIT {
        return 0;
    }
    // max_emission in [2^e, 2^(e+1)), e >= 16; after scaling by 2^-(e - 16) it is below 2^17.
    let e = ((max_emission.to_bits() >> 23) & 0xff) as i32 - 127;
    e - 16
}

/// Host bytes per pixel of the f64 statistics: sum and sum of squares (3 x f64 each) and the
/// sample count (u64).
pub const STATISTICS_BYTES_PER_PIXEL: u64 = 56;
const _: () = assert!(
    STATISTICS_BYTES_PER_PIXEL as usize == 2 * std::mem::size_of::<[f64; 3]>() + std::mem::size_of::<u64>()
);

/// Host bytes per pixel a whole render needs at its peak, writing a PNG and a checkpoint EXR:
/// the statistics and their EXR layer (2 x 56), the f32 mean image and its copy in the EXR
/// encoder (2 x 12), an 8-bit PNG's pixels (3) and the driver's batch and staging buffers
/// (about 20). Measured: 159 bytes per pixel at 4096 x 4096 (2.67 GB peak).
pub const RENDER_HOST_BYTES_PER_PIXEL: u64 = 2 * STATISTICS_BYTES_PER_PIXEL + 2 * 12 + 3 + 20;

/// Host bytes per pixel that a render ending inside a chunk needs on top: the copy of its
/// statistics at the last chunk boundary and that copy's EXR layer (see `checkpoint.rs`).
pub const ALIGNED_COPY_BYTES_PER_PIXEL: u64 = 2 * STATISTICS_BYTES_PER_PIXEL;

/// Checks, before anything is allocated, that a `width x height` render fits in `available`
/// bytes of host memory (`None`: unknown, not checked), with `extra_per_pixel` bytes per pixel
/// on top of [`RENDER_HOST_BYTES_PER_PIXEL`] (a low-discrepancy render's replicates and their
/// EXR layer: 2 x `Replicates::BYTES_PER_PIXEL`). The error says how much it would need.
pub fn check_host_memory(
    width: u32,
    height: u32,
    extra_per_pixel: u64,
    available: Option<u64>,
) -> Result<(), String> {
    let per_pixel = RENDER_HOST_BYTES_PER_PIXEL + extra_per_pixel;
    let needed = u64::from(width) * u64::from(height) * per_pixel;
    match available {
        Some(available) if needed > available => Err(format!(
            "camera.width x camera.height = {width} x {height}: the render needs {:.1} GiB of host memory \
             ({per_pixel} bytes per pixel: the f64 statistics, the output images and their encoders' copies), \
             but only {:.1} GiB are available",
            gib(needed),
            gib(available)
        )),
        _ => Ok(()),
    }
}

fn gib(bytes: u64) -> f64 {
    bytes as f64 / (1u64 << 30) as f64
}

/// Host memory available to a new allocation without swapping (Linux: `MemAvailable` in
/// /proc/meminfo); `None` where that is not known.
pub fn available_host_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

impl Accumulator {
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self::from_state(width, height, vec![[0.0; 3]; n], vec![[0.0; 3]; n], vec![0; n], 0)
            .expect("n entries each, as from_state checks")
    }

    /// As [`Self::new`], but reports the bytes it needed instead of aborting when the host cannot
    /// allocate them (a very large image: 56 bytes per pixel).
    pub fn try_new(width: u32, height: u32) -> Result<Self, u64> {
        let n = width as usize * height as usize;
        let bytes = n as u64 * STATISTICS_BYTES_PER_PIXEL;
        let mut sum = Vec::new();
        let mut sum_sq = Vec::new();
        let mut count = Vec::new();
        sum.try_reserve_exact(n).map_err(|_| bytes)?;
        sum_sq.try_reserve_exact(n).map_err(|_| bytes)?;
        count.try_reserve_exact(n).map_err(|_| bytes)?;
        sum.resize(n, [0.0; 3]);
        sum_sq.resize(n, [0.0; 3]);
        count.resize(n, 0);
        Ok(Self::from_state(width, height, sum, sum_sq, count, 0)
            .expect("n entries each, as from_state checks"))
    }

    /// Folds from now on values the GPU computed with radiance scaled by 2^-`exponent` (see
    /// [`radiance_exponent`]): sums are multiplied by 2^k, sums of squares by 2^(2k).
    pub fn set_radiance_exponent(&mut self, exponent: i32) {
        self.sum_scale = 2f64.powi(exponent);
    }

    /// The exact state, for checkpoints (see `checkpoint.rs`): per pixel the sum and sum of
    /// squares of its finite samples (f64, unscaled) and their count, plus the dropped total.
    pub fn state(&self) -> AccumulatorState<'_> {
        AccumulatorState { sum: &self.sum, sum_sq: &self.sum_sq, count: &self.count, dropped: self.dropped }
    }

    /// Rebuilds an accumulator from a saved state (its vectors must have `width x height`
    /// entries). The running total is recomputed; folding goes on exactly where it stopped.
    pub fn from_state(
        width: u32,
        height: u32,
        sum: Vec<[f64; 3]>,
        sum_sq: Vec<[f64; 3]>,
        count: Vec<u64>,
        dropped: u64,
    ) -> Result<Self, String> {
        let n = width as usize * height as usize;
        if sum.len() != n || sum_sq.len() != n || count.len() != n {
            return Err(format!(
                "the statistics have {} / {} / {} entries for a {width} x {height} image ({n} pixels)",
                sum.len(),
                sum_sq.len(),
                count.len()
            ));
        }
        let total = count.iter().sum();
        Ok(Self {
            width,
            height,
            sum,
            sum_sq,
            count,
            total,
            dropped,
            sum_scale: 1.0,
            replicates: None,
            glint: Vec::new(),
        })
    }

    /// Keeps per-replicate sums from now on (a low-discrepancy render, see `replicates.rs`); the
    /// accumulator must be empty. Fold its slots with [`Self::fold_slots`].
    pub fn enable_replicates(&mut self) {
        debug_assert_eq!(self.total, 0, "replicates enabled on a started accumulator");
        self.replicates = Some(Replicates::new(self.count.len()));
    }

    /// Sets the per-replicate sums (a checkpoint's); `None`: independent samples.
    pub fn set_replicates(&mut self, replicates: Option<Replicates>) -> Result<(), String> {
        if let Some(r) = &replicates
            && r.pixels() != self.count.len()
        {
            return Err(format!(
                "the replicate statistics have {} pixels for a {} x {} image",
                r.pixels(),
                self.width,
                self.height
            ));
        }
        self.replicates = replicates;
        Ok(())
    }

    /// The per-replicate sums, when kept.
    pub fn replicates(&self) -> Option<&Replicates> {
        self.replicates.as_ref()
    }

    /// [`Self::fold`] for one layer of slots (`batch::Layers`): with replicates kept, its sums
    /// also go to `replicate`, the replicate whose samples the layer holds.
    pub fn fold_slots(
        &mut self,
        first_pixel: usize,
        replicate: Option<usize>,
        sums: &[[f32; 4]],
        sums_sq: &[[f32; 4]],
    ) {
        debug_assert!(
            self.replicates.is_none() || replicate.is_some(),
            "replicates kept, but a slot of none"
        );
        self.fold(first_pixel, sums, sums_sq);
        let scale = self.sum_scale;
        if let (Some(replicates), Some(replicate)) = (&mut self.replicates, replicate) {
            for (i, s) in sums.iter().enumerate() {
                if s[3] > 0.0 {
                    let sum = [s[0] as f64 * scale, s[1] as f64 * scale, s[2] as f64 * scale];
                    replicates.add(first_pixel + i, replicate, sum, s[3] as u64);
                }
            }
        }
    }

    /// Adds another accumulator's samples of the same image (a disjoint set of sample indices:
    /// see the `merge` example), pixel by pixel in f64.
    pub fn merge(&mut self, other: &Accumulator) {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "merging images of different sizes"
        );
        for p in 0..self.count.len() {
            for c in 0..3 {
                self.sum[p][c] += other.sum[p][c];
                self.sum_sq[p][c] += other.sum_sq[p][c];
            }
            self.count[p] += other.count[p];
        }
        self.total += other.total;
        self.dropped += other.dropped;
        // Replicates add only when both sides kept them (a merge refuses mixed sequences first).
        match (&mut self.replicates, &other.replicates) {
            (Some(a), Some(b)) => a.merge(b),
            _ => self.replicates = None,
        }
    }

    /// Folds one batch for consecutive pixels starting at `first_pixel`. `sums[i]` is (sum, finite
    /// count), `sums_sq[i]` is (sum of squares, dropped count), as the shader writes them.
    pub fn fold(&mut self, first_pixel: usize, sums: &[[f32; 4]], sums_sq: &[[f32; 4]]) {
        // With scale 1 (every scene whose lights are below 2^16) the products are exact no-ops.
        let scale = self.sum_scale;
        let scale_sq = scale * scale;
        for (i, (s, q)) in sums.iter().zip(sums_sq).enumerate() {
            let p = first_pixel + i;
            for c in 0..3 {
                self.sum[p][c] += s[c] as f64 * scale;
                self.sum_sq[p][c] += q[c] as f64 * scale_sq;
            }
            self.count[p] += s[3] as u64;
            self.total += s[3] as u64;
            self.dropped += q[3] as u64;
        }
    }

    /// Folds, beside a camera chunk just folded with [`Self::fold`] (`camera`: its sums as the
    /// shader wrote them), a second, independent estimator's values for the same samples: per
    /// pixel the true-radiance sum `sum` and sum of squares `sum_sq` of its `frames` values,
    /// one per sample index of the chunk (the caustic's light tracer, `tracer/caustic.rs`).
    /// Sample k of the pixel is then c_k + s_k: the sums gain S1 and the sums of squares
    /// S2 + 2 C S1 / n (C the camera sum of n samples), whose expectation is that of the paired
    /// sum of (c_k + s_k)^2 since the two are independent; so the sample variance estimates
    /// var(c) + var(s). When some camera samples of the chunk were dropped (n < frames), S1
    /// and S2 are scaled by n / frames, the expected share of the kept samples. With replicates
    /// kept, S1 joins `replicate`, the camera layer's: frame k pairs with sample k, and the
    /// caustic's sampler deals frames to replicates as the camera's.
    pub fn fold_independent(
        &mut self,
        first_pixel: usize,
        replicate: Option<usize>,
        camera: &[[f32; 4]],
        sum: &[[f64; 3]],
        sum_sq: &[[f64; 3]],
        frames: u32,
    ) {
        if frames == 0 {
            return;
        }
        let scale = self.sum_scale;
        let frames = f64::from(frames);
        for (i, chunk) in camera.iter().enumerate() {
            let n = f64::from(chunk[3]);
            if n == 0.0 {
                continue;
            }
            let p = first_pixel + i;
            let share = n / frames;
            for c in 0..3 {
                self.sum[p][c] += sum[i][c] * share;
                self.sum_sq[p][c] +=
                    sum_sq[i][c] * share + 2.0 * f64::from(chunk[c]) * scale * sum[i][c] / frames;
            }
            if let (Some(replicates), Some(replicate)) = (&mut self.replicates, replicate) {
                replicates.add_values(p, replicate, sum[i].map(|v| v * share));
            }
        }
    }

    /// Counts `n` more dropped values (the caustic's particles too bright for its fixed point).
    pub fn add_dropped(&mut self, n: u64) {
        self.dropped += n;
    }

    /// Samples dropped because they were NaN or Inf.
    pub fn dropped_samples(&self) -> u64 {
        self.dropped
    }

    /// Finite samples in the pixel with the fewest (the spp every pixel has reached).
    pub fn min_samples(&self) -> u64 {
        self.count.iter().copied().min().unwrap_or(0)
    }

    /// Finite samples over all pixels (kept as a running total: constant time).
    pub fn total_samples(&self) -> u64 {
        self.total
    }

    /// Sum of the pixel's finite samples, per channel.
    pub fn pixel_sum(&self, pixel: usize) -> [f64; 3] {
        self.sum[pixel]
    }

    /// Finite samples in the pixel.
    pub fn pixel_count(&self, pixel: usize) -> u64 {
        self.count[pixel]
    }

    /// The pixel's estimate: the mean of its samples, plus the glint solved into it once it has
    /// a sample (0 before).
    pub fn pixel_mean(&self, pixel: usize) -> [f64; 3] {
        let n = self.count[pixel];
        let mean = self.sum[pixel].map(|s| s / n.max(1) as f64);
        match self.glint.binary_search_by_key(&pixel, |g| g.0) {
            Ok(i) if n > 0 => [0, 1, 2].map(|c| mean[c] + self.glint[i].1[c]),
            _ => mean,
        }
    }

    /// Sets the glint added to the pixels' means: (pixel, radiance), at most once per pixel
    /// Refused for a pixel outside the image.
    pub fn set_glint(&mut self, glint: &[(usize, [f64; 3])]) -> Result<(), String> {
        if let Some(&(p, _)) = glint.iter().find(|g| g.0 >= self.count.len()) {
            return Err(format!("glint pixel {p} is outside the {} x {} image", self.width, self.height));
        }
        let mut sorted = glint.to_vec();
        sorted.sort_by_key(|g| g.0);
        // Two entries for one pixel add.
        self.glint = Vec::with_capacity(sorted.len());
        for (p, v) in sorted {
            match self.glint.last_mut() {
                Some((q, w)) if *q == p => (0..3).for_each(|c| w[c] += v[c]),
                _ => self.glint.push((p, v)),
            }
        }
        Ok(())
    }

    /// The glint added to the means: (pixel, radiance), sorted by pixel.
    pub fn glint(&self) -> &[(usize, [f64; 3])] {
        &self.glint
    }

    /// Variance of the pixel's mean, per channel: from the spread of the replicate means when
    /// replicates are kept (low-discrepancy), else sample variance / n; infinite with < 2 samples
    /// (or < 2 replicates).
    pub fn pixel_variance_of_mean(&self, pixel: usize) -> [f64; 3] {
        match &self.replicates {
            Some(replicates) => replicates.variance_of_mean(pixel),
            None => self.pixel_sample_variance_over_n(pixel),
        }
    }

    /// The sample variance over n per channel, s^2 / n, whatever the sequence (the variance of
    /// the mean for independent samples; for the low-discrepancy sequence an overestimate, used
    /// where the per-sample spread is wanted: adaptive sampling's pilot). Infinite with < 2 samples.
    pub fn pixel_sample_variance_over_n(&self, pixel: usize) -> [f64; 3] {
        let n = self.count[pixel] as f64;
        if n < 2.0 {
            return [f64::INFINITY; 3];
        }
        let mut out = [0.0; 3];
        for (c, value) in out.iter_mut().enumerate() {
            let mean = self.sum[pixel][c] / n;
            // Unbiased sample variance; clamp the rounding residue of a constant pixel at zero.
            let variance = ((self.sum_sq[pixel][c] - n * mean * mean) / (n - 1.0)).max(0.0);
            *value = variance / n;
        }
        out
    }

    pub fn mean_image(&self) -> RgbImage32 {
        let mut image = RgbImage32::new(self.width, self.height);
        for (p, px) in image.pixels.iter_mut().enumerate() {
            // A mean beyond f32's range (a light near f32::MAX seen through noise) is stored as
            // f32::MAX rather than infinity: EXR and PNG hold f32 at most.
            *px = self.pixel_mean(p).map(|v| v.min(f32::MAX as f64) as f32);
        }
        image
    }

    /// Per-pixel variance of the mean, as an image (for Z-tests and the viewer's error view).
    pub fn variance_image(&self) -> RgbImage32 {
        let mut image = RgbImage32::new(self.width, self.height);
        for (p, px) in image.pixels.iter_mut().enumerate() {
            *px = self.pixel_variance_of_mean(p).map(|v| v as f32);
        }
        image
    }

    /// The relMSE of the current mean image against the (unknown) converged image, estimated from
    /// the per-pixel variance alone: mean over pixels and channels of Var(mean) / (mean^2 + eps).
    /// This is the expectation of `rel_mse(mean, truth)` when the estimator is unbiased.
    pub fn estimated_rel_mse(&self) -> f64 {
        let mut total = 0.0;
        let mut terms = 0usize;
        for p in 0..self.count.len() {
            let mean = self.pixel_mean(p);
            let var = self.pixel_variance_of_mean(p);
            for c in 0..3 {
                total += var[c] / (mean[c] * mean[c] + REL_MSE_EPSILON);
                terms += 1;
            }
        }
        if terms == 0 { f64::INFINITY } else { total / terms as f64 }
    }

    /// Samples per pixel from which [`Self::estimated_rel_mse`] is finite: 2 for independent
    /// samples (a sample variance needs two), and for a low-discrepancy render two replicates'
    /// runs (its variance comes from the spread of the replicates' means, and the first
    /// `REPLICATE_RUN` samples all go to one replicate; a range starts on a chunk, which starts
    /// a run of replicate 0).
    pub fn spp_for_error_estimate(&self) -> u32 {
        if self.replicates.is_some() { 2 * crate::replicates::REPLICATE_RUN } else { 2 }
    }

    /// Relative standard error of the image: the square root of [`Self::estimated_rel_mse`].
    pub fn estimated_relative_error(&self) -> f64 {
        self.estimated_rel_mse().sqrt()
    }

    /// Starts over (same size and radiance scale). Zeroes the statistics in place: fresh
    /// vectors would come from the system as untouched pages, and the first fold after a reset
    /// (a viewer's camera move) would pay a page fault per 4 KiB of statistics.
    pub fn reset(&mut self) {
        self.sum.fill([0.0; 3]);
        self.sum_sq.fill([0.0; 3]);
        self.count.fill(0);
        self.total = 0;
        self.dropped = 0;
        if let Some(replicates) = &mut self.replicates {
            replicates.reset();
        }
    }
}

/// A borrowed view of an [`Accumulator`]'s exact state (see [`Accumulator::state`]).
#[derive(Clone, Copy, Debug)]
pub struct AccumulatorState<'a> {
    pub sum: &'a [[f64; 3]],
    pub sum_sq: &'a [[f64; 3]],
    pub count: &'a [u64],
    pub dropped: u64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fold_matches_direct_f64_statistics() {
        // Two batches of known samples for one pixel: 1, 2, 3 then 4, 5.
        let mut acc = Accumulator::new(1, 1);
        acc.fold(0, &[[6.0, 6.0, 6.0, 3.0]], &[[14.0, 14.0, 14.0, 0.0]]);
        acc.fold(0, &[[9.0, 9.0, 9.0, 2.0]], &[[41.0, 41.0, 41.0, 1.0]]);
        assert_eq!(acc.min_samples(), 5);
        assert_eq!(acc.total_samples(), 5);
        assert_eq!(acc.dropped_samples(), 1);
        assert_eq!(acc.pixel_mean(0), [3.0; 3]);
        // Sample variance of 1..5 is 2.5; of the mean, 2.5 / 5 = 0.5.
        let v = acc.pixel_variance_of_mean(0);
        assert!((v[0] - 0.5).abs() < 1e-12, "{v:?}");
    }

    #[test]
    fn reset_starts_over_and_keeps_the_radiance_scale() {
        let mut acc = Accumulator::new(2, 1);
        acc.set_radiance_exponent(3);
        acc.fold(
            0,
            &[[1.0, 1.0, 1.0, 1.0], [2.0, 2.0, 2.0, 1.0]],
            &[[1.0, 1.0, 1.0, 1.0], [4.0, 4.0, 4.0, 0.0]],
        );
        acc.reset();
        let state = acc.state();
        assert!(state.sum.iter().chain(state.sum_sq).all(|v| *v == [0.0; 3]));
        assert!(state.count.iter().all(|&c| c == 0));
        assert_eq!((acc.total_samples(), acc.dropped_samples()), (0, 0));
        // Still scaled by 2^3 after the reset: one sample of 1 folds to a mean of 8.
        acc.fold(0, &[[1.0, 1.0, 1.0, 1.0]], &[[1.0, 1.0, 1.0, 0.0]]);
        assert_eq!(acc.pixel_mean(0), [8.0; 3]);
    }

    #[test]
    fn a_render_larger_than_memory_is_refused_with_what_it_needs() {
        let err = check_host_memory(8192, 8192, 0, Some(2 << 30)).unwrap_err();
        assert!(err.contains("8192 x 8192") && err.contains("9.9 GiB") && err.contains("2.0 GiB"), "{err}");
        // With the replicates of a low-discrepancy render: 159 + 512 bytes per pixel.
        let err = check_host_memory(8192, 8192, 512, Some(2 << 30)).unwrap_err();
        assert!(err.contains("41.9 GiB") && err.contains("671 bytes per pixel"), "{err}");
        assert!(check_host_memory(16384, 16384, 0, None).is_ok());
        assert!(check_host_memory(512, 512, 0, Some(1 << 30)).is_ok());
        if cfg!(target_os = "linux") {
            assert!(available_host_memory().is_some_and(|b| b > 0));
        }
    }

    #[test]
    fn radiance_is_scaled_only_above_the_limit_and_by_a_power_of_two() {
        assert_eq!(radiance_exponent(30.0), 0);
        assert_eq!(radiance_exponent(UNSCALED_RADIANCE_LIMIT), 0);
        assert_eq!(radiance_exponent(f32::NAN), 0);
        for m in [65536.5f32, 1e20, 1e30, f32::MAX] {
            let k = radiance_exponent(m);
            let scaled = m as f64 * 2f64.powi(-k);
            assert!((65536.0..131072.0).contains(&scaled), "{m}: k = {k}, scaled {scaled}");
        }
        // The fold undoes the scale exactly: a sample of f32::MAX, traced as f32::MAX / 2^k.
        let k = radiance_exponent(f32::MAX);
        let traced = f32::MAX * 2f32.powi(-k);
        let mut acc = Accumulator::new(1, 1);
        acc.set_radiance_exponent(k);
        for _ in 0..2 {
            acc.fold(0, &[[traced, 1.0, 1.0, 1.0]], &[[traced * traced, 1.0, 1.0, 0.0]]);
        }
        assert_eq!(acc.pixel_mean(0)[0], f32::MAX as f64);
        assert!(acc.estimated_relative_error().is_finite());
    }

    #[test]
    fn state_round_trips_and_merges_add() {
        let mut a = Accumulator::new(2, 1);
        a.fold(
            0,
            &[[1.0, 2.0, 3.0, 2.0], [4.0, 5.0, 6.0, 2.0]],
            &[[1.0, 4.0, 9.0, 0.0], [16.0, 25.0, 36.0, 1.0]],
        );
        let s = a.state();
        let b = Accumulator::from_state(2, 1, s.sum.to_vec(), s.sum_sq.to_vec(), s.count.to_vec(), s.dropped)
            .unwrap();
        assert_eq!(b.total_samples(), 4);
        assert_eq!(b.dropped_samples(), 1);
        assert_eq!(b.pixel_sum(1), [4.0, 5.0, 6.0]);
        let mut c = b.clone();
        c.merge(&a);
        assert_eq!(c.pixel_sum(0), [2.0, 4.0, 6.0]);
        assert_eq!(c.pixel_count(1), 4);
        assert!(Accumulator::from_state(3, 1, vec![], vec![], vec![], 0).unwrap_err().contains("3 x 1"));
    }

    #[test]
    fn the_glint_adds_to_the_mean_of_sampled_pixels_and_to_nothing_else() {
        let mut acc = Accumulator::new(3, 1);
        acc.set_glint(&[(1, [5.0, 6.0, 7.0]), (1, [1.0, 1.0, 1.0])]).unwrap();
        assert_eq!(acc.glint(), &[(1, [6.0, 7.0, 8.0])], "entries of one pixel add");
        assert_eq!(acc.pixel_mean(1), [0.0; 3], "no sample yet: no glint");
        let sums = [[2.0, 2.0, 2.0, 2.0]; 3];
        let squares = [[2.0, 2.0, 2.0, 0.0]; 3];
        acc.fold(0, &sums, &squares);
        assert_eq!(acc.pixel_mean(0), [1.0; 3]);
        assert_eq!(acc.pixel_mean(1), [7.0, 8.0, 9.0]);
        assert_eq!(acc.pixel_variance_of_mean(1), acc.pixel_variance_of_mean(0), "no variance of its own");
        assert_eq!(acc.pixel_sum(1), [2.0; 3], "the statistics hold the samples alone");
        acc.reset();
        acc.fold(0, &sums, &squares);
        assert_eq!(acc.pixel_mean(1), [7.0, 8.0, 9.0], "kept across a reset");
        assert!(acc.set_glint(&[(3, [1.0; 3])]).unwrap_err().contains("outside the 3 x 1 image"));
    }

    #[test]
    fn single_sample_has_unknown_variance() {
        let mut acc = Accumulator::new(1, 1);
        acc.fold(0, &[[1.0, 1.0, 1.0, 1.0]], &[[1.0, 1.0, 1.0, 0.0]]);
        assert!(acc.pixel_variance_of_mean(0)[0].is_infinite());
    }
}
