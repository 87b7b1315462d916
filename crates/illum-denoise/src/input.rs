//! What a denoiser reads, gathered from a render.

use illum_image::RgbImage32;
use illum_pathtrace::accumulator::ExactPart;
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
    /// Radiance the renderer solved exactly rather than sampled (the sun's glint: the exact part
    /// of illum-pathtrace's `ImageParts`), where the image shows it: left out of `image`, so that
    /// no denoiser spreads it (a glint pixel can be 10^3 times its neighbours) or bounds it by a
    /// noise it does not have, and added back by [`Self::finish`].
    pub exact: ExactPart,
}

impl DenoiseInput {
    /// The accumulator's image as its parts: the sampled mean and its variances, with `guides`
    /// of the same size, and the exact part it shows in [`Self::exact`].
    pub fn from_render(accumulator: &Accumulator, guides: &Guides) -> Self {
        let parts = accumulator.parts();
        let image = parts.sampled_mean();
        assert_eq!(
            (image.width, image.height),
            (guides.width, guides.height),
            "guides of another resolution than the image"
        );
        let variance = (0..image.pixels.len())
            .map(|p| channel_variance(accumulator.pixel_variance_of_mean(p)))
            .collect();
        let exact = parts.shown_exact();
        DenoiseInput { image, variance, albedo: guides.albedo.clone(), normal: guides.normal.clone(), exact }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The glint is taken out of the image the denoiser reads and put back by `finish`, after
    /// the bound: a denoiser that returned the noisy image unchanged gives back the render's
    /// mean, glint included, though the glint is far beyond the pixel's noise.
    #[test]
    fn the_glint_is_left_out_of_the_filter_and_added_back() {
        let mut accumulator = Accumulator::new(3, 1);
        accumulator
            .set_exact(ExactPart::new(&[(1, [500.0, 600.0, 700.0])], 3).expect("a pixel of the image"));
        // Two samples per pixel, values 1 and 3 in every channel: mean 2, variance of the mean 1.
        accumulator.fold(0, &[[4.0, 4.0, 4.0, 2.0]; 3], &[[10.0, 10.0, 10.0, 0.0]; 3]);
        let guides = Guides {
            width: 3,
            height: 1,
            samples: 1,
            albedo: vec![[0.5; 3]; 3],
            normal: vec![[0.0, 0.0, 1.0]; 3],
        };
        let input = DenoiseInput::from_render(&accumulator, &guides);
        assert_eq!(input.image.pixels, vec![[2.0; 3]; 3], "the glint is not in the filter's image");
        assert_eq!(input.exact.entries(), &[(1, [500.0, 600.0, 700.0])]);
        let mut denoised = input.image.clone();
        input.finish(&mut denoised);
        assert_eq!(denoised.pixels, vec![[2.0; 3], [502.0, 602.0, 702.0], [2.0; 3]]);
    }
}
