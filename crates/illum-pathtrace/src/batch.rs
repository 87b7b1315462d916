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
use crate::replicates::{REPLICATES, replicate_of, samples_in};

/// Bytes of one slot of a batch buffer: a vec4 of f32 (the sum buffer and the sum-of-squares
/// buffer each hold one per slot).
pub const SLOT_BYTES: u64 = 16;
/// Default samples per invocation (one chunk, one slot). An f32 sum of n positive terms is within
/// (n - 1) u of the exact sum, relatively (u = 2^-24): with 16, 15 u < 1e-6, so every batch the
/// CPU folds in f64 is within 1e-6 of the f64 fold of the very same samples. It also bounds one
/// invocation's work: lavapipe silently ends an invocation's loops after 65535 iterations (in
/// total), which a single invocation looping over thousands of samples would reach, losing them.
pub const CHUNK_SAMPLES: u32 = 16;

/// How a pass's samples are grouped into slots: per chunk of `chunk` samples, one layer of
/// slots, or with `replicated` (the low-discrepancy sequence, `replicates.rs`) one per
/// replicate, layer `k R + r` holding replicate r's samples of chunk k (pathtrace.wgsl's
/// SLOT_LAYERS and write_slot).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layers {
    pub chunk: u32,
    pub replicated: bool,
}

impl Layers {
    /// Slot layers per chunk.
    pub fn per_chunk(self) -> u32 {
        if self.replicated { REPLICATES as u32 } else { 1 }
    }

    /// Slot layers of a pass of `spp` samples.
    pub fn count(self, spp: u32) -> u32 {
        spp.div_ceil(self.chunk.max(1)) * self.per_chunk()
    }

    /// The chunk that layer `layer` belongs to.
    pub fn chunk_of(self, layer: u32) -> u32 {
        layer / self.per_chunk()
    }

    /// The replicate whose samples layer `layer` holds (`None`: not replicated).
    pub fn replicate(self, layer: u32) -> Option<usize> {
        self.replicated.then(|| (layer % self.per_chunk()) as usize)
    }

    /// The layer holding sample `relative` of a pass whose first sample index is `pass_start`.
    pub fn layer_of(self, pass_start: u32, relative: u32) -> u32 {
        let replicate =
            if self.replicated { replicate_of(u64::from(pass_start) + u64::from(relative)) } else { 0 };
        relative / self.chunk.max(1) * self.per_chunk() + replicate as u32
    }

    /// The samples layer `layer` holds when its chunk takes the first `taken` of its sample
    /// indices (pass starting at index `pass_start`).
    pub fn samples(self, pass_start: u32, layer: u32, taken: u32) -> u32 {
        let chunk_start = u64::from(pass_start) + u64::from(self.chunk_of(layer)) * u64::from(self.chunk);
        match self.replicate(layer) {
            None => taken,
            Some(r) => samples_in(chunk_start, u64::from(taken), r) as u32,
        }
    }
}

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

