//! The ways a band comes back to the CPU fold the same samples: polled readback (what the web
//! viewer uses, `Readback::Polled`) as the blocking one, and a reset while a band
//! is in flight never folds that band; batch buffers mapped where the GPU wrote them (a device
//! that shares the host's memory) as the staging copy a discrete GPU needs; and the caustic's
//! light tracer, whose frames are polled dispatch by dispatch in the browser, gives the image of
//! the blocking readback bit for bit.

use illum_pathtrace::{PathTracer, Readback};
use illum_scene::{Bounces, Sampling, Scene};

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
    if polled {
        tracer.set_readback(Readback::Polled);
    }
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

/// A change of readback while a band is on the GPU (polled and in flight, or launched ahead of
/// a caller that came straight back) drops that band, and its rows are traced again: the image
/// is the one of a render read one way throughout. Passes of bands of 5 rows, so that a band
/// is on the GPU between steps.
#[test]
fn a_change_of_readback_mid_pass_traces_the_dropped_band_again() {
    let waited = render(false, false);
    let scene = common::cornell(24, SPP, Bounces::Fixed(2), Sampling::Cosine, 5);
    let mut tracer = PathTracer::new(common::gpu(), &scene).expect("path tracer builds");
    tracer.set_chunk_samples(1);
    tracer.limit_batch_bytes(5 * 24 * 16).expect("five rows of one chunk fit");
    let mut modes =
        [Readback::Polled, Readback::Staging, Readback::Polled, Readback::Mapped].into_iter().cycle();
    while tracer.spp_done() < SPP {
        tracer.set_readback(modes.next().expect("cycles"));
        for _ in 0..3 {
            tracer.render_step(Some(SPP)).expect("a step");
        }
    }
    assert_same_image(&waited, &tracer, "readback changed mid-pass against waited");
    assert_eq!(tracer.spp_done(), SPP);
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
        tracer.set_readback(if mapped { Readback::Mapped } else { Readback::Staging });
        tracer.limit_batch_bytes(5 * 24 * 16).expect("five rows of one chunk fit");
        tracer.render_to_spp(SPP).expect("renders");
        tracer
    };
    let mapped = render(true);
    if common::gpu().adapter_info.device_type == illum_gpu::wgpu::DeviceType::Cpu {
        assert_eq!(
            mapped.readback(),
            Readback::Mapped,
            "a software driver shares the host's memory: bands are mapped"
        );
    }
    let copied = render(false);
    assert_eq!(copied.readback(), Readback::Staging);
    assert_same_image(&mapped, &copied, "mapped against copied");
    assert_eq!(mapped.spp_done(), SPP);
}

/// The Whitted scene (its light tracer on, as the file says) at 40 x 24 pixels.
fn caustic_scene(caustics: bool) -> Scene {
    let mut scene = common::scene("whitted", common::small(40, 24, CAUSTIC_SPP));
    scene.pathtrace.caustics = caustics;
    scene
}

/// Over two chunks plus a tail: passes of 16 or 32 spp and a last one of 8, so a pass of two
/// chunks takes two dispatches of caustic frames (16 frames each at this size).
const CAUSTIC_SPP: u32 = 40;

/// Renders `scene` to `CAUSTIC_SPP` with `render_step`, polling or waiting, with chunk-aligned
/// passes: however the planner sizes the passes and bands, every chunk of every pixel then holds
/// the same camera samples and the same caustic frames. With `reset_after_first_step` the
/// tracer is reset after its first step (polling, the first pass's caustic frames are then in
/// flight). Returns the tracer and the steps that returned before their results were back.
fn render_caustic(scene: &Scene, polled: bool, reset_after_first_step: bool) -> (PathTracer, u64) {
    render_caustic_aiming_at(scene, polled, reset_after_first_step, None)
}

/// [`render_caustic`], with `set_target_seconds(target)` when given.
fn render_caustic_aiming_at(
    scene: &Scene,
    polled: bool,
    reset_after_first_step: bool,
    target: Option<f64>,
) -> (PathTracer, u64) {
    let mut tracer = PathTracer::new(common::gpu(), scene).expect("path tracer builds");
    tracer.set_chunk_aligned_passes(true);
    if let Some(target) = target {
        tracer.set_target_seconds(target);
    }
    if polled {
        tracer.set_readback(Readback::Polled);
    }
    if reset_after_first_step {
        let first = tracer.render_step(Some(CAUSTIC_SPP)).expect("a step");
        assert_eq!(first.samples, 0, "a polled first step only submits the caustic's frames");
        tracer.reset();
    }
    let mut waits = 0u64;
    while tracer.spp_done() < CAUSTIC_SPP {
        if tracer.render_step(Some(CAUSTIC_SPP)).expect("a step").samples == 0 {
            waits += 1;
            std::thread::yield_now();
        }
    }
    (tracer, waits)
}

