//! The Whitted ray tracer's GPU side: buffers, the compute pipeline, its dispatches (one, or
//! parts of the image for a long render), readback.

#[cfg(not(target_arch = "wasm32"))]
use std::ops::ControlFlow;

use illum_gpu::buffers::{buffer_bind_group, dispatch};
use illum_gpu::shader::{self, ShaderFile};
use illum_gpu::{GpuContext, GpuError, readback, shader_file, wgpu};
use illum_image::RgbImage32;
use illum_rtcore::{BvhBindGroup, Geometry};
use illum_scene::{RendererKind, Scene, SceneError};
use wgpu::util::DeviceExt;

use crate::encode::{self, WhittedLight, WhittedParams};

/// The entry shader (entry point `main`).
pub const WHITTED_SHADER: ShaderFile = shader_file!("shaders/whitted.wgsl");

/// Workgroup side of the entry point (8 x 8 pixels).
const WORKGROUP: u32 = 8;
/// Bytes per pixel of the output buffer (a vec4 of f32).
const PIXEL_BYTES: u64 = 16;

/// Why the Whitted ray tracer could not render.
#[derive(Debug, thiserror::Error)]
pub enum WhittedError {
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Scene(#[from] SceneError),
}

/// The shader defs of the pipeline for `scene` ([`encode::Specialisation`]).
pub fn shader_defs(scene: &Scene) -> Vec<(&'static str, shader::Def)> {
    encode::Specialisation::new(scene).shader_defs()
}

/// The modules the entry shader imports for `scene`, in import order: illum-rtcore's shared
/// modules, then its traversal and materials generated for this scene with their numbers as
/// literals (the pipeline binds no object or material buffer).
pub fn shader_modules(scene: &Scene, geometry: &Geometry) -> Vec<ShaderFile> {
    let mut modules = illum_rtcore::shaders::core_modules();
    modules.push(illum_rtcore::traversal::generate(geometry).module(&scene.name));
    modules.push(illum_rtcore::materials_module(&scene.name, &encode::materials(scene)));
    modules
}

/// What the pipeline writes (`params.counts.w`, OUTPUT_* in the shader).
const OUTPUT_RADIANCE: u32 = 0;
const OUTPUT_OBJECT_IDS: u32 = 1;
/// The shader's markers in the shadow channel of the object-ID image.
const SHADOW_LIT: u32 = 0xffff_fffe;
const SHADOW_FACING_AWAY: u32 = 0xffff_fffd;
const NO_HIT: u32 = u32::MAX;

/// Whitted's algorithm on one scene, at the scene's resolution, depth and anti-aliasing.
pub struct WhittedTracer {
    gpu: GpuContext,
    width: u32,
    height: u32,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    /// The hierarchies' and shading normals' buffers (group 1), for a scene with a mesh or many
    /// spheres.
    bvh: Option<BvhBindGroup>,
    params: wgpu::Buffer,
    radiance_params: WhittedParams,
    image: wgpu::Buffer,
    /// The index in `scene.objects` of each object in the GPU's order (for the object-ID
    /// image, which only native tools read).
    scene_index: Vec<usize>,
}

/// Where the first light stands from the point a pixel's centre ray hits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shadow {
    /// The light reaches the point (also for a pixel that sees no object, or a scene without
    /// lights).
    Lit,
    /// The surface faces away from the light.
    FacingAway,
    /// This object (an index into `scene.objects`) is the nearest one blocking the light.
    BlockedBy(usize),
}

/// The object-ID image: for the ray through each pixel's centre, the object it hits and whether
/// the scene's first light reaches that point (the ladder's regions are cut from it).
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectIds {
    pub width: u32,
    pub height: u32,
    /// Per pixel, row-major from the top-left: the index into `scene.objects` of the object the
    /// centre ray hits, if any.
    pub hit: Vec<Option<usize>>,
    pub shadow: Vec<Shadow>,
}

