//! illum-denoise: denoising the path tracer's images, and measuring what the denoised image's
//! error is rather than assuming it (docs/denoising.md).
//!
//! - [`input`]: what a denoiser reads, gathered from a render: the mean image, the variance of
//!   each pixel's channels, and the guide buffers (albedo, normal; illum-pathtrace's
//!   `PathTracer::guides`).
//! - [`atrous`]: the edge-avoiding à-trous wavelet filter on the GPU (`shaders/atrous.wgsl`).
//! - [`reference`]: its f64 CPU copy, which the GPU output is tested against pixel by pixel.
//! - [`spread`]: the variance its colour stop reads where a pixel's own is unknown (1 spp).
//! - `oidn` (cargo feature `oidn`): Intel Open Image Denoise's RT filter on the CPU.
//! - [`bound`]: what any denoiser may do to a pixel: stay within 3.29 standard errors of its
//!   noisy value, channel by channel (applied to every denoiser's output).
//! - [`denoiser`]: either of them behind one call ([`Denoiser`]), bounded.
//! - [`estimate`]: the denoised image's error from two independent halves of the samples.
//! - [`split`]: a render kept as those two halves, on two path tracers.

pub mod atrous;
pub mod bound;
pub mod denoiser;
mod error;
pub mod estimate;
pub mod input;
#[cfg(feature = "oidn")]
pub mod oidn;
pub mod reference;
pub mod spread;
mod stops;
// Waits for the GPU: native only (a web page polls instead).
#[cfg(not(target_arch = "wasm32"))]
pub mod split;

pub use atrous::{ATROUS_SHADER, AtrousDenoiser, AtrousSettings, PendingDenoise};
pub use bound::{BOUND_Z, bound};
pub use denoiser::{Denoiser, OIDN_BUILT};
pub use error::DenoiseError;
pub use estimate::{HalvesError, halves_rel_mse};
/// The denoisers `render --denoise` knows; named in illum-scene beside the other render
/// settings, so that the planner of `--renderer auto` can name them without this crate.
pub use illum_scene::DenoiserKind;
pub use input::DenoiseInput;
#[cfg(not(target_arch = "wasm32"))]
pub use split::SplitRender;
