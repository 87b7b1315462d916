use thiserror::Error;

/// Why the rasterizer could not render.
#[derive(Debug, Error)]
pub enum RasterError {
    #[error(transparent)]
    Gpu(#[from] illum_gpu::GpuError),
    #[error(transparent)]
    Scene(#[from] illum_scene::SceneError),
    /// The device cannot take what the frame needs; the message names the size and the limit.
    #[error("{0}")]
    Unsupported(String),
}
