use thiserror::Error;

#[derive(Debug, Error)]
pub enum DenoiseError {
    #[error(transparent)]
    Gpu(#[from] illum_gpu::GpuError),
    #[error(transparent)]
    PathTrace(#[from] illum_pathtrace::PathTraceError),
    #[error("{0}")]
    Unsupported(String),
}
