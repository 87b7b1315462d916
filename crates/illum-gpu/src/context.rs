//! Adapter and device creation, and the device's error channel.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::error::GpuError;
#[cfg(not(target_arch = "wasm32"))]
use crate::policy;
use crate::shader::ComputePipelineKey;

/// How long any single wait for the GPU may take before it is reported as a hang. Submissions are
/// kept to a fraction of a second, so this is only reached when something is badly wrong.
pub const DEFAULT_GPU_TIMEOUT: Duration = Duration::from_secs(120);

/// A device and queue plus what illum needs to know about them.
///
/// `wgpu::Device` and `wgpu::Queue` are cheap handles, so renderers clone them; the viewer builds
/// a `GpuContext` around eframe's own device with [`GpuContext::from_device`].
#[derive(Clone)]
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter_info: wgpu::AdapterInfo,
    /// True when the device was created with `TIMESTAMP_QUERY`, so passes can be timed on the GPU.
    pub timestamps: bool,
    /// The compute pipelines built on this device (see [`crate::shader::compute_pipeline`]),
    /// shared by the clones of this context and dropped with the last of them.
    pub(crate) compute_pipelines: Arc<Mutex<HashMap<ComputePipelineKey, wgpu::ComputePipeline>>>,
    /// Errors raised outside any error scope (validation, out of memory) and device loss, drained
    /// by [`GpuContext::check`] after each submission.
    errors: Arc<Mutex<Vec<GpuError>>>,
}

impl GpuContext {
    /// Creates a headless device.
    ///
    /// Backends, adapter, features and limits follow [`crate::policy`]: `WGPU_BACKEND` (default:
    /// Vulkan, Metal and DX12), `WGPU_ADAPTER_NAME`, a hardware adapter first except under CI
    /// (`CI` set), where lavapipe is preferred.
    ///
    /// Not on `wasm32`: it waits for the adapter and the device, which a web page cannot do; the
    /// web viewer wraps the browser's device with [`GpuContext::from_device`].
    #[cfg(not(target_arch = "wasm32"))]
    pub fn new() -> Result<Self, GpuError> {
        pollster::block_on(Self::new_async())
    }

    #[cfg(not(target_arch = "wasm32"))]
    async fn new_async() -> Result<Self, GpuError> {
        let mut instance_desc = wgpu::InstanceDescriptor::new_without_display_handle();
        instance_desc.backends = policy::backends();
        // Other WGPU_* variables (validation flags, DX12 compiler, ...) as wgpu reads them.
        let instance_desc = instance_desc.with_env();
        let backends = instance_desc.backends;
        let instance = wgpu::Instance::new(instance_desc);

        let adapters = instance.enumerate_adapters(backends).await;
        let adapter = policy::choose_adapter(adapters, backends, policy::prefer_software_from_env())?;
        let info = adapter.get_info();
        log::info!("GPU adapter: {} ({:?}, {})", info.name, info.backend, info.driver);

        let (device, queue) = adapter
            .request_device(&policy::device_descriptor(&adapter, "illum device"))
            .await
            .map_err(|e| GpuError::RequestDevice { adapter: info.name.clone(), message: e.to_string() })?;
        Ok(Self::from_device(device, queue, info))
    }

    /// Wraps an existing device (for example eframe's), installing illum's error handlers.
    pub fn from_device(device: wgpu::Device, queue: wgpu::Queue, adapter_info: wgpu::AdapterInfo) -> Self {
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let errors: Arc<Mutex<Vec<GpuError>>> = Arc::default();
        {
            let errors = errors.clone();
            device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
                let converted = convert_error("an uncaptured GPU operation", error);
                log::error!("{converted}");
                errors.lock().unwrap_or_else(|p| p.into_inner()).push(converted);
            }));
        }
        {
            let errors = errors.clone();
            device.set_device_lost_callback(move |reason, message| {
                // Dropping the device on purpose also reports "lost"; that is not an error.
                if reason != wgpu::DeviceLostReason::Destroyed {
                    errors
                        .lock()
                        .unwrap_or_else(|p| p.into_inner())
                        .push(GpuError::DeviceLost { message: format!("{reason:?}: {message}") });
                }
            });
        }
        Self { device, queue, adapter_info, timestamps, errors, compute_pipelines: Arc::default() }
    }

    /// Returns the first error the device reported since the last call, if any.
    pub fn check(&self) -> Result<(), GpuError> {
        let mut errors = self.errors.lock().unwrap_or_else(|p| p.into_inner());
        if errors.is_empty() { Ok(()) } else { Err(errors.remove(0)) }
    }

    /// Blocks until all submitted work is done, turning a hang into [`GpuError::Timeout`].
    ///
    /// Not on `wasm32`: in the browser the device's poll returns at once whether or not the work
    /// is done, so a "wait" there would silently not wait.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn wait_idle(&self, context: &str) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::Wait { submission_index: None, timeout: Some(DEFAULT_GPU_TIMEOUT) })
            .map_err(|e| match e {
                wgpu::PollError::Timeout => GpuError::Timeout {
                    context: context.to_owned(),
                    seconds: DEFAULT_GPU_TIMEOUT.as_secs_f64(),
                },
                other => GpuError::DeviceLost { message: other.to_string() },
            })?;
        self.check()
    }

    /// Runs `f` inside validation and out-of-memory error scopes, returning the first error raised.
    /// Used around pipeline and buffer creation, where wgpu reports errors asynchronously.
    ///
    /// In the browser the scopes' results arrive only after control returns to the page, which
    /// cannot be waited for; there `f` runs without scopes and its errors, if any, reach
    /// [`GpuContext::check`] through the uncaptured-error handler a frame later.
    #[cfg(target_arch = "wasm32")]
    pub fn scoped<T>(&self, _context: &str, f: impl FnOnce() -> T) -> Result<T, GpuError> {
        let value = f();
        self.check()?;
        Ok(value)
    }

    /// Runs `f` inside validation and out-of-memory error scopes, returning the first error raised.
    /// Used around pipeline and buffer creation, where wgpu reports errors asynchronously.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn scoped<T>(&self, context: &str, f: impl FnOnce() -> T) -> Result<T, GpuError> {
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let value = f();
        let validation_error = pollster::block_on(validation.pop());
        let oom_error = pollster::block_on(oom.pop());
        if let Some(e) = validation_error.or(oom_error) {
            return Err(convert_error(context, e));
        }
        self.check()?;
        Ok(value)
    }
}

fn convert_error(context: &str, error: wgpu::Error) -> GpuError {
    match error {
        wgpu::Error::OutOfMemory { source } => {
            GpuError::OutOfMemory { context: context.to_owned(), message: source.to_string() }
        }
        wgpu::Error::Validation { description, .. } | wgpu::Error::Internal { description, .. } => {
            GpuError::Validation { context: context.to_owned(), message: description }
        }
    }
}
