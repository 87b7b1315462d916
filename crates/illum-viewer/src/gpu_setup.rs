//! How eframe creates its wgpu device, so that the renderers can share it.
//!
//! egui-wgpu's default asks for `wgpu::Limits::default()` and no features. The path tracer
//! wants what `illum_gpu::GpuContext::new` asks for: the adapter's own limits (large storage
//! buffers let big images render in few bands) and timestamp queries where the adapter has
//! them (the raster panel's GPU time per pass). GL is left out: the path tracer needs compute.

use std::sync::Arc;

use egui_wgpu::{WgpuSetup, WgpuSetupCreateNew, wgpu};

/// The device setup for the viewer window. `prefer_cpu` picks a software adapter (lavapipe)
/// when there is one, as the tests do so that snapshots come from the driver that made them.
pub fn wgpu_setup(prefer_cpu: bool) -> WgpuSetup {
    let mut setup = WgpuSetupCreateNew::without_display_handle();
    setup.instance_descriptor.backends = wgpu::Backends::from_env()
        .unwrap_or(wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12);
    if prefer_cpu {
        setup.native_adapter_selector = Some(Arc::new(|adapters, _surface| {
            let mut sorted: Vec<&wgpu::Adapter> = adapters.iter().collect();
            sorted.sort_by_key(|a| a.get_info().device_type != wgpu::DeviceType::Cpu);
            sorted.first().map(|a| (*a).clone()).ok_or_else(|| {
                "no GPU adapter found; on Debian/Ubuntu install lavapipe with \
                 `apt-get install mesa-vulkan-drivers`"
                    .to_owned()
            })
        }));
    }
    setup.device_descriptor = Arc::new(|adapter| {
        let mut required_features = wgpu::Features::empty();
        if adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            required_features |= wgpu::Features::TIMESTAMP_QUERY;
        }
        wgpu::DeviceDescriptor {
            label: Some("illum viewer device"),
            required_features,
            required_limits: adapter.limits(),
            ..Default::default()
        }
    });
    WgpuSetup::CreateNew(setup)
}
