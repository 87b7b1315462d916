use thiserror::Error;

#[derive(Debug, Error)]
pub enum PathTraceError {
    #[error(transparent)]
    Gpu(#[from] illum_gpu::GpuError),
    #[error(transparent)]
    Scene(#[from] illum_scene::SceneError),
    #[error("scene {scene}: {message}")]
    Unsupported { scene: String, message: String },
    #[error(
        "the GPU returned {found} of the {expected} samples of a chunk: the driver ended the shader \
         early (lavapipe stops an invocation after 65535 loop iterations); use fewer samples per \
         chunk (PathTracer::set_chunk_samples) or fewer bounces"
    )]
    IncompleteBatch { expected: u32, found: u64 },
}
