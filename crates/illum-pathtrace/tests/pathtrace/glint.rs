//! The sun's glint (`src/glint.rs`) on the GPU: a sun disc of 1 degree finds E S+ L by chance
//! (camera paths that leave a mirror or the glass into the disc), the delta sun by the host's
//! solve. Around the brightest glints of the Whitted view, the disc's image minus the delta
//! sun's samples must equal the solved glint (a z-test), and must not without it.

use illum_pathtrace::glint;
use illum_scene::{Bounces, Overrides};

use crate::common;

const WIDTH: u32 = 64;
const HEIGHT: u32 = 36;
const SPP: u32 = 8192;

#[test]
fn a_small_sun_disc_finds_the_glint_the_delta_sun_solves() {
    let overrides = Overrides {
        width: Some(WIDTH),
        height: Some(HEIGHT),
        spp: Some(SPP),
        bounces: Some(Bounces::Fixed(8)),
        seed: Some(3),
        ..Default::default()
    };
    let delta = common::scene("whitted", overrides);
    let mut disc = delta.clone();
    disc.directional_light.as_mut().expect("a sun").angular_radius_deg = 1.0;
    disc.pathtrace.seed = 4;
    let points = glint::solve(&delta);
    assert!(glint::glint_active(&delta) && !glint::glint_active(&disc));
    let delta_render = common::render(&delta);
    let disc_render = common::render(&disc);
    let (a, b) = (delta_render.accumulator(), disc_render.accumulator());
    assert_eq!(
        a.exact().entries(),
        glint::pixel_values(&points).as_slice(),
        "the tracer holds the solved glint"
    );
    assert!(b.exact().is_empty(), "a sun disc has no solved glint");

    // The 3 x 3 pixels around each glint worth 1% of the brightest, grouped by the object its
    // chain meets first (1 the glass ball, 2 the mirror ball).
    let brightest = points.iter().map(|p| p.value[2]).fold(0.0, f64::max);
    for object in [1usize, 2] {
        let mut window = std::collections::BTreeSet::new();
        for p in points.iter().filter(|p| p.chain[0].0 == object && p.value[2] > 0.01 * brightest) {
            let (x, y) = ((p.pixel % WIDTH as usize) as i64, (p.pixel / WIDTH as usize) as i64);
            for (dx, dy) in (-1..=1).flat_map(|dx| (-1..=1).map(move |dy| (dx, dy))) {
                let (u, v) = (x + dx, y + dy);
                if (0..i64::from(WIDTH)).contains(&u) && (0..i64::from(HEIGHT)).contains(&v) {
                    window.insert((v * i64::from(WIDTH) + u) as usize);
                }
            }
        }
        assert!(!window.is_empty(), "object {object} has no bright glint");
        for c in 0..3 {
            let (mut difference, mut variance, mut solved) = (0.0, 0.0, 0.0);
            for &p in &window {
                let samples = a.pixel_sum(p)[c] / a.pixel_count(p) as f64;
                let glint = a.pixel_mean(p)[c] - samples;
                difference += b.pixel_mean(p)[c] - samples;
                variance += a.pixel_variance_of_mean(p)[c] + b.pixel_variance_of_mean(p)[c];
                solved += glint;
            }
            let sigma = variance.sqrt();
            let (z, z_without) = ((difference - solved) / sigma, difference / sigma);
            println!(
                "object {object}, channel {c}, {} pixels: disc - delta samples {difference:.4} +- {sigma:.4}, \
                 solved glint {solved:.4}: z = {z:.2} (without the glint {z_without:.2})",
                window.len()
            );
            // |z| < 3.29: a false alarm in 0.1% of runs per channel and object.
            assert!(z.abs() < 3.29, "object {object}, channel {c}: z = {z:.2}");
            assert!(
                z_without > 4.0,
                "object {object}, channel {c}: the glint is not needed (z = {z_without:.2})"
            );
        }
    }
}
