//! Copying GPU buffers back to the CPU.

use crate::{GpuContext, GpuError};

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
    gpu.wait_idle(context)?;
    match receiver.try_recv() {
        Ok(Ok(())) => {}
        Ok(Err(e)) => {
            return Err(GpuError::Map { context: context.to_owned(), message: e.to_string() });
        }
        Err(_) => {
            return Err(GpuError::Map {
                context: context.to_owned(),
                message: "the map callback did not run after the device went idle".to_owned(),
            });
        }
    }
    let bytes = {
        let view = buffer
            .get_mapped_range(0..size)
            .map_err(|e| GpuError::Map { context: context.to_owned(), message: e.to_string() })?;
        view.to_vec()
    };
    buffer.unmap();
    Ok(bytes)
}