impl WhittedTracer {
    /// Uploads `scene`, or says which of its features Whitted's algorithm does not model or why
    /// the device cannot hold its image.
    pub fn new(gpu: &GpuContext, scene: &Scene) -> Result<Self, WhittedError> {
        scene.require(RendererKind::Whitted.noun(), encode::implements)?;
        let (width, height) = (scene.camera.width, scene.camera.height);
        let bytes = u64::from(width) * u64::from(height) * PIXEL_BYTES;
        let limit = gpu.device.limits().max_storage_buffer_binding_size;
        if bytes > limit {
            return Err(SceneError::invalid(
                &format!("scene {:?}", scene.name),
                "camera.width x camera.height",
                format!("{width} x {height} ({bytes} bytes of image)"),
                format!("must fit in {limit} bytes, the device's max_storage_buffer_binding_size"),
            )
            .into());
        }
        // Objects in illum-rtcore's order (emitters last), as the traversal indexes them.
        let geometry = Geometry::new(scene);
        let lights = encode::lights(scene);
        let radiance_params =
            encode::params(scene, geometry.first_emitter, lights.len() as u32, OUTPUT_RADIANCE);
        let scene_index = {
            let triangles =
                geometry.meshes.iter().flat_map(|m| m.triangles().iter().map(|t| t.object as usize));
            geometry.scene_index.iter().copied().chain(triangles).collect()
        };

        let device = &gpu.device;
        // Storage buffers may not be empty: a scene without lights binds one unused record.
        let storage =
            |label: &str, contents: &[u8]| illum_gpu::buffers::storage_buffer(device, label, contents);
        let lights_or_one = if lights.is_empty() { vec![WhittedLight::default()] } else { lights };
        // Checked before compiling: a scene past the limits would fail there, or take minutes.
        BvhBindGroup::check_size(
            scene,
            &geometry,
            limit,
            gpu.device.limits().max_uniform_buffer_binding_size,
        )?;
        let pipeline = shader::compute_pipeline(
            gpu,
            &shader_modules(scene, &geometry),
            &WHITTED_SHADER,
            &shader_defs(scene),
            "whitted ray tracer",
        )?;
        let (bind_group, image, params, bvh) =
            gpu.scoped("creating the Whitted ray tracer's buffers", || {
                let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("whitted params"),
                    contents: bytemuck::bytes_of(&radiance_params),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                });
                let lights = storage("whitted lights", bytemuck::cast_slice(&lights_or_one));
                let image = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("whitted image"),
                    size: bytes,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                });
                let bind_group = buffer_bind_group(
                    device,
                    "whitted",
                    &pipeline.get_bind_group_layout(0),
                    &[(0, &params), (1, &lights), (2, &image)],
                );
                let bvh = BvhBindGroup::new(device, &pipeline, scene, &geometry);
                (bind_group, image, params, bvh)
            })?;
        Ok(WhittedTracer {
            gpu: gpu.clone(),
            width,
            height,
            pipeline,
            bind_group,
            bvh,
            params,
            radiance_params,
            image,
            scene_index,
        })
    }

    /// The image's size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// [`Self::render`] without waiting (what a web page needs): submits the frame and starts
    /// its readback; [`PendingImage::poll`] on later frames returns the image.
    pub fn render_polled(&self) -> PendingImage {
        self.dispatch(OUTPUT_RADIANCE, 0, self.width, self.height);
        self.start_read("reading the Whitted image")
    }

    /// [`Self::object_ids`] without waiting (what a web page needs): submits the dispatch and
    /// starts its readback; [`PendingObjectIds::poll`] on later frames returns the image.
    pub fn object_ids_polled(&self) -> PendingObjectIds {
        self.dispatch(OUTPUT_OBJECT_IDS, 0, self.width, self.height);
        PendingObjectIds {
            image: self.start_read("reading the object-ID image"),
            scene_index: self.scene_index.clone(),
        }
    }

    /// Copies the image buffer to a staging buffer of its own and starts mapping it.
    fn start_read(&self, reading: &str) -> PendingImage {
        let bytes = u64::from(self.width) * u64::from(self.height) * PIXEL_BYTES;
        let staging = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("whitted staging"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("whitted readback") });
        encoder.copy_buffer_to_buffer(&self.image, 0, &staging, 0, bytes);
        self.gpu.queue.submit([encoder.finish()]);
        PendingImage {
            read: readback::PendingRead::start(staging, bytes, reading),
            width: self.width,
            height: self.height,
        }
    }

    /// Submits one dispatch writing `output` (OUTPUT_RADIANCE or OUTPUT_OBJECT_IDS) for the
    /// `columns` x `rows` pixels from `first_pixel` (row-major index of the top-left one). A
    /// workgroup that reaches past them computes pixels of the next part: the same values.
    fn dispatch(&self, output: u32, first_pixel: u32, columns: u32, rows: u32) {
        let [lights, depth, aa, _] = self.radiance_params.counts;
        let [width, height, first_emitter, _] = self.radiance_params.sizes;
        let params = WhittedParams {
            counts: [lights, depth, aa, output],
            sizes: [width, height, first_emitter, first_pixel],
            ..self.radiance_params
        };
        self.gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("whitted") });
        let workgroups = [columns.div_ceil(WORKGROUP), rows.div_ceil(WORKGROUP), 1];
        match &self.bvh {
            None => dispatch(&mut encoder, "whitted", &self.pipeline, &self.bind_group, workgroups),
            Some(bvh) => {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("whitted"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &self.bind_group, &[]);
                bvh.set(&mut pass);
                pass.dispatch_workgroups(workgroups[0], workgroups[1], workgroups[2]);
            }
        }
        self.gpu.queue.submit([encoder.finish()]);
    }
}

