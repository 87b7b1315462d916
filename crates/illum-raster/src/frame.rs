//! Recording one frame: the shadow pass, the cube-map captures and the main pass.
//!
//! Order matters because each pass reads what the previous ones wrote:
//! 1. shadow: the spheres' and the meshes' depth from the light;
//! 2. glass cube: six faces from the glass sphere's centre showing everything but the glass
//!    (the floor with its shadows, the meshes, the metal sphere Phong-lit, the sky), then the
//!    same six at an eighth of the side, the prefiltered level for lookups with a wide footprint;
//! 3. metal cube: six faces from the metal sphere's centre showing everything but the metal,
//!    the glass refracting the glass cube just made;
//! 4. main: the floor, the meshes, then the spheres back to front, the glass reading the glass
//!    cube and (enhanced) the metal reading the metal cube; with anti-aliasing each sphere's edge
//!    is blended over what is behind it by its coverage, so what is behind must be drawn first.
//!
//! A pass the frame's [`FramePlan`] leaves out is not recorded at all (plan.rs says when).
//!
//! So the metal seen inside the glass lacks its own reflection, and the glass seen in the
//! metal's mirror has one cube level less: a rasterizer's stand-in for recursion depth.

use illum_gpu::timing::PassTimer;
use illum_gpu::wgpu;

use crate::plan::{Cube, FramePlan, Pass};
use crate::views::CUBE_FACE_NAMES;

/// Slots of the view uniform buffer.
pub const MAIN_VIEW: usize = 0;
pub const GLASS_FACE_VIEWS: usize = 1;
pub const METAL_FACE_VIEWS: usize = 7;
pub const SHADOW_VIEW: usize = 13;
pub const VIEW_COUNT: usize = 14;

/// Six vertices: the two triangles of a quad.
const QUAD: std::ops::Range<u32> = 0..6;
/// Sides of a penumbra ring and an umbra disc (`RING_SIDES` in floor.wgsl, which builds them).
const RING_SIDES: u32 = 32;
/// A penumbra ring and an umbra disc: RING_SIDES quads and triangles.
const RING_VERTICES: std::ops::Range<u32> = 0..6 * RING_SIDES;
const DISC_VERTICES: std::ops::Range<u32> = 0..3 * RING_SIDES;
/// The band along the floor's outline: a quad for each of its four sides (floor.wgsl).
const OUTLINE_VERTICES: std::ops::Range<u32> = 0..24;

