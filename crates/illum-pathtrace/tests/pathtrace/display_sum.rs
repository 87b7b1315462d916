//! The display sum (the viewer's GPU-resident running image) against the f64 statistics: the
//! same samples, so rgb / w must be the f64 mean up to f32 rounding, and w the sample count. It
//! must follow resets, scene updates and resizes, cover every band of a tiled pass, and refuse an
//! image that does not fit one storage binding.

use illum_gpu::readback;
use illum_pathtrace::{DISPLAY_PIXEL_BYTES, PathTracer, SLOT_BYTES};
use illum_scene::{Overrides, Scene};

use crate::common;

fn cornell(width: u32, height: u32, spp: u32, seed: u32) -> Scene {
    common::scene("cornell", Overrides { seed: Some(seed), ..common::small(width, height, spp) })
}

/// A tracer of the Cornell box at `width` x `height`.
fn tracer(width: u32, height: u32, spp: u32, seed: u32) -> PathTracer {
    PathTracer::new(common::gpu(), &cornell(width, height, spp, seed)).expect("builds")
}

/// The display sum read back: (rgb sum, count) per pixel.
pub(crate) fn read_display_sum(tracer: &PathTracer) -> Vec<[f32; 4]> {
    let buffer = tracer.display_sum_buffer().expect("display sum enabled");
    let camera = tracer.scene().camera;
    let size = u64::from(camera.width) * u64::from(camera.height) * DISPLAY_PIXEL_BYTES;
    assert_eq!(buffer.size(), size, "one vec4<f32> per pixel");
    let bytes = readback::read_buffer(common::gpu(), buffer, 0, size, "reading the display sum back")
        .unwrap_or_else(|e| panic!("{e}"));
    bytes
        .chunks_exact(16)
        .map(|c| {
            std::array::from_fn(|i| f32::from_le_bytes(c[4 * i..4 * i + 4].try_into().expect("4 bytes")))
        })
        .collect()
}

/// Asserts that every pixel's rgb / w is the accumulator's f64 mean within f32 rounding and that
/// w is `spp`. The display sum adds f32 chunk sums in f32, a few roundings of 2^-24 each; 1e-4
/// relative (plus 1e-6 absolute for near-black channels) is far above that and far below any
/// real mismatch, such as a band counted twice or a pixel out of place.
fn assert_matches_statistics(tracer: &PathTracer, spp: u32, what: &str) {
    let acc = tracer.accumulator();
    assert_eq!(acc.dropped_samples(), 0, "{what}: the Cornell box has no NaN samples");
    let display = read_display_sum(tracer);
    let mean = acc.mean_image();
    let width = acc.width as usize;
    let mut worst = 0.0f64;
    for (p, (sum, expected)) in display.iter().zip(&mean.pixels).enumerate() {
        let (x, y) = (p % width, p / width);
        assert_eq!(sum[3], spp as f32, "{what}: pixel ({x}, {y}) has {} samples, not {spp}", sum[3]);
        for c in 0..3 {
            let shown = f64::from(sum[c] / sum[3].max(1.0));
            let exact = f64::from(expected[c]);
            let error = (shown - exact).abs();
            worst = worst.max(error / exact.abs().max(1e-6));
            assert!(
                error <= 1e-4 * exact.abs() + 1e-6,
                "{what}: pixel ({x}, {y}) channel {c}: display mean {shown} vs f64 mean {exact}"
            );
        }
    }
    println!("{what}: display mean within {worst:.2e} (relative) of the f64 mean");
}

#[test]
fn the_display_sum_is_the_mean_of_the_same_samples() {
    let mut tracer = tracer(40, 24, 40, 3);
    tracer.enable_display_sum().expect("a small image fits");
    tracer.enable_display_sum().expect("enabling twice does nothing");
    // Several passes of several chunks each (16 samples per chunk): 16 + 24 spp.
    tracer.add_samples_in_one_pass(16).expect("renders");
    tracer.add_samples_in_one_pass(24).expect("renders");
    assert_matches_statistics(&tracer, 40, "two passes");
}

