//! The caustic's light tracer on the host (shader `crates/illum-pathtrace/shaders/caustic.wgsl`; the
//! estimator and its path space are in docs/caustics.md).
//!
//! Frame k, N = width x height particles, pairs with sample index k of every pixel: pixel p's
//! sample k is the camera path's estimate plus frame k's splat at p. Rather than adding the two
//! per sample on the GPU, each pass traces its frames first (in dispatches of up to
//! `frames_per_dispatch`), reads each frame back and keeps, per slot layer of the pass (the same
//! groups of sample indices as the camera's f32 slot sums, `batch::Layers`) and pixel, the f64 sum S1 and sum
//! of squares S2 of the frames' values. Folding a camera chunk (sum C of n samples) then adds
//!     sum += S1,   sum of squares += S2 + 2 C S1 / n.
//! The last term replaces sum_k c_k s_k by its mean over the pairings of the chunk's camera and
//! caustic values, which has the same expectation n^2 mu_c mu_s / n as the paired sum because
//! the two estimators are independent. So the accumulator's mean is exactly the two
//! estimators' sum, and its sample variance is an unbiased estimate of var(c) + var(s): the
//! error estimate stays honest, and checkpoints, resume, merge and the stop rules work
//! unchanged. Frames depend only on (seed, particle, frame index), and integer atomics add in
//! any order to the same result, so the image does not depend on how a render is batched.
//!
//! Readback: a pass's frames go to the GPU in dispatches of up to `frames_per_dispatch` frames,
//! each read back and folded before the next is submitted. Natively the tools wait for each
//! dispatch ([`CausticTracer::prepare_pass`]); a web page cannot wait, so there each dispatch's
//! mapping is started and asked again on later frames ([`CausticTracer::poll_pass`]). Both
//! submit the same dispatches and fold the same frames in the same order, so the pass's
//! statistics are the same bit for bit.
//!
//! Fixed point: see [`fixed_point`].
//!
//! With a delta sun each dispatch also runs the photon gather (`shaders/gather.wgsl`) after the
//! particles, into the same frames: its photon maps and grid are allocated and cleared here.
//!
//! Over 600 lines with its tests (about 600 of code): one estimator, from its parameters to its
//! fold, with the two ways its frames come back (waited for, or polled), and the photon gather
//! that shares its frames and buffers.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use illum_gpu::readback::PendingRead;
use illum_gpu::timing::PassTimer;
use illum_gpu::{GpuContext, wgpu};
use illum_scene::{MaterialKind, Scene};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use web_time::Instant;

use crate::accumulator::Accumulator;
use crate::batch::{self, Layers};
use illum_rtcore::GpuShape;

use crate::gpu_scene::{GpuParams, GpuScene};
use crate::options::TracerOptions;
use crate::{PathTraceError, shaders};

/// Mirrors `struct CausticParams` in caustic.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct CausticParams {
    pub particles: u32,
    pub row_stride: u32,
    pub frame_base: u32,
    pub frame_count: u32,
    pub num_discs: u32,
    pub seed: u32,
    pub pixel_area: f32,
    pub area_per_particle: f32,
    pub scene_centre: [f32; 3],
    pub scene_radius: f32,
    pub fixed_scale: f32,
    pub fixed_cap: f32,
    pub disc_area: f32,
    /// r_1 of the photon gather (0 without it).
    pub gather_radius: f32,
    /// Photon-grid buckets per frame (a power of two; 1 without the gather).
    pub buckets: u32,
    /// The dispatch's first particle (or pixel, in the gather): nonzero for a frame's pieces.
    pub first_index: u32,
    pub padding_b: u32,
    pub padding_c: u32,
}

/// Mixed into the scene's seed for the particles, so that particle i of frame k never draws
/// the random numbers of sample k of pixel i.
const PARTICLE_SEED_KEY: u32 = 0x5ca0_571c;
const WORKGROUP: u32 = 64;
/// Words per pixel of a frame: (lo, hi) for each of three channels.
const WORDS_PER_PIXEL: u64 = 6;
/// The most bytes one dispatch's frames take (and the most host memory one pass's chunk
/// statistics may take, below).
const SPLAT_BYTES: u64 = 64 << 20;
/// Bytes per photon: three vec4 (caustic_buffers.wgsl).
const PHOTON_BYTES: u64 = 48;
/// r_1 of the photon gather as a fraction of the largest specular object's bounding radius
/// (docs/caustics.md, "The caustic seen through a specular surface").
pub const GATHER_RADIUS_FRACTION: f32 = 0.02;
/// Host bytes per pixel and slot layer of a pass: S1 and S2, three f64 each.
pub(crate) const PASS_BYTES_PER_PIXEL_LAYER: u64 = 48;
/// The most host memory one pass's caustic statistics may take.
pub(crate) const PASS_BYTES: u64 = 256 << 20;

/// The bounding sphere (centre, radius) of a shape, in f32 (what the GPU tests against).
pub fn bounding_sphere(shape: &GpuShape) -> (Vec3, f32) {
    match *shape {
        GpuShape::Aabb { min, max } => (0.5 * (min + max), 0.5 * (max - min).length()),
        GpuShape::Box { local_min, local_max, cos, sin, offset } => {
            let c = 0.5 * (local_min + local_max);
            let centre = Vec3::new(cos * c.x + sin * c.z, c.y, -sin * c.x + cos * c.z) + offset;
            (centre, 0.5 * (local_max - local_min).length())
        }
        GpuShape::Quad { corner, edge_u, edge_v } => {
            let radius = 0.5 * (edge_u + edge_v).length().max((edge_u - edge_v).length());
            (corner + 0.5 * (edge_u + edge_v), radius)
        }
        GpuShape::Sphere { center, radius } => (center, radius),
    }
}

