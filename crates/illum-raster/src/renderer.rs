//! [`RasterRenderer`]: owns the GPU resources and turns a scene plus [`Options`] into frames.
//!
//! Over 450 lines: the GPU resources and the frame loops that share them read best in one type.

#[cfg(not(target_arch = "wasm32"))]
use std::ops::ControlFlow;

use crate::scene::RasterScene;
use glam::Vec3;
use illum_gpu::readback;
use illum_gpu::timing::PassTimer;
use illum_gpu::{GpuContext, wgpu};
use illum_image::RgbImage32;

use crate::RasterError;
use crate::bindings::{Samplers, TextureGroups, Uniforms};
use crate::frame::{
    FrameResources, GLASS_FACE_VIEWS, MAIN_VIEW, METAL_FACE_VIEWS, MainBand, SHADOW_VIEW, VIEW_COUNT,
};
use crate::options::Options;
#[cfg(not(target_arch = "wasm32"))]
use crate::pass_times::Frame;
use crate::pass_times::PassTimes;
use crate::pipelines::Pipelines;
use crate::plan::{FramePlan, Pass};
use crate::shadow_fit::{MAX_SHADOW_MAP, ShadowFit, fit_shadow};
use crate::targets::{CubeSet, MainTargets, ShadowMap};
use crate::uniforms::{self, ViewUniform};
use crate::variants::{PipelineKey, Surface, Target};
use crate::views::{capture_clip, cube_face_view_proj, main_view_proj};

/// The pipelines of one frame.
struct Keys {
    cube_floor: PipelineKey,
    cube_receiver: PipelineKey,
    cube_metal: PipelineKey,
    cube_glass: PipelineKey,
    main_floor: PipelineKey,
    /// The floor's interior, when `main_floor` draws only the band along its outline.
    main_floor_interior: PipelineKey,
    main_receiver: PipelineKey,
    /// The floor's shadows as rings and discs (`FramePlan::shadow_rings`), in the main pass.
    main_penumbra: PipelineKey,
    main_umbra: PipelineKey,
    main_glass: PipelineKey,
    main_metal: PipelineKey,
}

/// Bytes per output pixel (RGBA8), for the frame's readback.
const BYTES_PER_PIXEL: u32 = 4;

/// The rasterizer (Whitted's look, faked): a scene, a fixed output size and the GPU resources for them.
pub struct RasterRenderer {
    gpu: GpuContext,
    scene: RasterScene,
    width: u32,
    height: u32,
    pipelines: Pipelines,
    uniforms: Uniforms,
    samplers: Samplers,
    shadow_fit: ShadowFit,
    shadow_map: ShadowMap,
    cubes: CubeSet,
    texture_groups: TextureGroups,
    main: Option<MainTargets>,
    /// Timestamp queries for exactly the passes of the last frame's plan (rebuilt when the plan
    /// changes, so that every query resolved was written).
    timer: PassTimer,
    timer_plan: Option<FramePlan>,
    /// Where frames and pass times are read back with a wait (natively only).
    #[cfg(not(target_arch = "wasm32"))]
    staging: Option<wgpu::Buffer>,
    /// What the shadow map and cube maps hold now, if a recorded frame made them (see
    /// [`ViewsKey`]).
    views: Option<ViewsKey>,
    /// The cube-map side the scene asks for; `scene.quality.cube_size` is the side in use,
    /// smaller while the scene changes (see [`Self::set_scene`]).
    full_cube_size: u32,
    /// A [`Self::set_scene`] changed what the shadow map or the cube maps show since the last
    /// frame was recorded.
    changed_since_frame: bool,
    /// Whether a changing scene's cube maps are captured at [`moving_cube_size`] (see
    /// [`Self::set_reduced_cubes_while_changing`]).
    reduced_cubes_while_changing: bool,
}

/// Cube-map side while the scene changes from frame to frame: a quarter of the scene's side (a
/// sixteenth of the texels to render every frame), at least [`MIN_MOVING_CUBE_SIZE`]. The first
/// frame drawn with the scene still captures them at full size again. What it costs in the
/// image while moving is measured in docs/performance-raster.md.
pub fn moving_cube_size(full: u32) -> u32 {
    (full / 4).max(MIN_MOVING_CUBE_SIZE).min(full)
}

