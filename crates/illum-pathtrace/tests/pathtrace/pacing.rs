//! The time a tracer counts as its bands' (what the planner learns the cost of a sample from)
//! is the time its bands took, whoever calls `render_step`: a caller that goes away between
//! steps (a viewer drawing its window) must not have its absence counted. A band launched ahead
//! and timed across the caller's absence would make the planner take the window's drawing for
//! the band's cost and shrink every later band toward one row.
//!
//! Functional, not timed: the caller sleeps a known time between steps, and the time the tracer
//! attributes to its bands must leave that out. (Comparing band sizes instead depends on the
//! machine's load: a busy machine's scheduling latency is part of every band's cost.)

use std::time::{Duration, Instant};

use illum_pathtrace::PathTracer;

use crate::common;

const STEPS: u32 = 16;
const AWAY: Duration = Duration::from_millis(40);

#[test]
fn a_caller_that_goes_away_between_steps_is_not_charged_for_its_absence() {
    // An image larger than one submission, so that every pass is split into bands and a band
    // could be launched ahead of the caller's return.
    let scene = common::scene("cornell", common::small(512, 384, 1_000_000));
    let mut tracer = PathTracer::new(common::gpu(), &scene).expect("path tracer builds");
    tracer.set_target_seconds(0.015);
    let started = Instant::now();
    let mut bands = Vec::new();
    for step in 0..STEPS {
        let report = tracer.render_step(None).expect("a step");
        assert_eq!(report.samples, report.scheduled_samples, "step {step}: samples lost");
        bands.push(report.scheduled_samples);
        std::thread::sleep(AWAY);
    }
    let elapsed = started.elapsed().as_secs_f64();
    let away = (AWAY * STEPS).as_secs_f64();
    let charged = tracer.wall_seconds();
    println!(
        "{charged:.3} s charged to the bands of {elapsed:.3} s, {away:.3} s of it away; bands {bands:?}"
    );
    // The bands' time is at most what was not spent away; with the absences counted it would
    // hold nearly all of them. Half of them is the line: the first step may launch a band
    // ahead (the caller's habits are not known yet), and the time away is a minimum.
    assert!(
        charged <= elapsed - 0.5 * away,
        "the bands were charged {charged:.3} s of {elapsed:.3} s, though the caller was away {away:.3} s"
    );
}
