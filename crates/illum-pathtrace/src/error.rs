use thiserror::Error;

#[derive(Debug, Error)]
pub enum PathTraceError {
    #[error(transparent)]
    Gpu(#[from] illum_gpu::GpuError),
    #[error(transparent)]
    Scene(#[from] illum_scene::SceneError),
    #[error("scene {scene}: {message}")]
    Unsupported { scene: String, message: String },
}
