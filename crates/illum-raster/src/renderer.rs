//! [`RasterRenderer`]: owns the GPU resources and turns a scene plus [`Options`] into frames.
//!
//! This file holds the renderer's resources and what sizes them (the scene, the output size,
//! the shadow map and cube maps); `renderer/record.rs` records a frame's passes and
//! `renderer/frames.rs` draws frames and reads them back.

mod frames;
mod record;

pub use frames::PendingFrame;

use illum_gpu::GpuContext;
use illum_gpu::timing::PassTimer;

use crate::RasterError;
use crate::bindings::{Samplers, TextureGroups, Uniforms};
use crate::mesh::MeshBuffer;
use crate::options::Options;
use crate::pipelines::Pipelines;
use crate::plan::FramePlan;
use crate::scene::RasterScene;
use crate::shadow_fit::{MAX_SHADOW_MAP, ShadowFit, fit_shadow};
use crate::targets::{CubeSet, MainTargets, ShadowMap};

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
    /// The scene's meshes' vertices (`None`: no mesh).
    mesh: Option<MeshBuffer>,
    main: Option<MainTargets>,
    /// Timestamp queries for exactly the passes of the last frame's plan (rebuilt when the plan
    /// changes, so that every query resolved was written).
    timer: PassTimer,
    timer_plan: Option<FramePlan>,
    /// Where frames and pass times are read back with a wait (natively only).
    #[cfg(not(target_arch = "wasm32"))]
    staging: Option<illum_gpu::wgpu::Buffer>,
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
        let mesh = gpu.scoped("uploading the meshes' vertices", || MeshBuffer::new(&gpu.device, &scene))?;
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
            mesh,
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
        if scene.meshes != self.scene.meshes {
            self.mesh = self
                .gpu
                .scoped("uploading the meshes' vertices", || MeshBuffer::new(&self.gpu.device, &scene))?;
        }
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
}
