//! A compute shader run once on the test device, for tests of single WGSL routines: the entry
//! point reads storage buffers at bindings 0..k-1 and writes the last one, which comes back.

use illum::gpu::buffers::{buffer_bind_group, dispatch};
use illum::gpu::readback::read_buffer;
use illum::gpu::shader::{self, ShaderFile};
use illum::gpu::wgpu;
use illum::gpu::wgpu::util::DeviceExt;

use super::gpu;

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
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    dispatch(&mut encoder, label, &pipeline, &bind_group, [workgroups.0, workgroups.1, workgroups.2]);
    gpu.queue.submit([encoder.finish()]);
    let output = buffers.last().expect("the output buffer");
    read_buffer(gpu, output, 0, output_bytes, label).expect("readback")
}