/// The statistics of two renders agree bit for bit: every pixel's f64 sum, sum of squares and
/// count, and the dropped totals.
fn assert_identical(a: &PathTracer, b: &PathTracer, what: &str) {
    let (a, b) = (a.accumulator().state(), b.accumulator().state());
    assert_eq!(a.dropped, b.dropped, "{what}: dropped samples differ");
    assert_eq!(a.count, b.count, "{what}: sample counts differ");
    for (pixel, (x, y)) in a.sum.iter().zip(b.sum).enumerate() {
        let bits = |v: &[f64; 3]| v.map(f64::to_bits);
        assert_eq!(bits(x), bits(y), "{what}: pixel {pixel}'s sum {x:?} vs {y:?}");
    }
    for (pixel, (x, y)) in a.sum_sq.iter().zip(b.sum_sq).enumerate() {
        let bits = |v: &[f64; 3]| v.map(f64::to_bits);
        assert_eq!(bits(x), bits(y), "{what}: pixel {pixel}'s sum of squares {x:?} vs {y:?}");
    }
}

/// What the web viewer does with the Whitted scene: the caustic's frames read back by polling
/// (dispatch by dispatch, over several steps) give the very image of the blocking readback.
#[test]
fn polled_caustic_frames_give_the_blocking_image_bit_for_bit() {
    let scene = caustic_scene(true);
    let (waited, _) = render_caustic(&scene, false, false);
    assert!(waited.caustics(), "scenes/whitted.toml turns the light tracer on");
    let (polled, waits) = render_caustic(&scene, true, false);
    println!("polled: {waits} steps returned before their caustic frames or band were back");
    // Each pass's first step submits its caustic frames and returns without samples.
    assert!(waits >= 2, "{waits} steps without samples over at least two passes");
    assert_eq!(polled.spp_done(), CAUSTIC_SPP);
    assert_identical(&waited, &polled, "polled against waited, caustics on");

    // A reset while the first pass's caustic frames are in flight drops them.
    let (reset, _) = render_caustic(&scene, true, true);
    assert_identical(&waited, &reset, "reset with caustic frames in flight against a fresh render");

    // The light tracer did add its caustic: without it the image is another.
    let (plain, _) = render_caustic(&caustic_scene(false), true, false);
    assert!(!plain.caustics());
    let mean = |t: &PathTracer| t.accumulator().mean_image().mean_luminance();
    println!("image mean luminance: {:.6} with the caustic, {:.6} without", mean(&waited), mean(&plain));
    assert_ne!(mean(&waited), mean(&plain), "the caustic's frames changed nothing");
}

/// Every caller's steps are sized to its time target, the light tracer's too
/// (`tracer/caustic/schedule.rs`): a target shorter than any frame cuts every frame into pieces
/// of one workgroup (its particles, then its gather: 15 each at this size), one per step, so a
/// render's loop, a signal's answer and a viewer's window wait for one piece, never a pass's
/// frames. A target without limit packs whole frames, as many as the buffers hold, once a
/// frame's cost is known (the first frame goes in pieces of the probe's size, one per stage at
/// this size). The image is the same bit for bit.
#[test]
fn a_time_target_traces_the_caustic_in_pieces_with_the_same_image() {
    let scene = caustic_scene(true);
    let (whole, whole_waits) = render_caustic_aiming_at(&scene, false, false, Some(f64::INFINITY));
    let (waited, waits) = render_caustic_aiming_at(&scene, false, false, Some(1e-9));
    println!("steps without samples: {whole_waits} without a limit, {waits} with a target of 1 ns");
    assert!(whole_waits < u64::from(CAUSTIC_SPP), "without a limit a step traces many frames at once");
    assert!(waits > 2 * u64::from(CAUSTIC_SPP), "with it, several steps per caustic frame");
    assert_identical(&whole, &waited, "pieces of one workgroup against whole frames");
    let (polled, polled_waits) = render_caustic_aiming_at(&scene, true, false, Some(1e-9));
    println!("polled with a target: {polled_waits} steps without samples");
    assert!(
        polled_waits > 2 * u64::from(CAUSTIC_SPP),
        "{polled_waits} polled steps for {CAUSTIC_SPP} frames"
    );
    assert_identical(&whole, &polled, "polled, one frame per dispatch, against whole passes");
}
