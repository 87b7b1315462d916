//! Recording a [`RasterRenderer`]'s frame: the frame's uniforms, the pipelines its plan's passes
//! draw with, and the passes themselves (`frame.rs`).

use glam::Vec3;
use illum_gpu::timing::PassTimer;
use illum_gpu::wgpu;

use crate::RasterError;
use crate::frame::{
    FrameResources, GLASS_FACE_VIEWS, MAIN_VIEW, METAL_FACE_VIEWS, MainBand, SHADOW_VIEW, VIEW_COUNT,
};
use crate::options::Options;
use crate::plan::{FramePlan, Pass};
use crate::renderer::{RasterRenderer, ViewsKey};
use crate::targets::MainTargets;
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
    cube_mesh: PipelineKey,
    main_mesh: PipelineKey,
}

impl RasterRenderer {
    /// Writes the frame's uniforms and records its passes, the main pass for `main_band`'s rows
    /// only if given.
    pub(super) fn record(
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
            cube_mesh: key(Surface::Mesh, Target::Cube),
            main_mesh: key(Surface::Mesh, main),
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
                Pass::Capture(_) => {
                    [keys.cube_floor, keys.cube_receiver, keys.cube_glass, keys.cube_metal, keys.cube_mesh]
                }
                Pass::Main => {
                    [keys.main_floor, keys.main_receiver, keys.main_glass, keys.main_metal, keys.main_mesh]
                }
            };
            let drawn = [draws.floor, draws.receiver && !rings, draws.glass, draws.metal, draws.meshes];
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
            mesh_shadow_pipeline: &self.pipelines.mesh_shadow,
            shadow_map: &self.shadow_map.view,
            mesh: self.mesh.as_ref().map(|m| (&m.buffer, m.vertices)),
            cube_mesh: get(keys.cube_mesh),
            main_mesh: get(keys.main_mesh),
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