/// Smallest side [`moving_cube_size`] chooses: the coarse level is an eighth of it, 8 texels.
pub const MIN_MOVING_CUBE_SIZE: u32 = 64;

/// Everything the shadow map and the cube maps depend on: the scene but for its camera (the
/// captures are made from the light and the spheres' centres, with their own clip planes) and
/// the frame's options and plan.
#[derive(Clone, Debug, PartialEq)]
struct ViewsKey {
    scene: RasterScene,
    options: Options,
    plan: FramePlan,
}

impl ViewsKey {
    fn new(scene: &RasterScene, options: &Options, plan: FramePlan) -> Self {
        let camera = illum_scene::Camera {
            eye: glam::Vec3::ZERO,
            target: glam::Vec3::ZERO,
            up: glam::Vec3::ZERO,
            vfov_deg: 0.0,
            width: 0,
            height: 0,
        };
        ViewsKey { scene: RasterScene { camera, ..scene.clone() }, options: *options, plan }
    }
}

impl RasterRenderer {
    /// Compiles the pipelines and allocates everything for `width` x `height` output, after
    /// checking the size (and the scene's cube maps) against the device's limits.
    pub fn new(gpu: &GpuContext, scene: &RasterScene, width: u32, height: u32) -> Result<Self, RasterError> {
        let scene = Self::sized(gpu, scene, width, height)?;
        let pipelines = Pipelines::new(gpu)?;
        let uniforms = Uniforms::new(gpu, &pipelines.uniforms_layout)?;
        let samplers = Samplers::new(gpu)?;
        let shadow_fit = fit_shadow(&scene, Self::max_shadow_map(gpu));
        let shadow_map = ShadowMap::new(gpu, shadow_fit.size)?;
        let cubes = CubeSet::new(gpu, scene.quality.cube_size)?;
        let cubes_side = scene.quality.cube_size;
        let texture_groups =
            TextureGroups::new(gpu, &pipelines.textures_layout, &samplers, &shadow_map, &cubes)?;
        Ok(RasterRenderer {
            gpu: gpu.clone(),
            scene,
            width,
            height,
            pipelines,
            uniforms,
            samplers,
            shadow_fit,
            shadow_map,
            cubes,
            texture_groups,
            main: None,
            timer: PassTimer::new(gpu, &[]),
            timer_plan: None,
            #[cfg(not(target_arch = "wasm32"))]
            staging: None,
            views: None,
            full_cube_size: cubes_side,
            changed_since_frame: false,
            reduced_cubes_while_changing: false,
        })
    }

    /// `scene` with the output size set to `width` x `height`, checked against the device.
    fn sized(
        gpu: &GpuContext,
        scene: &RasterScene,
        width: u32,
        height: u32,
    ) -> Result<RasterScene, RasterError> {
        let mut scene = scene.clone();
        scene.set_resolution(Some(width), Some(height), "RasterRenderer")?;
        crate::limits::check_device_limits(&scene, &gpu.device.limits())?;
        Ok(scene)
    }

    fn max_shadow_map(gpu: &GpuContext) -> u32 {
        gpu.device.limits().max_texture_dimension_2d.min(MAX_SHADOW_MAP)
    }

