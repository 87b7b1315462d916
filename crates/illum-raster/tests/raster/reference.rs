//! Image regression: both looks at 320 x 180 against tests/reference/whitted-figure.png and
//! tests/reference/whitted-enhanced.png.
//!
//! Tolerance, in 8-bit levels of the (linear) PNG: the mean absolute difference over all pixels
//! and channels at most [`MAX_MEAN_LEVELS`], and the 99th percentile of each pixel's largest
//! channel difference at most [`MAX_P99_LEVELS`]. A driver that rounds or blends edge pixels
//! slightly differently moves them by a few levels; a wrong shadow, reflection or
//! refraction moves thousands of pixels by tens of levels (`the_tolerance_tells_...` shows the
//! metric catches that). The references are this renderer's output on lavapipe, checked in once
//! the reference-free checks (`figure`, `effects`) held; regenerate them after an intended
//! change with `ILLUM_BLESS=1 cargo test --workspace --test raster reference`.

use illum_image::{Encoding, RgbImage32, save_diff_images, save_png};
use illum_raster::{Look, Options};

use illum_gpu::testing;

use crate::{HEIGHT, WIDTH, level, render, scene};

pub const MAX_MEAN_LEVELS: f64 = 1.0;
pub const MAX_P99_LEVELS: i32 = 12;

/// Mean absolute difference (levels, over all channels) and the 99th percentile of the
/// per-pixel largest channel difference (levels).
fn difference(actual: &RgbImage32, reference: &RgbImage32) -> (f64, i32) {
    assert_eq!((actual.width, actual.height), (reference.width, reference.height));
    let mut sum = 0i64;
    let mut largest: Vec<i32> = actual
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, r)| {
            let d = [0, 1, 2].map(|c| (level(a[c]) - level(r[c])).abs());
            sum += i64::from(d[0] + d[1] + d[2]);
            d.into_iter().max().unwrap_or(0)
        })
        .collect();
    largest.sort_unstable();
    let p99 = largest[(largest.len() * 99 / 100).min(largest.len() - 1)];
    (sum as f64 / (3 * actual.pixels.len()) as f64, p99)
}

fn within_tolerance((mean, p99): (f64, i32)) -> bool {
    mean <= MAX_MEAN_LEVELS && p99 <= MAX_P99_LEVELS
}

fn reference_path(look: Look) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/reference/whitted-{look}.png"))
}

fn load_reference(look: Look) -> RgbImage32 {
    let path = reference_path(look);
    let png = image::open(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (ILLUM_BLESS=1 makes it)", path.display()))
        .to_rgb8();
    RgbImage32::from_fn(png.width(), png.height(), |x, y| png.get_pixel(x, y).0.map(|v| f32::from(v) / 255.0))
}

fn check(look: Look) {
    let actual = render(&scene(), &Options::all_on(look));
    if std::env::var_os("ILLUM_BLESS").is_some() {
        save_png(reference_path(look), &actual, 0.0, Encoding::Linear).expect("write the reference");
    }
    let reference = load_reference(look);
    assert_eq!((reference.width, reference.height), (WIDTH, HEIGHT));
    let (mean, p99) = difference(&actual, &reference);
    if !within_tolerance((mean, p99)) {
        let written =
            save_diff_images(testing::failure_dir(), &format!("whitted-{look}"), &actual, &reference);
        panic!(
            "look {look}: mean |difference| {mean:.3} levels (max {MAX_MEAN_LEVELS}), 99th percentile {p99} \
             levels (max {MAX_P99_LEVELS}); see {written:?}"
        );
    }
}

#[test]
fn figure_matches_its_reference() {
    check(Look::Figure);
}

#[test]
fn enhanced_matches_its_reference() {
    check(Look::Enhanced);
}

#[test]
fn the_tolerance_tells_the_looks_and_missing_effects_apart() {
    let figure = render(&scene(), &Options::all_on(Look::Figure));
    let enhanced_reference = load_reference(Look::Enhanced);
    assert!(!within_tolerance(difference(&figure, &enhanced_reference)), "the looks are indistinguishable");
    let mut no_shadows = Options::all_on(Look::Figure);
    no_shadows.effects.shadows = false;
    let shadowless = render(&scene(), &no_shadows);
    let d = difference(&shadowless, &load_reference(Look::Figure));
    assert!(!within_tolerance(d), "dropping the shadows stays within tolerance: {d:?}");
}
