// The path tracer's display: the mean of the path tracer's display sum (a GPU buffer, see
// crates/illum-pathtrace/shaders/display_sum.wgsl), exposure-scaled and encoded with the PNG output's pure
// gamma 2.2 into an 8-bit texture that egui shows as it is (egui takes native Rgba8Unorm textures
// as already gamma-encoded).

struct Params {
    // Image width in pixels: the display sum is row-major, pixel y * width + x.
    width: u32,
    // 2^exposure: the display-only exposure slider, in stops.
    scale: f32,
    pad0: u32,
    pad1: u32,
}

// Per pixel: rgb = running sum of finite samples, w = their count.
@group(0) @binding(0) var<storage, read> display_sum: array<vec4<f32>>;
@group(0) @binding(1) var<uniform> params: Params;
// Per pixel: rgb = the image's exact part (the sun's glint, solved on the host), which joins the
// pixel's mean once it has a sample (crates/illum-pathtrace/src/accumulator/parts.rs), in the
// display sum's units.
@group(0) @binding(2) var<storage, read> exact: array<vec4<f32>>;

// One triangle covering the whole target: vertices (-1,-1), (3,-1), (-1,3).
@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let xy = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(xy * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    // The target has the image's size, so each fragment (at pixel centre x + 0.5, y + 0.5; row 0
    // at the top, as in the image) reads its own pixel.
    let pixel = vec2<u32>(position.xy);
    let index = pixel.y * params.width + pixel.x;
    let sum = display_sum[index];
    // The mean of the finite samples and the exact part; a pixel without any (w = 0, rgb = 0)
    // shows black.
    let mean = sum.rgb / max(sum.w, 1.0) + select(vec3<f32>(0.0), exact[index].rgb, sum.w > 0.0);
    let encoded = pow(clamp(mean * params.scale, vec3<f32>(0.0), vec3<f32>(1.0)), vec3<f32>(1.0 / 2.2));
    return vec4<f32>(encoded, 1.0);
}
