//! The ways a band comes back to the CPU fold the same samples: polled readback (what the web
//! viewer uses, `PathTracer::set_polled_readback`) as the blocking one, and a reset while a band
//! is in flight never folds that band; batch buffers mapped where the GPU wrote them (a device
//! that shares the host's memory) as the staging copy a discrete GPU needs.

use illum::pathtrace::PathTracer;
use illum::scene::{Bounces, Sampling};

use crate::common;

const SPP: u32 = 8;

/// Renders to `SPP` with `render_step`, polling or waiting; `reset_after_first_step` resets the
/// tracer after its first step (a band is then in flight when polling).
fn render(polled: bool, reset_after_first_step: bool) -> PathTracer {
    let scene = common::cornell(24, SPP, Bounces::Fixed(2), Sampling::Cosine, 5);
    let mut tracer = PathTracer::new(common::gpu(), &scene).expect("path tracer builds");
    // One sample per chunk: each sample reaches the f64 fold as its own f32 value, so how the
    // samples were grouped into bands changes only the f64 rounding of the sums.
    tracer.set_chunk_samples(1);
    tracer.set_polled_readback(polled);
    let mut steps_without_samples = 0u64;
    if reset_after_first_step {
        tracer.render_step(Some(SPP)).expect("a step");
        tracer.reset();
    }
    while tracer.spp_done() < SPP {
        let report = tracer.render_step(Some(SPP)).expect("a step");
        if report.samples == 0 {
            steps_without_samples += 1;
            std::thread::yield_now();
        }
    }
    println!("polled {polled}: {steps_without_samples} steps returned before their band was back");
    tracer
}

fn assert_same_image(a: &PathTracer, b: &PathTracer, what: &str) {
    let (a, b) = (a.accumulator(), b.accumulator());
    assert_eq!(a.total_samples(), b.total_samples(), "{what}: sample counts differ");
    assert_eq!(a.dropped_samples(), b.dropped_samples(), "{what}: dropped samples differ");
    for pixel in 0..(a.width * a.height) as usize {
        assert_eq!(a.pixel_count(pixel), b.pixel_count(pixel), "{what}: pixel {pixel}'s count");
        let (sa, sb) = (a.pixel_sum(pixel), b.pixel_sum(pixel));
        for c in 0..3 {
            let scale = sa[c].abs().max(sb[c].abs()).max(1e-30);
            assert!(
                (sa[c] - sb[c]).abs() / scale < 1e-12,
                "{what}: pixel {pixel} channel {c}: {} vs {}",
                sa[c],
                sb[c]
            );
        }
    }
}

#[test]
fn polled_readback_folds_the_same_samples_as_waiting() {
    let waited = render(false, false);
    let polled = render(true, false);
    assert_same_image(&waited, &polled, "polled against waited");
    assert_eq!(polled.spp_done(), SPP);
}

#[test]
fn a_reset_while_a_band_is_in_flight_drops_that_band() {
    let waited = render(false, false);
    let reset = render(true, true);
    assert_same_image(&waited, &reset, "reset mid-flight against a fresh render");
}

/// Mapped readback, the default on lavapipe, against the staging copy, over passes split into
/// bands of 5 rows: each band is traced while the one before it is folded, so the mapped form
/// alternates between its two sets of batch buffers.
#[test]
fn mapped_readback_folds_the_same_samples_as_the_staging_copy() {
    let render = |mapped: bool| {
        let scene = common::cornell(24, SPP, Bounces::Fixed(2), Sampling::Cosine, 5);
        let mut tracer = PathTracer::new(common::gpu(), &scene).expect("path tracer builds");
        tracer.set_chunk_samples(1);
        tracer.set_mapped_readback(mapped);
        tracer.limit_batch_bytes(5 * 24 * 16).expect("five rows of one chunk fit");
        tracer.render_to_spp(SPP).expect("renders");
        tracer
    };
    let mapped = render(true);
    if common::gpu().adapter_info.device_type == illum::gpu::wgpu::DeviceType::Cpu {
        assert!(mapped.mapped_readback(), "a software driver shares the host's memory: bands are mapped");
    }
    let copied = render(false);
    assert!(!copied.mapped_readback());
    assert_same_image(&mapped, &copied, "mapped against copied");
    assert_eq!(mapped.spp_done(), SPP);
}
