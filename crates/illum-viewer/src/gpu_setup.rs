//! How eframe creates its wgpu device, so that the renderers can share it.
//!
//! egui-wgpu's default asks for `wgpu::Limits::default()` and no features. The viewer instead
//! follows illum's one device policy ([`illum_gpu::policy`]), as `GpuContext::new` does: the
//! same backends (no GL: the path tracer needs compute), the same adapter choice
//! (`WGPU_ADAPTER_NAME`, hardware first) and the same features and limits.

use std::sync::Arc;

use egui_wgpu::{WgpuSetup, WgpuSetupCreateNew};
use illum_gpu::policy;

/// The device setup for the viewer window. `prefer_software` picks a software adapter
/// (lavapipe) when there is one, as the tests do so that snapshots come from the driver that
/// made them ([`policy::prefer_software_from_env`] gives the headless renderers' choice).
pub fn wgpu_setup(prefer_software: bool) -> WgpuSetup {
    let mut setup = WgpuSetupCreateNew::without_display_handle();
    setup.instance_descriptor.backends = policy::backends();
    setup.native_adapter_selector = Some(Arc::new(move |adapters, surface| {
        // Only adapters that can present to the window (when there is one yet).
        let usable: Vec<_> =
            adapters.iter().filter(|a| surface.is_none_or(|s| a.is_surface_supported(s))).cloned().collect();
        policy::choose_adapter(usable, policy::backends(), prefer_software).map_err(|e| e.to_string())
    }));
    setup.device_descriptor = Arc::new(|adapter| policy::device_descriptor(adapter, "illum viewer device"));
    WgpuSetup::CreateNew(setup)
}
