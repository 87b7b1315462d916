//! What a denoiser reads, gathered from a render.

use illum_image::RgbImage32;
use illum_pathtrace::{Accumulator, Guides};

/// A variance standing for "unknown" (a pixel with fewer than 2 samples): large enough that
/// the colour stop lets every neighbour in and the bound ([`crate::bound`]) lets any value
/// through, small enough that the filter's sums of a few dozen of them stay finite in f32.
pub const UNKNOWN_VARIANCE: f32 = 1.0e30;

/// One image and what the filter's edge stops need, all row-major, `width x height`.
#[derive(Clone, Debug, PartialEq)]
pub struct DenoiseInput {
    pub image: RgbImage32,
    /// Variance of each pixel's mean, per channel ([`channel_variance`]).
    pub variance: Vec<[f32; 3]>,
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
            .map(|p| channel_variance(accumulator.pixel_variance_of_mean(p)))
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

/// A pixel's variances of the mean per channel in f32: infinite or NaN (fewer than 2
/// samples) as [`UNKNOWN_VARIANCE`], negative rounding as 0.
pub fn channel_variance(channels: [f64; 3]) -> [f32; 3] {
    channels.map(|v| if v.is_finite() { (v.max(0.0) as f32).min(UNKNOWN_VARIANCE) } else { UNKNOWN_VARIANCE })
}
