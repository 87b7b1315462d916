#define_import_path illum::pathtrace::scene

#import illum::rtcore::geometry::Object
#import illum::rtcore::camera::Camera
#import illum::rtcore::material::Material
#import illum::pathtrace::bindings::{BINDING_PARAMS, BINDING_OBJECTS, BINDING_MATERIALS, BINDING_LIGHTS, BINDING_BATCH_SUM, BINDING_BATCH_SUM_SQ, BINDING_BLOCK_SAMPLES}

// The path tracer's scene as the GPU sees it (mirrored by gpu_scene.rs): its parameters, lights
// and bindings. Objects, materials, the camera and the ray-shape tests are illum-rtcore's.

struct Params {
    camera: Camera,
    light_area: f32,
    num_objects: u32,
    width: u32,
    height: u32,
    row_offset: u32,
    rows: u32,
    sample_base: u32,
    sample_count: u32,
    seed: u32,
    bounces: u32,
    num_lights: u32,
    // Objects [first_emitter, num_objects) are the emitters.
    first_emitter: u32,
    // Samples per invocation (one chunk); the dispatch's z dimension counts chunks.
    chunk_samples: u32,
    // Unused: the vectors after them start at a multiple of 16 bytes, as gpu_scene.rs lays them.
    padding_a: u32,
    padding_b: u32,
    padding_c: u32,
    // The directional light (shader def SUN): xyz = unit vector toward it, w = 1 - cos of its
    // angular radius (0 for a delta light; see sample_uniform_cone); its irradiance on a
    // surface facing it.
    sun: vec4<f32>,
    sun_irradiance: vec4<f32>,
    // The environment's radiance (shader def SKY).
    sky: vec4<f32>,
}

// corner.w = running sum of light areas up to and including this light (for selection).
struct Light {
    corner: vec4<f32>,
    edge_u: vec4<f32>,
    edge_v: vec4<f32>,
    normal: vec4<f32>,
    emission: vec4<f32>,
}

@group(0) @binding(BINDING_PARAMS) var<uniform> params: Params;
@group(0) @binding(BINDING_OBJECTS) var<storage, read> objects: array<Object>;
@group(0) @binding(BINDING_MATERIALS) var<storage, read> materials: array<Material>;
@group(0) @binding(BINDING_LIGHTS) var<storage, read> lights: array<Light>;
// Per slot (one chunk of samples of one pixel, see pathtrace.wgsl's main): (sum of radiance,
// number of finite samples) and (sum of squares, number of dropped samples).
@group(0) @binding(BINDING_BATCH_SUM) var<storage, read_write> batch_sum: array<vec4<f32>>;
@group(0) @binding(BINDING_BATCH_SUM_SQ) var<storage, read_write> batch_sum_sq: array<vec4<f32>>;
#ifdef ADAPTIVE
// Adaptive sampling (allocation.rs): samples per pixel of each block of ADAPTIVE_BLOCK x
// ADAPTIVE_BLOCK pixels, row-major over blocks; a pixel takes sample indices [0, n) of its block.
@group(0) @binding(BINDING_BLOCK_SAMPLES) var<storage, read> block_samples: array<u32>;
#endif
