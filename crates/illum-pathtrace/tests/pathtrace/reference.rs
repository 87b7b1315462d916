//! A small Cornell box against checked-in reference images, per pixel and statistically.
//!
//! The references (tests/reference/cornell-64-b*-{mean,variance}.exr) are converged renders of
//! this path tracer (16384 spp, seed 1000): this is a regression test, and its tolerance is
//! statistical. A fresh render with another seed must pass a two-sample per-pixel Z-test at
//! alpha = 0.01 (Bonferroni over the three channels), using both the render's and the
//! reference's variance of the mean, on at least 97% of pixels; a correct renderer passes about
//! 99%. Correctness itself is covered independently by the closed-form and oracle tests.
//!
//! Regenerate with `ILLUM_BLESS=1 cargo test --workspace --test pathtrace reference` after an
//! intended change.

use illum_image::{load_exr, save_diff_images, save_exr, z_test_pass_fraction};
use illum_scene::{Bounces, Overrides};

use crate::common;

const SIZE: u32 = 64;
const REFERENCE_SPP: u32 = 16384;
const TEST_SPP: u32 = 1024;

fn check_against_reference(bounces: u32) {
    let stem = format!("cornell-{SIZE}-b{bounces}");
    let mean_path = common::crate_path(&format!("tests/reference/{stem}-mean.exr"));
    let variance_path = common::crate_path(&format!("tests/reference/{stem}-variance.exr"));
    let overrides = |spp, seed| Overrides {
        width: Some(SIZE),
        height: Some(SIZE),
        spp: Some(spp),
        seed: Some(seed),
        bounces: Some(Bounces::Fixed(bounces)),
        ..Default::default()
    };
    if std::env::var_os("ILLUM_BLESS").is_some() {
        let tracer = common::render(&common::scene("cornell", overrides(REFERENCE_SPP, 1000)));
        let metadata = illum_pathtrace::metadata::exr_metadata(
            &tracer,
            0.0,
            Some(illum_pathtrace::StopReason::SppReached),
            "tests/pathtrace/reference.rs (ILLUM_BLESS)",
        );
        save_exr(&mean_path, &tracer.accumulator().mean_image(), &metadata).expect("write mean");
        save_exr(&variance_path, &tracer.accumulator().variance_image(), &metadata).expect("write variance");
    }
    let (reference, _) = load_exr(&mean_path).expect("reference mean exists (ILLUM_BLESS=1 makes it)");
    let (reference_variance, _) = load_exr(&variance_path).expect("reference variance exists");

    let tracer = common::render(&common::scene("cornell", overrides(TEST_SPP, 7)));
    let image = tracer.accumulator().mean_image();
    common::assert_all_finite(&image, &stem);
    let pass = z_test_pass_fraction(
        &image,
        &tracer.accumulator().variance_image(),
        &reference,
        &reference_variance,
        0.01,
    )
    .expect("same size");
    if pass < 0.97 {
        let written = save_diff_images(common::failure_dir(), &stem, &image, &reference);
        panic!("{stem}: only {pass:.4} of pixels pass the Z-test against the reference; see {written:?}");
    }
    println!("{stem}: {pass:.4} of pixels pass");
}

#[test]
fn direct_light_matches_the_reference() {
    check_against_reference(0);
}

#[test]
fn two_bounces_match_the_reference() {
    check_against_reference(2);
}
