//! The à-trous filter of `shaders/atrous.wgsl` in f64 on the CPU, term for term: what the GPU's
//! output is tested against (tests/atrous.rs), and the definition in plain Rust.

use illum_image::RgbImage32;

use crate::atrous::AtrousSettings;
use crate::input::DenoiseInput;
use crate::spread::filter_variance;
use crate::stops::{TINY, normal_weight, unit_normals};

/// One pixel of a pass: its colour and its channels' variances.
type Pixel = ([f64; 3], [f64; 3]);

/// The filtered image and the variance of each pixel's channels after the last iteration.
pub fn denoise(input: &DenoiseInput, settings: &AtrousSettings) -> (RgbImage32, Vec<[f64; 3]>) {
    let (width, height) = (input.width() as i64, input.height() as i64);
    let variance = filter_variance(input, settings.sigma_albedo);
    let mut current: Vec<Pixel> =
        input.image.pixels.iter().zip(&variance).map(|(c, v)| (c.map(f64::from), v.map(f64::from))).collect();
    let albedo: Vec<[f64; 3]> = input.albedo.iter().map(|a| a.map(f64::from)).collect();
    let normal: Vec<[f64; 4]> = unit_normals(&input.normal).iter().map(|n| n.map(f64::from)).collect();
    let sigma_albedo = f64::from(settings.sigma_albedo);
    for iteration in 0..settings.iterations {
        let step = 1i64 << iteration;
        let index = |x: i64, y: i64| (y * width + x) as usize;
        let mut next = Vec::with_capacity(current.len());
        for y in 0..height {
            for x in 0..width {
                let p = index(x, y);
                let (cp, vp) = current[p];
                let mut blurred = [0.0; 3];
                for dy in -1i64..=1 {
                    for dx in -1i64..=1 {
                        let q = index((x + dx).clamp(0, width - 1), (y + dy).clamp(0, height - 1));
                        let w = ((2 - dx.abs()) * (2 - dy.abs())) as f64 / 16.0;
                        for (b, v) in blurred.iter_mut().zip(current[q].1) {
                            *b += w * v;
                        }
                    }
                }
                let scale: [f64; 3] = std::array::from_fn(|k| {
                    f64::from(settings.sigma_colour) * vp[k].min(blurred[k]).sqrt() + TINY
                });
                let (mut sum, mut weights, mut variance) = ([0.0; 3], [0.0; 3], [0.0; 3]);
                for j in -2i64..=2 {
                    for i in -2i64..=2 {
                        let (qx, qy) = (x + i * step, y + j * step);
                        if qx < 0 || qy < 0 || qx >= width || qy >= height {
                            continue;
                        }
                        let q = index(qx, qy);
                        let (c, v) = current[q];
                        let da: f64 = (0..3).map(|k| (albedo[p][k] - albedo[q][k]).powi(2)).sum();
                        let shared = kernel(i)
                            * kernel(j)
                            * normal_weight(normal[p], normal[q])
                            * (-da / (sigma_albedo * sigma_albedo)).exp();
                        for k in 0..3 {
                            let w = shared * (-(cp[k] - c[k]).abs() / scale[k]).exp();
                            sum[k] += w * c[k];
                            weights[k] += w;
                            variance[k] += w * w * v[k];
                        }
                    }
                }
                next.push((
                    std::array::from_fn(|k| sum[k] / weights[k]),
                    std::array::from_fn(|k| variance[k] / (weights[k] * weights[k])),
                ));
            }
        }
        current = next;
    }
    let image = RgbImage32 {
        width: input.width(),
        height: input.height(),
        pixels: current.iter().map(|(c, _)| c.map(|v| v as f32)).collect(),
    };
    (image, current.iter().map(|&(_, v)| v).collect())
}

/// The B3 spline's taps at offsets -2..2.
fn kernel(i: i64) -> f64 {
    [0.0625, 0.25, 0.375, 0.25, 0.0625][(i + 2) as usize]
}
