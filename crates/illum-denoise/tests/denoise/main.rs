//! GPU tests of the denoiser, in one test binary that shares one device on lavapipe.
//!
//! - `atrous`: the WGSL filter against its f64 CPU copy, pixel by pixel; its constants;
//! - `guides`: the path tracer's guide buffers against the scene's albedos and normals;
//! - `quality`: a converged image is left within its noise, a furnace's flat region keeps its
//!   mean, the 16-spp Cornell box's error falls by the stated factor (with its per-region
//!   bias), and the halves' error estimate tracks the true error from 2 to 1024 spp;
//! - `oidn` (cargo feature `oidn` only): Open Image Denoise beside à-trous on the 16-spp
//!   Cornell box, its cost, and the halves' estimate of its error.

mod atrous;
mod common;
mod guides;
#[cfg(feature = "oidn")]
mod oidn;
mod quality;
