//! From linear radiance to 8-bit display values.
//!
//! A display value is made in three steps: scale by the exposure (in stops, so `2^exposure`),
//! apply the display encoding (the inverse of the display's response), then quantise to 8
//! bits. Values outside [0, 1] after scaling are clipped: negative radiance (which only
//! appears through estimator noise) becomes black, over-bright pixels become white. NaN
//! becomes black so that a single bad sample never shows as a bright speck.

use std::fmt;
use std::str::FromStr;

use crate::rgb_image::RgbImage32;

/// How linear values are encoded for an 8-bit display.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Encoding {
    /// A pure power law, `c^(1/2.2)`: the encoding the assignment prescribes.
    #[default]
    Gamma22,
    /// The piecewise sRGB transfer function of IEC 61966-2-1: linear near black (slope 12.92
    /// below 0.0031308), then `1.055 c^(1/2.4) - 0.055`. It is close to gamma 2.2 overall but
    /// differs in the shadows.
    Srgb,
    /// No encoding: the linear value is quantised directly (for data, not for viewing).
    Linear,
}

impl Encoding {
    /// All encodings, in the order they are listed in messages.
    pub const ALL: [Encoding; 3] = [Encoding::Gamma22, Encoding::Srgb, Encoding::Linear];

    /// Applies the encoding to a value already clamped to [0, 1].
    fn apply(self, c: f64) -> f64 {
        match self {
            Encoding::Gamma22 => c.powf(1.0 / 2.2),
            Encoding::Srgb => {
                if c <= 0.003_130_8 {
                    12.92 * c
                } else {
                    1.055 * c.powf(1.0 / 2.4) - 0.055
                }
            }
            Encoding::Linear => c,
        }
    }
}

impl fmt::Display for Encoding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Encoding::Gamma22 => "gamma2.2",
            Encoding::Srgb => "srgb",
            Encoding::Linear => "linear",
        })
    }
}

/// A PNG's exposure: a number of stops, or [`Exposure::Auto`], chosen from the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Exposure {
    Stops(f32),
    /// The stops that bring the median luminance of the pixels that are not black to mid-grey
    /// (0.18): a readable PNG of any scene, however bright its lights (an emission of 1e30
    /// needs about -100 stops).
    Auto,
}

impl Default for Exposure {
    fn default() -> Self {
        Exposure::Stops(0.0)
    }
}

/// The luminance [`Exposure::Auto`] brings the median pixel to.
pub const MID_GREY: f64 = 0.18;
/// Most stops [`Exposure::Auto`] chooses either way: 2^-149 is f32's smallest positive value,
/// which still brings the brightest finite radiance (3.4e38, 2^128) below 1.
pub const MAX_AUTO_STOPS: f64 = 149.0;

impl Exposure {
    /// The stops to apply to `image`. `Auto` over an image with no positive luminance is 0.
    pub fn stops_for(self, image: &RgbImage32) -> f32 {
        match self {
            Exposure::Stops(stops) => stops,
            Exposure::Auto => {
                let mut lit: Vec<f64> = image
                    .pixels
                    .iter()
                    .map(|&p| crate::rgb_image::luminance(p))
                    .filter(|l| *l > 0.0 && l.is_finite())
                    .collect();
                if lit.is_empty() {
                    return 0.0;
                }
                let mid = lit.len() / 2;
                let median = *lit.select_nth_unstable_by(mid, f64::total_cmp).1;
                (MID_GREY / median).log2().clamp(-MAX_AUTO_STOPS, MAX_AUTO_STOPS) as f32
            }
        }
    }
}

impl fmt::Display for Exposure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Exposure::Stops(stops) => write!(f, "{stops}"),
            Exposure::Auto => f.write_str("auto"),
        }
    }
}

/// A string that names no [`Encoding`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown encoding '{given}': expected one of gamma2.2 (or gamma), srgb, linear")]
pub struct ParseEncodingError {
    pub given: String,
}

impl FromStr for Encoding {
    type Err = ParseEncodingError;

    /// Accepts "gamma2.2" or "gamma", "srgb", "linear", ignoring ASCII case and surrounding
    /// white space.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "gamma2.2" | "gamma" => Ok(Encoding::Gamma22),
            "srgb" => Ok(Encoding::Srgb),
            "linear" => Ok(Encoding::Linear),
            _ => Err(ParseEncodingError { given: s.to_owned() }),
        }
    }
}

/// The exposure multiplier `2^exposure` (exposure in stops).
fn exposure_scale(exposure: f32) -> f64 {
    2f64.powf(f64::from(exposure))
}

/// Encodes an already exposure-scaled linear value. Clamping happens before the encoding,
/// which is equivalent to clamping after it (every encoding maps [0, 1] onto [0, 1]
/// monotonically) and keeps `powf` away from negative inputs.
fn encode_scaled(scaled: f64, encoding: Encoding) -> u8 {
    if scaled.is_nan() {
        return 0;
    }
    let encoded = encoding.apply(scaled.clamp(0.0, 1.0));
    // Round to nearest: 255 * encoded lies in [0, 255], so the cast cannot saturate wrongly.
    (255.0 * encoded).round() as u8
}

/// One linear channel value to an 8-bit display value: multiply by `2^exposure`, encode,
/// clamp to [0, 1], round to the nearest of 256 levels. NaN maps to 0, +inf to 255.
pub fn encode_8bit(value_linear: f32, exposure: f32, encoding: Encoding) -> u8 {
    encode_scaled(f64::from(value_linear) * exposure_scale(exposure), encoding)
}

fn encode_pixel(p: [f32; 3], scale: f64, encoding: Encoding) -> [u8; 3] {
    p.map(|c| encode_scaled(f64::from(c) * scale, encoding))
}

