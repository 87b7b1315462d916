//! The size of each submission follows what a sample costs, whoever calls `render_step`: a
//! caller that goes away between steps (a viewer drawing its window) must get the bands a render
//! loop gets. When the band launched ahead was timed across the caller's absence, the planner
//! took the window's drawing for the band's cost and shrank every later band toward one row.
//!
//! Functional, not timed: the two callers' band sizes are compared with each other, measured
//! side by side on the same device, and the failure they guard against is a factor of about a
//! hundred, against the factor of two allowed for noise.

use std::time::Duration;

use illum::pathtrace::PathTracer;

use crate::common;

/// Steps each caller takes; the first ones learn the cost of a sample.
const WARM_UP: usize = 6;
const MEASURED: usize = 10;

/// The samples each measured step scheduled, for a caller that sleeps `away` between steps.
fn band_samples(away: Duration) -> Vec<u64> {
    // An image larger than one submission, so that every pass is split into bands and a band
    // can be launched ahead of the caller's return.
    let scene = common::scene("cornell", common::small(512, 384, 1_000_000));
    let mut tracer = PathTracer::new(common::gpu(), &scene).expect("path tracer builds");
    tracer.set_target_seconds(0.015);
    let mut scheduled = Vec::new();
    for step in 0..WARM_UP + MEASURED {
        let report = tracer.render_step(None).expect("a step");
        assert_eq!(report.samples, report.scheduled_samples, "step {step}: samples lost");
        if step >= WARM_UP {
            scheduled.push(report.scheduled_samples);
        }
        std::thread::sleep(away);
    }
    scheduled
}

fn median(mut values: Vec<u64>) -> u64 {
    values.sort_unstable();
    values[values.len() / 2]
}

#[test]
fn a_caller_that_goes_away_between_steps_keeps_full_size_bands() {
    let straight = median(band_samples(Duration::ZERO));
    let away = median(band_samples(Duration::from_millis(40)));
    println!("median samples per band: {straight} back to back, {away} with 40 ms away between steps");
    assert!(
        2 * away >= straight,
        "a caller away 40 ms between steps gets bands of {away} samples, one back to back {straight}: \
         the caller's absence is being counted as the bands' cost"
    );
}