/// The readbacks that wait for the GPU: native only (a web page cannot wait; it uses
/// [`WhittedTracer::render_polled`]).
#[cfg(not(target_arch = "wasm32"))]
impl WhittedTracer {
    /// Renders the image: linear radiance per pixel, row-major from the top-left.
    pub fn render(&self) -> Result<RgbImage32, WhittedError> {
        self.dispatch(OUTPUT_RADIANCE, 0, self.width, self.height);
        let data = self.read("reading the Whitted image")?;
        Ok(decode_image(self.width, self.height, &data))
    }

    /// [`Self::render`] in parts of about `pixels_per_part` pixels (at least one 8 x 8
    /// workgroup), each its own submission, waited for before the next: a long render then
    /// never holds the GPU for long at a time, and `after_part` (given the pixels done) can show
    /// progress, and stop the render by returning [`ControlFlow::Break`], which returns
    /// `Ok(None)`; after the last part the image is complete and is returned whatever
    /// `after_part` says. The parts are bands of whole rows, a multiple of 8, when
    /// `pixels_per_part` holds 8 rows; otherwise tiles of 8 rows and a multiple of 8 columns.
    /// Every pixel is computed as by [`Self::render`], so the image is the same bit for bit.
    pub fn render_in_parts(
        &self,
        pixels_per_part: u64,
        mut after_part: impl FnMut(u64) -> ControlFlow<()>,
    ) -> Result<Option<RgbImage32>, WhittedError> {
        let (width, height) = (u64::from(self.width), u64::from(self.height));
        let step = u64::from(WORKGROUP);
        let per_part = pixels_per_part.max(step * step);
        let (rows, columns) = if per_part >= width * step {
            ((per_part / width / step * step).min(height.next_multiple_of(step)), width)
        } else {
            (step, per_part / step / step * step)
        };
        let mut done = 0;
        for first_row in (0..height).step_by(rows as usize) {
            let part_rows = rows.min(height - first_row);
            for first_column in (0..width).step_by(columns as usize) {
                let part_columns = columns.min(width - first_column);
                let first_pixel = first_row * width + first_column;
                self.dispatch(OUTPUT_RADIANCE, first_pixel as u32, part_columns as u32, part_rows as u32);
                self.gpu.wait_idle("rendering a part of the Whitted image")?;
                done += part_rows * part_columns;
                // After the last part the image is complete: returned whatever `after_part` says.
                if after_part(done).is_break() && done < width * height {
                    return Ok(None);
                }
            }
        }
        let data = self.read("reading the Whitted image")?;
        Ok(Some(decode_image(self.width, self.height, &data)))
    }

