//! The batch buffers: where one submission's samples land on the GPU, and how they come back.
//!
//! A pass over the image is split into bands of rows. Each invocation traces one chunk of a
//! pixel's samples and writes one slot of each batch buffer: the f32 sum of its finite samples
//! (rgb) with their count (w), and their sum of squares (rgb) with the count of dropped NaN/Inf
//! samples (w). The slots of a band are laid out chunk by chunk, `rows x width` slots each.

use illum_gpu::buffers::buffer_bind_group;
use illum_gpu::{GpuContext, GpuError, wgpu};
use illum_scene::Scene;

use crate::PathTraceError;
use crate::bindings::Binding;

/// Bytes of one slot of a batch buffer: a vec4 of f32 (the sum buffer and the sum-of-squares
/// buffer each hold one per slot).
pub const SLOT_BYTES: u64 = 16;
/// Default samples per invocation (one chunk, one slot). An f32 sum of n positive terms is within
/// (n - 1) u of the exact sum, relatively (u = 2^-24): with 16, 15 u < 1e-6, so every batch the
/// CPU folds in f64 is within 1e-6 of the f64 fold of the very same samples. It also bounds one
/// invocation's work: lavapipe silently ends an invocation's loops after 65535 iterations (in
/// total), which a single invocation looping over thousands of samples would reach, losing them.
pub const CHUNK_SAMPLES: u32 = 16;

/// The batch buffers (sum, sum of squares) and the bind group of the pipeline that uses them.
pub(crate) struct BatchBuffers {
    pub(crate) slots: u64,
    pub(crate) sum: wgpu::Buffer,
    pub(crate) sum_sq: wgpu::Buffer,
    /// Where the band's timestamps are copied, when the batch buffers are read where they lie
    /// (`mappable`) and the device has timestamp queries.
    pub(crate) timestamps: Option<wgpu::Buffer>,
    pub(crate) bind_group: wgpu::BindGroup,
}

impl BatchBuffers {
    /// Allocates the two batch buffers of `slots` slots each (bindings 4 and 5) and binds them,
    /// with the `inputs` the pipeline reads (binding, buffer: the scene's params, objects,
    /// materials and lights, and adaptive sampling's block counts, as far as the pipeline
    /// declares them), to `layout`. `mapped_readback`: `Some(timestamp bytes)` when the CPU maps
    /// the sums where the shader wrote them (a device with `MAPPABLE_PRIMARY_BUFFERS`); that many
    /// bytes of mappable buffer then take the band's timestamps.
    pub(crate) fn new(
        gpu: &GpuContext,
        slots: u64,
        layout: &wgpu::BindGroupLayout,
        inputs: &[(u32, &wgpu::Buffer)],
        mapped_readback: Option<u64>,
    ) -> Result<Self, GpuError> {
        let device = &gpu.device;
        gpu.scoped("allocating path-tracer batch buffers", || {
            let read = if mapped_readback.is_some() {
                wgpu::BufferUsages::MAP_READ
            } else {
                wgpu::BufferUsages::empty()
            };
            let buffer = |label: &str| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: slots * SLOT_BYTES,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | read,
                    mapped_at_creation: false,
                })
            };
            let sum = buffer("pathtrace batch sum");
            let sum_sq = buffer("pathtrace batch sum of squares");
            let timestamps = mapped_readback.filter(|&bytes| bytes > 0).map(|size| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("pathtrace batch timestamps"),
                    size,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            });
            let mut bound: Vec<(u32, &wgpu::Buffer)> = inputs.to_vec();
            bound.extend([(Binding::BatchSum.index(), &sum), (Binding::BatchSumSq.index(), &sum_sq)]);
            let bind_group = buffer_bind_group(device, "pathtrace", layout, &bound);
            BatchBuffers { slots, sum, sum_sq, timestamps, bind_group }
        })
    }
}

/// Most slots one batch buffer may hold on this device: its storage binding limit (or its buffer
/// limit, if lower) over [`SLOT_BYTES`].
pub(crate) fn device_max_slots(limits: &wgpu::Limits) -> u64 {
    limits.max_storage_buffer_binding_size.min(limits.max_buffer_size) / SLOT_BYTES
}

/// One row of one chunk is the smallest band; it must fit in one batch buffer.
pub(crate) fn check_row_fits(scene: &Scene, max_slots: u64) -> Result<(), PathTraceError> {
    let width = u64::from(scene.camera.width);
    if width > max_slots {
        return Err(PathTraceError::Unsupported {
            scene: scene.name.clone(),
            message: format!(
                "camera.width = {width}: one row needs {} bytes per batch buffer, more than the {} \
                 bytes allowed (the device's max_storage_buffer_binding_size, or a lower cap)",
                width * SLOT_BYTES,
                max_slots * SLOT_BYTES
            ),
        });
    }
    Ok(())
}

