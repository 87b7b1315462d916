//! Without a Vulkan driver, device creation fails with an error that names the fix.
//! (Its own test binary: it changes the process environment before any device exists.)

#[test]
fn a_missing_vulkan_driver_is_a_clear_error_naming_the_fix() {
    // SAFETY: this binary has a single test, so no other thread reads the environment.
    unsafe {
        // Point the Vulkan loader at a driver manifest that does not exist, and allow no
        // other backend: exactly what a machine without mesa-vulkan-drivers looks like.
        std::env::set_var("VK_ICD_FILENAMES", "/nonexistent/illum-test-icd.json");
        std::env::set_var("VK_DRIVER_FILES", "/nonexistent/illum-test-icd.json");
        std::env::set_var("WGPU_BACKEND", "vulkan");
        std::env::remove_var("WGPU_ADAPTER_NAME");
    }
    let error = match illum::gpu::GpuContext::new() {
        Ok(gpu) => panic!("expected no adapter, got {:?}", gpu.adapter_info.name),
        Err(e) => e.to_string(),
    };
    assert!(error.contains("no GPU adapter found"), "{error}");
    assert!(error.contains("apt-get install mesa-vulkan-drivers"), "{error}");
}
