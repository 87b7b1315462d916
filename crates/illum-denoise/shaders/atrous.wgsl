// One iteration of the edge-avoiding à-trous wavelet filter (Dammertz et al. 2010), with the
// edge stops of SVGF's spatial filter (Schied et al. 2017): a 5 x 5 B3-spline kernel whose taps
// lie `step` pixels apart (1, 2, 4, ... over the iterations), each tap weighed by
//     h(dx) h(dy) w_luminance w_normal w_albedo,
//     w_luminance = exp(-|L_p - L_q| / (SIGMA_LUMINANCE sigma_p + TINY)),
//     w_normal    = max(0, n_p . n_q)^NORMAL_POWER (1 where neither has a normal, 0 where one has;
//                   the normals arrive as unit vectors, w = 1, or zero, w = 0: atrous.rs),
//     w_albedo    = exp(-|a_p - a_q|^2 / SIGMA_ALBEDO^2),
// with sigma_p the standard error of p's luminance: the square root of the smaller of its own
// variance and that variance blurred over 3 x 3 pixels (a variance from few samples is itself
// noisy, and the edge of a light, where a pixel's own variance is large, must not take in the
// dark ceiling). A pixel whose variance is 0 (converged, or every sample the same) takes
// nothing from a neighbour of another luminance: it is left alone. The variance is
// carried along as that of the weighted mean of independent pixels, sum w^2 var / (sum w)^2.
// crates/illum-denoise/src/reference.rs is the f64 CPU copy the GPU output is tested against.

struct Params {
    width: u32,
    height: u32,
    step: u32,
    padding: u32,
    sigma_luminance: f32,
    sigma_albedo: f32,
    padding_b: f32,
    padding_c: f32,
}

// n_p . n_q to this power (2^7: seven squarings, see normal_weight): SVGF's sigma_n.
const NORMAL_SQUARINGS: u32 = 7u;
// Keeps the luminance stop's division finite at a standard error of 0.
const TINY: f32 = 1.0e-10;
const LUMINANCE: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

@group(0) @binding(0) var<uniform> params: Params;
// rgb = the image, w = the variance of its luminance.
@group(0) @binding(1) var<storage, read> input: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> albedo: array<vec4<f32>>;
// xyz = the unit normal and w = 1, or 0 and 0 where there is none.
@group(0) @binding(3) var<storage, read> normal: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> output: array<vec4<f32>>;

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

// The 3 x 3 binomial blur (1 2 1) x (1 2 1) / 16 of the variance around (x, y), clamped at the
// image's border.
fn blurred_variance(x: i32, y: i32) -> f32 {
    var v = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let qx = clamp(x + dx, 0, i32(params.width) - 1);
            let qy = clamp(y + dy, 0, i32(params.height) - 1);
            let w = f32((2 - abs(dx)) * (2 - abs(dy))) / 16.0;
            v += w * input[index(qx, qy)].w;
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
    let lp = dot(centre.xyz, LUMINANCE);
    let ap = albedo[p].xyz;
    let np = normal[p];
    let scale = params.sigma_luminance * sqrt(min(centre.w, blurred_variance(x, y))) + TINY;
    let inv_sigma_albedo2 = 1.0 / (params.sigma_albedo * params.sigma_albedo);
    let step = i32(params.step);
    let last = vec2<i32>(i32(params.width) - 1, i32(params.height) - 1);
    var sum = vec3<f32>(0.0);
    var weights = 0.0;
    var variance = 0.0;
    for (var j = -2; j <= 2; j++) {
        for (var i = -2; i <= 2; i++) {
            // Straight code: a tap outside the image reads the clamped pixel and weighs 0.
            let tap = vec2<i32>(x + i * step, y + j * step);
            let inside = all(tap >= vec2<i32>(0)) && all(tap <= last);
            let t = clamp(tap, vec2<i32>(0), last);
            let q = index(t.x, t.y);
            let c = input[q];
            let da = ap - albedo[q].xyz;
            // The luminance and albedo stops in one exp.
            let stops = exp(-abs(lp - dot(c.xyz, LUMINANCE)) / scale - dot(da, da) * inv_sigma_albedo2);
            let w = select(0.0, kernel(i) * kernel(j) * stops * normal_weight(np, normal[q]), inside);
            sum += w * c.xyz;
            weights += w;
            variance += w * w * c.w;
        }
    }
    // The centre's own weight is kernel(0)^2 > 0 (every stop is 1 at q = p), so weights > 0.
    output[p] = vec4<f32>(sum / weights, variance / (weights * weights));
}