#[test]
fn enabling_late_starts_from_the_samples_already_taken() {
    let mut tracer = tracer(32, 20, 12, 5);
    assert!(tracer.display_sum_buffer().is_none(), "opt-in: no display sum by default");
    tracer.add_samples_in_one_pass(5).expect("renders");
    tracer.enable_display_sum().expect("a small image fits");
    tracer.add_samples_in_one_pass(7).expect("renders");
    assert_matches_statistics(&tracer, 12, "enabled after 5 spp");
}

#[test]
fn reset_scene_updates_and_resizes_restart_the_display_sum() {
    let mut tracer = tracer(32, 20, 8, 7);
    tracer.enable_display_sum().expect("fits");
    tracer.add_samples_in_one_pass(8).expect("renders");
    assert_matches_statistics(&tracer, 8, "before reset");

    tracer.reset();
    assert!(
        read_display_sum(&tracer).iter().all(|s| *s == [0.0; 4]),
        "reset leaves samples in the display sum"
    );
    tracer.add_samples_in_one_pass(3).expect("renders");
    assert_matches_statistics(&tracer, 3, "after reset");

    // Another camera at the same size: the same buffer, cleared.
    let mut moved = tracer.scene().clone();
    moved.camera.eye.x += 20.0;
    tracer.update_scene(&moved).expect("same geometry");
    assert!(read_display_sum(&tracer).iter().all(|s| *s == [0.0; 4]), "a camera change keeps old samples");
    tracer.add_samples_in_one_pass(4).expect("renders");
    assert_matches_statistics(&tracer, 4, "after a camera change");

    // Another resolution: a new buffer of the new size, still enabled.
    let mut larger = moved.clone();
    larger.camera.width = 44;
    larger.camera.height = 28;
    tracer.update_scene(&larger).expect("same geometry");
    assert!(tracer.display_sum_buffer().is_some(), "a resize must keep the display sum enabled");
    assert!(read_display_sum(&tracer).iter().all(|s| *s == [0.0; 4]), "a resize starts from zero");
    tracer.add_samples_in_one_pass(6).expect("renders");
    assert_matches_statistics(&tracer, 6, "after a resize");
}

#[test]
fn every_band_of_a_tiled_pass_reaches_the_display_sum() {
    // Batch buffers capped at two rows of one chunk: a 32 spp pass (2 chunks) goes one row per
    // submission, an 8 spp pass (1 chunk) two rows per submission.
    let mut tracer = tracer(36, 22, 40, 11);
    tracer.limit_batch_bytes(2 * 36 * SLOT_BYTES).expect("two rows fit");
    tracer.enable_display_sum().expect("fits");
    let mut submissions = 0;
    while tracer.spp_done() < 40 {
        tracer.render_step(Some(40)).expect("renders");
        submissions += 1;
    }
    println!("36 x 22, 40 spp in bands: {submissions} submissions");
    assert!(submissions >= 22, "the capped render was not split into bands ({submissions} submissions)");
    assert_matches_statistics(&tracer, 40, "banded");
}

#[test]
fn an_image_beyond_one_storage_binding_has_no_display_sum() {
    // The smallest image 4096 pixels wide whose display sum (16 bytes per pixel) exceeds the
    // device's storage binding. The tracer itself renders it in bands; only the display sum,
    // which holds the whole image in one binding, is refused, with the limit named.
    let limits = common::gpu().device.limits();
    let binding = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
    let width = 4096u32;
    let height = (binding / (DISPLAY_PIXEL_BYTES * u64::from(width)) + 1) as u32;
    assert!(
        height <= limits.max_texture_dimension_2d,
        "a {width} x {height} image is beyond the texture limit: pick another shape for this device"
    );
    let scene = cornell(width, height, 1, 0);
    let mut tracer = PathTracer::new(common::gpu(), &scene).expect("the tracer itself works in bands");
    let message = tracer.enable_display_sum().expect_err("the display sum cannot fit").to_string();
    println!("{width} x {height}, binding {binding} bytes: {message}");
    assert!(
        message.contains("max_storage_buffer_binding_size")
            && message.contains(&binding.to_string())
            && message.contains(&format!("{width} x {height}")),
        "{message}"
    );
    assert!(tracer.display_sum_buffer().is_none());
}
