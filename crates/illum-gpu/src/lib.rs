//! illum-gpu: the GPU core shared by both renderers.
//!
//! - [`GpuContext`]: instance, adapter and device creation that works headless on Mesa lavapipe,
//!   honours `WGPU_BACKEND` / `WGPU_ADAPTER_NAME`, and turns "no adapter", device loss and
//!   validation errors into [`GpuError`]s instead of panics or hangs.
//! - [`policy`]: the backends, adapter choice, features and limits, shared with the viewer.
//! - [`buffers`]: buffers, bind groups and compute dispatches every renderer makes alike.
//! - [`readback`]: copy a GPU buffer back to the CPU.
//! - [`timing`]: GPU pass timing with timestamp queries, where the adapter has them.
//! - [`shader`]: WGSL composition (naga_oil) and validation.
//! - `testing` (with the feature `testing`, which the workspace's tests enable): what every crate's GPU
//!   tests share (one device per test binary, paths).

pub mod buffers;
mod context;
mod error;
pub mod policy;
pub mod readback;
pub mod shader;
#[cfg(all(any(test, feature = "testing"), not(target_arch = "wasm32")))]
pub mod testing;
pub mod timing;

pub use context::{DEFAULT_GPU_TIMEOUT, GpuContext};
pub use error::GpuError;
pub use wgpu;
