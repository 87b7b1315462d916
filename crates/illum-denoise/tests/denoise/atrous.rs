//! The WGSL à-trous filter against its f64 CPU copy (src/reference.rs), pixel by pixel.

use illum_denoise::{AtrousDenoiser, AtrousSettings, DenoiseInput, reference};
use illum_image::RgbImage32;

use crate::common;

/// A noisy image with edges in albedo, normal and radiance, and pixels of every kind of
/// variance: zero (converged), unknown (fewer than 2 samples), and ordinary.
fn synthetic(width: u32, height: u32, seed: u64) -> DenoiseInput {
    // A 64-bit LCG (Knuth's MMIX constants): enough for test noise.
    let mut state = seed;
    let mut uniform = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut image = RgbImage32::new(width, height);
    let mut variance = Vec::new();
    let mut albedo = Vec::new();
    let mut normal = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let left = x < width / 2;
            let top = y < height / 3;
            let base = if left { [0.8, 0.3, 0.2] } else { [0.2, 0.6, 0.9] };
            let noise = 0.3 * (uniform() - 0.5);
            image.pixels[(y * width + x) as usize] = base.map(|b: f64| (b * (1.0 + noise)) as f32);
            // Channels of their own variance, one of them sometimes 0 alone.
            variance.push(match (x + 3 * y) % 17 {
                0 => [0.0; 3],
                1 => [illum_denoise::input::UNKNOWN_VARIANCE; 3],
                2 => [0.0, (0.01 * uniform()) as f32, (0.01 * uniform()) as f32],
                _ => [0; 3].map(|_| (0.01 * uniform()) as f32),
            });
            albedo.push(if left { [0.7, 0.7, 0.7] } else { [0.5, 0.2, 0.2] });
            normal.push(if top {
                [0.0, 0.0, 0.0]
            } else if left {
                [0.0, 1.0, 0.0]
            } else {
                [0.6, 0.8, 0.0]
            });
        }
    }
    DenoiseInput { image, variance, albedo, normal, exact: Default::default() }
}

/// Tolerance: f32 against f64 through five iterations of sums of 25 weighted terms and exps,
/// each within a few units of f32 rounding (6e-8) relative; 1e-4 of the pixel's magnitude
/// (plus 1e-6 absolute) leaves room for the exp of a colour stop amplifying a rounding of its
/// argument by |dL| / scale, which stays below 20 where the weight is not already negligible.
fn assert_matches_f64(input: &DenoiseInput, what: &str) {
    let filter = AtrousDenoiser::new(common::gpu()).expect("compiles");
    let settings = AtrousSettings::default();
    let (gpu_image, gpu_variance) = filter.denoise(input, &settings).expect("denoises");
    let (cpu_image, cpu_variance) = reference::denoise(input, &settings);
    let mut worst = 0.0f64;
    for (p, (g, c)) in gpu_image.pixels.iter().zip(&cpu_image.pixels).enumerate() {
        for k in 0..3 {
            let (g, c) = (f64::from(g[k]), f64::from(c[k]));
            let error = (g - c).abs() / (1e-6 + 1e-4 * c.abs());
            worst = worst.max(error);
            assert!(error <= 1.0, "{what}: pixel {p} channel {k}: GPU {g}, f64 {c}");
        }
        for k in 0..3 {
            let (gv, cv) = (f64::from(gpu_variance[p][k]), cpu_variance[p][k]);
            assert!(
                (gv - cv).abs() <= 1e-3 * cv.abs() + 1e-12,
                "{what}: pixel {p} channel {k} variance: GPU {gv}, f64 {cv}"
            );
        }
    }
    println!("{what}: worst |GPU - f64| / tolerance = {worst:.3}");
}

#[test]
fn the_gpu_filter_matches_its_f64_copy_on_a_synthetic_image() {
    // 37 x 29: odd sizes, partial workgroups, taps clipped at every border.
    assert_matches_f64(&synthetic(37, 29, 5), "synthetic 37 x 29");
}

#[test]
fn the_gpu_filter_matches_its_f64_copy_on_a_render() {
    let tracer = common::render(&common::cornell(8, 3));
    let guides = tracer.guides(8).expect("guides");
    assert_matches_f64(&DenoiseInput::from_render(tracer.accumulator(), &guides), "Cornell 64 x 64, 8 spp");
}

/// The filter read back without waiting (`AtrousDenoiser::start`, the viewer's) gives the
/// blocking readback's image and variances, bit for bit.
#[test]
fn the_polled_filter_is_the_blocking_one() {
    let input = synthetic(23, 17, 9);
    let filter = AtrousDenoiser::new(common::gpu()).expect("compiles");
    let settings = AtrousSettings::default();
    let blocking = filter.denoise(&input, &settings).expect("denoises");
    let pending = filter.start(&input, &settings).expect("submitted");
    let polled = loop {
        if let Some(result) = pending.poll(common::gpu()) {
            break result.expect("read back");
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    };
    assert!(polled == blocking, "the polled filter differs from the blocking one");
}
