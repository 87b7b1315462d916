//! Copying GPU buffers back to the CPU.

use crate::{DEFAULT_GPU_TIMEOUT, GpuContext, GpuError};

/// Reads `size` bytes at `offset` of `source` (which needs `COPY_SRC`). Blocks until done.
/// `offset` and `size` must be multiples of 4 (`wgpu::COPY_BUFFER_ALIGNMENT`).
pub fn read_buffer(
    gpu: &GpuContext,
    source: &wgpu::Buffer,
    offset: u64,
    size: u64,
    context: &str,
) -> Result<Vec<u8>, GpuError> {
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("illum readback staging"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder =
        gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("illum readback") });
    encoder.copy_buffer_to_buffer(source, offset, &staging, 0, size);
    gpu.queue.submit([encoder.finish()]);
    read_mapped(gpu, &staging, size, context)
}

/// Maps the first `size` bytes of a `MAP_READ` buffer, copies them out and unmaps it.
pub fn read_mapped(
    gpu: &GpuContext,
    buffer: &wgpu::Buffer,
    size: u64,
    context: &str,
) -> Result<Vec<u8>, GpuError> {
    let (sender, receiver) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, 0..size, move |result| {
        // The receiver outlives this callback unless we already returned with an error.
        let _ = sender.send(result);
    });
    // Another thread polling the same device may be the one that runs this callback, and may
    // still be running it when our own wait returns; so wait on the channel, polling again
    // meanwhile, until the callback reports or the overall timeout passes.
    let started = std::time::Instant::now();
    let result = loop {
        gpu.wait_idle(context)?;
        match receiver.recv_timeout(std::time::Duration::from_millis(20)) {
            Ok(result) => break result,
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) if started.elapsed() < DEFAULT_GPU_TIMEOUT => {}
            Err(_) => {
                return Err(GpuError::Timeout {
                    context: format!("{context} (waiting for the buffer to map)"),
                    seconds: DEFAULT_GPU_TIMEOUT.as_secs_f64(),
                });
            }
        }
    };
    result.map_err(|e| GpuError::Map { context: context.to_owned(), message: e.to_string() })?;
    let bytes = {
        let view = buffer
            .get_mapped_range(0..size)
            .map_err(|e| GpuError::Map { context: context.to_owned(), message: e.to_string() })?;
        view.to_vec()
    };
    buffer.unmap();
    Ok(bytes)
}
