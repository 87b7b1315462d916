//! What a denoiser reads, gathered from a render.

use illum_image::RgbImage32;
use illum_image::rgb_image::REC709_LUMINANCE;
use illum_pathtrace::{Accumulator, Guides};

/// A variance standing for "unknown" (a pixel with fewer than 2 samples): large enough that
/// the luminance stop lets every neighbour in, small enough that the filter's sums of a few
/// dozen of them stay finite in f32.
pub const UNKNOWN_VARIANCE: f32 = 1.0e30;

/// One image and what the filter's edge stops need, all row-major, `width x height`.
#[derive(Clone, Debug, PartialEq)]
pub struct DenoiseInput {
    pub image: RgbImage32,
    /// Variance of each pixel's luminance estimate ([`luminance_variance`]).
    pub variance: Vec<f32>,
    pub albedo: Vec<[f32; 3]>,
    pub normal: Vec<[f32; 3]>,
}

impl DenoiseInput {
    /// The accumulator's mean image and variances, with `guides` of the same size.
    pub fn from_render(accumulator: &Accumulator, guides: &Guides) -> Self {
        let image = accumulator.mean_image();
        assert_eq!(
            (image.width, image.height),
            (guides.width, guides.height),
            "guides of another resolution than the image"
        );
        let variance = (0..image.pixels.len())
            .map(|p| luminance_variance(accumulator.pixel_variance_of_mean(p)))
            .collect();
        DenoiseInput { image, variance, albedo: guides.albedo.clone(), normal: guides.normal.clone() }
    }

    pub fn width(&self) -> u32 {
        self.image.width
    }

    pub fn height(&self) -> u32 {
        self.image.height
    }
}

/// The variance of a pixel's luminance from its channels' variances of the mean, taking the
/// channels as fully correlated (one path carries all three): (sum_c w_c sigma_c)^2, an upper
/// bound of the true variance. Infinite or NaN (fewer than 2 samples): [`UNKNOWN_VARIANCE`].
pub fn luminance_variance(channels: [f64; 3]) -> f32 {
    let sigma: f64 = channels.iter().zip(REC709_LUMINANCE).map(|(v, w)| w * v.max(0.0).sqrt()).sum();
    let variance = sigma * sigma;
    if variance.is_finite() { (variance as f32).min(UNKNOWN_VARIANCE) } else { UNKNOWN_VARIANCE }
}
