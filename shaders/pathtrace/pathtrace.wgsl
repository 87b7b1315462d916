// The Cornell box path tracer: one invocation per pixel, `sample_count` samples per dispatch.
//
// Estimator (docs/theory.md): at every diffuse hit x the direct light is estimated by next-event
// estimation on the rectangular lights,
//     L_direct(x) = (albedo / pi) * Le * cos(theta_x) cos(theta_y) / |x - y|^2 * A_total * V(x, y),
// with y uniform on the union of the lights (pdf 1 / A_total over area). Bounce directions are
// drawn from the cosine or the uniform hemisphere pdf; a bounce ray that reaches a light adds
// nothing, because that light was already counted by next-event estimation at the previous hit.
// A camera ray that hits a light sees its emitted radiance.

#import illum::constants::INV_PI
#import illum::sampler::{Sampler, sampler_new, sample_1d}
#import illum::sampling::{sample_cosine_hemisphere, sample_uniform_hemisphere, to_world, sample_parallelogram}
#import illum::pathtrace::scene::{NO_HIT, params, objects, materials, lights, batch_sum, batch_sum_sq}
#import illum::pathtrace::traversal::{closest_hit, occluded, surface_normal, choose_light}

const SAMPLING_COSINE: u32 = 0u;
const UNBOUNDED: u32 = 0xffffffffu;
// Russian roulette starts after this many bounces; survival is capped below 1 so that even an
// albedo-1 closed box terminates (expected extra length <= 1 / (1 - 0.95) = 20 bounces).
const RR_START: u32 = 3u;
const RR_MAX_SURVIVAL: f32 = 0.95;
// A safety net for `unbounded`: reaching it needs 0.95^1000 ~ 5e-23 survival odds, so the bias it
// introduces is far below f32 resolution.
const UNBOUNDED_DEPTH_CAP: u32 = 1024u;
// Shadow rays stop this fraction short of the sampled light point, so the light's own plane
// (and a ceiling coplanar with it) never shadows it.
const SHADOW_SHORTEN: f32 = 1.0e-4;

// Distance to move a new ray's origin off the surface at p: relative to p's magnitude, because
// the rounding error of a computed hit point grows with it (about 2^-23 |p| per operation).
fn spawn_offset(p: vec3<f32>) -> f32 {
    let m = max(max(abs(p.x), abs(p.y)), abs(p.z));
    return 3.0e-5 * max(m, 1.0e-3);
}

// Next-event estimation: radiance arriving at p from one point sampled uniformly on the lights,
// already divided by its pdf (1 / A_total) and multiplied by cos(theta_x); the caller multiplies
// by albedo / pi.
fn direct_light(p: vec3<f32>, n: vec3<f32>, sampler: ptr<function, Sampler>) -> vec3<f32> {
    let pick = sample_1d(sampler) * params.light_area;
    let u1 = sample_1d(sampler);
    let u2 = sample_1d(sampler);
    let light = lights[choose_light(pick)];
    let y = sample_parallelogram(light.corner.xyz, light.edge_u.xyz, light.edge_v.xyz, u1, u2);
    let to_light = y - p;
    let dist2 = dot(to_light, to_light);
    let dist = sqrt(dist2);
    let wi = to_light / dist;
    let cos_x = dot(n, wi);
    let cos_y = -dot(light.normal.xyz, wi);
    if (cos_x <= 0.0 || cos_y <= 0.0) {
        return vec3<f32>(0.0);
    }
    if (occluded(p, wi, dist * (1.0 - SHADOW_SHORTEN))) {
        return vec3<f32>(0.0);
    }
    return light.emission.xyz * (cos_x * cos_y / dist2 * params.light_area);
}

fn max3(v: vec3<f32>) -> f32 {
    return max(max(v.x, v.y), v.z);
}

