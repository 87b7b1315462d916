//! The ladder's regions and errors (`illum_auto::regions`, shared with Auto's pilots), with
//! FLIP (Andersson et al. 2020, LDR-FLIP, NVIDIA's implementation by the `nv-flip` crate) on
//! both images tone-mapped the way the PNGs are (exposure 0, sRGB), the mean of its per-pixel
//! error map over the pixels; 0 means no visible difference, 1 the largest.

use illum_image::{Encoding, RgbImage32, to_rgb8};

pub use illum_auto::regions::{Comparison, Errors, Regions, SMALL_REGION, region_mask};

/// Pixels at which FLIP evaluates: its default observer (a 0.7 m away 24" 4K monitor).
pub const FLIP_PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

/// FLIP's per-pixel error between `image` and `reference`, both tone-mapped as the PNGs are.
///
/// # Panics
/// When the sizes differ.
pub fn flip_map(image: &RgbImage32, reference: &RgbImage32) -> Vec<f32> {
    assert_eq!((image.width, image.height), (reference.width, reference.height), "FLIP compares equal sizes");
    let ldr = |i: &RgbImage32| {
        nv_flip::FlipImageRgb8::with_data(i.width, i.height, &to_rgb8(i, 0.0, Encoding::Srgb).into_raw())
    };
    nv_flip::flip(ldr(reference), ldr(image), FLIP_PIXELS_PER_DEGREE).to_vec()
}

/// FLIP's error map drawn with its magma colour scale (black: no difference; yellow: the most).
pub fn flip_heat_map(map: &[f32], width: u32, height: u32) -> image::RgbaImage {
    let errors = nv_flip::FlipImageFloat::with_data(width, height, map);
    let rgb = errors.apply_color_lut(&nv_flip::magma_lut()).to_vec();
    image::RgbaImage::from_fn(width, height, |x, y| {
        let i = 3 * (y * width + x) as usize;
        image::Rgba([rgb[i], rgb[i + 1], rgb[i + 2], 255])
    })
}

/// Compares `image` with `reference` overall and over each of `regions`, FLIP included.
///
/// # Panics
/// When the sizes of the images and the regions differ.
pub fn compare(image: &RgbImage32, reference: &RgbImage32, regions: &Regions) -> Comparison {
    illum_auto::regions::compare_with_map(image, reference, regions, flip_map(image, reference))
}

#[cfg(test)]
mod tests {
    use illum_image::metrics::REL_MSE_EPSILON;

    use super::*;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 3]) -> RgbImage32 {
        RgbImage32::from_fn(w, h, f)
    }

    #[test]
    fn an_image_equal_to_the_reference_has_no_error_anywhere() {
        let reference = image(32, 16, |x, y| [x as f32 / 32.0, y as f32 / 16.0, 0.5]);
        let regions = Regions {
            names: vec!["left".into(), "right".into()],
            of_pixel: (0..512).map(|i| usize::from(i % 32 >= 16)).collect(),
        };
        let c = compare(&reference, &reference, &regions);
        for e in std::iter::once(&c.overall).chain(&c.regions) {
            assert_eq!((e.rel_mse, e.luminance_ratio, e.flip), (0.0, 1.0, 0.0), "{e:?}");
        }
        assert_eq!(c.regions[0].pixels + c.regions[1].pixels, 512);
    }

    /// An error confined to one region shows there and not in the other (FLIP near the edge
    /// aside); the overall relMSE is
    /// the pixel-weighted mean of the regions'; a uniform scale s gives relMSE (s - 1)^2 r^2 /
    /// (r^2 + 0.01) and a luminance ratio of s exactly.
    #[test]
    fn an_error_in_one_region_is_measured_there_alone() {
        let reference = image(32, 16, |_, _| [0.5, 0.5, 0.5]);
        let darker = image(32, 16, |x, _| if x >= 16 { [0.35, 0.35, 0.35] } else { [0.5, 0.5, 0.5] });
        let regions = Regions {
            names: vec!["left".into(), "right".into()],
            of_pixel: (0..512).map(|i| usize::from(i % 32 >= 16)).collect(),
        };
        let c = compare(&darker, &reference, &regions);
        let (left, right) = (c.regions[0], c.regions[1]);
        assert_eq!((left.rel_mse, left.luminance_ratio), (0.0, 1.0));
        // FLIP filters spatially (as the eye does), so the edge shows a few pixels into the left
        // region; far from it the left region has no error.
        assert!(left.flip < 0.25 * right.flip, "{left:?} {right:?}");
        assert!((0..16).all(|y| (0..8).all(|x| c.flip_map[y * 32 + x] == 0.0)));
        let expected = (0.15f64 * 0.15) / (0.25 + REL_MSE_EPSILON);
        assert!((right.rel_mse - expected).abs() < 1e-6 * expected, "{right:?}");
        assert!((right.luminance_ratio - 0.7).abs() < 1e-6, "{right:?}");
        assert!(right.flip > 0.05, "a 30% darker half is visible: {right:?}");
        assert!((c.overall.rel_mse - 0.5 * right.rel_mse).abs() < 1e-9);
    }
}