    pub fn scene(&self) -> &RasterScene {
        &self.scene
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The shadow map's side in texels and one texel's size in scene units.
    pub fn shadow_map_resolution(&self) -> (u32, f32) {
        (self.shadow_fit.size, self.shadow_fit.texel)
    }

    /// With `true`, a change of what the shadow map or the cube maps show (anything but the
    /// camera) makes the next frame capture the cube maps at [`moving_cube_size`]: a scene
    /// edited every frame (a sphere dragged in a viewer) pays a sixteenth of the capture, and
    /// its glass and mirror show a blurrier environment while it moves. The next frame recorded
    /// with no change in between captures them again at the scene's own size, so a still scene
    /// always shows its full-resolution image. Off by default: every frame is then exact.
    pub fn set_reduced_cubes_while_changing(&mut self, reduced: bool) {
        self.reduced_cubes_while_changing = reduced;
    }

    /// Replaces the scene (a moved sphere or light, other colours): refits the shadow map and,
    /// if the cube size changed, reallocates the cube maps. The output size stays. See
    /// [`Self::set_reduced_cubes_while_changing`] for scenes that change every frame.
    pub fn set_scene(&mut self, scene: &RasterScene) -> Result<(), RasterError> {
        let mut scene = Self::sized(&self.gpu, scene, self.width, self.height)?;
        let full = scene.quality.cube_size;
        let mut before = self.scene.clone();
        before.camera = scene.camera;
        before.quality.cube_size = self.full_cube_size;
        let changed = self.reduced_cubes_while_changing && before != scene;
        self.changed_since_frame |= changed;
        self.full_cube_size = full;
        scene.quality.cube_size = if changed { moving_cube_size(full) } else { self.scene.quality.cube_size };
        self.fit_targets(scene)
    }

    /// Takes `scene` (its cube size the one to use) and makes the shadow map and the cube maps
    /// fit it, reallocating what changed size.
    fn fit_targets(&mut self, scene: RasterScene) -> Result<(), RasterError> {
        let fit = fit_shadow(&scene, Self::max_shadow_map(&self.gpu));
        let cube_size = scene.quality.cube_size;
        if fit.size != self.shadow_map.size {
            self.shadow_map = ShadowMap::new(&self.gpu, fit.size)?;
            self.views = None;
        }
        if cube_size != self.cubes.glass.size {
            self.cubes = CubeSet::new(&self.gpu, cube_size)?;
            self.views = None;
        }
        self.texture_groups = TextureGroups::new(
            &self.gpu,
            &self.pipelines.textures_layout,
            &self.samplers,
            &self.shadow_map,
            &self.cubes,
        )?;
        self.shadow_fit = fit;
        self.scene = scene;
        Ok(())
    }

    /// The passes the next frame with `options` records (see [`FramePlan`]): without the shadow
    /// and capture passes when the last frame made their results for this scene (camera aside)
    /// and these options.
    pub fn plan(&self, options: &Options) -> FramePlan {
        let fresh = FramePlan::new(&self.scene, options, &self.shadow_fit);
        let reuse_views = self.views.as_ref() == Some(&ViewsKey::new(&self.scene, options, fresh));
        FramePlan { reuse_views, ..fresh }
    }

    /// Changes the output size (checked against the device's limits).
    pub fn resize(&mut self, width: u32, height: u32) -> Result<(), RasterError> {
        self.scene = Self::sized(&self.gpu, &self.scene, width, height)?;
        self.width = width;
        self.height = height;
        self.main = None;
        Ok(())
    }

    /// Renders one frame and reads it back: linear RGB, row 0 at the top, each value one of the
    /// 256 levels k / 255 of the 8-bit output. Waits for the GPU (not on `wasm32`, where a web
    /// page shows [`Self::output_view`] instead).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn render(&mut self, options: &Options) -> Result<RgbImage32, RasterError> {
        Ok(self.render_timed(options)?.image)
    }