/// The fixed-point scale S (a power of two) and cap for frames of `particles` particles whose
/// typical splat is `reference` (in the GPU's scaled radiance).
///
/// Each particle adds to one pixel once, as q = round(v S) < cap, cap = 2^(64 - ceil(log2 N))
/// (particles at or above it are dropped and counted). A frame's pixel sum is then below
/// N cap <= 2^64: the two-word (64-bit) sum cannot overflow, for any scene, sun or particle.
/// S puts the reference splat at cap / 2^24: a particle may be 2^24 times brighter than the
/// reference (the floor 4096 times nearer the eye, say) before it is dropped, and the reference
/// splat has 64 - ceil(log2 N) - 24 bits (22 at 512 x 512: relative rounding 2^-23, below f32's
/// own). The scale follows the sun's irradiance, so a very bright sun changes nothing but S.
pub fn fixed_point(particles: u64, reference: f64) -> (f32, f32) {
    let bits = 64 - (particles.max(1) as f64).log2().ceil() as i32;
    let cap = 2f64.powi(bits);
    let exponent = if reference > 0.0 && reference.is_finite() {
        ((cap / 2f64.powi(24) / reference).log2().floor() as i32).clamp(-120, 120)
    } else {
        0
    };
    (2f32.powi(exponent), cap as f32)
}

/// Which pass a caustic pass belongs to: its first absolute sample index, its spp and the
/// slot layers of the camera's sums that its statistics are grouped by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct PassKey {
    pub first_sample: u32,
    pub spp: u32,
    pub layers: Layers,
}

/// One pass's caustic statistics: per slot layer and pixel, S1 and S2 of its frames, complete once
/// `frames_done` reaches the pass's spp.
struct CausticPass {
    key: PassKey,
    sum: Vec<[f64; 3]>,
    sum_sq: Vec<[f64; 3]>,
    dropped: u64,
    /// Frames folded so far: frames `key.first_sample..key.first_sample + frames_done`.
    frames_done: u32,
    /// The dispatch of the pass's next frames whose polled readback is under way.
    in_flight: Option<InFlight>,
    /// The pass's next frame, while it is traced in pieces.
    pieces: Option<FramePieces>,
}

impl CausticPass {
    fn new(key: PassKey, pixels: usize) -> Self {
        let layers = key.layers.count(key.spp) as usize;
        CausticPass {
            key,
            sum: vec![[0.0; 3]; layers * pixels],
            sum_sq: vec![[0.0; 3]; layers * pixels],
            dropped: 0,
            frames_done: 0,
            in_flight: None,
            pieces: None,
        }
    }

    fn complete(&self) -> bool {
        self.frames_done >= self.key.spp
    }

    /// Folds `count` frames of `pixels` pixels read back from a dispatch (the splat buffer's
    /// words, frames first, then one dropped-particle counter per frame): they are the pass's
    /// next frames. A fixed-point unit is worth `unit` in true radiance.
    fn fold_frames(&mut self, words: &[u32], count: u32, pixels: usize, unit: f64) {
        let words_per_frame = WORDS_PER_PIXEL as usize * pixels;
        for f in 0..count as usize {
            let relative = self.frames_done as usize + f;
            let offset = self.key.layers.layer_of(self.key.first_sample, relative as u32) as usize * pixels;
            let frame = &words[f * words_per_frame..(f + 1) * words_per_frame];
            for (p, w) in frame.chunks_exact(WORDS_PER_PIXEL as usize).enumerate() {
                for c in 0..3 {
                    let q = (u64::from(w[2 * c + 1]) << 32) | u64::from(w[2 * c]);
                    if q != 0 {
                        let v = q as f64 * unit;
                        self.sum[offset + p][c] += v;
                        self.sum_sq[offset + p][c] += v * v;
                    }
                }
            }
            self.dropped += u64::from(words[count as usize * words_per_frame + f]);
        }
        self.frames_done += count;
    }
}

/// A dispatch of frames whose readback is under way (polled).
struct InFlight {
    read: PendingRead,
    bytes: DispatchBytes,
    /// The frames it traced.
    count: u32,
    launched: Instant,
    /// Whether it is the last piece of a frame traced in pieces (not timed).
    pieced: bool,
}

/// A frame traced in pieces, one submission per call, for a caller whose time target is
/// shorter than a frame: its particles in `count` ranges, then (with the gather) its pixels in
/// `count` ranges, the last read back. Integer atomics add in any order, so the frame's values
/// are those of one dispatch, bit for bit.
struct FramePieces {
    /// Pieces of the particles and of the gather (0 without it).
    counts: [u32; 2],
    /// Submissions made so far (of `counts[0] + counts[1]`).
    submitted: u32,
    /// Set when the last submitted piece's work is done (polled).
    done: Arc<AtomicBool>,
    /// Seconds the waited pieces of each stage took so far.
    seconds: [f64; 2],
    /// Whether its pieces were waited for (a waiting caller restarts a frame begun by polling;
    /// a web page only polls).
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    waited: bool,
}

