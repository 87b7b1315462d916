//! The device policy: which backends, which adapter, and which features and limits illum asks
//! for. One copy, used by [`crate::GpuContext::new`] (headless) and by the viewer, whose device
//! eframe creates through these functions, so that both renderers get the same device anywhere.

use crate::error::GpuError;

/// The backends illum tries: `WGPU_BACKEND` when set, else Vulkan, Metal and DX12. GL is left
/// out because the path tracer needs compute shaders.
#[cfg(not(target_arch = "wasm32"))]
pub fn backends() -> wgpu::Backends {
    wgpu::Backends::from_env()
        .unwrap_or(wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12)
}

/// In the browser: WebGPU only. WebGL has no compute shaders, so a browser without WebGPU gets
/// the page's explanation instead of a half-working viewer.
#[cfg(target_arch = "wasm32")]
pub fn backends() -> wgpu::Backends {
    wgpu::Backends::BROWSER_WEBGPU
}

/// Whether to prefer a software adapter (lavapipe) over a hardware one: under CI (`CI` set), so
/// that reference images and snapshots are compared on the driver that made them.
pub fn prefer_software_from_env() -> bool {
    std::env::var_os("CI").is_some()
}

/// What illum asks of a device on `adapter`: timestamp queries where the adapter has them (GPU
/// time per pass), mappable storage buffers where the GPU shares the host's memory (see
/// [`shares_host_memory`]), and the adapter's own limits (large storage buffers are what let big
/// renders proceed in few bands; the resolution checks report against these same limits).
pub fn device_descriptor(adapter: &wgpu::Adapter, label: &'static str) -> wgpu::DeviceDescriptor<'static> {
    let mut required_features = wgpu::Features::empty();
    if adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
        required_features |= wgpu::Features::TIMESTAMP_QUERY;
    }
    if shares_host_memory(adapter.get_info().device_type)
        && adapter.features().contains(wgpu::Features::MAPPABLE_PRIMARY_BUFFERS)
    {
        required_features |= wgpu::Features::MAPPABLE_PRIMARY_BUFFERS;
    }
    wgpu::DeviceDescriptor {
        label: Some(label),
        required_features,
        required_limits: adapter.limits(),
        experimental_features: wgpu::ExperimentalFeatures::disabled(),
        memory_hints: wgpu::MemoryHints::Performance,
        trace: wgpu::Trace::Off,
    }
}

/// Whether a device of this type computes in the host's own memory (a software driver such as
/// lavapipe, or an integrated GPU). There the path tracer maps the buffers its shader wrote
/// instead of copying them into a staging buffer first (`MAPPABLE_PRIMARY_BUFFERS`): at 1024 x
/// 1024 that copy is 32 MB per band. On a discrete GPU mappable storage buffers would live in
/// slow host-visible memory, so there the copy stays.
pub fn shares_host_memory(device_type: wgpu::DeviceType) -> bool {
    matches!(device_type, wgpu::DeviceType::Cpu | wgpu::DeviceType::IntegratedGpu)
}

/// Picks the adapter. `WGPU_ADAPTER_NAME` picks one by case-insensitive substring. Otherwise a
/// discrete GPU is preferred, then an integrated one, then any other hardware adapter, then a
/// software one; `prefer_software` puts software adapters first. With no adapter at all the
/// error names the driver to install.
pub fn choose_adapter(
    adapters: Vec<wgpu::Adapter>,
    backends: wgpu::Backends,
    prefer_software: bool,
) -> Result<wgpu::Adapter, GpuError> {
    if adapters.is_empty() {
        return Err(GpuError::NoAdapter { backends: format!("{backends:?}") });
    }
    let describe = |adapters: &[wgpu::Adapter]| {
        adapters
            .iter()
            .map(|a| {
                let info = a.get_info();
                format!("{:?} ({:?})", info.name, info.backend)
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Ok(wanted) = std::env::var("WGPU_ADAPTER_NAME") {
        let needle = wanted.to_lowercase();
        let available = describe(&adapters);
        return adapters
            .into_iter()
            .find(|a| a.get_info().name.to_lowercase().contains(&needle))
            .ok_or(GpuError::AdapterNotFound { wanted, available });
    }
    let rank = |a: &wgpu::Adapter| {
        let t = a.get_info().device_type;
        let software = t == wgpu::DeviceType::Cpu;
        match (prefer_software, software, t) {
            (true, true, _) => 0,
            (_, false, wgpu::DeviceType::DiscreteGpu) => 1,
            (_, false, wgpu::DeviceType::IntegratedGpu) => 2,
            (_, false, _) => 3,
            (false, true, _) => 4,
        }
    };
    Ok(adapters.into_iter().min_by_key(rank).expect("checked non-empty above"))
}
