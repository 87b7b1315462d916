//! Copying GPU buffers back to the CPU.
//!
//! Two ways: [`read_buffer`] / [`read_mapped`] / [`with_mapped`] block until the bytes are there
//! (native tools and tests), and [`PendingRead`] starts the mapping and is asked again later,
//! never waiting (the only way a web page can read the GPU: the browser maps the buffer between
//! frames, after the page's code has returned).
//!
//! The blocking functions do not exist on `wasm32`: a wait there would never end, so a caller
//! that could reach one from the web viewer is a compile error rather than a message in a panel.

use std::sync::{Arc, Mutex};

use crate::{GpuContext, GpuError};

/// Reads `size` bytes at `offset` of `source` (which needs `COPY_SRC`). Blocks until done.
/// `offset` and `size` must be multiples of 4 (`wgpu::COPY_BUFFER_ALIGNMENT`).
#[cfg(not(target_arch = "wasm32"))]
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

/// Maps the first `size` bytes of a `MAP_READ` buffer, copies them out and unmaps it. Blocks
/// until done.
#[cfg(not(target_arch = "wasm32"))]
pub fn read_mapped(
    gpu: &GpuContext,
    buffer: &wgpu::Buffer,
    size: u64,
    context: &str,
) -> Result<Vec<u8>, GpuError> {
    with_mapped(gpu, buffer, size, context, <[u8]>::to_vec)
}

/// Maps the first `size` bytes of a `MAP_READ` buffer, gives them to `read` where they lie (no
/// copy: a large batch is folded straight from the mapping) and unmaps it. Blocks until done.
#[cfg(not(target_arch = "wasm32"))]
pub fn with_mapped<R>(
    gpu: &GpuContext,
    buffer: &wgpu::Buffer,
    size: u64,
    context: &str,
    read: impl FnOnce(&[u8]) -> R,
) -> Result<R, GpuError> {
    wait_for_mapping(gpu, buffer, size, context)?;
    read_and_unmap(buffer, size, context, read)
}

/// Asks for the first `size` bytes of `buffer` to be mapped and waits until they are.
#[cfg(not(target_arch = "wasm32"))]
fn wait_for_mapping(
    gpu: &GpuContext,
    buffer: &wgpu::Buffer,
    size: u64,
    context: &str,
) -> Result<(), GpuError> {
    use crate::DEFAULT_GPU_TIMEOUT;
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
    Ok(())
}

/// Gives the mapped first `size` bytes of `buffer` to `read`, then unmaps it.
fn read_and_unmap<R>(
    buffer: &wgpu::Buffer,
    size: u64,
    context: &str,
    read: impl FnOnce(&[u8]) -> R,
) -> Result<R, GpuError> {
    let value = {
        let view = buffer
            .get_mapped_range(0..size)
            .map_err(|e| GpuError::Map { context: context.to_owned(), message: e.to_string() })?;
        read(&view)
    };
    buffer.unmap();
    Ok(value)
}

/// Copies the first `size` bytes out of a mapped buffer and unmaps it.
fn copy_out(buffer: &wgpu::Buffer, size: u64, context: &str) -> Result<Vec<u8>, GpuError> {
    read_and_unmap(buffer, size, context, <[u8]>::to_vec)
}

/// A readback that does not wait: [`PendingRead::start`] asks for the buffer to be mapped, and
/// [`PendingRead::poll`], called again on later frames, returns the bytes once the mapping is
/// done. Dropping it before then abandons the read (the buffer must not be used again until
/// it is unmapped, so callers drop the buffer with it).
pub struct PendingRead {
    buffer: wgpu::Buffer,
    size: u64,
    context: String,
    outcome: Arc<Mutex<Option<Result<(), wgpu::BufferAsyncError>>>>,
}

impl PendingRead {
    /// Starts mapping the first `size` bytes of `buffer` (`MAP_READ`, after the submission
    /// that fills it).
    pub fn start(buffer: wgpu::Buffer, size: u64, context: &str) -> Self {
        let outcome: Arc<Mutex<Option<Result<(), wgpu::BufferAsyncError>>>> = Arc::default();
        let slot = outcome.clone();
        buffer.map_async(wgpu::MapMode::Read, 0..size, move |result| {
            *slot.lock().unwrap_or_else(|p| p.into_inner()) = Some(result);
        });
        PendingRead { buffer, size, context: context.to_owned(), outcome }
    }

    /// `None` while the mapping is under way; then the bytes (and the buffer, unmapped, for
    /// reuse), or the mapping's error. Never waits: natively it polls the device once.
    pub fn poll(&self, gpu: &GpuContext) -> Option<Result<Vec<u8>, GpuError>> {
        // Native wgpu runs map callbacks from poll; in the browser this does nothing and the
        // browser runs them between frames.
        if let Err(e) = gpu.device.poll(wgpu::PollType::Poll) {
            return Some(Err(GpuError::DeviceLost { message: e.to_string() }));
        }
        let outcome = self.outcome.lock().unwrap_or_else(|p| p.into_inner()).take()?;
        Some(
            outcome
                .map_err(|e| GpuError::Map { context: self.context.clone(), message: e.to_string() })
                .and_then(|()| copy_out(&self.buffer, self.size, &self.context)),
        )
    }

    /// The buffer being read, to reuse once [`Self::poll`] returned its bytes (it is unmapped).
    pub fn into_buffer(self) -> wgpu::Buffer {
        self.buffer
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pending read returns exactly the bytes written, after some polls, without a blocking
    /// wait on the mapping.
    #[test]
    fn pending_read_returns_the_bytes() {
        let gpu = match GpuContext::new() {
            Ok(gpu) => gpu,
            Err(e) => panic!("{e}"),
        };
        let data: Vec<u8> = (0..=255u8).collect();
        let source = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("test source"),
            size: data.len() as u64,
            usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        gpu.queue.write_buffer(&source, 0, &data);
        let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("test staging"),
            size: data.len() as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&source, 0, &staging, 0, data.len() as u64);
        gpu.queue.submit([encoder.finish()]);
        let pending = PendingRead::start(staging, data.len() as u64, "test read");
        let bytes = loop {
            if let Some(result) = pending.poll(&gpu) {
                break result.unwrap();
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        };
        assert_eq!(bytes, data);
        // Unmapped again: the buffer takes another copy and reads back again.
        let staging = pending.into_buffer();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&source, 0, &staging, 0, data.len() as u64);
        gpu.queue.submit([encoder.finish()]);
        assert_eq!(read_mapped(&gpu, &staging, data.len() as u64, "test read again").unwrap(), data);
    }
}
