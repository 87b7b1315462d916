//! Whether a Whitted image agrees with this crate's f64 copy of the algorithm
//! ([`WhittedOracle`]), pixel by pixel: the one criterion of every test that compares a GPU
//! Whitted image with it.
//!
//! Both are deterministic, so the only differences are f32 rounding and what it can flip:
//!
//! - **Tolerance.** A pixel agrees when each channel is within [`tolerance`] of the oracle's,
//!   relative to the larger of 1 and the oracle's value: f32's unit roundoff u = 2^-24 times
//!   [`ROUNDINGS_PER_BOUNCE`] for each of the depth + 1 segments of a ray's tree.
//! - **Edges.** A ray that grazes an edge (a silhouette, a shadow's boundary, a tile's border,
//!   directly or after bounces) can fall on the other side in f32, which changes that ray's
//!   whole colour. A pixel beyond the tolerance is allowed only where the oracle shows such an
//!   edge: moving the pixel's rays by [`EDGE_MOVE`] of a pixel (more than f32 and the spawn
//!   offsets move them, far less than any smooth change of the image across it) changes the
//!   oracle's rays, each counted at its share of the pixel and at the largest change of any
//!   move, by at least half the pixel's difference together ([`edge_change`]). Such pixels are
//!   at most [`MAX_EDGE_FRACTION`] of the image.
//!
//! [`power`] shows the criterion's power on an image: it must fail the image with a small local
//! error where the oracle's image is smooth.

use illum_image::RgbImage32;

use crate::WhittedOracle;

/// f32's unit roundoff, 2^-24.
pub const U: f64 = f32::EPSILON as f64 / 2.0;

/// Roundings a colour carries per segment of a ray's tree, as a bound: a segment is a ray
/// set up, intersected (a normalised direction, a quadratic with one square root, a hit point
/// and its normal: about 40 operations on values of the scene's size), shaded (dot products,
/// a half vector, Fresnel: about 40 more) and its colour added to its parent's. The highlight
/// raises a cosine to the shininess (100 on the glass), which multiplies that cosine's
/// relative error by 100, and is computed by `pow` (exp2 of log2, a few ulp each): about 250
/// in all. Measured, the largest is 203 u at depth 0 (the glass's highlight on the Whitted
/// scene) and 2.6e-4 at depth 64; twice the estimate leaves room for another driver's `pow`.
/// The error adds over the segments of the tree.
pub const ROUNDINGS_PER_BOUNCE: f64 = 512.0;

/// The largest difference of a channel, relative to the larger of 1 and the oracle's value,
/// that f32 rounding explains in a pixel whose rays follow `depth` bounces:
/// (depth + 1) x 512 x 2^-24, 3.1e-5 at depth 0 and 2.7e-4 at depth 8.
pub fn tolerance(depth: u32) -> f64 {
    f64::from(depth + 1) * ROUNDINGS_PER_BOUNCE * U
}

/// How far a pixel's rays are moved, in pixels, to find an edge under it. f32 rounding moves a
/// camera ray's point on the film by about 1e-5 pixel here, but a new ray starts off its surface
/// by the shape's error bound (2^-18 of its size: 1.1e-4 units on the Whitted scene's 30-unit
/// floor, whose pixels are 0.03 to 0.1 units wide at 160 x 90), so a shadow ray or a bounce can
/// start up to 4e-3 pixel from the oracle's; 1e-2 pixel covers that. A smooth image changes
/// across it by 1e-2 of its change across a pixel.
pub const EDGE_MOVE: f64 = 1e-2;

/// The most pixels that may differ beyond the tolerance at an edge: edges are lines, and a ray
/// must pass within f32's reach of one, so such pixels are few (measured: at most 15 of 14400 on
/// the Whitted scene, 11 of 5184 in the extremes, 1 of 4096 on the Cornell box); 0.5% is 72 of
/// 14400.
pub const MAX_EDGE_FRACTION: f64 = 0.005;

/// What a comparison found.
#[derive(Debug)]
pub struct Comparison {
    pub pixels: usize,
    /// Pixels beyond the tolerance at an edge.
    pub edges: usize,
    /// Pixels beyond the tolerance with no edge to explain them: (x, y, difference).
    pub unexplained: Vec<(u32, u32, f64)>,
    /// The largest difference among the pixels within the tolerance.
    pub worst_within: f64,
}

impl Comparison {
    /// No difference beyond the tolerance without an edge, and few at edges.
    pub fn passes(&self) -> bool {
        self.unexplained.is_empty() && self.edges as f64 <= MAX_EDGE_FRACTION * self.pixels as f64
    }

    /// What it found, in one line, for a comparison at `depth`.
    pub fn summary(&self, depth: u32) -> String {
        format!(
            "{} of {} pixels at edges beyond {:.1e}, unexplained {:?}, largest difference within it {:.2e}",
            self.edges,
            self.pixels,
            tolerance(depth),
            self.unexplained,
            self.worst_within
        )
    }
}

