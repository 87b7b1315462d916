//! Per-pixel statistics folded in f64.
//!
//! The GPU returns, per pixel and batch, the f32 sum and sum of squares of its finite samples, the
//! number of finite samples, and the number of dropped (NaN/Inf) ones. Folding those batch sums in
//! f64 keeps 10^6 spp free of drift: f32 only ever sums one short batch.

use illum_image::RgbImage32;
// The epsilon of `illum_image::metrics::rel_mse` itself, so that the estimated and the measured
// relMSE are the same quantity.
use illum_image::metrics::REL_MSE_EPSILON;

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
}

/// Host bytes per pixel of the f64 statistics: sum and sum of squares (3 x f64 each) and the
/// sample count (u64).
pub const STATISTICS_BYTES_PER_PIXEL: u64 = 56;
const _: () = assert!(
    STATISTICS_BYTES_PER_PIXEL as usize == 2 * std::mem::size_of::<[f64; 3]>() + std::mem::size_of::<u64>()
);

/// Host bytes per pixel a whole render needs at its peak: the statistics, the f32 mean image
/// written to files (12) and an 8-bit PNG's pixels (3).
pub const RENDER_HOST_BYTES_PER_PIXEL: u64 = STATISTICS_BYTES_PER_PIXEL + 12 + 3;

/// Checks, before anything is allocated, that a `width x height` render fits in `available`
/// bytes of host memory (`None`: unknown, not checked). The error says how much it would need.
pub fn check_host_memory(width: u32, height: u32, available: Option<u64>) -> Result<(), String> {
    let needed = u64::from(width) * u64::from(height) * RENDER_HOST_BYTES_PER_PIXEL;
    match available {
        Some(available) if needed > available => Err(format!(
            "camera.width x camera.height = {width} x {height}: the render needs {:.1} GiB of host memory \
             ({RENDER_HOST_BYTES_PER_PIXEL} bytes per pixel: f64 statistics and the output image), \
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
        Self {
            width,
            height,
            sum: vec![[0.0; 3]; n],
            sum_sq: vec![[0.0; 3]; n],
            count: vec![0; n],
            total: 0,
            dropped: 0,
        }
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
        Ok(Self { width, height, sum, sum_sq, count, total: 0, dropped: 0 })
    }

    /// Folds one batch for consecutive pixels starting at `first_pixel`. `sums[i]` is (sum, finite
    /// count), `sums_sq[i]` is (sum of squares, dropped count), as the shader writes them.
    pub fn fold(&mut self, first_pixel: usize, sums: &[[f32; 4]], sums_sq: &[[f32; 4]]) {
        for (i, (s, q)) in sums.iter().zip(sums_sq).enumerate() {
            let p = first_pixel + i;
            for c in 0..3 {
                self.sum[p][c] += s[c] as f64;
                self.sum_sq[p][c] += q[c] as f64;
            }
            self.count[p] += s[3] as u64;
            self.total += s[3] as u64;
            self.dropped += q[3] as u64;
        }
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

    pub fn pixel_mean(&self, pixel: usize) -> [f64; 3] {
        let n = self.count[pixel].max(1) as f64;
        self.sum[pixel].map(|s| s / n)
    }

    /// Variance of the pixel's mean (sample variance / n), per channel; infinite with < 2 samples.
    pub fn pixel_variance_of_mean(&self, pixel: usize) -> [f64; 3] {
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
            *px = self.pixel_mean(p).map(|v| v as f32);
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
    /// the per-pixel variance alone: mean over pixels and channels of Var[mean] / (mean^2 + eps).
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

    /// Relative standard error of the image: the square root of [`Self::estimated_rel_mse`].
    pub fn estimated_relative_error(&self) -> f64 {
        self.estimated_rel_mse().sqrt()
    }

    pub fn reset(&mut self) {
        *self = Self::new(self.width, self.height);
    }
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
    fn a_render_larger_than_memory_is_refused_with_what_it_needs() {
        let err = check_host_memory(8192, 8192, Some(2 << 30)).unwrap_err();
        assert!(err.contains("8192 x 8192") && err.contains("4.4 GiB") && err.contains("2.0 GiB"), "{err}");
        assert!(check_host_memory(16384, 16384, None).is_ok());
        assert!(check_host_memory(512, 512, Some(1 << 30)).is_ok());
        if cfg!(target_os = "linux") {
            assert!(available_host_memory().is_some_and(|b| b > 0));
        }
    }

    #[test]
    fn single_sample_has_unknown_variance() {
        let mut acc = Accumulator::new(1, 1);
        acc.fold(0, &[[1.0, 1.0, 1.0, 1.0]], &[[1.0, 1.0, 1.0, 0.0]]);
        assert!(acc.pixel_variance_of_mean(0)[0].is_infinite());
    }
}
