//! illum-denoise: denoising the path tracer's images, and measuring what the denoised image's
//! error is rather than assuming it (docs/denoising.md).
//!
//! - [`input`]: what a denoiser reads, gathered from a render: the mean image, the variance of
//!   each pixel's luminance, and the guide buffers (albedo, normal; illum-pathtrace's
//!   `PathTracer::guides`).
//! - [`atrous`]: the edge-avoiding à-trous wavelet filter on the GPU (`shaders/atrous.wgsl`).
//! - [`reference`]: its f64 CPU copy, which the GPU output is tested against pixel by pixel.
//! - `oidn` (cargo feature `oidn`): Intel Open Image Denoise's RT filter on the CPU.
//! - [`denoiser`]: either of them behind one call ([`Denoiser`]).
//! - [`estimate`]: the denoised image's error from two independent halves of the samples.
//! - [`split`]: a render kept as those two halves, on two path tracers.

pub mod atrous;
pub mod denoiser;
mod error;
pub mod estimate;
pub mod input;
#[cfg(feature = "oidn")]
pub mod oidn;
pub mod reference;
// Waits for the GPU: native only (a web page polls instead).
#[cfg(not(target_arch = "wasm32"))]
pub mod split;

pub use atrous::{ATROUS_SHADER, AtrousDenoiser, AtrousSettings, PendingDenoise};
pub use denoiser::{Denoiser, OIDN_BUILT};
pub use error::DenoiseError;
pub use estimate::{HalvesError, halves_rel_mse};
pub use input::DenoiseInput;
#[cfg(not(target_arch = "wasm32"))]
pub use split::SplitRender;

/// The denoisers `render --denoise` knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DenoiserKind {
    /// The edge-avoiding à-trous filter ([`atrous`]): runs wherever illum runs.
    Atrous,
    /// Intel Open Image Denoise's RT filter (only in builds with the cargo feature `oidn`).
    Oidn,
}

impl std::str::FromStr for DenoiserKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "atrous" => Ok(DenoiserKind::Atrous),
            "oidn" => Ok(DenoiserKind::Oidn),
            other => Err(format!("'{other}' is not a denoiser: use atrous or oidn")),
        }
    }
}

impl std::fmt::Display for DenoiserKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            DenoiserKind::Atrous => "atrous",
            DenoiserKind::Oidn => "oidn",
        })
    }
}