/// The slots read back from the GPU (little-endian f32 vec4s), where they lie when the bytes
/// are aligned for f32 on a little-endian host (a mapped buffer is), else decoded into a copy.
pub(crate) fn slots(bytes: &[u8]) -> std::borrow::Cow<'_, [[f32; 4]]> {
    match bytemuck::try_cast_slice::<u8, [f32; 4]>(bytes) {
        Ok(slots) if cfg!(target_endian = "little") => std::borrow::Cow::Borrowed(slots),
        _ => std::borrow::Cow::Owned(decode_slots(bytes)),
    }
}

/// The slots read back from the GPU (little-endian f32 vec4s), decoded into a copy.
pub(crate) fn decode_slots(bytes: &[u8]) -> Vec<[f32; 4]> {
    bytes
        .chunks_exact(SLOT_BYTES as usize)
        .map(|c| {
            let f = |i: usize| f32::from_le_bytes(c[4 * i..4 * i + 4].try_into().expect("4 bytes"));
            [f(0), f(1), f(2), f(3)]
        })
        .collect()
}

/// Checks that every slot accounts for all of its chunk's samples (finite + dropped): `chunks`
/// chunks of `band_pixels` slots each, slot i of chunk k expecting `expected(k, i)` samples.
/// A shortfall means the driver ended an invocation early, and the band's statistics would
/// silently be short. Returns the samples of the band.
pub(crate) fn check_complete(
    sums: &[[f32; 4]],
    sums_sq: &[[f32; 4]],
    chunks: u32,
    band_pixels: usize,
    expected: impl Fn(u32, usize) -> u32,
) -> Result<u64, PathTraceError> {
    let mut total = 0;
    for k in 0..chunks {
        let range = k as usize * band_pixels..(k as usize + 1) * band_pixels;
        for (i, (s, q)) in sums[range.clone()].iter().zip(&sums_sq[range]).enumerate() {
            let found = s[3] as u64 + q[3] as u64;
            let expected = expected(k, i);
            if found != u64::from(expected) {
                return Err(PathTraceError::IncompleteBatch { expected, found });
            }
            total += found;
        }
    }
    Ok(total)
}

/// The samples slot i of chunk k holds in a pass of `spp` samples in chunks of `chunk`.
pub(crate) fn uniform_chunk(spp: u32, chunk: u32) -> impl Fn(u32, usize) -> u32 {
    move |k, _| chunk.min(spp - k * chunk)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slot_short_of_its_chunk_is_an_incomplete_batch() {
        // 2 pixels, 20 spp in chunks of 16: chunk 0 holds 16 samples, chunk 1 holds 4.
        let sums = [[0.0, 0.0, 0.0, 16.0], [0.0, 0.0, 0.0, 15.0], [0.0, 0.0, 0.0, 4.0], [0.0, 0.0, 0.0, 3.0]];
        let sums_sq = [[0.0; 4], [0.0, 0.0, 0.0, 1.0], [0.0; 4], [0.0, 0.0, 0.0, 1.0]];
        let total =
            check_complete(&sums, &sums_sq, 2, 2, uniform_chunk(20, 16)).expect("dropped samples count");
        assert_eq!(total, 40);
        let mut short = sums_sq;
        short[3][3] = 0.0;
        let error = check_complete(&sums, &short, 2, 2, uniform_chunk(20, 16)).expect_err("a lost sample");
        assert!(matches!(error, PathTraceError::IncompleteBatch { expected: 4, found: 3 }), "{error}");
    }

    #[test]
    fn slots_decode_as_little_endian_vec4s() {
        let bytes: Vec<u8> =
            [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0].iter().flat_map(|f| f.to_le_bytes()).collect();
        assert_eq!(decode_slots(&bytes), [[1.0, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.0]]);
        // Aligned or not, `slots` reads the same values (borrowed where it can).
        let aligned: Vec<[f32; 4]> = vec![[1.0, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.0]];
        assert!(matches!(slots(bytemuck::cast_slice(&aligned)), std::borrow::Cow::Borrowed(_)));
        let mut shifted = vec![0u8];
        shifted.extend_from_slice(&bytes);
        assert_eq!(&*slots(&shifted[1..]), &aligned[..]);
    }
}
