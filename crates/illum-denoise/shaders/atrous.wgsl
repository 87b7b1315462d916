// One iteration of the edge-avoiding à-trous wavelet filter (Dammertz et al. 2010), with the
// edge stops of SVGF's spatial filter (Schied et al. 2017), applied to each colour channel c
// with its own weights: a 5 x 5 B3-spline kernel whose taps lie `step` pixels apart (1, 2, 4,
// ... over the iterations), each tap weighed by
//     h(dx) h(dy) w_colour,c w_normal w_albedo,
//     w_colour,c = exp(-|x_p,c - x_q,c| / (SIGMA_COLOUR sigma_p,c + TINY)),
//     w_normal   = max(0, n_p . n_q)^NORMAL_POWER (1 where neither has a normal, 0 where one has;
//                  the normals arrive as unit vectors, w = 1, or zero, w = 0: atrous.rs),
//     w_albedo   = exp(-|a_p - a_q|^2 / SIGMA_ALBEDO^2),
// with sigma_p,c the standard error of p's channel c: the square root of the smaller of its own
// variance and that variance blurred over 3 x 3 pixels (a variance from few samples is itself
// noisy, and the edge of a light, where a pixel's own variance is large, must not take in the
// dark ceiling). The stop is per channel, not on luminance, because neighbours of one
// luminance and another hue (a white wall beside a red one) would otherwise be averaged and
// move a converged pixel's colour. A channel whose variance is 0 (converged, or every sample
// the same) takes nothing from a neighbour of another value in that channel: it is left
// alone. Each channel's variance is carried along as that of the weighted mean of independent
// pixels, sum w^2 var / (sum w)^2.
// crates/illum-denoise/src/reference.rs is the f64 CPU copy the GPU output is tested against.

struct Params {
    width: u32,
    height: u32,
    step: u32,
    padding: u32,
    sigma_colour: f32,
    sigma_albedo: f32,
    padding_b: f32,
    padding_c: f32,
}

// n_p . n_q to this power (2^7: seven squarings, see normal_weight): SVGF's sigma_n.
const NORMAL_SQUARINGS: u32 = 7u;
// Keeps the colour stop's division finite at a standard error of 0.
const TINY: f32 = 1.0e-10;

// A pixel of the image being filtered: its colour and the variance of each channel (w unused).
struct Pixel {
    colour: vec4<f32>,
    variance: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> input: array<Pixel>;
@group(0) @binding(2) var<storage, read> albedo: array<vec4<f32>>;
// xyz = the unit normal and w = 1, or 0 and 0 where there is none.
@group(0) @binding(3) var<storage, read> normal: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> output: array<Pixel>;

// The B3 spline's taps at offsets -2..2 (it sums to 1).
fn kernel(i: i32) -> f32 {
    let a = abs(i);
    return select(select(0.0625, 0.25, a == 1), 0.375, a == 0);
}

fn index(x: i32, y: i32) -> u32 {
    return u32(y) * params.width + u32(x);
}

// Without branches: a missing normal is the zero vector, so c = 0 where one is missing, and
// (1 - p.w)(1 - q.w) is 1 exactly where both are.
fn normal_weight(p: vec4<f32>, q: vec4<f32>) -> f32 {
    var c = max(dot(p.xyz, q.xyz), 0.0);
    for (var i = 0u; i < NORMAL_SQUARINGS; i++) {
        c = c * c;
    }
    return c + (1.0 - p.w) * (1.0 - q.w);
}

// The 3 x 3 binomial blur (1 2 1) x (1 2 1) / 16 of the channels' variances around (x, y),
// clamped at the image's border.
fn blurred_variance(x: i32, y: i32) -> vec3<f32> {
    var v = vec3<f32>(0.0);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let qx = clamp(x + dx, 0, i32(params.width) - 1);
            let qy = clamp(y + dy, 0, i32(params.height) - 1);
            let w = f32((2 - abs(dx)) * (2 - abs(dy))) / 16.0;
            v += w * input[index(qx, qy)].variance.xyz;
        }
    }
    return v;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let x = i32(gid.x);
    let y = i32(gid.y);
    let p = index(x, y);
    let centre = input[p];
    let cp = centre.colour.xyz;
    let ap = albedo[p].xyz;
    let np = normal[p];
    // A reciprocal once per pixel: the taps multiply (a division per channel and tap costs as
    // much as the exp on a CPU device).
    let inv_scale = 1.0 / (params.sigma_colour * sqrt(min(centre.variance.xyz, blurred_variance(x, y))) + vec3<f32>(TINY));
    let inv_sigma_albedo2 = 1.0 / (params.sigma_albedo * params.sigma_albedo);
    let step = i32(params.step);
    let last = vec2<i32>(i32(params.width) - 1, i32(params.height) - 1);
    var sum = vec3<f32>(0.0);
    var weights = vec3<f32>(0.0);
    var variance = vec3<f32>(0.0);
    for (var j = -2; j <= 2; j++) {
        for (var i = -2; i <= 2; i++) {
            // Straight code: a tap outside the image reads the clamped pixel and weighs 0.
            let tap = vec2<i32>(x + i * step, y + j * step);
            let inside = all(tap >= vec2<i32>(0)) && all(tap <= last);
            let t = clamp(tap, vec2<i32>(0), last);
            let q = index(t.x, t.y);
            let c = input[q].colour.xyz;
            let da = ap - albedo[q].xyz;
            let shared_weight = kernel(i) * kernel(j) * normal_weight(np, normal[q]);
            // The colour and albedo stops in one exp per channel.
            let stops = exp(-abs(cp - c) * inv_scale - vec3<f32>(dot(da, da) * inv_sigma_albedo2));
            let w = select(vec3<f32>(0.0), shared_weight * stops, inside);
            sum += w * c;
            weights += w;
            variance += w * w * input[q].variance.xyz;
        }
    }
    // The centre's own weight is kernel(0)^2 > 0 in every channel (every stop is 1 at q = p),
    // so each weight sum is > 0.
    output[p] = Pixel(vec4<f32>(sum / weights, 0.0), vec4<f32>(variance / (weights * weights), 0.0));
}
