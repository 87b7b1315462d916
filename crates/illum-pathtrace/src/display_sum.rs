//! The display sum: an opt-in running image kept on the GPU, for showing the render live.
//!
//! The path tracer's statistics live on the CPU: each band's f32 slots are read back and folded
//! in f64 (see [`crate::accumulator`]). A viewer that showed that f64 mean would copy the whole
//! image back to the GPU every frame. With the display sum enabled
//! ([`crate::PathTracer::enable_display_sum`]), each band's submission also runs
//! `crates/illum-pathtrace/shaders/display_sum.wgsl`, which adds the band's slots into one storage buffer of
//! `width x height` `vec4<f32>`: rgb = running sum of finite samples, w = running count of
//! finite samples. The viewer binds that buffer directly and divides rgb by w when it draws.
//!
//! Why f32 is fine for it: the buffer is only ever shown through an 8-bit texture. Its rounding
//! (at most (n - 1) x 2^-24 relative after n additions, one per pass; the shader explains it) stays
//! below one 8-bit level for any interactive sample count, and the count is exact up to 2^24.
//! The f64 fold remains the source of truth for saved images, statistics and stop rules; the
//! display sum is never read back by illum itself.

use bytemuck::{Pod, Zeroable};
use illum_gpu::buffers::{buffer_bind_group, dispatch};
use illum_gpu::shader::{self, ShaderFile};
use illum_gpu::{GpuContext, shader_file, wgpu};

use crate::{Accumulator, PathTraceError};

/// Adds one band's slots into the display sum (entry point `main`).
pub const DISPLAY_SUM_SHADER: ShaderFile = shader_file!("shaders/display_sum.wgsl");
/// Bytes per pixel of the display sum: one `vec4<f32>`.
pub const DISPLAY_PIXEL_BYTES: u64 = 16;
const WORKGROUP: u32 = 8;

/// Mirrors `DisplayParams` in display_sum.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct DisplayParams {
    width: u32,
    rows: u32,
    row_offset: u32,
    layers: u32,
}

/// The display-sum pipeline (cached in the context: every tracer on a device uses the same one,
/// so a tracer rebuilt for a new size does not recompile).
fn pipeline(gpu: &GpuContext) -> Result<wgpu::ComputePipeline, PathTraceError> {
    Ok(shader::compute_pipeline(gpu, &[], &DISPLAY_SUM_SHADER, &[], "display-sum")?)
}

/// Refuses an image whose display sum would not fit in one storage binding of `limit` bytes
/// (the device's `max_storage_buffer_binding_size`, or `max_buffer_size` if lower). Unlike the
/// batch buffers, which hold one band of rows at a time, the display sum holds the whole image.
pub fn check_display_fits(scene: &str, width: u32, height: u32, limit: u64) -> Result<(), PathTraceError> {
    let bytes = u64::from(width) * u64::from(height) * DISPLAY_PIXEL_BYTES;
    if bytes > limit {
        return Err(PathTraceError::Unsupported {
            scene: scene.to_owned(),
            message: format!(
                "camera.width x camera.height = {width} x {height}: the display sum needs {bytes} bytes \
                 ({DISPLAY_PIXEL_BYTES} per pixel) in one storage buffer, more than the device's \
                 max_storage_buffer_binding_size of {limit} bytes; use a lower resolution to show it \
                 live (rendering without the display sum has no such limit)"
            ),
        });
    }
    Ok(())
}

/// The display-sum buffer, the pipeline that adds into it, and its bind group.
pub(crate) struct DisplaySum {
    width: u32,
    height: u32,
    buffer: wgpu::Buffer,
    params: wgpu::Buffer,
    pipeline: wgpu::ComputePipeline,
    /// The bind group and the batch-sum buffer it binds: the batch buffers are reallocated when
    /// they grow, and the bind group is rebuilt then.
    bound: Option<(wgpu::Buffer, wgpu::BindGroup)>,
}