/// One row of one chunk (its `per_chunk` slot layers) is the smallest band; it must fit in one
/// batch buffer.
pub(crate) fn check_row_fits(scene: &Scene, per_chunk: u32, max_slots: u64) -> Result<(), PathTraceError> {
    let width = u64::from(scene.camera.width);
    let slots = width * u64::from(per_chunk);
    if slots > max_slots {
        return Err(PathTraceError::Unsupported {
            scene: scene.name.clone(),
            message: format!(
                "camera.width = {width}: one row needs {} bytes per batch buffer, more than the {} \
                 bytes allowed (the device's max_storage_buffer_binding_size, or a lower cap)",
                slots * SLOT_BYTES,
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

/// Checks that every slot accounts for all of its samples (finite + dropped): `layers` layers
/// of `band_pixels` slots each, slot i of layer l expecting `expected(l, i)` samples.
/// A shortfall means the driver ended an invocation early, and the band's statistics would
/// silently be short. Returns the samples of the band.
pub(crate) fn check_complete(
    sums: &[[f32; 4]],
    sums_sq: &[[f32; 4]],
    layers: u32,
    band_pixels: usize,
    expected: impl Fn(u32, usize) -> u32,
) -> Result<u64, PathTraceError> {
    let mut total = 0;
    for k in 0..layers {
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

/// The samples slot i of layer l holds in a pass of `spp` samples starting at sample index
/// `pass_start`, laid out as `layers`.
pub(crate) fn uniform_chunk(layers: Layers, pass_start: u32, spp: u32) -> impl Fn(u32, usize) -> u32 {
    move |l, _| layers.samples(pass_start, l, chunk_taken(layers, spp, l))
}

/// The samples of the pass that the chunk of layer `l` takes: a whole chunk, or the rest.
pub(crate) fn chunk_taken(layers: Layers, spp: u32, l: u32) -> u32 {
    let chunk = layers.chunk.max(1);
    chunk.min(spp - layers.chunk_of(l) * chunk)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slot_short_of_its_chunk_is_an_incomplete_batch() {
        // 2 pixels, 20 spp in chunks of 16: chunk 0 holds 16 samples, chunk 1 holds 4.
        let sums = [[0.0, 0.0, 0.0, 16.0], [0.0, 0.0, 0.0, 15.0], [0.0, 0.0, 0.0, 4.0], [0.0, 0.0, 0.0, 3.0]];
        let sums_sq = [[0.0; 4], [0.0, 0.0, 0.0, 1.0], [0.0; 4], [0.0, 0.0, 0.0, 1.0]];
        let layers = Layers { chunk: 16, replicated: false };
        let total = check_complete(&sums, &sums_sq, 2, 2, uniform_chunk(layers, 0, 20))
            .expect("dropped samples count");
        assert_eq!(total, 40);
        let mut short = sums_sq;
        short[3][3] = 0.0;
        let error =
            check_complete(&sums, &short, 2, 2, uniform_chunk(layers, 0, 20)).expect_err("a lost sample");
        assert!(matches!(error, PathTraceError::IncompleteBatch { expected: 4, found: 3 }), "{error}");
    }

    /// The shader's layer count is the Rust one.
    #[test]
    fn slot_layers_match_the_shader() {
        let source = include_str!("../shaders/pathtrace.wgsl");
        assert!(source.contains("const SLOT_LAYERS: u32 = REPLICATES;"));
        assert!(source.contains("const SLOT_LAYERS: u32 = 1u;"));
        assert_eq!(Layers { chunk: 16, replicated: true }.per_chunk() as usize, REPLICATES);
    }

    /// Replicated layers: every sample of a pass is in the layer of its chunk and replicate, and
    /// each layer's count is the number of its samples, for passes starting and ending inside
    /// runs and chunks.
    #[test]
    fn every_sample_is_counted_in_its_chunks_replicate_layer() {
        let layers = Layers { chunk: 16, replicated: true };
        for pass_start in [0u32, 1, 6, 16, 29, 1 << 31] {
            for spp in [1u32, 3, 16, 17, 40, 64] {
                let mut counted = vec![0u32; layers.count(spp) as usize];
                for relative in 0..spp {
                    let l = layers.layer_of(pass_start, relative);
                    assert_eq!(layers.chunk_of(l), relative / 16);
                    let absolute = u64::from(pass_start) + u64::from(relative);
                    assert_eq!(layers.replicate(l), Some(replicate_of(absolute)));
                    counted[l as usize] += 1;
                }
                let expected = uniform_chunk(layers, pass_start, spp);
                for (l, &n) in counted.iter().enumerate() {
                    assert_eq!(expected(l as u32, 0), n, "start {pass_start}, {spp} spp, layer {l}");
                }
            }
        }
        let plain = Layers { chunk: 16, replicated: false };
        assert_eq!((plain.count(40), plain.layer_of(5, 33), plain.replicate(2)), (3, 2, None));
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