/// Everything a frame's passes bind or render into.
pub struct FrameResources<'a> {
    pub plan: FramePlan,
    pub timer: &'a PassTimer,
    pub uniforms: &'a wgpu::BindGroup,
    pub view_stride: u64,
    pub shadow_pipeline: &'a wgpu::RenderPipeline,
    pub mesh_shadow_pipeline: &'a wgpu::RenderPipeline,
    pub shadow_map: &'a wgpu::TextureView,
    /// The meshes' vertex buffer and its vertex count (`None`: the scene has no mesh).
    pub mesh: Option<(&'a wgpu::Buffer, u32)>,
    /// The meshes in cube faces and in the main view (`None`: no mesh, or no such pass).
    pub cube_mesh: Option<&'a wgpu::RenderPipeline>,
    pub main_mesh: Option<&'a wgpu::RenderPipeline>,
    /// The floor in cube faces (`None`: the frame captures no cube map).
    pub cube_floor: Option<&'a wgpu::RenderPipeline>,
    /// The floor's shadow receiver (`None`: shadows off), for the cube faces and the main view.
    pub cube_floor_receiver: Option<&'a wgpu::RenderPipeline>,
    pub main_floor_receiver: Option<&'a wgpu::RenderPipeline>,
    /// The floor's shadows as each sphere's penumbra ring and umbra disc, instead of the
    /// receiver (floor.wgsl, PART 1 and 2), and the spheres present (instance 0 the glass, 1 the
    /// metal).
    pub main_floor_rings: Option<(&'a wgpu::RenderPipeline, &'a wgpu::RenderPipeline)>,
    pub ring_spheres: std::ops::Range<u32>,
    /// The metal sphere as the glass capture draws it (`None`: no metal sphere).
    pub cube_metal: Option<&'a wgpu::RenderPipeline>,
    /// The glass sphere as the metal capture draws it (`None`: no glass sphere, or no metal cube).
    pub cube_glass: Option<&'a wgpu::RenderPipeline>,
    pub cube_depth: &'a wgpu::TextureView,
    pub coarse_depth: &'a wgpu::TextureView,
    pub glass_faces: &'a [wgpu::TextureView],
    pub glass_coarse_faces: &'a [wgpu::TextureView],
    pub metal_faces: &'a [wgpu::TextureView],
    /// Group 1 for the glass capture (no cube map readable), the metal capture (glass cube
    /// readable) and the main pass (both).
    pub glass_capture_textures: &'a wgpu::BindGroup,
    pub metal_capture_textures: &'a wgpu::BindGroup,
    pub main_textures: &'a wgpu::BindGroup,
    /// The floor without the shadow lookups: the whole floor, or, with `main_floor_interior`
    /// (an anti-aliased view), only the band along its outline.
    pub main_floor: &'a wgpu::RenderPipeline,
    pub main_floor_interior: Option<&'a wgpu::RenderPipeline>,
    /// The spheres in the main view, the farther first (`None`: the scene lacks that sphere);
    /// see [`metal_behind_glass`].
    pub main_spheres: [Option<&'a wgpu::RenderPipeline>; 2],
    pub main_output: &'a wgpu::TextureView,
    pub main_depth: &'a wgpu::TextureView,
    /// The rows the main pass draws (`None`: all). A band after the first keeps what the
    /// earlier bands drew (the first clears the whole output); see [`MainBand`].
    pub main_band: Option<MainBand>,
    pub background: [f32; 3],
}

/// Rows `first_row .. first_row + rows` of a `width`-wide main view: what one submission of a
/// long render draws ([`crate::RasterRenderer::render_in_bands`]). The scissor keeps every
/// fragment outside the band from being written, and each band clears its own depth, so the
/// bands together are the whole frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MainBand {
    pub first_row: u32,
    pub rows: u32,
    pub width: u32,
}

/// One cube map's capture.
#[derive(Clone, Copy)]
struct Capture<'a> {
    /// For the pass names: "cube NAME +X" and so on.
    name: &'a str,
    /// The six layers to render, in CUBE_FACE_NAMES order.
    faces: &'a [wgpu::TextureView],
    depth: &'a wgpu::TextureView,
    /// View-uniform slot of the +X face; the others follow.
    first_view: usize,
    textures: &'a wgpu::BindGroup,
    /// The other sphere, as seen from this one (`None`: the scene has no other sphere).
    sphere: Option<&'a wgpu::RenderPipeline>,
}

