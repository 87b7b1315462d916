//! The light tracer's resources: its pipelines (the particles', and with a delta sun the photon
//! gather's), its buffers (parameters, discs, splats, photon maps and grid) and their bind
//! groups, made once per tracer from the scene.

use glam::Vec3;
use illum_gpu::timing::PassTimer;
use illum_gpu::{GpuContext, wgpu};
use illum_scene::{MaterialKind, Scene};

use super::dispatch::{CAUSTIC_PASS, GATHER_PASS};
use super::params::{PARTICLE_SEED_KEY, PHOTON_BYTES, SPLAT_BYTES, WORDS_PER_PIXEL};
use super::schedule::Costs;
use super::{CausticParams, CausticTracer, Gather, bounding_sphere, fixed_point};
use crate::bindings::Binding;
use crate::estimators::GATHER_RADIUS_FRACTION;
use crate::gpu_scene::{GpuParams, GpuScene};
use crate::options::TracerOptions;
use crate::tracer::pipeline::bvh_bind_group;
use crate::{PathTraceError, shaders};

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

        let max_groups_x = limits.max_compute_workgroups_per_dimension;
        let base = CausticParams {
            particles: particles as u32,
            row_stride: 0,
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
            index_end: 0,
            radius_origin: 0,
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
        fn entry(binding: Binding, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry { binding: binding.index(), resource: buffer.as_entire_binding() }
        }
        let mut entries = vec![
            entry(Binding::Params, params),
            entry(Binding::Objects, objects),
            entry(Binding::Materials, materials),
            entry(Binding::CausticParams, &params_buffer),
            entry(Binding::Splat, &splat),
        ];
        if let Some((photons, heads)) = &photon_buffers {
            entries.push(entry(Binding::Photons, photons));
            entries.push(entry(Binding::Heads, heads));
        }
        // The gather reads no discs.
        let gather_entries = entries.clone();
        entries.push(entry(Binding::Discs, &discs_buffer));
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
                let bvh = bvh_bind_group(device, &pipeline, scene, gpu_scene, options);
                Some(Gather {
                    pipeline,
                    bind_group,
                    bvh,
                    heads: heads.clone(),
                    heads_frame_bytes: 4 * buckets,
                })
            }
            None => None,
        };
        Ok(Some(CausticTracer {
            bvh: bvh_bind_group(device, &pipeline, scene, gpu_scene, options),
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
            costs: Costs::default(),
            seconds_spent: 0.0,
            parts: Default::default(),
            timer,
            max_groups_x,
            pixels,
            unit: 2f64.powi(gpu_scene.radiance_exponent) / f64::from(fixed_scale),
            pass: None,
        }))
    }
}