impl DisplaySum {
    /// Allocates a zeroed display sum for a `width` x `height` image (wgpu zero-initialises new
    /// buffers), after checking it fits the device's storage binding limit.
    pub(crate) fn new(
        gpu: &GpuContext,
        scene: &str,
        width: u32,
        height: u32,
    ) -> Result<Self, PathTraceError> {
        let limits = gpu.device.limits();
        check_display_fits(
            scene,
            width,
            height,
            limits.max_storage_buffer_binding_size.min(limits.max_buffer_size),
        )?;
        let pipeline = pipeline(gpu)?;
        let device = &gpu.device;
        let (buffer, params) = gpu.scoped("allocating the display sum", || {
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pathtrace display sum"),
                size: u64::from(width) * u64::from(height) * DISPLAY_PIXEL_BYTES,
                // COPY_DST for clearing and seeding, COPY_SRC so that tests can read it back.
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let params = illum_gpu::buffers::uniform_buffer(
                device,
                "pathtrace display sum params",
                std::mem::size_of::<DisplayParams>() as u64,
            );
            (buffer, params)
        })?;
        Ok(Self { width, height, buffer, params, pipeline, bound: None })
    }

    pub(crate) fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// Zeroes the sum on the GPU (its own small submission, so that a viewer that redraws before
    /// the next band already shows the restart).
    pub(crate) fn clear(&self, gpu: &GpuContext) {
        let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("pathtrace display clear"),
        });
        encoder.clear_buffer(&self.buffer, 0, None);
        gpu.queue.submit([encoder.finish()]);
    }

    /// Sets the sum to what `accumulator` holds (rounded to f32). Used only when samples exist
    /// that never went through the display pass: the display sum was enabled after rendering
    /// started, or a band failed after its display pass had run. This one upload is the only
    /// time the display sum takes data from the CPU.
    /// `radiance_exponent` is the tracer's k: the display sum holds the GPU's samples, which are
    /// the true ones times 2^-k (see `accumulator::radiance_exponent`).
    pub(crate) fn seed(&self, gpu: &GpuContext, accumulator: &Accumulator, radiance_exponent: i32) {
        if accumulator.total_samples() == 0 {
            self.clear(gpu);
            return;
        }
        let pixels = self.width as usize * self.height as usize;
        let data: Vec<[f32; 4]> = (0..pixels)
            .map(|p| {
                let [r, g, b] = accumulator.pixel_sum(p).map(|v| (v * 2f64.powi(-radiance_exponent)) as f32);
                [r, g, b, accumulator.pixel_count(p) as f32]
            })
            .collect();
        gpu.queue.write_buffer(&self.buffer, 0, bytemuck::cast_slice(&data));
    }

    /// Records, into the band's encoder after its path-tracing pass, the pass that adds the
    /// band's `batch_sum` slots (`layers` slot layers of `rows` rows from `row_offset`, see
    /// `batch::Layers`) into the sum.
    pub(crate) fn record(
        &mut self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        batch_sum: &wgpu::Buffer,
        rows: u32,
        row_offset: u32,
        layers: u32,
    ) {
        let params = DisplayParams { width: self.width, rows, row_offset, layers };
        // Queue writes land before the next submission, which is this band's.
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        if self.bound.as_ref().is_none_or(|(bound, _)| bound != batch_sum) {
            let bind_group = buffer_bind_group(
                &gpu.device,
                "pathtrace display sum",
                &self.pipeline.get_bind_group_layout(0),
                &[(0, &self.params), (1, batch_sum), (2, &self.buffer)],
            );
            self.bound = Some((batch_sum.clone(), bind_group));
        }
        let (_, bind_group) = self.bound.as_ref().expect("bound above");
        let workgroups = [self.width.div_ceil(WORKGROUP), rows.div_ceil(WORKGROUP), 1];
        dispatch(encoder, "pathtrace display sum", &self.pipeline, bind_group, workgroups);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_image_beyond_the_storage_limit_is_refused_by_name() {
        // 1024 x 1024 pixels need 16 MiB; a 16 MiB limit takes it, one byte less does not.
        let limit = 1024 * 1024 * DISPLAY_PIXEL_BYTES;
        check_display_fits("big", 1024, 1024, limit).expect("exactly at the limit fits");
        let error = check_display_fits("big", 1024, 1024, limit - 1).expect_err("over the limit").to_string();
        for needed in ["big", "1024 x 1024", "max_storage_buffer_binding_size", &(limit - 1).to_string()] {
            assert!(error.contains(needed), "{error:?} does not name {needed:?}");
        }
    }
}
