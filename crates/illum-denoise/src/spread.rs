//! The variance the filter's colour stop reads for a pixel whose own is unknown (fewer than 2
//! samples: [`crate::input::UNKNOWN_VARIANCE`], a 1-spp render): the spread of its neighbours'
//! values. Without it the stop lets every neighbour in at 1 spp, and a single bright sample (a
//! caustic's, a light's) is smeared over the 30-pixel reach of the filter: on the Whitted scene
//! at 1 spp that made the filtered image's relMSE 5 times the raw one's (docs/denoising.md).
//!
//! The estimate, per channel: the weighted variance sum w (x_q - m)^2 / sum w, m = sum w x_q /
//! sum w, over the 5 x 5 pixels q around p (p included), each weighed by the filter's own
//! normal and albedo stops against p (`shaders/atrous.wgsl`), so that a neighbour across an
//! edge does not count. With one sample per pixel, each x_q is one draw, so this is the
//! per-sample variance of p's surroundings, the variance of p's one-sample mean where the
//! surroundings have p's expected value (and larger where the image varies: the stop is then
//! only wider). SVGF (Schied et al. 2017) estimates a short history's variance the same way.
//! Known variances pass through unchanged; the bound ([`crate::bound`]) still reads only the
//! pixel's own, so a 1-spp pixel stays unbounded.

use crate::input::{DenoiseInput, UNKNOWN_VARIANCE};
use crate::stops::{normal_weight, unit_normals};

/// Half the side of the neighbourhood: 5 x 5 pixels.
pub const SPREAD_RADIUS: i64 = 2;

/// Each pixel's channel variances as the filter takes them: its own where known, the spread of
/// its neighbourhood where unknown (module docs). `sigma_albedo` is the filter's albedo stop.
pub fn filter_variance(input: &DenoiseInput, sigma_albedo: f32) -> Vec<[f32; 3]> {
    let unknown = |v: &[f32; 3]| v.iter().any(|&c| c >= UNKNOWN_VARIANCE);
    if !input.variance.iter().any(unknown) {
        return input.variance.clone();
    }
    let (width, height) = (i64::from(input.width()), i64::from(input.height()));
    let normal: Vec<[f64; 4]> = unit_normals(&input.normal).iter().map(|n| n.map(f64::from)).collect();
    let inv_sigma2 = 1.0 / (f64::from(sigma_albedo) * f64::from(sigma_albedo));
    let mut out = input.variance.clone();
    for y in 0..height {
        for x in 0..width {
            let p = (y * width + x) as usize;
            if !unknown(&input.variance[p]) {
                continue;
            }
            let (mut w_sum, mut sum, mut sum_sq) = (0.0f64, [0.0f64; 3], [0.0f64; 3]);
            for qy in (y - SPREAD_RADIUS).max(0)..=(y + SPREAD_RADIUS).min(height - 1) {
                for qx in (x - SPREAD_RADIUS).max(0)..=(x + SPREAD_RADIUS).min(width - 1) {
                    let q = (qy * width + qx) as usize;
                    let da: f64 =
                        (0..3).map(|k| f64::from(input.albedo[p][k] - input.albedo[q][k]).powi(2)).sum();
                    let w = normal_weight(normal[p], normal[q]) * (-da * inv_sigma2).exp();
                    w_sum += w;
                    for k in 0..3 {
                        let v = f64::from(input.image.pixels[q][k]);
                        sum[k] += w * v;
                        sum_sq[k] += w * v * v;
                    }
                }
            }
            // p's own weight is 1 (every stop is 1 at q = p), so w_sum >= 1.
            out[p] = std::array::from_fn(|k| {
                let mean = sum[k] / w_sum;
                ((sum_sq[k] / w_sum - mean * mean).max(0.0) as f32).min(UNKNOWN_VARIANCE)
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use illum_image::RgbImage32;

    fn input(
        pixels: Vec<[f32; 3]>,
        variance: Vec<[f32; 3]>,
        albedo: Vec<[f32; 3]>,
        width: u32,
    ) -> DenoiseInput {
        let n = pixels.len();
        DenoiseInput {
            image: RgbImage32 { width, height: n as u32 / width, pixels },
            variance,
            albedo,
            normal: vec![[0.0, 0.0, 1.0]; n],
            exact: Default::default(),
        }
    }

    /// Known variances pass through; an unknown one becomes the spread of the neighbours of its
    /// own albedo: a 1-spp pixel among draws of 0 and 1 in equal numbers (on a checkerboard of
    /// draws) gets about 1/4, and the pixels of another albedo beside them, all 5, do not count.
    #[test]
    fn an_unknown_variance_is_the_spread_of_like_neighbours() {
        let (width, height) = (9u32, 9u32);
        let n = (width * height) as usize;
        let mut pixels = Vec::new();
        let mut albedo = Vec::new();
        for y in 0..height {
            for x in 0..width {
                let like = x < 6;
                pixels.push(if like { [((x + y) % 2) as f32, 0.5, 0.5] } else { [5.0, 5.0, 5.0] });
                albedo.push(if like { [0.5; 3] } else { [0.9, 0.1, 0.1] });
            }
        }
        let mut variance = vec![[UNKNOWN_VARIANCE; 3]; n];
        variance[0] = [0.01, 0.02, 0.03];
        let filled = filter_variance(&input(pixels, variance, albedo, width), 0.05);
        assert_eq!(filled[0], [0.01, 0.02, 0.03], "a known variance changed");
        let centre = (4 * width + 3) as usize;
        assert!((filled[centre][0] - 0.25).abs() < 0.01, "spread {:?}", filled[centre]);
        assert!(filled[centre][1].abs() < 1e-6, "a constant channel: {:?}", filled[centre]);
        let right = (4 * width + 7) as usize;
        assert!(
            filled[right].iter().all(|v| v.abs() < 1e-6),
            "the other albedo's pixels: {:?}",
            filled[right]
        );
    }

    /// Every pixel known: the variances come back as they were.
    #[test]
    fn known_variances_are_untouched() {
        let input = input(vec![[1.0; 3], [2.0; 3]], vec![[0.1; 3], [0.2; 3]], vec![[0.5; 3]; 2], 2);
        assert_eq!(filter_variance(&input, 0.05), input.variance);
    }
}
