//! Helpers for every crate's GPU integration tests, so that none is written twice: the one
//! device a test binary shares, the workspace's paths, where failing image tests leave their
//! images, and a compute shader run once (for tests of single WGSL routines).
//!
//! Native only: tests wait for the GPU, which a browser page cannot.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use wgpu::util::DeviceExt;

use crate::GpuContext;
use crate::buffers::buffer_bind_group;
use crate::readback::read_buffer;
use crate::shader::{self, ShaderFile};

/// The device every test in this test binary shares (one device on lavapipe, not one per test).
/// Without a Vulkan adapter this panics with the error, which names the fix (`apt-get install
/// mesa-vulkan-drivers`): a missing driver fails the tests, it never skips them.
pub fn gpu() -> &'static GpuContext {
    static GPU: OnceLock<GpuContext> = OnceLock::new();
    GPU.get_or_init(|| match GpuContext::new() {
        Ok(gpu) => gpu,
        Err(e) => panic!("GPU tests need a Vulkan adapter: {e}"),
    })
}

/// `relative` (e.g. `scenes/cornell.toml`) under the workspace's root, from any crate's tests.
pub fn workspace_path(relative: &str) -> PathBuf {
    // This crate is crates/illum-gpu: the root is two folders up.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).ancestors().nth(2).expect("the workspace root");
    root.join(relative)
}

/// Where failing image tests write `*-actual.png` and `*-diff.png`: `target/test-failures`.
pub fn failure_dir() -> PathBuf {
    workspace_path("target/test-failures")
}

/// Compiles `source` (WGSL importing from `modules`) and runs its `main` over `workgroups`, with
/// `inputs` bound read-only at bindings 0, 1, ... and an output of `output_bytes` bytes at the
/// next binding; returns the output's bytes.
pub fn run_compute(
    label: &str,
    modules: &[ShaderFile],
    source: String,
    inputs: &[&[u8]],
    output_bytes: u64,
    workgroups: (u32, u32, u32),
) -> Vec<u8> {
    run_compute_with(label, modules, source, inputs, output_bytes, workgroups, |_| Vec::new())
}

/// As [`run_compute`], the buffers above at group 0, with the further bind groups `groups` makes
/// for the compiled pipeline (whose layouts the shader's use of them decides), each with its
/// group index.
pub fn run_compute_with(
    label: &str,
    modules: &[ShaderFile],
    source: String,
    inputs: &[&[u8]],
    output_bytes: u64,
    workgroups: (u32, u32, u32),
    groups: impl FnOnce(&wgpu::ComputePipeline) -> Vec<(u32, wgpu::BindGroup)>,
) -> Vec<u8> {
    let gpu = gpu();
    let entry = ShaderFile::generated(label.into(), source);
    let pipeline = shader::compute_pipeline(gpu, modules, &entry, &[], label)
        .unwrap_or_else(|e| panic!("{label} compiles: {e}"));
    let mut buffers: Vec<wgpu::Buffer> = inputs
        .iter()
        .map(|bytes| {
            gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytes,
                usage: wgpu::BufferUsages::STORAGE,
            })
        })
        .collect();
    buffers.push(gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: output_bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    }));
    let bindings: Vec<(u32, &wgpu::Buffer)> =
        buffers.iter().enumerate().map(|(i, b)| (i as u32, b)).collect();
    let bind_group = buffer_bind_group(&gpu.device, label, &pipeline.get_bind_group_layout(0), &bindings);
    let more = groups(&pipeline);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        for (index, group) in &more {
            pass.set_bind_group(*index, group, &[]);
        }
        pass.dispatch_workgroups(workgroups.0, workgroups.1, workgroups.2);
    }
    gpu.queue.submit([encoder.finish()]);
    let output = buffers.last().expect("the output buffer");
    read_buffer(gpu, output, 0, output_bytes, label).expect("readback")
}
