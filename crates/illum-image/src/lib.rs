//! Image output, tone mapping and image metrics for illum. No GPU.
//!
//! Everything inside illum is linear radiance in f32 ([`RgbImage32`]). This crate is where
//! that radiance leaves the program:
//!
//! - [`tonemap`]: exposure and the 8-bit display encodings (gamma 2.2, sRGB, linear);
//! - [`mod@png`] and [`mod@exr`]: the two output formats, both written atomically ([`atomic`]), EXR
//!   staying linear and carrying the render settings as text attributes;
//! - [`metrics`]: RMSE, relative MSE, mean-luminance bias and the per-pixel Z-test used to
//!   compare a render with a reference statistically;
//! - [`mod@diff`]: pictures for humans, written when an image test fails.

pub mod atomic;
pub mod diff;
pub mod exr;
pub mod metrics;
pub mod png;
pub mod rgb_image;
pub mod tonemap;

use std::path::PathBuf;

pub use atomic::{check_output, write_atomically};
pub use diff::{DiffImages, save_diff_images};
pub use exr::{
    ExrHeader, ExrMetadata, F32Layer, U32Layer, exr_bytes_with_layers, load_exr, load_exr_header,
    load_f32_layer, load_u32_layer, load_u32_layers, save_exr, save_exr_with_f32_layers,
    save_exr_with_float_layers, save_exr_with_layers,
};
pub use metrics::{
    MetricsError, binomial_critical_count, inverse_normal_cdf, mean_luminance_bias, median, rel_mse, rmse,
    z_test_pass_fraction,
};
pub use png::{png_bytes, save_png, save_rgba8_png};
pub use rgb_image::{RgbImage32, luminance};
pub use tonemap::{Encoding, Exposure, ParseEncodingError, encode_8bit, to_rgb8, to_rgba8};

/// An error while writing or reading an image file. Every variant names the file it concerns.
///
/// The underlying cause (an `io::Error`, a codec error) is kept as the error's `source()`,
/// so `anyhow`'s `{:#}` or `{:?}` prints the whole chain.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// A file-system operation failed; `action` says which one ("creating the directory", ...).
    #[error("{action} for '{}' failed", path.display())]
    Io {
        path: PathBuf,
        action: &'static str,
        #[source]
        source: std::io::Error,
    },
    /// The encoder for `format` rejected the image.
    #[error("encoding '{}' as {format} failed", path.display())]
    Encode {
        path: PathBuf,
        format: &'static str,
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The file could not be read or is not a valid `format` file (for EXR: one with R, G and
    /// B channels).
    #[error("reading '{}' as {format} failed", path.display())]
    Decode {
        path: PathBuf,
        format: &'static str,
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The image (or its metadata) cannot be written as asked: `reason` says what is wrong
    /// and what is allowed.
    #[error("cannot write '{}': {reason}", path.display())]
    Invalid { path: PathBuf, reason: String },
    /// The file was read but its content is not what was expected (for example a metadata
    /// attribute that does not parse).
    #[error("'{}': {reason}", path.display())]
    BadContent { path: PathBuf, reason: String },
}

impl ImageError {
    pub(crate) fn io(path: impl Into<PathBuf>, action: &'static str, source: std::io::Error) -> Self {
        ImageError::Io { path: path.into(), action, source }
    }

    pub(crate) fn invalid(path: impl Into<PathBuf>, reason: impl Into<String>) -> Self {
        ImageError::Invalid { path: path.into(), reason: reason.into() }
    }
}
