//! The anti-aliased edges of two or more rasterizer images compared, pixel by pixel.
//!
//! ```text
//! cargo run --release --example raster_edge_error -- --jagged J.exr IMAGE.exr ... [--reference R.exr]
//! ```
//! `--jagged`: the same frame without anti-aliasing (`render ... --no-antialiasing`), which says
//! where the edges are: a pixel is an edge pixel when some IMAGE differs from it there by more
//! than 2 levels. Each IMAGE (e.g. the analytic anti-aliasing, and 4x MSAA from an older build)
//! is compared with every other and with `--reference`: the same frame rendered at k times the
//! width and height without anti-aliasing and box-filtered down here by k x k (k = 4: 16x
//! supersampling). For each pair it prints, in 8-bit levels of each pixel's largest channel
//! difference, the mean and the largest difference over edge pixels and where the largest is,
//! and the mean over all pixels. docs/performance-raster.md has the figures.

use std::path::PathBuf;

use anyhow::{Context, ensure};
use clap::Parser;
use illum::image::{RgbImage32, load_exr};

#[derive(Parser, Debug)]
#[command(
    about = "Compare the anti-aliased edges of rasterizer images (EXR) pixel by pixel, with each other and with a \
             supersampled reference: mean and largest 8-bit differences over the edge pixels"
)]
struct Args {
    /// The frame without anti-aliasing, at the images' size.
    #[arg(long)]
    jagged: PathBuf,
    /// A supersampled frame (k times the size, no anti-aliasing) to box-filter down.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// The images to compare (EXR, same size as --jagged).
    images: Vec<PathBuf>,
}

fn load(path: &PathBuf) -> anyhow::Result<RgbImage32> {
    Ok(load_exr(path).with_context(|| path.display().to_string())?.0)
}

/// `image` box-filtered by an integer factor down to `width` x `height`.
fn downsample(image: &RgbImage32, width: u32, height: u32) -> anyhow::Result<RgbImage32> {
    let k = image.width / width;
    ensure!(
        k >= 1 && image.width == k * width && image.height == k * height,
        "the reference is not k x the size"
    );
    Ok(RgbImage32::from_fn(width, height, |x, y| {
        let mut sum = [0.0f64; 3];
        for j in 0..k {
            for i in 0..k {
                let p = image.get(x * k + i, y * k + j);
                for c in 0..3 {
                    sum[c] += f64::from(p[c]);
                }
            }
        }
        sum.map(|s| (s / f64::from(k * k)) as f32)
    }))
}

/// The largest channel difference of a pixel, in levels.
fn diff(a: &RgbImage32, b: &RgbImage32, x: u32, y: u32) -> f64 {
    let (p, q) = (a.get(x, y), b.get(x, y));
    (0..3).map(|c| f64::from((p[c] - q[c]).abs()) * 255.0).fold(0.0, f64::max)
}

fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    let jagged = load(&args.jagged)?;
    let (w, h) = (jagged.width, jagged.height);
    let mut named: Vec<(String, RgbImage32)> = Vec::new();
    for path in &args.images {
        let image = load(path)?;
        ensure!((image.width, image.height) == (w, h), "{}: not {w} x {h}", path.display());
        named.push((path.display().to_string(), image));
    }
    let mut edge = vec![false; (w * h) as usize];
    let mut edges = 0;
    for y in 0..h {
        for x in 0..w {
            if named.iter().any(|(_, image)| diff(image, &jagged, x, y) > 2.0) {
                edge[(y * w + x) as usize] = true;
                edges += 1;
            }
        }
    }
    println!(
        "{w} x {h}: {edges} edge pixels (where an image differs from {} by > 2 levels)",
        args.jagged.display()
    );
    named.push((args.jagged.display().to_string(), jagged));
    if let Some(path) = &args.reference {
        let reference = downsample(&load(path)?, w, h)?;
        named.push((format!("{} box-filtered", path.display()), reference));
    }
    println!("| A | B | edge mean | edge max (at x, y) | all-pixel mean |\n|---|---|---|---|---|");
    for i in 0..named.len() {
        for j in i + 1..named.len() {
            let (a, b) = (&named[i].1, &named[j].1);
            let (mut sum, mut max, mut at, mut all) = (0.0, 0.0, (0, 0), 0.0);
            for y in 0..h {
                for x in 0..w {
                    let d = diff(a, b, x, y);
                    all += d;
                    if edge[(y * w + x) as usize] {
                        sum += d;
                        if d > max {
                            (max, at) = (d, (x, y));
                        }
                    }
                }
            }
            println!(
                "| {} | {} | {:.2} | {:.1} ({}, {}) | {:.3} |",
                named[i].0,
                named[j].0,
                sum / f64::from(edges.max(1)),
                max,
                at.0,
                at.1,
                all / f64::from(w * h)
            );
        }
    }
    Ok(())
}