impl FrameResources<'_> {
    fn view_offset(&self, slot: usize) -> u32 {
        (slot as u64 * self.view_stride) as u32
    }

    fn clear_colour(&self) -> wgpu::Color {
        let [r, g, b] = self.background.map(f64::from);
        wgpu::Color { r, g, b, a: 1.0 }
    }

    fn clear_depth<'t>(
        &self,
        view: &'t wgpu::TextureView,
    ) -> Option<wgpu::RenderPassDepthStencilAttachment<'t>> {
        Some(wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Discard,
            }),
            stencil_ops: None,
        })
    }

    /// Records the passes of the frame's plan, in its order.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder) {
        for pass in self.plan.passes() {
            match pass {
                Pass::Shadow => self.shadow_pass(encoder),
                Pass::Capture(cube) => self.capture(encoder, &self.capture_of(cube)),
                Pass::Main => self.main_pass(encoder),
            }
        }
    }

    /// What the capture of `cube` renders into and draws.
    fn capture_of(&self, cube: Cube) -> Capture<'_> {
        match cube {
            Cube::Glass => Capture {
                name: cube.name(),
                faces: self.glass_faces,
                depth: self.cube_depth,
                first_view: GLASS_FACE_VIEWS,
                textures: self.glass_capture_textures,
                sphere: self.cube_metal,
            },
            Cube::GlassCoarse => Capture {
                faces: self.glass_coarse_faces,
                depth: self.coarse_depth,
                name: cube.name(),
                ..self.capture_of(Cube::Glass)
            },
            Cube::Metal => Capture {
                name: cube.name(),
                faces: self.metal_faces,
                depth: self.cube_depth,
                first_view: METAL_FACE_VIEWS,
                textures: self.metal_capture_textures,
                sphere: self.cube_glass,
            },
        }
    }

    /// The six faces of one cube map.
    fn capture(&self, encoder: &mut wgpu::CommandEncoder, capture: &Capture) {
        for (face, face_name) in CUBE_FACE_NAMES.iter().enumerate() {
            let name = format!("cube {} {face_name}", capture.name);
            self.cube_face(encoder, &name, capture, face);
        }
    }

    fn shadow_pass(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("raster shadow"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: self.shadow_map,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: self.timer.render_writes("shadow"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(self.shadow_pipeline);
        pass.set_bind_group(0, self.uniforms, &[self.view_offset(SHADOW_VIEW)]);
        pass.draw(QUAD, self.plan.shadow_casters());
        if let Some((buffer, vertices)) = self.mesh {
            pass.set_pipeline(self.mesh_shadow_pipeline);
            pass.set_vertex_buffer(0, buffer.slice(..));
            pass.draw(0..vertices, 0..1);
        }
    }

    /// Draws the meshes with `pipeline` (if there are meshes and a pipeline for them).
    fn draw_meshes(&self, pass: &mut wgpu::RenderPass<'_>, pipeline: Option<&wgpu::RenderPipeline>) {
        if let (Some((buffer, vertices)), Some(pipeline)) = (self.mesh, pipeline) {
            pass.set_pipeline(pipeline);
            pass.set_vertex_buffer(0, buffer.slice(..));
            pass.draw(0..vertices, 0..1);
        }
    }

    /// One cube face: the other sphere, if any, the meshes and the floor.
    fn cube_face(&self, encoder: &mut wgpu::CommandEncoder, name: &str, capture: &Capture, face: usize) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(name),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &capture.faces[face],
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(self.clear_colour()),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: self.clear_depth(capture.depth),
            timestamp_writes: self.timer.render_writes(name),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, self.uniforms, &[self.view_offset(capture.first_view + face)]);
        pass.set_bind_group(1, capture.textures, &[]);
        // Sphere first: it hides part of the floor, whose fragments then fail the early depth
        // test before shading (the sphere writes its depth from the fragment shader, so it gets
        // no early test itself). On lavapipe this order also avoids a fixed cost per pass that a
        // floor-first pass pays (docs/performance-raster.md, "Levers").
        // The floor's shadow receiver goes before the rest of the floor (floor.wgsl).
        // The meshes are opaque and hide floor too.
        if let Some(sphere) = capture.sphere {
            pass.set_pipeline(sphere);
            pass.draw(QUAD, 0..1);
        }
        self.draw_meshes(&mut pass, self.cube_mesh);
        for pipeline in [self.cube_floor_receiver, self.cube_floor].into_iter().flatten() {
            pass.set_pipeline(pipeline);
            pass.draw(QUAD, 0..1);
        }
    }

    fn main_pass(&self, encoder: &mut wgpu::CommandEncoder) {
        // A later band draws over the output the earlier ones left.
        let load = match self.main_band {
            Some(band) if band.first_row > 0 => wgpu::LoadOp::Load,
            _ => wgpu::LoadOp::Clear(self.clear_colour()),
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("raster main"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: self.main_output,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: self.clear_depth(self.main_depth),
            timestamp_writes: self.timer.render_writes("main"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let Some(band) = self.main_band {
            pass.set_scissor_rect(0, band.first_row, band.width, band.rows);
        }
        pass.set_bind_group(0, self.uniforms, &[self.view_offset(MAIN_VIEW)]);
        pass.set_bind_group(1, self.main_textures, &[]);
        // Unlike the cube faces, the floor comes first and the spheres after it, back to front:
        // an anti-aliased edge blends over what is already drawn behind it. So a partly covered
        // edge pixel never hides anything: all that is drawn after a sphere is the nearer sphere.
        // (The floor fragments under the spheres are shaded too: docs/performance-raster.md,
        // "Levers", has what that costs against multisampling.)
        let [back, front] = self.main_spheres;
        if let Some(receiver) = self.main_floor_receiver {
            pass.set_pipeline(receiver);
            pass.draw(QUAD, 0..1);
        }
        // Or the rings (the lookups), then the discs inside them (biased: they fail where a
        // ring drew), then the rest of the floor (biased more).
        if let Some((penumbra, umbra)) = self.main_floor_rings {
            pass.set_pipeline(penumbra);
            pass.draw(RING_VERTICES, self.ring_spheres.clone());
            pass.set_pipeline(umbra);
            pass.draw(DISC_VERTICES, self.ring_spheres.clone());
        }
        // The interior and the outline's band share their edges and never overlap.
        if let Some(interior) = self.main_floor_interior {
            pass.set_pipeline(interior);
            pass.draw(QUAD, 0..1);
        }
        pass.set_pipeline(self.main_floor);
        pass.draw(if self.main_floor_interior.is_some() { OUTLINE_VERTICES } else { QUAD }, 0..1);
        // The meshes are opaque: drawn before the spheres, whose edges blend over them.
        self.draw_meshes(&mut pass, self.main_mesh);
        for pipeline in [back, front].into_iter().flatten() {
            pass.set_pipeline(pipeline);
            pass.draw(QUAD, 0..1);
        }
    }
}

/// Whether the metal sphere is the farther one from `eye`, to be drawn first. The spheres are
/// ordered by the eye's power with respect to each, |c - eye|^2 - r^2 (the squared length of a
/// tangent from the eye), not by the distance to their centres, which a large sphere behind a
/// small one can invert. Two disjoint spheres (scene validation: they must not touch) are
/// separated by their radical plane, where the two powers are equal; the sphere on the eye's side
/// of it has the smaller power, and a ray from the eye meets that one first wherever it meets both.
pub fn metal_behind_glass(eye: glam::Vec3, glass: (glam::Vec3, f32), metal: (glam::Vec3, f32)) -> bool {
    let power = |(c, r): (glam::Vec3, f32)| f64::from((c - eye).length_squared()) - f64::from(r * r);
    power(metal) > power(glass)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn the_rings_drawn_have_the_sides_the_shader_builds() {
        let declaration = format!("const RING_SIDES: u32 = {RING_SIDES}u;");
        assert!(
            crate::shaders::FLOOR_SHADER.source.contains(&declaration),
            "floor.wgsl must declare `{declaration}`"
        );
    }

    #[test]
    fn spheres_are_ordered_by_power_not_by_centre_distance() {
        let eye = Vec3::ZERO;
        // A small sphere whose centre is nearer (10 against 11.8) beside a large one that is in
        // front of it where they overlap on screen (powers 99 and 75.25; 9.96 apart, disjoint).
        let small = (Vec3::new(0.0, 0.0, -10.0), 1.0);
        let large = (Vec3::new(9.5, 0.0, -7.0), 8.0);
        assert!(metal_behind_glass(eye, large, small), "the large sphere's power is smaller");
        assert!(!metal_behind_glass(eye, small, large));
        // Equal radii: the nearer centre is in front.
        assert!(metal_behind_glass(eye, (Vec3::new(0.0, 0.0, -5.0), 1.0), (Vec3::new(0.0, 0.0, -9.0), 1.0)));
    }
}
