//! Per-pixel estimates with their statistics, and the image loop (on the threads of `parallel.rs`).

use glam::DVec3;

use crate::integrator::Oracle;
use crate::parallel::{in_parallel, rows_in_parallel};

/// The estimate of one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelEstimate {
    /// Mean of the finite samples, per channel.
    pub mean: [f64; 3],
    /// Unbiased sample variance / number of samples: the squared standard error of `mean`.
    /// NaN when fewer than two finite samples were taken (no estimate of the spread).
    pub variance_of_mean: [f64; 3],
    /// Non-finite samples, left out of the statistics (none are expected in f64).
    pub dropped: u32,
}

/// Running mean and sum of squared deviations (Welford's update): stable for any number of
/// samples, with no catastrophic cancellation between E[x^2] and E[x]^2.
#[derive(Clone, Copy, Debug, Default)]
struct Moments {
    n: u64,
    mean: DVec3,
    m2: DVec3,
}

impl Moments {
    fn add(&mut self, x: DVec3) {
        self.n += 1;
        let delta = x - self.mean;
        self.mean += delta / self.n as f64;
        self.m2 += delta * (x - self.mean);
    }

    fn variance_of_mean(&self) -> DVec3 {
        if self.n < 2 {
            return DVec3::NAN;
        }
        let n = self.n as f64;
        self.m2 / (n - 1.0) / n
    }
}

impl Oracle {
    /// `spp` samples (indices 0..spp) of pixel (x, y) under `seed`. With the caustic on, sample
    /// k is the camera path's estimate plus the pixel's share of caustic frame k (`caustic.rs`):
    /// the two are independent, so the sample variance below estimates the sum of their
    /// variances. (One pixel then costs spp whole frames of particles: [`Self::render`] traces
    /// each frame once for all pixels.)
    ///
    /// # Panics
    /// If `spp` is 0.
    pub fn pixel(&self, x: u32, y: u32, spp: u32, seed: u64) -> PixelEstimate {
        let index = y as usize * self.camera.width as usize + x as usize;
        self.pixel_with(x, y, spp, seed, |k| {
            if self.caustics() { self.caustic_frame(seed, k)[index] } else { DVec3::ZERO }
        })
    }

    fn pixel_with(
        &self,
        x: u32,
        y: u32,
        spp: u32,
        seed: u64,
        caustic: impl Fn(u32) -> DVec3,
    ) -> PixelEstimate {
        assert!(spp > 0, "illum-oracle: spp must be at least 1");
        let mut moments = Moments::default();
        let mut dropped = 0;
        for sample in 0..spp {
            let l = self.pixel_sample(x, y, seed, sample) + caustic(sample);
            if l.is_finite() {
                moments.add(l);
            } else {
                dropped += 1;
            }
        }
        PixelEstimate {
            mean: moments.mean.to_array(),
            variance_of_mean: moments.variance_of_mean().to_array(),
            dropped,
        }
    }

    /// The caustic frames 0..spp (empty when the caustic is off), on `threads` threads.
    pub fn caustic_frames(&self, spp: u32, seed: u64, threads: usize) -> Vec<Vec<DVec3>> {
        if !self.caustics() {
            return Vec::new();
        }
        in_parallel(spp, threads, |k| self.caustic_frame(seed, k))
    }

    /// The whole image on `threads` threads (at least one), which take rows one at a time.
    /// The result does not depend on `threads`: every sample's random numbers are keyed by
    /// (seed, pixel, sample index).
    ///
    /// # Panics
    /// If `spp` is 0 (an oracle with no samples is a caller bug).
    pub fn render(&self, spp: u32, seed: u64, threads: usize) -> OracleImage {
        assert!(spp > 0, "illum-oracle: spp must be at least 1");
        let (width, height) = (self.camera.width, self.camera.height);
        let frames = self.caustic_frames(spp, seed, threads);
        let pixels = rows_in_parallel(width, height, threads, |x, y| {
            let index = y as usize * width as usize + x as usize;
            self.pixel_with(x, y, spp, seed, |k| frames.get(k as usize).map_or(DVec3::ZERO, |f| f[index]))
        });
        let mut image = OracleImage {
            width,
            height,
            mean: Vec::with_capacity(width as usize * height as usize),
            variance_of_mean: Vec::with_capacity(width as usize * height as usize),
            spp,
            dropped: 0,
        };
        for p in pixels {
            image.mean.push(p.mean);
            image.variance_of_mean.push(p.variance_of_mean);
            image.dropped += u64::from(p.dropped);
        }
        image
    }
}

/// A rendered estimate: per pixel, row-major from the top-left, the mean radiance and the
/// squared standard error of that mean, per linear RGB channel.
#[derive(Clone, Debug, PartialEq)]
pub struct OracleImage {
    pub width: u32,
    pub height: u32,
    pub mean: Vec<[f64; 3]>,
    /// Unbiased sample variance / spp per channel (NaN everywhere when spp = 1).
    pub variance_of_mean: Vec<[f64; 3]>,
    pub spp: u32,
    /// Non-finite samples left out of the statistics, over the whole image (expected 0).
    pub dropped: u64,
}

impl OracleImage {
    /// Row-major index of pixel (x, y).
    pub fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }

    /// Mean over all pixels and channels, and the squared standard error of that mean (the
    /// pixels' estimates are independent).
    pub fn overall_mean(&self) -> (f64, f64) {
        let n = (self.mean.len() * 3) as f64;
        let mean = self.mean.iter().flatten().sum::<f64>() / n;
        let var = self.variance_of_mean.iter().flatten().sum::<f64>() / (n * n);
        (mean, var)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welford_matches_the_two_pass_formulas() {
        let xs = [1.0, 4.0, 4.0, 7.0, 10.0e6 + 1.0];
        let mut m = Moments::default();
        for x in xs {
            m.add(DVec3::new(x, 2.0 * x, 5.0));
        }
        let n = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / n;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
        assert!((m.mean.x - mean).abs() < 1e-9 * mean);
        assert!((m.variance_of_mean().x - var / n).abs() < 1e-9 * var / n);
        assert!((m.variance_of_mean().y - 4.0 * var / n).abs() < 1e-9 * var / n);
        assert_eq!(m.variance_of_mean().z, 0.0);
        let mut one = Moments::default();
        one.add(DVec3::ONE);
        assert!(one.variance_of_mean().is_nan());
    }
}
