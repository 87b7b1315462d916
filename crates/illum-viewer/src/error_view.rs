//! The path tracer's error view: each pixel's estimated relative standard error
//! (`illum_pathtrace::error_map`, the EXR layer `illum.error`) as a heat map.
//!
//! The scale is logarithmic, from [`LOWEST`] (0.01%, black) to [`HIGHEST`] (100%, pale yellow),
//! one stop of colour per decade (0.1% purple, 1% red, 10% orange): a decade of error is a fixed step, so the same
//! colour means the same error in every image and at every spp. A pixel whose error is not
//! known yet (fewer than two samples, or replicates) shows as [`UNKNOWN`], a blue outside the ramp.
//!
//! [`ramp`] and [`colour_map`] are the colour-map code, shared with the difference view
//! (`difference_view.rs`).
//!
//! The map reads the f64 statistics of every pixel, so it is computed on the CPU and uploaded as
//! an egui texture, and only while the view is on (the image itself never leaves the GPU).

/// The error at the bottom of the scale, and below it.
pub const LOWEST: f32 = 1e-4;
/// The error at the top of the scale, and above it.
pub const HIGHEST: f32 = 1.0;
/// The colour of a pixel whose error is not known yet.
pub const UNKNOWN: [u8; 3] = [40, 90, 200];

/// The ramp's stops, evenly spaced in log10(error): black, purple, red, orange, pale yellow.
const STOPS: [[f32; 3]; 5] =
    [[0.0, 0.0, 0.0], [80.0, 20.0, 120.0], [200.0, 40.0, 60.0], [250.0, 150.0, 30.0], [255.0, 250.0, 190.0]];

/// The colour of relative error `error`.
pub fn heat_colour(error: f32) -> [u8; 3] {
    if !error.is_finite() {
        return UNKNOWN;
    }
    let t =
        ((error.max(LOWEST).log10() - LOWEST.log10()) / (HIGHEST.log10() - LOWEST.log10())).clamp(0.0, 1.0);
    ramp(&STOPS, t)
}

/// The colour at `t` (0 to 1, clamped) of a ramp through `stops` (at least two, evenly
/// spaced), interpolated linearly between neighbours. The error view's and the difference
/// view's colour maps are ramps.
pub fn ramp(stops: &[[f32; 3]], t: f32) -> [u8; 3] {
    let x = t.clamp(0.0, 1.0) * (stops.len() - 1) as f32;
    let i = (x.floor() as usize).min(stops.len() - 2);
    let f = x - i as f32;
    let (a, b) = (stops[i], stops[i + 1]);
    [0, 1, 2].map(|c| (a[c] + (b[c] - a[c]) * f).round() as u8)
}

/// The image of per-pixel `values` (row-major, `width x height`) through `colour`.
pub fn colour_map(
    values: &[f32],
    width: u32,
    height: u32,
    colour: impl Fn(f32) -> [u8; 3],
) -> egui::ColorImage {
    let pixels = values.iter().map(|&v| {
        let [r, g, b] = colour(v);
        egui::Color32::from_rgb(r, g, b)
    });
    egui::ColorImage::new([width as usize, height as usize], pixels.collect())
}

/// The heat map of per-pixel errors `errors` (row-major, `width x height`).
pub fn heat_map(errors: &[f32], width: u32, height: u32) -> egui::ColorImage {
    colour_map(errors, width, height, heat_colour)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brightness(c: [u8; 3]) -> u32 {
        c.iter().map(|&v| u32::from(v)).sum()
    }

    #[test]
    fn the_ramp_brightens_with_the_error_and_is_clamped_at_both_ends() {
        assert_eq!(heat_colour(LOWEST), [0, 0, 0]);
        assert_eq!(heat_colour(0.0), [0, 0, 0]);
        assert_eq!(heat_colour(HIGHEST), [255, 250, 190]);
        assert_eq!(heat_colour(50.0), [255, 250, 190]);
        let mut last = 0;
        for k in 0..=40 {
            let e = LOWEST * 10f32.powf(k as f32 / 10.0);
            let b = brightness(heat_colour(e));
            assert!(b >= last, "{e}: brightness {b} below {last}");
            last = b;
        }
        // A decade is one step of the ramp: 0.1% purple, 1% red, 10% orange.
        assert_eq!(heat_colour(0.001), [80, 20, 120]);
        assert_eq!(heat_colour(0.01), [200, 40, 60]);
        assert_eq!(heat_colour(0.1), [250, 150, 30]);
    }

    #[test]
    fn unknown_errors_are_outside_the_ramp() {
        assert_eq!(heat_colour(f32::INFINITY), UNKNOWN);
        assert_eq!(heat_colour(f32::NAN), UNKNOWN);
        let map = heat_map(&[f32::INFINITY, 0.1], 2, 1);
        assert_eq!(map.pixels[0], egui::Color32::from_rgb(UNKNOWN[0], UNKNOWN[1], UNKNOWN[2]));
        assert_eq!(map.size, [2, 1]);
    }
}