    /// [`Self::render`] plus the GPU time of each pass.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn render_timed(&mut self, options: &Options) -> Result<Frame, RasterError> {
        let encoder = self.record(options, None)?;
        self.read_frame(encoder)
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// [`Self::render`] for a long render: the main pass in bands of `rows_per_band` rows
    /// (rounded up to a multiple of 64, the tile side of Mesa's llvmpipe, so that no band edge
    /// cuts a tile), each its own submission, waited for before the next; the shadow map and
    /// cube maps are made with the first band. After each band `after_band`, given the rows
    /// done, can show progress, and stop the render by returning [`ControlFlow::Break`], which
    /// returns `Ok(None)`; after the last band (called before the readback, which takes seconds
    /// for a frame of gigabytes) the frame is complete and is returned whatever `after_band`
    /// says. The frame is the one
    /// [`Self::render`] draws, pixel for pixel (`tests/raster/bands.rs`); it has no pass times
    /// (the main pass is timed in pieces).
    pub fn render_in_bands(
        &mut self,
        options: &Options,
        rows_per_band: u32,
        mut after_band: impl FnMut(u32) -> ControlFlow<()>,
    ) -> Result<Option<RgbImage32>, RasterError> {
        let band = rows_per_band.max(1).next_multiple_of(64);
        let mut first_row = 0;
        while first_row < self.height {
            let rows = band.min(self.height - first_row);
            let encoder = self.record(options, Some(MainBand { first_row, rows, width: self.width }))?;
            self.gpu.queue.submit([encoder.finish()]);
            self.gpu.wait_idle("drawing a band of a raster frame")?;
            first_row += rows;
            // After the last band the frame is complete: returned whatever `after_band` says.
            if after_band(first_row).is_break() && first_row < self.height {
                return Ok(None);
            }
        }
        let encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("raster readback") });
        Ok(Some(self.read_frame(encoder)?.image))
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// Copies the output (and the pass times) into the staging buffer, submits `encoder` and
    /// reads the frame back.
    fn read_frame(&mut self, mut encoder: wgpu::CommandEncoder) -> Result<Frame, RasterError> {
        let row = (self.width * BYTES_PER_PIXEL).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let image_bytes = u64::from(row) * u64::from(self.height);
        let staging = self.staging(image_bytes + self.timer.result_size());
        let main = self.main.as_ref().expect("record() made the main targets");
        copy_output(&mut encoder, &main.output, &staging, self.width, self.height, row);
        self.timer.copy_results(&mut encoder, &staging, image_bytes);
        self.gpu.queue.submit([encoder.finish()]);
        let bytes =
            readback::read_mapped(&self.gpu, &staging, staging.size(), "reading back a raster frame")?;
        let (pixels, timestamps) = bytes.split_at(image_bytes as usize);
        let image = decode_frame(self.width, self.height, pixels);
        let pass_times = self.timer.decode(timestamps).map(|named| PassTimes::from_named(&named));
        Ok(Frame { image, pass_times })
    }

    /// Starts reading back the last frame drawn ([`Self::draw`]) without waiting, as a web page
    /// must: [`PendingFrame::poll`], called on later frames, returns the image [`Self::render`]
    /// returns for the same frame. The copy has a staging buffer of its own, so frames drawn
    /// meanwhile neither wait for it nor change it.
    pub fn read_polled(&self) -> Result<PendingFrame, RasterError> {
        let main = self.main.as_ref().ok_or_else(|| {
            RasterError::Unsupported("no raster frame to read back: draw one first".to_owned())
        })?;
        let row = (self.width * BYTES_PER_PIXEL).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let bytes = u64::from(row) * u64::from(self.height);
        let staging = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("raster polled staging"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("raster polled readback"),
        });
        copy_output(&mut encoder, &main.output, &staging, self.width, self.height, row);
        self.gpu.queue.submit([encoder.finish()]);
        Ok(PendingFrame {
            read: readback::PendingRead::start(staging, bytes, "reading back a raster frame"),
            width: self.width,
            height: self.height,
        })
    }

    /// Renders one frame into [`Self::output_view`] without reading it back, waits for the GPU
    /// and returns the pass times (what a benchmark or a viewer needs).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn draw(&mut self, options: &Options) -> Result<Option<PassTimes>, RasterError> {
        let mut encoder = self.record(options, None)?;
        if !self.timer.enabled() {
            self.gpu.queue.submit([encoder.finish()]);
            self.gpu.wait_idle("drawing a raster frame")?;
            return Ok(None);
        }
        let size = self.timer.result_size();
        let staging = self.staging(size);
        self.timer.copy_results(&mut encoder, &staging, 0);
        self.gpu.queue.submit([encoder.finish()]);
        let bytes = readback::read_mapped(&self.gpu, &staging, size, "reading raster pass times")?;
        Ok(self.timer.decode(&bytes).map(|named| PassTimes::from_named(&named)))
    }

    /// Renders one frame into [`Self::output_view`] and submits it, without waiting: in a web
    /// page the browser orders the page's drawing of the output after this submission. No pass
    /// times (reading them back would wait): always `None`.
    #[cfg(target_arch = "wasm32")]
    pub fn draw(&mut self, options: &Options) -> Result<Option<PassTimes>, RasterError> {
        let encoder = self.record(options, None)?;
        self.gpu.queue.submit([encoder.finish()]);
        self.gpu.check()?;
        Ok(None)
    }

    /// The last frame (RGBA8, linear values), after [`Self::draw`] or [`Self::render`].
    pub fn output_view(&self) -> Option<&wgpu::TextureView> {
        self.main.as_ref().map(|m| &m.output_view)
    }

    /// A mappable staging buffer of at least `size` bytes (reused between frames).
    #[cfg(not(target_arch = "wasm32"))]
    fn staging(&mut self, size: u64) -> wgpu::Buffer {
        if self.staging.as_ref().is_none_or(|s| s.size() != size) {
            self.staging = Some(self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("raster staging"),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        self.staging.clone().expect("allocated above")
    }

    /// Writes the frame's uniforms and records its passes, the main pass for `main_band`'s rows
    /// only if given.
    fn record(
        &mut self,
        options: &Options,
        main_band: Option<MainBand>,
    ) -> Result<wgpu::CommandEncoder, RasterError> {
        // A frame's first (or only) recording: if the scene stood still since the last frame,
        // back to full-size cube maps. Later bands of the same frame keep what the first made.
        if main_band.is_none_or(|band| band.first_row == 0)
            && !std::mem::take(&mut self.changed_since_frame)
            && self.scene.quality.cube_size != self.full_cube_size
        {
            let mut scene = self.scene.clone();
            scene.quality.cube_size = self.full_cube_size;
            self.fit_targets(scene)?;
        }
        if self.main.is_none() {
            crate::targets::check_main_targets(&self.gpu.device.limits(), self.width, self.height)
                .map_err(RasterError::Unsupported)?;
            self.main = Some(MainTargets::new(&self.gpu, self.width, self.height)?);
        }
        let main = Target::main(options);
        let plan = self.plan(options);
        let views = ViewsKey::new(&self.scene, options, FramePlan { reuse_views: false, ..plan });
        if self.timer_plan != Some(plan) {
            let names = plan.pass_names();
            let name_refs: Vec<&str> = names.iter().map(String::as_str).collect();
            self.timer = PassTimer::new(&self.gpu, &name_refs);
            self.timer_plan = Some(plan);
        }
        let key = |surface, target| PipelineKey::new(surface, target, options, &plan);
        let keys = Keys {
            cube_floor: key(Surface::Floor, Target::Cube),
            cube_receiver: key(Surface::FloorReceiver, Target::Cube),
            cube_metal: key(Surface::Metal, Target::Cube),
            cube_glass: key(Surface::Glass, Target::Cube),
            main_floor: key(Surface::Floor, main),
            main_floor_interior: key(Surface::FloorInterior, main),
            main_receiver: key(Surface::FloorReceiver, main),
            main_penumbra: key(Surface::FloorPenumbra, main),
            main_umbra: key(Surface::FloorUmbra, main),
            main_glass: key(Surface::Glass, main),
            main_metal: key(Surface::Metal, main),
        };
        // The pipelines the plan's passes draw with.
        let mut needed = std::collections::HashSet::new();
        for pass in plan.passes() {
            let draws = plan.draws(pass);
            // The main pass draws the floor's shadows as rings and discs when the plan allows,
            // and, anti-aliased, the floor as its interior and the band along its outline.
            let rings = pass == Pass::Main && plan.shadow_rings;
            let interior = pass == Pass::Main && draws.floor && main.antialiased();
            let pass_keys = match pass {
                Pass::Shadow => continue,
                Pass::Capture(_) => [keys.cube_floor, keys.cube_receiver, keys.cube_glass, keys.cube_metal],
                Pass::Main => [keys.main_floor, keys.main_receiver, keys.main_glass, keys.main_metal],
            };
            let drawn = [draws.floor, draws.receiver && !rings, draws.glass, draws.metal];
            let main_only = [
                (keys.main_penumbra, draws.receiver && rings),
                (keys.main_umbra, draws.receiver && rings),
                (keys.main_floor_interior, interior),
            ];
            for (key, drawn) in pass_keys.into_iter().zip(drawn).chain(main_only) {
                if drawn {
                    self.pipelines.ensure(&self.gpu, key)?;
                    needed.insert(key);
                }
            }
        }
        self.write_uniforms();

        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("raster frame") });
        let main = self.main.as_ref().expect("made above");
        let get = |key: PipelineKey| needed.contains(&key).then(|| self.pipelines.get(&key));
        let resources = FrameResources {
            plan,
            timer: &self.timer,
            uniforms: &self.uniforms.group,
            view_stride: self.uniforms.view_stride,
            shadow_pipeline: &self.pipelines.shadow,
            shadow_map: &self.shadow_map.view,
            cube_floor: get(keys.cube_floor),
            cube_floor_receiver: get(keys.cube_receiver),
            main_floor_receiver: get(keys.main_receiver),
            main_floor_rings: get(keys.main_penumbra).zip(get(keys.main_umbra)),
            ring_spheres: u32::from(!plan.glass)..1 + u32::from(plan.metal),
            cube_metal: get(keys.cube_metal),
            cube_glass: get(keys.cube_glass),
            cube_depth: &self.cubes.depth,
            coarse_depth: &self.cubes.coarse_depth,
            glass_faces: &self.cubes.glass.face_views,
            glass_coarse_faces: &self.cubes.glass_coarse.face_views,
            metal_faces: &self.cubes.metal.face_views,
            glass_capture_textures: &self.texture_groups.glass_capture,
            metal_capture_textures: &self.texture_groups.metal_capture,
            main_textures: &self.texture_groups.main,
            main_floor: get(keys.main_floor).expect("the main pass draws the floor"),
            main_floor_interior: get(keys.main_floor_interior),
            main_spheres: if self.metal_behind_glass() {
                [get(keys.main_metal), get(keys.main_glass)]
            } else {
                [get(keys.main_glass), get(keys.main_metal)]
            },
            main_output: &main.output_view,
            main_depth: &main.depth,
            main_band,
            background: self.scene.background.to_array(),
        };
        resources.record(&mut encoder);
        self.views = Some(views);
        Ok(encoder)
    }

    /// Whether the main pass draws the metal sphere before the glass ([`crate::frame::metal_behind_glass`]).
    fn metal_behind_glass(&self) -> bool {
        let s = &self.scene;
        match (&s.glass, &s.metal) {
            (Some(glass), Some(metal)) => crate::frame::metal_behind_glass(
                s.camera.eye,
                (glass.center, glass.radius),
                (metal.center, metal.radius),
            ),
            _ => false,
        }
    }

    fn write_uniforms(&self) {
        let scene = &self.scene;
        let mut views: [ViewUniform; VIEW_COUNT] = bytemuck::Zeroable::zeroed();
        views[MAIN_VIEW] =
            uniforms::perspective_view(main_view_proj(scene, self.width, self.height), scene.camera.eye, {
                // 2 tan(vfov / 2) / height: the image plane at distance 1 is 2 tan(vfov / 2) high.
                2.0 * scene.camera.basis().tan_half_fov / self.height as f32
            });
        let cube_view = |center: Vec3, face: usize| {
            uniforms::perspective_view(
                cube_face_view_proj(center, face, capture_clip(scene, center)),
                center,
                0.0,
            )
        };
        // An absent sphere's face views stay zero: no capture uses them.
        for face in 0..6 {
            if let Some(glass) = &scene.glass {
                views[GLASS_FACE_VIEWS + face] = cube_view(glass.center, face);
            }
            if let Some(metal) = &scene.metal {
                views[METAL_FACE_VIEWS + face] = cube_view(metal.center, face);
            }
        }
        views[SHADOW_VIEW] = uniforms::shadow_view(&self.shadow_fit);
        self.uniforms.write(&self.gpu, &uniforms::scene_uniform(scene, &self.shadow_fit), &views);
    }
}