// One path's radiance estimate along the camera ray (o, d).
fn radiance(origin: vec3<f32>, direction: vec3<f32>, sampler: ptr<function, Sampler>) -> vec3<f32> {
    var o = origin;
    var d = direction;
    var hit = closest_hit(o, d);
    if (hit.index == NO_HIT) {
        return vec3<f32>(0.0);
    }
    var obj = objects[hit.index];
    if (obj.emitter != 0u) {
        // One-sided emitter: visible only from its front.
        let facing = dot(surface_normal(obj, o + hit.t * d), d) < 0.0;
        return select(vec3<f32>(0.0), materials[obj.material].emission.xyz, facing);
    }
    var radiance = vec3<f32>(0.0);
    var throughput = vec3<f32>(1.0);
    var depth = 0u;
    loop {
        let p = o + hit.t * d;
        var n = surface_normal(obj, p);
        if (dot(n, d) > 0.0) {
            n = -n;
        }
        let albedo = materials[obj.material].albedo.xyz;
        let p_spawn = p + n * spawn_offset(p);
        radiance += throughput * albedo * INV_PI * direct_light(p_spawn, n, sampler);

        if (params.bounces != UNBOUNDED && depth >= params.bounces) {
            break;
        }
        if (depth >= UNBOUNDED_DEPTH_CAP) {
            break;
        }
        let u1 = sample_1d(sampler);
        let u2 = sample_1d(sampler);
        // Lambertian f = albedo / pi. Cosine pdf cos/pi: f cos / pdf = albedo.
        // Uniform pdf 1/(2 pi): f cos / pdf = 2 albedo cos.
        if (params.sampling == SAMPLING_COSINE) {
            d = to_world(n, sample_cosine_hemisphere(u1, u2));
            throughput *= albedo;
        } else {
            let local = sample_uniform_hemisphere(u1, u2);
            d = to_world(n, local);
            throughput *= albedo * (2.0 * local.z);
        }
        if (params.bounces == UNBOUNDED && depth >= RR_START) {
            // Survive with probability q and divide by q: E[throughput] is unchanged.
            let q = min(max3(throughput), RR_MAX_SURVIVAL);
            if (sample_1d(sampler) >= q) {
                break;
            }
            throughput /= q;
        }
        if (max3(throughput) <= 0.0) {
            break;
        }
        o = p_spawn;
        hit = closest_hit(o, d);
        if (hit.index == NO_HIT) {
            break;
        }
        obj = objects[hit.index];
        if (obj.emitter != 0u) {
            break;
        }
        depth += 1u;
    }
    return radiance;
}

// True when no component is Inf or NaN (exponent bits all ones), tested on the bits so no
// compiler fast-math assumption can remove the check.
fn is_finite3(v: vec3<f32>) -> bool {
    let exponent = bitcast<vec3<u32>>(v) & vec3<u32>(0x7f800000u);
    return all(exponent != vec3<u32>(0x7f800000u));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.rows) {
        return;
    }
    let x = gid.x;
    let y = gid.y + params.row_offset;
    let pixel = y * params.width + x;
    var sum = vec3<f32>(0.0);
    var sum_sq = vec3<f32>(0.0);
    var finite = 0u;
    var dropped = 0u;
    let inv_width = 1.0 / f32(params.width);
    let inv_height = 1.0 / f32(params.height);
    for (var i = 0u; i < params.sample_count; i++) {
        var sampler = sampler_new(params.seed, pixel, params.sample_base + i);
        // Jitter uniformly inside the pixel; row 0 is the top of the image.
        let sx = (2.0 * (f32(x) + sample_1d(&sampler)) * inv_width - 1.0) * params.aspect * params.tan_half_fov;
        let sy = (1.0 - 2.0 * (f32(y) + sample_1d(&sampler)) * inv_height) * params.tan_half_fov;
        let d = normalize(params.forward + sx * params.right + sy * params.up);
        let l = radiance(params.eye, d, &sampler);
        if (is_finite3(l)) {
            sum += l;
            sum_sq += l * l;
            finite += 1u;
        } else {
            dropped += 1u;
        }
    }
    batch_sum[pixel] = vec4<f32>(sum, f32(finite));
    batch_sum_sq[pixel] = vec4<f32>(sum_sq, f32(dropped));
}