/// What [`CausticTracer::launch`] submitted.
enum Launched {
    /// A piece of a frame, not read back.
    Piece,
    /// Frames to read back: whole ones, or a frame's last piece (`pieces_seconds`: what its
    /// waited pieces of each stage took).
    Frames { staging: wgpu::Buffer, bytes: DispatchBytes, count: u32, pieces_seconds: Option<[f64; 2]> },
}

/// What one submission of caustic work does.
#[derive(Clone, Copy)]
enum Stage {
    /// Whole frames: clear, particles, gather, read back.
    Whole,
    /// A range of a frame's particles (the first clears the frame; the last, without the
    /// gather, reads it back).
    Particles { first: bool, last: bool },
    /// A range of a frame's gathering pixels (the last reads the frame back).
    Gather { last: bool },
}

/// What a dispatch's staging copy holds: its frames' bytes, then the timestamps (if timed).
#[derive(Clone, Copy)]
struct DispatchBytes {
    frames: u64,
    total: u64,
}

/// The timer's names of the light tracer's and the photon gather's passes.
const CAUSTIC_PASS: &str = "caustic";
const GATHER_PASS: &str = "photon gather";

/// The photon gather's pipeline and grid (shader def CAUSTIC_GATHER).
struct Gather {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    /// The grid's bucket heads, cleared before each dispatch.
    heads: wgpu::Buffer,
    heads_frame_bytes: u64,
}

pub(crate) struct CausticTracer {
    pipeline: wgpu::ComputePipeline,
    /// The photon gather, with a delta sun.
    gather: Option<Gather>,
    params_buffer: wgpu::Buffer,
    /// The path tracer's parameters buffer, which the shader reads the camera from, and the
    /// scene's parameters to write there before each dispatch (a band writes its own fields
    /// there too; the camera's are the same).
    scene_params_buffer: wgpu::Buffer,
    scene_params: GpuParams,
    splat: wgpu::Buffer,
    /// The mappable copy of a dispatch's frames; taken by a polled read while it is mapped
    /// (`None` then, or after a read was abandoned: made again when needed).
    staging: Option<wgpu::Buffer>,
    splat_size: u64,
    bind_group: wgpu::BindGroup,
    base: CausticParams,
    /// The most frames one dispatch may carry (the splat and photon buffers' size).
    max_frames_per_dispatch: u32,
    /// What one frame cost in the last dispatch, in seconds: sizes the next dispatch when the
    /// caller aims at a time per step (see [`Self::dispatch_frames`]).
    seconds_per_frame: Option<f64>,
    /// Seconds the frames folded so far took, each dispatch at the cost that sized the next
    /// one (its GPU time where the device has timestamps): the light tracer's share of a
    /// render's time, which the bands' own reports do not hold ([`crate::PathTracer::caustic_seconds`]).
    seconds_spent: f64,
    /// What a frame's particles and its gather cost, from the last frame traced in waited
    /// pieces: how the next frame is cut (see [`Self::frame_pieces`]).
    stage_seconds: Option<[f64; 2]>,
    /// Times the light tracer's and the gather's passes, where the device has timestamps.
    timer: PassTimer,
    groups: (u32, u32),
    pixels: usize,
    /// What a fixed-point unit is worth in true radiance: 2^radiance_exponent / S.
    unit: f64,
    /// The pass being gathered or held, with its dispatch in flight.
    pass: Option<CausticPass>,
}

