use thiserror::Error;

/// The fix a user needs when Vulkan is missing, named in every "no adapter" error.
pub const VULKAN_DRIVER_FIX: &str = "on Debian/Ubuntu install the software Vulkan driver with \
`apt-get install mesa-vulkan-drivers` (lavapipe), or install your GPU vendor's Vulkan driver";

#[derive(Debug, Error)]
pub enum GpuError {
    #[error("no GPU adapter found (backends tried: {backends}); {VULKAN_DRIVER_FIX}")]
    NoAdapter { backends: String },

    #[error("WGPU_ADAPTER_NAME = {wanted:?} matches no adapter; available adapters: {available}")]
    AdapterNotFound { wanted: String, available: String },

    #[error("could not create a device on adapter {adapter:?}: {message}")]
    RequestDevice { adapter: String, message: String },

    #[error("GPU validation error in {context}: {message}")]
    Validation { context: String, message: String },

    #[error("GPU out of memory in {context}: {message}")]
    OutOfMemory { context: String, message: String },

    #[error("the GPU device was lost ({message}); results since the last completed batch are gone")]
    DeviceLost { message: String },

    #[error(
        "the GPU did not finish {context} within {seconds} s (device hung or far too much work per submission)"
    )]
    Timeout { context: String, seconds: f64 },

    #[error("mapping a GPU buffer for readback failed in {context}: {message}")]
    Map { context: String, message: String },

    #[error("shader {file}: {message}")]
    Shader { file: String, message: String },
}