    /// The object-ID image of the same camera (one ray through each pixel's centre).
    pub fn object_ids(&self) -> Result<ObjectIds, WhittedError> {
        self.dispatch(OUTPUT_OBJECT_IDS, 0, self.width, self.height);
        let data = self.read("reading the object-ID image")?;
        Ok(decode_object_ids(self.width, self.height, &self.scene_index, &data))
    }

    /// The image buffer, read back with a wait (one vec4 per pixel).
    fn read(&self, reading: &str) -> Result<Vec<u8>, WhittedError> {
        let bytes = u64::from(self.width) * u64::from(self.height) * PIXEL_BYTES;
        let data = readback::read_buffer(&self.gpu, &self.image, 0, bytes, reading)?;
        self.gpu.check()?;
        Ok(data)
    }
}

/// A Whitted frame whose readback is under way ([`WhittedTracer::render_polled`]).
pub struct PendingImage {
    read: readback::PendingRead,
    width: u32,
    height: u32,
}

impl PendingImage {
    /// `None` while the image is still being read back; never waits.
    pub fn poll(&self, gpu: &GpuContext) -> Option<Result<RgbImage32, WhittedError>> {
        let data = self.read.poll(gpu)?;
        Some(data.map_err(WhittedError::from).and_then(|data| {
            gpu.check()?;
            Ok(decode_image(self.width, self.height, &data))
        }))
    }
}

/// An object-ID image whose readback is under way ([`WhittedTracer::object_ids_polled`]).
pub struct PendingObjectIds {
    image: PendingImage,
    /// The scene's object index of each GPU object index.
    scene_index: Vec<usize>,
}

impl PendingObjectIds {
    /// `None` while the image is still being read back; never waits.
    pub fn poll(&self, gpu: &GpuContext) -> Option<Result<ObjectIds, WhittedError>> {
        let data = self.image.read.poll(gpu)?;
        Some(data.map_err(WhittedError::from).and_then(|data| {
            gpu.check()?;
            Ok(decode_object_ids(self.image.width, self.image.height, &self.scene_index, &data))
        }))
    }
}

/// The object-ID image's texels: per pixel the GPU index of the object hit and of the one that
/// blocks the light (or a marker), as two u32 in a vec4 of f32 bits.
fn decode_object_ids(width: u32, height: u32, scene_index: &[usize], data: &[u8]) -> ObjectIds {
    // The copy has no alignment guarantee: read the words one by one.
    let words: Vec<u32> =
        data.chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes"))).collect();
    let texels: Vec<&[u32]> = words.chunks_exact(4).collect();
    let scene_object = |gpu_index: u32| scene_index.get(gpu_index as usize).copied();
    let hit = texels.iter().map(|t| scene_object(t[0])).collect();
    let shadow = texels
        .iter()
        .map(|t| match t[1] {
            SHADOW_LIT | NO_HIT => Shadow::Lit,
            SHADOW_FACING_AWAY => Shadow::FacingAway,
            i => scene_object(i).map_or(Shadow::Lit, Shadow::BlockedBy),
        })
        .collect();
    ObjectIds { width, height, hit, shadow }
}

/// The image buffer's RGBA f32 texels as linear RGB.
fn decode_image(width: u32, height: u32, data: &[u8]) -> RgbImage32 {
    // The mapped copy has no alignment guarantee, so read the floats one by one.
    let floats: Vec<f32> =
        data.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes"))).collect();
    let mut image = RgbImage32::new(width, height);
    for (pixel, texel) in image.pixels.iter_mut().zip(floats.chunks_exact(4)) {
        *pixel = [texel[0], texel[1], texel[2]];
    }
    image
}

#[cfg(test)]
mod tests {
    use std::mem::size_of;

    use illum_gpu::members;
    use illum_gpu::shader::wgsl_struct;