impl CausticTracer {
    /// The light tracer for `scene`, or `None` when its scene code has no caustic (caustics
    /// off, no directional light or no specular object).
    pub(crate) fn new(
        gpu: &GpuContext,
        scene: &Scene,
        gpu_scene: &GpuScene,
        options: TracerOptions,
        scene_buffers: [&wgpu::Buffer; 3],
        scene_params: GpuParams,
    ) -> Result<Option<Self>, PathTraceError> {
        if !gpu_scene.code.caustic {
            return Ok(None);
        }
        let sun = scene.directional_light.expect("CAUSTIC needs a directional light");
        let camera = scene.camera;
        let pixels = camera.width as usize * camera.height as usize;
        let particles = pixels as u64;
        let frame_bytes = WORDS_PER_PIXEL * 4 * particles + 4;
        let gather = gpu_scene.code.caustic_gather;
        // The photon grid: a bucket per particle or more (a power of two), 4 bytes each.
        let buckets = if gather { particles.next_power_of_two() } else { 1 };
        let photon_frame_bytes = if gather { PHOTON_BYTES * particles } else { 4 };
        let largest_frame_bytes = frame_bytes.max(photon_frame_bytes).max(4 * buckets);
        let limits = gpu.device.limits();
        let max_binding = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        if largest_frame_bytes > max_binding {
            return Err(PathTraceError::Unsupported {
                scene: scene.name.clone(),
                message: format!(
                    "pathtrace.caustics = true at camera.width x camera.height = {} x {}: one frame of the caustic \
                     (24 bytes per pixel, and 48 per pixel for the photons with a delta sun) needs \
                     {largest_frame_bytes} bytes in one buffer, over the device's storage binding limit of \
                     {max_binding}; render smaller or set caustics = false",
                    camera.width, camera.height
                ),
            });
        }
        let max_frames_per_dispatch =
            (SPLAT_BYTES.min(max_binding) / largest_frame_bytes).clamp(1, crate::CHUNK_SAMPLES as u64) as u32;

        let specular = |material: u32| {
            matches!(
                scene.materials[material as usize].kind,
                MaterialKind::Mirror { .. } | MaterialKind::Dielectric { .. }
            )
        };
        let discs: Vec<[f32; 4]> = gpu_scene
            .geometry
            .objects
            .iter()
            .filter(|o| !o.emitter && specular(o.material))
            .map(|o| {
                let (c, r) = bounding_sphere(&o.shape);
                [c.x, c.y, c.z, r]
            })
            .collect();
        let disc_area: f32 = discs.iter().map(|d| std::f32::consts::PI * d[3] * d[3]).sum();
        let spheres: Vec<(Vec3, f32)> =
            gpu_scene.geometry.objects.iter().map(|o| bounding_sphere(&o.shape)).collect();
        let scene_centre = spheres.iter().map(|s| s.0).sum::<Vec3>() / spheres.len() as f32;
        let scene_radius = spheres.iter().map(|(c, r)| (*c - scene_centre).length() + r).fold(0.0, f32::max);

        let basis = scene.camera.basis();
        let pixel_area = (2.0 * basis.aspect * basis.tan_half_fov / camera.width as f32)
            * (2.0 * basis.tan_half_fov / camera.height as f32);
        // The reference splat: a particle of the brightest channel's flux landing at the
        // distance of the nearest specular object, facing the eye on the axis.
        let scale = 2f64.powi(-gpu_scene.radiance_exponent);
        let flux_density = f64::from(sun.irradiance.max_element()) * scale;
        let nearest = discs
            .iter()
            .map(|d| {
                f64::from((Vec3::new(d[0], d[1], d[2]) - scene.camera.eye).length()).max(f64::from(d[3]))
            })
            .fold(f64::INFINITY, f64::min);
        let reference = flux_density * f64::from(disc_area)
            / particles as f64
            / std::f64::consts::PI
            / (f64::from(pixel_area) * nearest * nearest);
        // The gather adds one value per pixel and frame beside the particles' (at most N).
        let (fixed_scale, fixed_cap) = fixed_point(if gather { 2 * particles } else { particles }, reference);
        let largest_radius = discs.iter().map(|d| d[3]).fold(0.0, f32::max);

        let groups_total = (particles as u32).div_ceil(WORKGROUP);
        let gx = groups_total.min(limits.max_compute_workgroups_per_dimension);
        let gy = groups_total.div_ceil(gx);
        let base = CausticParams {
            particles: particles as u32,
            row_stride: gx * WORKGROUP,
            frame_base: 0,
            frame_count: 0,
            num_discs: discs.len() as u32,
            seed: scene.pathtrace.seed ^ PARTICLE_SEED_KEY,
            pixel_area,
            area_per_particle: disc_area / particles as f32,
            scene_centre: scene_centre.to_array(),
            scene_radius,
            fixed_scale,
            fixed_cap,
            disc_area,
            gather_radius: if gather { GATHER_RADIUS_FRACTION * largest_radius } else { 0.0 },
            buckets: buckets as u32,
            first_index: 0,
            padding_b: 0,
            padding_c: 0,
        };
        let pipeline = shaders::companion_pipeline(
            gpu,
            scene,
            gpu_scene,
            options,
            &shaders::CAUSTIC_SHADER,
            "caustic light-tracing",
        )?;
        let device = &gpu.device;
        let splat_size = frame_bytes * u64::from(max_frames_per_dispatch);
        let (params_buffer, discs_buffer, splat) = gpu.scoped("allocating the caustic's buffers", || {
            (
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("caustic params"),
                    size: std::mem::size_of::<CausticParams>() as u64,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                illum_gpu::buffers::storage_buffer(device, "caustic discs", bytemuck::cast_slice(&discs)),
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("caustic splats"),
                    size: splat_size,
                    usage: wgpu::BufferUsages::STORAGE
                        | wgpu::BufferUsages::COPY_SRC
                        | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
            )
        })?;
        let layout = pipeline.get_bind_group_layout(0);
        let [params, objects, materials] = scene_buffers;
        // The photon maps: (photons, heads), the photons not cleared (only the heads lead to them).
        let photon_buffers = if gather {
            let frames = u64::from(max_frames_per_dispatch);
            Some(gpu.scoped("allocating the photon maps", || {
                let storage = |label, size| {
                    device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(label),
                        size,
                        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                        mapped_at_creation: false,
                    })
                };
                (
                    storage("caustic photons", photon_frame_bytes * frames),
                    storage("photon grid", 4 * buckets * frames),
                )
            })?)
        } else {
            None
        };
        let mut entries = vec![
            wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: objects.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: materials.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 6, resource: params_buffer.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 8, resource: splat.as_entire_binding() },
        ];
        if let Some((photons, heads)) = &photon_buffers {
            entries.push(wgpu::BindGroupEntry { binding: 9, resource: photons.as_entire_binding() });
            entries.push(wgpu::BindGroupEntry { binding: 10, resource: heads.as_entire_binding() });
        }
        // The gather reads no discs.
        let gather_entries = entries.clone();
        entries.push(wgpu::BindGroupEntry { binding: 7, resource: discs_buffer.as_entire_binding() });
        let bind_group = gpu.scoped("binding the caustic's buffers", || {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("caustic"),
                layout: &layout,
                entries: &entries,
            })
        })?;
        let timer = PassTimer::new(gpu, if gather { &[CAUSTIC_PASS, GATHER_PASS] } else { &[CAUSTIC_PASS] });
        let gather = match &photon_buffers {
            Some((_, heads)) => {
                let pipeline = shaders::companion_pipeline(
                    gpu,
                    scene,
                    gpu_scene,
                    options,
                    &shaders::GATHER_SHADER,
                    "caustic photon gather",
                )?;
                let layout = pipeline.get_bind_group_layout(0);
                let bind_group = gpu.scoped("binding the photon gather's buffers", || {
                    device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("photon gather"),
                        layout: &layout,
                        entries: &gather_entries,
                    })
                })?;
                Some(Gather { pipeline, bind_group, heads: heads.clone(), heads_frame_bytes: 4 * buckets })
            }
            None => None,
        };
        Ok(Some(CausticTracer {
            pipeline,
            gather,
            params_buffer,
            scene_params_buffer: params.clone(),
            scene_params,
            splat,
            staging: None,
            splat_size,
            bind_group,
            base,
            max_frames_per_dispatch,
            seconds_per_frame: None,
            seconds_spent: 0.0,
            stage_seconds: None,
            timer,
            groups: (gx, gy),
            pixels,
            unit: 2f64.powi(gpu_scene.radiance_exponent) / f64::from(fixed_scale),
            pass: None,
        }))
    }

    /// The parameters the shader gets (for the layout test and the overflow tests).
    /// Seconds the light tracer's frames folded so far took (see `seconds_spent`).
    pub(crate) fn seconds_spent(&self) -> f64 {
        self.seconds_spent
    }

    pub(crate) fn params(&self) -> CausticParams {
        self.base
    }

    /// The most samples per pixel one pass may have so that its layers' statistics fit
    /// [`PASS_BYTES`] (at least one chunk).
    pub(crate) fn max_pass_spp(&self, layers: Layers) -> u32 {
        let per_chunk = PASS_BYTES_PER_PIXEL_LAYER * u64::from(layers.per_chunk()) * self.pixels as u64;
        let chunks = (PASS_BYTES / per_chunk).max(1);
        (chunks * u64::from(layers.chunk)).min(u64::from(u32::MAX)) as u32
    }

    /// Whether the frames of pass `key` are all traced and folded.
    pub(crate) fn holds(&self, key: PassKey) -> bool {
        self.pass.as_ref().is_some_and(|p| p.key == key && p.complete())
    }

    /// Takes pass `key` out of the tracer to gather its frames: the one being gathered or held,
    /// or a new one (a pass of another key, and a dispatch in flight for it, are dropped). The
    /// caller puts it back once its step is done; after an error it is dropped, and its frames
    /// are traced again.
    fn take_pass(&mut self, key: PassKey) -> CausticPass {
        match self.pass.take() {
            Some(pass) if pass.key == key => pass,
            _ => CausticPass::new(key, self.pixels),
        }
    }

    /// Traces the frames of pass `key` (absolute sample indices `key.first_sample..`, grouped
    /// in the slot layers `key.layers`) and folds them, waiting for each submission. Without
    /// `target_seconds` all of them, and it returns true; with it, one submission sized to that
    /// time (a viewer's share of a frame: some frames, or a piece of one), and it returns true
    /// only when the pass's frames were all folded before this call (so a step is one
    /// submission of caustic work or one band, never both).
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn prepare_pass(
        &mut self,
        gpu: &GpuContext,
        key: PassKey,
        target_seconds: Option<f64>,
    ) -> Result<bool, PathTraceError> {
        let mut pass = self.take_pass(key);
        // A polled read left in flight is abandoned, and so is a frame begun in pieces by
        // polling (its pieces may not all be done): their frames are traced again here.
        if pass.in_flight.take().is_some() || pass.pieces.as_ref().is_some_and(|p| !p.waited) {
            pass.pieces = None;
        }
        let ready = pass.complete();
        let (pixels, unit) = (self.pixels, self.unit);
        loop {
            let started = Instant::now();
            match self.launch(gpu, &mut pass, target_seconds, true)? {
                None => break,
                Some(Launched::Piece) => {
                    gpu.wait_idle("tracing a piece of a caustic frame")?;
                    if let Some(pieces) = &mut pass.pieces {
                        let stage = usize::from(pieces.submitted > pieces.counts[0]);
                        pieces.seconds[stage] += started.elapsed().as_secs_f64();
                    }
                }
                Some(Launched::Frames { staging, bytes, count, pieces_seconds }) => {
                    illum_gpu::readback::with_mapped(
                        gpu,
                        &staging,
                        bytes.total,
                        "reading back caustic frames",
                        |data| {
                            let words = bytemuck::cast_slice(&data[..bytes.frames as usize]);
                            pass.fold_frames(words, count, pixels, unit)
                        },
                    )?;
                    self.staging = Some(staging);
                    // What the steps waited for: the frames (or the frame's pieces), their
                    // readback and their fold.
                    let elapsed = started.elapsed().as_secs_f64();
                    let seconds = match pieces_seconds {
                        Some(mut stages) => {
                            stages[usize::from(self.gather.is_some())] += elapsed;
                            self.stage_seconds = Some(stages);
                            stages[0] + stages[1]
                        }
                        None => elapsed,
                    };
                    self.seconds_per_frame = Some(seconds / f64::from(count));
                    self.seconds_spent += seconds;
                }
            }
            if target_seconds.is_some() {
                break;
            }
        }
        self.pass = Some(pass);
        Ok(ready)
    }

    /// The polled form of [`Self::prepare_pass`]: true once the frames of pass `key` are all
    /// folded. Each call folds the frames in flight if their mapping is done, or sees whether
    /// the piece in flight is done, and then submits the next work; it never waits.
    pub(crate) fn poll_pass(
        &mut self,
        gpu: &GpuContext,
        key: PassKey,
        target_seconds: Option<f64>,
    ) -> Result<bool, PathTraceError> {
        let mut pass = self.take_pass(key);
        if let Some(flight) = pass.in_flight.take() {
            let Some(result) = flight.read.poll(gpu) else {
                pass.in_flight = Some(flight);
                self.pass = Some(pass);
                return Ok(false);
            };
            let data = result?;
            let frames = flight.bytes.frames as usize;
            pass.fold_frames(bytemuck::cast_slice(&data[..frames]), flight.count, self.pixels, self.unit);
            // Whole frames: the GPU's time where the device has timestamps; else the time until
            // the mapping was seen done, which counts the frames drawn meanwhile (so dispatches
            // stay short). A frame traced in pieces keeps the cost that cut it.
            if !flight.pieced {
                let gpu_ms =
                    self.timer.decode(&data[frames..]).map(|passes| passes.iter().map(|p| p.1).sum::<f64>());
                let seconds = gpu_ms.map_or_else(|| flight.launched.elapsed().as_secs_f64(), |ms| ms * 1e-3);
                self.seconds_per_frame = Some(seconds / f64::from(flight.count));
            }
            self.seconds_spent += self.seconds_per_frame.unwrap_or(0.0) * f64::from(flight.count);
            self.staging = Some(flight.read.into_buffer());
        } else if let Some(pieces) = &pass.pieces {
            // One piece on the GPU at a time: the queue never holds more than a step's work.
            if let Err(e) = gpu.device.poll(wgpu::PollType::Poll) {
                return Err(illum_gpu::GpuError::DeviceLost { message: e.to_string() }.into());
            }
            if !pieces.done.load(Ordering::Acquire) {
                self.pass = Some(pass);
                return Ok(false);
            }
        }
        let launched = self.launch(gpu, &mut pass, target_seconds, false)?;
        let complete = launched.is_none();
        match launched {
            Some(Launched::Frames { staging, bytes, count, pieces_seconds }) => {
                pass.in_flight = Some(InFlight {
                    read: PendingRead::start(staging, bytes.total, "reading back caustic frames"),
                    bytes,
                    count,
                    launched: Instant::now(),
                    pieced: pieces_seconds.is_some(),
                });
            }
            Some(Launched::Piece) => {
                let done = pass.pieces.as_ref().map(|p| p.done.clone()).expect("a piece belongs to a frame");
                gpu.queue.on_submitted_work_done(move || done.store(true, Ordering::Release));
            }
            None => {}
        }
        self.pass = Some(pass);
        Ok(complete)
    }

    /// Frames for the next dispatch: as many as the buffers hold without a `target_seconds`,
    /// else the target's worth at the last measured cost (one before any measurement, and at
    /// least one).
    fn dispatch_frames(&self, target_seconds: Option<f64>) -> u32 {
        match (target_seconds, self.seconds_per_frame) {
            (None, _) => self.max_frames_per_dispatch,
            (Some(_), None) => 1,
            (Some(target), Some(cost)) => {
                (target / cost.max(1e-9)).floor().clamp(1.0, f64::from(self.max_frames_per_dispatch)) as u32
            }
        }
    }

    /// Pieces of the next frame's particles and of its gather: `None` (a whole frame) unless
    /// a `target_seconds` is shorter than the last measured frame; then each stage in pieces
    /// of about the target, by the stages' measured costs (half the frame's each before they
    /// are measured), at most one per workgroup row or column of the dispatch, none empty.
    fn frame_pieces(&self, target_seconds: Option<f64>) -> Option<[u32; 2]> {
        let (target, cost) = (target_seconds?, self.seconds_per_frame?);
        if cost <= target {
            return None;
        }
        let split = match (self.stage_seconds, self.gather.is_some()) {
            (Some(stages), _) => stages,
            (None, true) => [cost / 2.0, cost / 2.0],
            (None, false) => [cost, 0.0],
        };
        let units = self.piece_units();
        let pieces = |seconds: f64| {
            let wanted = (seconds / target.max(1e-9)).ceil().clamp(1.0, f64::from(units)) as u32;
            units.div_ceil(units.div_ceil(wanted))
        };
        Some([pieces(split[0]), if self.gather.is_some() { pieces(split[1]) } else { 0 }])
    }

    /// The units a frame's dispatch is cut along: its workgroups along x when it has one row
    /// of them, else its rows.
    fn piece_units(&self) -> u32 {
        let (gx, gy) = self.groups;
        if gy == 1 { gx } else { gy }
    }

    /// Piece `i` of `count` of a frame's dispatch: its workgroups and its first particle (or
    /// pixel). The pieces cover the dispatch once, in order.
    fn piece(&self, i: u32, count: u32) -> ((u32, u32), u32) {
        let (gx, gy) = self.groups;
        let units = self.piece_units();
        let per = units.div_ceil(count);
        let first = (i * per).min(units);
        let n = per.min(units - first);
        if gy == 1 { ((n, 1), first * WORKGROUP) } else { ((gx, n), first * self.base.row_stride) }
    }

    /// The staging buffer for a dispatch's frames (the one read last, or a new one).
    fn take_staging(&mut self, gpu: &GpuContext) -> Result<wgpu::Buffer, PathTraceError> {
        match self.staging.take() {
            Some(staging) => Ok(staging),
            None => Ok(gpu.scoped("allocating the caustic's staging buffer", || {
                gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("caustic staging"),
                    size: self.splat_size + self.timer.result_size(),
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            })?),
        }
    }

    /// Submits the next work of `pass`: whole frames (sized by [`Self::dispatch_frames`]), or
    /// the next piece of a frame cut by [`Self::frame_pieces`] (the frame's particles piece by
    /// piece, then its gather piece by piece, its copy for readback with the last piece).
    /// `None` when the pass is complete. `waited`: the caller waits for each piece.
    fn launch(
        &mut self,
        gpu: &GpuContext,
        pass: &mut CausticPass,
        target_seconds: Option<f64>,
        waited: bool,
    ) -> Result<Option<Launched>, PathTraceError> {
        if pass.complete() {
            return Ok(None);
        }
        let frame = pass.key.first_sample + pass.frames_done;
        if pass.pieces.is_none()
            && let Some(counts) = self.frame_pieces(target_seconds)
        {
            pass.pieces =
                Some(FramePieces { counts, submitted: 0, done: Arc::default(), seconds: [0.0; 2], waited });
        }
        let Some(pieces) = &mut pass.pieces else {
            let count = self.dispatch_frames(target_seconds).min(pass.key.spp - pass.frames_done);
            let groups = (self.groups.0, self.groups.1, count);
            let (staging, bytes) =
                self.submit(gpu, frame, count, groups, 0, Stage::Whole)?.expect("whole frames are read back");
            return Ok(Some(Launched::Frames { staging, bytes, count, pieces_seconds: None }));
        };
        let (k, [particles, gathers]) = (pieces.submitted, pieces.counts);
        let last = k + 1 == particles + gathers;
        pieces.submitted += 1;
        pieces.done.store(false, Ordering::Release);
        let (((gx, gy), first), stage) = if k < particles {
            (self.piece(k, particles), Stage::Particles { first: k == 0, last })
        } else {
            (self.piece(k - particles, gathers), Stage::Gather { last })
        };
        match self.submit(gpu, frame, 1, (gx, gy, 1), first, stage)? {
            None => Ok(Some(Launched::Piece)),
            Some((staging, bytes)) => {
                let seconds = pass.pieces.take().map_or([0.0; 2], |p| p.seconds);
                Ok(Some(Launched::Frames { staging, bytes, count: 1, pieces_seconds: Some(seconds) }))
            }
        }
    }

    /// Records and submits one dispatch of `frames` frames from sample index `frame`, over
    /// `groups` workgroups from particle (or pixel) `first`, as `stage` says. Returns the
    /// staging buffer and what to read from it when the frames are complete (whole frames, or
    /// a frame's last piece).
    fn submit(
        &mut self,
        gpu: &GpuContext,
        frame: u32,
        frames: u32,
        groups: (u32, u32, u32),
        first: u32,
        stage: Stage,
    ) -> Result<Option<(wgpu::Buffer, DispatchBytes)>, PathTraceError> {
        let params =
            CausticParams { frame_base: frame, frame_count: frames, first_index: first, ..self.base };
        let words_per_frame = WORDS_PER_PIXEL * self.pixels as u64;
        let bytes = (words_per_frame + 1) * 4 * u64::from(frames);
        let (clear, particles, gather, read) = match stage {
            Stage::Whole => (true, true, true, true),
            Stage::Particles { first, last } => (first, true, false, last),
            Stage::Gather { last } => (false, false, true, last),
        };
        // Whole frames are timed; a piece is timed by its caller's wait.
        let timed = matches!(stage, Stage::Whole);
        let staging = if read { Some(self.take_staging(gpu)?) } else { None };
        gpu.queue.write_buffer(&self.scene_params_buffer, 0, bytemuck::bytes_of(&self.scene_params));
        gpu.queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("caustic frames") });
        if clear {
            encoder.clear_buffer(&self.splat, 0, Some(bytes));
            if let Some(gather) = &self.gather {
                encoder.clear_buffer(&gather.heads, 0, Some(gather.heads_frame_bytes * u64::from(frames)));
            }
        }
        if particles {
            let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("caustic"),
                timestamp_writes: if timed { self.timer.compute_writes(CAUSTIC_PASS) } else { None },
            });
            compute.set_pipeline(&self.pipeline);
            compute.set_bind_group(0, &self.bind_group, &[]);
            compute.dispatch_workgroups(groups.0, groups.1, groups.2);
        }
        // Its own pass: the gather reads what every particle of the frames stored.
        if let Some(gather) = self.gather.as_ref().filter(|_| gather) {
            let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("photon gather"),
                timestamp_writes: if timed { self.timer.compute_writes(GATHER_PASS) } else { None },
            });
            compute.set_pipeline(&gather.pipeline);
            compute.set_bind_group(0, &gather.bind_group, &[]);
            compute.dispatch_workgroups(groups.0, groups.1, groups.2);
        }
        let result = staging.map(|staging| {
            encoder.copy_buffer_to_buffer(&self.splat, 0, &staging, 0, bytes);
            let timestamps = if timed && self.timer.enabled() {
                self.timer.copy_results(&mut encoder, &staging, bytes);
                self.timer.result_size()
            } else {
                0
            };
            (staging, DispatchBytes { frames: bytes, total: bytes + timestamps })
        });
        gpu.queue.submit([encoder.finish()]);
        Ok(result)
    }

    /// Adds the held pass's layer `l` for the band's pixels `first_pixel..` to the accumulator,
    /// beside the camera's slot sums `camera` of that layer just folded for them (see the module
    /// documentation for the cross term).
    pub(crate) fn fold(
        &self,
        accumulator: &mut Accumulator,
        l: u32,
        first_pixel: usize,
        camera: &[[f32; 4]],
    ) {
        let pass = self.pass.as_ref().filter(|p| p.complete()).expect("prepare_pass before fold");
        let PassKey { first_sample, spp, layers } = pass.key;
        let frames = layers.samples(first_sample, l, batch::chunk_taken(layers, spp, l));
        let at = l as usize * self.pixels + first_pixel;
        let range = at..at + camera.len();
        accumulator.fold_independent(
            first_pixel,
            layers.replicate(l),
            camera,
            &pass.sum[range.clone()],
            &pass.sum_sq[range],
            frames,
        );
    }

    /// Forgets the held pass and abandons its dispatch in flight (their frames belong to a
    /// render that was reset).
    pub(crate) fn discard_pass(&mut self) {
        self.pass = None;
    }

    /// Ends the held pass: its dropped particles are counted once, and its memory freed.
    pub(crate) fn finish_pass(&mut self, accumulator: &mut Accumulator) {
        if let Some(pass) = self.pass.take() {
            accumulator.add_dropped(pass.dropped);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The no-overflow argument: N particles, each below the cap, sum below 2^64; the reference
    /// splat sits 2^24 below the cap (within a factor 2, S being a power of two), for one pixel
    /// up to 2^28 particles and references from a dim to a blinding sun.
    #[test]
    fn the_fixed_point_cannot_overflow_and_keeps_headroom() {
        for particles in [1u64, 2, 3, 1000, 512 * 512, 1 << 24, (1 << 28) - 1] {
            for reference in [1e-30, 1e-6, 0.37, 3.0, 1e6, 1e20] {
                let (scale, cap) = fixed_point(particles, reference);
                assert_eq!(scale.to_bits() & 0x007f_ffff, 0, "{scale} is a power of two");
                assert_eq!(cap.to_bits() & 0x007f_ffff, 0, "{cap} is a power of two");
                // N cap <= 2^64: the largest total of a frame's pixel fits the two words.
                assert!(particles as f64 * f64::from(cap) <= 2f64.powi(64), "N {particles}, cap {cap}");
                // Every q below the cap splits exactly into two words.
                assert!(f64::from(cap) <= 2f64.powi(64));
                let q = reference * f64::from(scale);
                let target = f64::from(cap) / 2f64.powi(24);
                // (S is an f32: beyond 2^120 it stops growing, and a light of 1e-30 keeps
                // fewer bits, still about 20.)
                let clamped = scale == 2f32.powi(120);
                assert!(
                    q <= target && (q > 0.5 * target || clamped),
                    "N {particles}, reference {reference}: q {q}, target {target}"
                );
            }
        }
        // A reference of zero (no light) or not a number gives scale 1, not infinity.
        assert_eq!(fixed_point(100, 0.0).0, 1.0);
        assert_eq!(fixed_point(100, f64::NAN).0, 1.0);
    }

    #[test]
    fn bounding_spheres_contain_their_shapes() {
        let quad = GpuShape::Quad {
            corner: Vec3::ZERO,
            edge_u: Vec3::new(2.0, 0.0, 0.0),
            edge_v: Vec3::new(1.0, 0.0, 3.0),
        };
        let (c, r) = bounding_sphere(&quad);
        for p in [Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 3.0), Vec3::new(3.0, 0.0, 3.0)] {
            assert!((p - c).length() <= r * (1.0 + 1e-6), "{p} outside ({c}, {r})");
        }
        let (cos, sin) = (0.5f32.sqrt(), 0.5f32.sqrt());
        let boxed = GpuShape::Box {
            local_min: Vec3::ZERO,
            local_max: Vec3::new(1.0, 2.0, 3.0),
            cos,
            sin,
            offset: Vec3::new(5.0, 0.0, 1.0),
        };
        let (c, r) = bounding_sphere(&boxed);
        for i in 0..8 {
            let l = Vec3::new((i & 1) as f32, 2.0 * ((i >> 1) & 1) as f32, 3.0 * ((i >> 2) & 1) as f32);
            let p = Vec3::new(cos * l.x + sin * l.z, l.y, -sin * l.x + cos * l.z) + Vec3::new(5.0, 0.0, 1.0);
            assert!((p - c).length() <= r * (1.0 + 1e-6), "corner {p} outside ({c}, {r})");
        }
    }
}
