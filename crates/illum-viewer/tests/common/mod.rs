//! What the viewer's kittest tests share: one device per test process, as the real window has.
// Each test binary compiles this module and uses a part of it.
#![allow(dead_code)]

use std::sync::OnceLock;

use egui_kittest::Harness;
use illum_scene::RendererKind;
use illum_viewer::gpu_setup::wgpu_setup;
use illum_viewer::{StartOptions, ViewerApp};

/// The one device of this test process (lavapipe when present), created with the viewer's setup.
pub fn shared_device() -> egui_wgpu::WgpuSetupExisting {
    static STATE: OnceLock<egui_wgpu::RenderState> = OnceLock::new();
    let state = STATE.get_or_init(|| {
        egui_kittest::wgpu::create_render_state(wgpu_setup(true), egui_wgpu::RendererOptions::PREDICTABLE)
    });
    egui_wgpu::WgpuSetupExisting {
        instance: state.instance.clone(),
        adapter: state.adapter.clone(),
        device: state.device.clone(),
        queue: state.queue.clone(),
    }
}

/// The viewer at `size` points with `scene` open in `mode`, on the shared device.
pub fn harness_sized(
    scene: &'static str,
    mode: RendererKind,
    size: egui::Vec2,
) -> Harness<'static, ViewerApp> {
    Harness::builder()
        .with_size(size)
        .wgpu_setup(egui_wgpu::WgpuSetup::Existing(shared_device()))
        .build_eframe(move |cc| {
            ViewerApp::new(
                cc,
                StartOptions {
                    scene: scene.into(),
                    mode: Some(mode),
                    screenshot: None,
                    // The harness clears to transparent: the panels paint their own fill.
                    clear_is_backdrop: false,
                },
            )
        })
}

/// A left drag across the middle of the image, in steps (the image fills the central panel,
/// right of the settings panel).
pub fn drag_across_the_image(harness: &mut Harness<'_, ViewerApp>) {
    let start = egui::pos2(600.0, 300.0);
    harness.event(egui::Event::PointerMoved(start));
    harness.event(egui::Event::PointerButton {
        pos: start,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: egui::Modifiers::NONE,
    });
    harness.run_steps(1);
    for step in 1..=5 {
        harness.event(egui::Event::PointerMoved(start + egui::vec2(12.0 * step as f32, 4.0 * step as f32)));
        harness.run_steps(1);
    }
    let end = start + egui::vec2(60.0, 20.0);
    harness.event(egui::Event::PointerButton {
        pos: end,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: egui::Modifiers::NONE,
    });
    harness.run_steps(2);
}