    use super::*;
    use crate::encode::WhittedParams;

    /// Every combination of the specialisation's flags composes and validates without a GPU, so
    /// the code behind each `#ifdef` is checked before a scene happens to need it.
    #[test]
    fn every_combination_of_the_specialisation_validates() {
        let scene = illum_scene::testing::shipped_scene("whitted.toml", 32, 32);
        let modules = shader_modules(&scene, &Geometry::new(&scene));
        for bits in 0u32..1 << 6 {
            let bit = |i: u32| bits & (1 << i) != 0;
            let specialisation = encode::Specialisation {
                stack: 3,
                checker: bit(0),
                mirrors: bit(1),
                dielectrics: bit(2),
                emitters: bit(3),
                directional_light: bit(4),
                point_lights: bit(5),
                // Needs a mesh's traversal: the_shader_validates_for_smooth_meshes.
                smooth_shading: false,
            };
            let composed = shader::compose(&modules, &WHITTED_SHADER, &specialisation.shader_defs())
                .unwrap_or_else(|e| panic!("{specialisation:?}: {e}"));
            shader::validate(&composed, "whitted.wgsl").unwrap_or_else(|e| panic!("{specialisation:?}: {e}"));
        }
    }

    /// With smooth meshes (shader def SMOOTH_SHADING) the shader composes and validates, the
    /// triangles as literals and under a BVH, with every material that reads the shading normal
    /// (the Whitted scene's spheres are glass and a mirror).
    #[test]
    fn the_shader_validates_for_smooth_meshes() {
        use illum_scene::testing::obj::{icosphere_obj, scene_with_files};
        for k in [0, 1] {
            let obj = icosphere_obj(k, true);
            let mut text =
                std::fs::read_to_string(illum_scene::resolve_scene_path("scenes/whitted.toml".as_ref()))
                    .unwrap();
            // 20 triangles are literals in the traversal, 80 under a BVH (mesh_traversal.rs).
            text.push_str("\n[[objects]]\nmaterial = \"glass\"\nmesh = { file = \"ball.obj\" }\n");
            let scene = scene_with_files(&text, "whitted.toml", &[("ball.obj", &obj)])
                .unwrap_or_else(|e| panic!("{e}"));
            let specialisation = encode::Specialisation::new(&scene);
            assert!(specialisation.smooth_shading && specialisation.mirrors && specialisation.dielectrics);
            let composed = shader::compose(
                &shader_modules(&scene, &Geometry::new(&scene)),
                &WHITTED_SHADER,
                &specialisation.shader_defs(),
            )
            .unwrap_or_else(|e| panic!("subdivision {k}: {e}"));
            shader::validate(&composed, "whitted.wgsl").unwrap_or_else(|e| panic!("subdivision {k}: {e}"));
        }
    }

    /// The shader composes and validates without a GPU for every shipped scene, and the Rust
    /// records have naga's layout of the WGSL structs.
    #[test]
    fn the_shader_validates_and_the_records_match_its_structs() {
        let mut module = None;
        for name in ["whitted.toml", "cornell.toml"] {
            let scene = illum_scene::testing::shipped_scene(name, 32, 32);
            let geometry = Geometry::new(&scene);
            let composed =
                shader::compose(&shader_modules(&scene, &geometry), &WHITTED_SHADER, &shader_defs(&scene))
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
            let mut validator = naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            );
            validator.validate(&composed).unwrap_or_else(|e| panic!("whitted.wgsl for {name}: {e:?}"));
            module = Some(composed);
        }
        let module = module.expect("two scenes");
        let wgsl = |name: &str| {
            wgsl_struct(&module, "", name).unwrap_or_else(|| panic!("no struct {name} in whitted.wgsl"))
        };
        wgsl("Params").assert_matches(
            size_of::<WhittedParams>(),
            &members!(WhittedParams: camera, background, ambient, mirror_specular, shading, sizes, counts),
        );
        wgsl("Light")
            .assert_matches(size_of::<WhittedLight>(), &members!(WhittedLight: kind, pad, a, normal, power));
    }
}