/// Tone-maps a linear image to 8-bit RGBA (alpha 255) with [`encode_8bit`]'s rules.
///
/// # Panics
/// When `image.pixels.len() != width * height`.
pub fn to_rgba8(image: &RgbImage32, exposure: f32, encoding: Encoding) -> image::RgbaImage {
    let scale = exposure_scale(exposure);
    image::RgbaImage::from_fn(image.width, image.height, |x, y| {
        let [r, g, b] = encode_pixel(image.get(x, y), scale, encoding);
        image::Rgba([r, g, b, 255])
    })
}

/// Tone-maps a linear image to 8-bit RGB with [`encode_8bit`]'s rules.
///
/// # Panics
/// When `image.pixels.len() != width * height`.
pub fn to_rgb8(image: &RgbImage32, exposure: f32, encoding: Encoding) -> image::RgbImage {
    let scale = exposure_scale(exposure);
    image::RgbImage::from_fn(image.width, image.height, |x, y| {
        image::Rgb(encode_pixel(image.get(x, y), scale, encoding))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Auto exposure brings the median pixel to mid-grey whatever the scale, up to f32's largest
    /// values, and leaves a black image alone.
    #[test]
    fn auto_exposure_brings_the_median_to_mid_grey() {
        for scale in [1e-30f32, 1.0, 1e30, 3e38] {
            // The black pixel does not count: the median of the other four is the third, 0.5.
            let pixels = [0.125f32, 0.25, 0.5, 0.0, 1.0].map(|v| [v * scale; 3]).to_vec();
            let image = RgbImage32 { width: 5, height: 1, pixels };
            let stops = Exposure::Auto.stops_for(&image);
            let shown = 0.5 * f64::from(scale) * 2f64.powf(f64::from(stops));
            assert!(
                (shown / MID_GREY - 1.0).abs() < 1e-3,
                "scale {scale}: {stops} stops show the median as {shown}"
            );
        }
        let black = RgbImage32 { width: 2, height: 1, pixels: vec![[0.0; 3]; 2] };
        assert_eq!(Exposure::Auto.stops_for(&black), 0.0);
        assert_eq!(Exposure::Stops(-2.0).stops_for(&black), -2.0);
    }

    #[test]
    fn gamma22_of_one_half() {
        // 255 * 0.5^(1/2.2) = 186.08
        assert_eq!(encode_8bit(0.5, 0.0, Encoding::Gamma22), 186);
    }

    #[test]
    fn srgb_of_one_half() {
        // 255 * (1.055 * 0.5^(1/2.4) - 0.055) = 187.52
        assert_eq!(encode_8bit(0.5, 0.0, Encoding::Srgb), 188);
        // Linear segment: 255 * 12.92 * 0.001 = 3.29
        assert_eq!(encode_8bit(0.001, 0.0, Encoding::Srgb), 3);
    }

    #[test]
    fn linear_is_plain_quantisation() {
        assert_eq!(encode_8bit(0.5, 0.0, Encoding::Linear), 128); // 127.5 rounds away from 0
        assert_eq!(encode_8bit(0.25, 0.0, Encoding::Linear), 64); // 63.75
    }

    #[test]
    fn clamping_and_non_finite() {
        for enc in Encoding::ALL {
            assert_eq!(encode_8bit(1.7, 0.0, enc), 255, "{enc}");
            assert_eq!(encode_8bit(f32::INFINITY, 0.0, enc), 255, "{enc}");
            assert_eq!(encode_8bit(-0.3, 0.0, enc), 0, "{enc}");
            assert_eq!(encode_8bit(f32::NEG_INFINITY, 0.0, enc), 0, "{enc}");
            assert_eq!(encode_8bit(f32::NAN, 0.0, enc), 0, "{enc}");
            assert_eq!(encode_8bit(0.0, 0.0, enc), 0, "{enc}");
            assert_eq!(encode_8bit(1.0, 0.0, enc), 255, "{enc}");
        }
    }

    #[test]
    fn exposure_is_in_stops() {
        // +1 stop doubles: 0.25 * 2 = 0.5 -> 186 under gamma 2.2.
        assert_eq!(encode_8bit(0.25, 1.0, Encoding::Gamma22), 186);
        assert_eq!(encode_8bit(0.25, 1.0, Encoding::Linear), 128);
        // -2 stops quarters: 2.0 / 4 = 0.5.
        assert_eq!(encode_8bit(2.0, -2.0, Encoding::Linear), 128);
    }

    #[test]
    fn parse_and_display_round_trip() {
        for enc in Encoding::ALL {
            assert_eq!(enc.to_string().parse::<Encoding>().unwrap(), enc);
        }
        assert_eq!("gamma".parse::<Encoding>().unwrap(), Encoding::Gamma22);
        assert_eq!(" SRGB ".parse::<Encoding>().unwrap(), Encoding::Srgb);
        let err = "gamma2.4".parse::<Encoding>().unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("'gamma2.4'") && msg.contains("srgb"), "{msg}");
    }

    #[test]
    fn image_conversion_matches_scalar_rule() {
        let img = RgbImage32::from_fn(2, 1, |x, _| if x == 0 { [0.5, 2.0, -1.0] } else { [0.25; 3] });
        let rgba = to_rgba8(&img, 0.0, Encoding::Gamma22);
        assert_eq!(rgba.get_pixel(0, 0).0, [186, 255, 0, 255]);
        let rgb = to_rgb8(&img, 1.0, Encoding::Gamma22);
        assert_eq!(rgb.get_pixel(1, 0).0, [186, 186, 186]);
    }
}
