//! Pictures of a failed image comparison, for a human to look at.
//!
//! A failing image test calls [`save_diff_images`] to leave `{stem}-actual.png`,
//! `{stem}-reference.png` and `{stem}-diff.png` under `target/`, then reports their paths.

use std::path::{Path, PathBuf};

use crate::ImageError;
use crate::png::{check_writable, save_png, save_rgba8_png};
use crate::rgb_image::RgbImage32;
use crate::tonemap::{Encoding, encode_8bit};

/// Colour marking pixels where either image is NaN or infinite.
pub const NON_FINITE_COLOUR: [u8; 3] = [255, 0, 255];

/// What [`save_diff_images`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct DiffImages {
    pub actual: PathBuf,
    pub reference: PathBuf,
    pub diff: PathBuf,
    /// The largest finite per-channel absolute difference: the value shown as white.
    pub max_abs_difference: f32,
}

/// Writes the tone-mapped actual and reference images (exposure 0, gamma 2.2) and a diff
/// picture into `dir`.
///
/// The diff shows the per-channel absolute difference `|actual - reference|`, scaled so the
/// largest finite difference over all channels is 1 (white), then gamma-2.2 encoded so that
/// small differences remain visible. One scale for all channels keeps the colour of the
/// diff meaningful (a red diff means the red channel differs). Pixels where either image is
/// non-finite are drawn in [`NON_FINITE_COLOUR`]. Identical images give a black diff.
///
/// The actual image is written even when the sizes differ (it is what the test produced);
/// then the function returns an error naming the diff file it could not make.
pub fn save_diff_images(
    dir: impl AsRef<Path>,
    stem: &str,
    actual: &RgbImage32,
    reference: &RgbImage32,
) -> Result<DiffImages, ImageError> {
    let dir = dir.as_ref();
    let paths = DiffImages {
        actual: dir.join(format!("{stem}-actual.png")),
        reference: dir.join(format!("{stem}-reference.png")),
        diff: dir.join(format!("{stem}-diff.png")),
        max_abs_difference: 0.0,
    };
    save_png(&paths.actual, actual, 0.0, Encoding::Gamma22)?;
    save_png(&paths.reference, reference, 0.0, Encoding::Gamma22)?;
    check_writable(&paths.diff, reference)?;
    if (actual.width, actual.height) != (reference.width, reference.height) {
        return Err(ImageError::invalid(
            &paths.diff,
            format!(
                "the actual image is {}x{} but the reference is {}x{}; a diff needs equal sizes",
                actual.width, actual.height, reference.width, reference.height
            ),
        ));
    }

    let differences: Vec<Option<[f32; 3]>> = actual
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, r)| {
            let d = [0, 1, 2].map(|c| (a[c] - r[c]).abs());
            d.iter().all(|v| v.is_finite()).then_some(d)
        })
        .collect();
    let max = differences.iter().flatten().flatten().fold(0.0f32, |m, &v| m.max(v));
    // With no difference at all, any scale gives black; 1 avoids dividing by zero.
    let scale = if max > 0.0 { 1.0 / max } else { 1.0 };
    let diff = image::RgbaImage::from_fn(actual.width, actual.height, |x, y| {
        let i = y as usize * actual.width as usize + x as usize;
        let [r, g, b] = match differences[i] {
            Some(d) => d.map(|v| encode_8bit(v * scale, 0.0, Encoding::Gamma22)),
            None => NON_FINITE_COLOUR,
        };
        image::Rgba([r, g, b, 255])
    });
    save_rgba8_png(&paths.diff, &diff)?;
    Ok(DiffImages { max_abs_difference: max, ..paths })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_three_pictures_with_max_difference_white() {
        let dir = tempfile::tempdir().unwrap();
        let reference = RgbImage32::filled(3, 2, [0.5; 3]);
        let mut actual = reference.clone();
        actual.set(0, 0, [0.5, 0.9, 0.5]); // largest difference: 0.4 in green
        actual.set(1, 0, [0.6, 0.5, 0.5]); // 0.1 in red: a quarter of the max
        actual.set(2, 1, [f32::NAN, 0.5, 0.5]);
        let out = save_diff_images(dir.path().join("fail"), "cornell", &actual, &reference).unwrap();
        assert!(out.actual.ends_with("fail/cornell-actual.png"));
        assert!((out.max_abs_difference - 0.4).abs() < 1e-6);
        assert_eq!(image::open(&out.reference).unwrap().to_rgb8().get_pixel(0, 0).0, [186; 3]);

        let diff = image::open(&out.diff).unwrap().to_rgb8();
        assert_eq!(diff.get_pixel(0, 0).0, [0, 255, 0]);
        // 0.25^(1/2.2) * 255 = 135.1 (the f32 difference 0.6 - 0.5 is not exactly 0.1).
        let red = diff.get_pixel(1, 0).0;
        assert!((134..=136).contains(&red[0]) && red[1] == 0 && red[2] == 0, "{red:?}");
        assert_eq!(diff.get_pixel(2, 1).0, NON_FINITE_COLOUR);
        assert_eq!(diff.get_pixel(1, 1).0, [0, 0, 0]);
    }

    #[test]
    fn identical_images_give_black_diff() {
        let dir = tempfile::tempdir().unwrap();
        let img = RgbImage32::filled(2, 2, [0.3, 0.2, 0.1]);
        let out = save_diff_images(dir.path(), "same", &img, &img).unwrap();
        assert_eq!(out.max_abs_difference, 0.0);
        let diff = image::open(&out.diff).unwrap().to_rgb8();
        assert!(diff.pixels().all(|p| p.0 == [0, 0, 0]));
    }

    #[test]
    fn size_mismatch_keeps_actual_and_names_diff() {
        let dir = tempfile::tempdir().unwrap();
        let err = save_diff_images(dir.path(), "odd", &RgbImage32::new(2, 2), &RgbImage32::new(3, 2))
            .unwrap_err()
            .to_string();
        assert!(err.contains("odd-diff.png") && err.contains("2x2") && err.contains("3x2"), "{err}");
        assert!(dir.path().join("odd-actual.png").exists());
        assert!(!dir.path().join("odd-diff.png").exists());
    }
}