/// The largest difference of a channel between `a` and the oracle's `o`, relative to the
/// larger of 1 and the oracle's value.
pub fn difference(a: [f64; 3], o: [f64; 3]) -> f64 {
    (0..3).map(|c| (a[c] - o[c]).abs() / o[c].max(1.0)).fold(0.0, f64::max)
}

/// Compares `image` with the oracle's `reference` (its render of the same scene), pixel by
/// pixel, as the module's comment says.
pub fn compare(image: &RgbImage32, reference: &[[f64; 3]], oracle: &WhittedOracle, depth: u32) -> Comparison {
    let tolerance = tolerance(depth);
    let mut comparison =
        Comparison { pixels: reference.len(), edges: 0, unexplained: Vec::new(), worst_within: 0.0 };
    for (i, (g, &o)) in image.pixels.iter().zip(reference).enumerate() {
        let d = difference(g.map(f64::from), o);
        if d <= tolerance {
            comparison.worst_within = comparison.worst_within.max(d);
            continue;
        }
        let (x, y) = ((i % image.width as usize) as u32, (i / image.width as usize) as u32);
        if edge_change(oracle, x, y) >= 0.5 * d {
            comparison.edges += 1;
        } else {
            comparison.unexplained.push((x, y, d));
        }
    }
    comparison
}

/// The largest difference the rays of pixel (x, y) at edges can make to it: for each ray, the
/// largest change of its colour when the rays move by [`EDGE_MOVE`] along either axis, at its
/// share of the pixel (1 / aa²), summed over the rays.
///
/// Summed, because f32 can flip several of a pixel's rays at once: an edge whose image passes
/// through two of a pixel's ray positions (a floor tile's border running toward the vanishing
/// point along the pixel's diagonal) is crossed by both together, and the pixel differs by both
/// shares. Each ray counts once, at its own largest change, so rays that one move carries across
/// an edge one way and another the other do not cancel.
pub fn edge_change(oracle: &WhittedOracle, x: u32, y: u32) -> f64 {
    let rays = oracle.rays_moved(x, y, 0.0, 0.0);
    let share = 1.0 / rays.len() as f64;
    let mut largest = vec![0.0f64; rays.len()];
    for (dx, dy) in [(EDGE_MOVE, 0.0), (-EDGE_MOVE, 0.0), (0.0, EDGE_MOVE), (0.0, -EDGE_MOVE)] {
        let moved = oracle.rays_moved(x, y, dx, dy);
        for ((most, &r), m) in largest.iter_mut().zip(&rays).zip(moved) {
            *most = most.max(difference(m, r));
        }
    }
    share * largest.iter().sum::<f64>()
}

/// The top-left corner of a 4 x 4 block of pixels whose rays change by at most 1e-3 of a pixel
/// when they move (no edge in it, so a 1% error there is not explained by one) and are not
/// black, nearest the image's centre; `None` when the image has none (a black image).
pub fn smooth_block(
    oracle: &WhittedOracle,
    reference: &[[f64; 3]],
    width: u32,
    height: u32,
) -> Option<(u32, u32)> {
    let smooth = |x: u32, y: u32| {
        reference[(y * width + x) as usize].iter().any(|&c| c > 0.05) && edge_change(oracle, x, y) <= 1e-3
    };
    let mut blocks: Vec<(u32, u32)> =
        (0..height - 3).step_by(4).flat_map(|y| (0..width - 3).step_by(4).map(move |x| (x, y))).collect();
    blocks.sort_by_key(|&(x, y)| (2 * x + 4).abs_diff(width) + (2 * y + 4).abs_diff(height));
    blocks.into_iter().find(|&(x0, y0)| (y0..y0 + 4).all(|y| (x0..x0 + 4).all(|x| smooth(x, y))))
}

/// The criterion's power on `image`: the comparison must fail it with a 4 x 4 patch of smooth
/// pixels 3% too bright, and with one of them 1% too bright. `Ok(None)` when the oracle's image
/// has no smooth block that is not black (nothing to brighten); `Err` names an error that passed.
pub fn power(
    image: &RgbImage32,
    reference: &[[f64; 3]],
    oracle: &WhittedOracle,
    depth: u32,
) -> Result<Option<(u32, u32)>, String> {
    let Some((x0, y0)) = smooth_block(oracle, reference, image.width, image.height) else { return Ok(None) };
    let brighten = |pixels: &[(u32, u32)], factor: f32| {
        let mut wrong = image.clone();
        for &(x, y) in pixels {
            let p = &mut wrong.pixels[(y * image.width + x) as usize];
            *p = p.map(|c| c * factor);
        }
        compare(&wrong, reference, oracle, depth)
    };
    let patch: Vec<(u32, u32)> = (y0..y0 + 4).flat_map(|y| (x0..x0 + 4).map(move |x| (x, y))).collect();
    for (what, pixels, factor) in
        [("a 4 x 4 patch 3% too bright", &patch[..], 1.03), ("one pixel 1% too bright", &patch[5..6], 1.01)]
    {
        let wrong = brighten(pixels, factor);
        if wrong.passes() {
            return Err(format!("{what} at ({x0}, {y0}) passes: {wrong:?}"));
        }
    }
    Ok(Some((x0, y0)))
}
