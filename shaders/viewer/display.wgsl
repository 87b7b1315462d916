// The path tracer's display: the linear mean image (exposure-scaled) encoded with the PNG
// output's pure gamma 2.2 into an 8-bit texture that egui shows as it is (egui takes native
// Rgba8Unorm textures as already gamma-encoded).

struct Params {
    // 2^exposure: the display-only exposure slider, in stops.
    scale: f32,
    pad0: f32,
    pad1: f32,
    pad2: f32,
}

@group(0) @binding(0) var source: texture_2d<f32>;
@group(0) @binding(1) var<uniform> params: Params;

// One triangle covering the whole target: vertices (-1,-1), (3,-1), (-1,3).
@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let xy = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(xy * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    // Source and target have the same size, so each fragment reads its own texel.
    let linear = textureLoad(source, vec2<i32>(position.xy), 0).rgb * params.scale;
    let encoded = pow(clamp(linear, vec3<f32>(0.0), vec3<f32>(1.0)), vec3<f32>(1.0 / 2.2));
    return vec4<f32>(encoded, 1.0);
}