/// A raster frame whose readback is under way ([`RasterRenderer::read_polled`]).
pub struct PendingFrame {
    read: readback::PendingRead,
    width: u32,
    height: u32,
}

impl PendingFrame {
    /// `None` while the frame is still being read back; never waits.
    pub fn poll(&self, gpu: &GpuContext) -> Option<Result<RgbImage32, RasterError>> {
        let bytes = self.read.poll(gpu)?;
        Some(bytes.map_err(RasterError::from).map(|bytes| decode_frame(self.width, self.height, &bytes)))
    }

    /// The frame's size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
}

/// The output's RGBA8 rows (each padded to the copy alignment) as linear RGB: each value one of
/// the 256 levels k / 255.
fn decode_frame(width: u32, height: u32, pixels: &[u8]) -> RgbImage32 {
    let row = (width * BYTES_PER_PIXEL).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    RgbImage32::from_fn(width, height, |x, y| {
        let i = (y * row + x * BYTES_PER_PIXEL) as usize;
        [0, 1, 2].map(|c| f32::from(pixels[i + c]) / 255.0)
    })
}

/// Records the copy of the output texture (`width` x `height`) into `staging`, rows `row` bytes
/// apart (a multiple of wgpu's copy alignment).
fn copy_output(
    encoder: &mut wgpu::CommandEncoder,
    output: &wgpu::Texture,
    staging: &wgpu::Buffer,
    width: u32,
    height: u32,
    row: u32,
) {
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture: output,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: staging,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: None },
        },
        wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
    );
}
