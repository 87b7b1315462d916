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
#import illum::rng::{rng_seed, rng_f32}
#import illum::sampling::{sample_cosine_hemisphere, sample_uniform_hemisphere, to_world, sample_parallelogram}

const KIND_BOX: u32 = 0u;
const KIND_QUAD: u32 = 1u;
const KIND_SPHERE: u32 = 2u;
const SAMPLING_COSINE: u32 = 0u;
const UNBOUNDED: u32 = 0xffffffffu;
const NO_HIT: u32 = 0xffffffffu;
const FAR: f32 = 3.0e38;
// Russian roulette starts after this many bounces; survival is capped below 1 so that even an
// albedo-1 closed box terminates (expected extra length <= 1 / (1 - 0.95) = 20 bounces).
const RR_START: u32 = 3u;
const RR_MAX_SURVIVAL: f32 = 0.95;
// A safety net for `unbounded`: reaching it needs 0.95^1000 ~ 5e-23 survival odds, so the bias it
// introduces is far below f32 resolution.
const UNBOUNDED_DEPTH_CAP: u32 = 1024u;
// A bounce ray that hits an emitter within this relative distance of a coplanar surface sees the
// emitter: the light's face lies exactly in the ceiling's plane and must win that tie.
const EMITTER_TIE: f32 = 1.0e-5;
// Shadow rays stop this fraction short of the sampled light point, so the light's own plane
// (and a ceiling coplanar with it) never shadows it.
const SHADOW_SHORTEN: f32 = 1.0e-4;

struct Params {
    eye: vec3<f32>,
    tan_half_fov: f32,
    right: vec3<f32>,
    aspect: f32,
    up: vec3<f32>,
    light_area: f32,
    forward: vec3<f32>,
    num_objects: u32,
    width: u32,
    height: u32,
    row_offset: u32,
    rows: u32,
    sample_base: u32,
    sample_count: u32,
    seed: u32,
    bounces: u32,
    sampling: u32,
    num_lights: u32,
    _pad0: u32,
    _pad1: u32,
}

// Box: a = (local min, cos), b = (local max, sin), c = (offset, 0): world = R_y local + offset.
// Quad: a = corner, b = edge_u, c = edge_v, d = (edge_u x edge_v, 0).
// Sphere: a = (centre, radius).
struct Object {
    kind: u32,
    material: u32,
    emitter: u32,
    _pad: u32,
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
    d: vec4<f32>,
}

struct Material {
    albedo: vec4<f32>,
    emission: vec4<f32>,
}

// corner.w = running sum of light areas up to and including this light (for selection).
struct Light {
    corner: vec4<f32>,
    edge_u: vec4<f32>,
    edge_v: vec4<f32>,
    normal: vec4<f32>,
    emission: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> objects: array<Object>;
@group(0) @binding(2) var<storage, read> materials: array<Material>;
@group(0) @binding(3) var<storage, read> lights: array<Light>;
// Per pixel: (sum of radiance, number of finite samples) and (sum of squares, dropped samples).
@group(0) @binding(4) var<storage, read_write> batch_sum: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> batch_sum_sq: array<vec4<f32>>;

// Ray direction with zero components replaced by a tiny value of the same slab behaviour, so the
// slab test divides by it without producing 0 * inf = NaN.
fn safe_inverse(d: vec3<f32>) -> vec3<f32> {
    let tiny = vec3<f32>(1.0e-30);
    return 1.0 / select(d, tiny, abs(d) < tiny);
}

// Inverse of R_y(angle): world-to-local for a direction. R_y maps (x, y, z) to
// (c x + s z, y, -s x + c z), so its transpose maps (x, y, z) to (c x - s z, y, s x + c z).
fn rotate_y_inverse(v: vec3<f32>, c: f32, s: f32) -> vec3<f32> {
    return vec3<f32>(c * v.x - s * v.z, v.y, s * v.x + c * v.z);
}

fn rotate_y(v: vec3<f32>, c: f32, s: f32) -> vec3<f32> {
    return vec3<f32>(c * v.x + s * v.z, v.y, -s * v.x + c * v.z);
}

// Nearest t > 0 at which the ray meets the box surface, or FAR. Slab method in the box's frame.
fn hit_box(o: vec3<f32>, d: vec3<f32>, obj: Object) -> f32 {
    let ol = rotate_y_inverse(o - obj.c.xyz, obj.a.w, obj.b.w);
    let inv = safe_inverse(rotate_y_inverse(d, obj.a.w, obj.b.w));
    let t0 = (obj.a.xyz - ol) * inv;
    let t1 = (obj.b.xyz - ol) * inv;
    let near = min(t0, t1);
    let far = max(t0, t1);
    let t_enter = max(max(near.x, near.y), near.z);
    let t_exit = min(min(far.x, far.y), far.z);
    if (t_exit < t_enter || t_exit <= 0.0) {
        return FAR;
    }
    return select(t_exit, t_enter, t_enter > 0.0);
}

fn hit_quad(o: vec3<f32>, d: vec3<f32>, obj: Object) -> f32 {
    let n = obj.d.xyz;
    let denom = dot(n, d);
    if (denom == 0.0) {
        return FAR;
    }
    let t = dot(obj.a.xyz - o, n) / denom;
    if (!(t > 0.0)) {
        return FAR;
    }
    // Barycentric-like coordinates of the hit in the (edge_u, edge_v) basis: with w = n / |n|^2,
    // alpha = w . (h x v) and beta = w . (u x h) (h = hit - corner).
    let w = n / dot(n, n);
    let h = o + t * d - obj.a.xyz;
    let alpha = dot(w, cross(h, obj.c.xyz));
    let beta = dot(w, cross(obj.b.xyz, h));
    if (alpha < 0.0 || alpha > 1.0 || beta < 0.0 || beta > 1.0) {
        return FAR;
    }
    return t;
}

fn hit_sphere(o: vec3<f32>, d: vec3<f32>, obj: Object) -> f32 {
    let oc = o - obj.a.xyz;
    let b = dot(oc, d);
    let c = dot(oc, oc) - obj.a.w * obj.a.w;
    let disc = b * b - c;
    if (disc < 0.0) {
        return FAR;
    }
    let s = sqrt(disc);
    let t_near = -b - s;
    let t_far = -b + s;
    if (t_near > 0.0) {
        return t_near;
    }
    return select(FAR, t_far, t_far > 0.0);
}

fn hit_object(o: vec3<f32>, d: vec3<f32>, obj: Object) -> f32 {
    switch obj.kind {
        case KIND_BOX: { return hit_box(o, d, obj); }
        case KIND_QUAD: { return hit_quad(o, d, obj); }
        default: { return hit_sphere(o, d, obj); }
    }
}

struct Hit {
    t: f32,
    index: u32,
}

// Closest hit over all objects. `d` must be unit length.
fn closest_hit(o: vec3<f32>, d: vec3<f32>) -> Hit {
    var best = Hit(FAR, NO_HIT);
    for (var i = 0u; i < params.num_objects; i++) {
        let obj = objects[i];
        let t = hit_object(o, d, obj);
        // Emitters are stored last; they win ties with the surface they are set into.
        let limit = select(best.t, best.t * (1.0 + EMITTER_TIE), obj.emitter != 0u);
        if (t < limit) {
            best = Hit(t, i);
        }
    }
    return best;
}

// True when a non-emitting object lies on the ray strictly between 0 and t_max.
fn occluded(o: vec3<f32>, d: vec3<f32>, t_max: f32) -> bool {
    for (var i = 0u; i < params.num_objects; i++) {
        let obj = objects[i];
        if (obj.emitter != 0u) {
            continue;
        }
        if (hit_object(o, d, obj) < t_max) {
            return true;
        }
    }
    return false;
}

// Geometric normal at p on the object (not yet oriented toward the ray).
fn surface_normal(obj: Object, p: vec3<f32>) -> vec3<f32> {
    switch obj.kind {
        case KIND_BOX: {
            // The face is the axis on which p sits farthest out, relative to the half-extent.
            let pl = rotate_y_inverse(p - obj.c.xyz, obj.a.w, obj.b.w);
            let centre = 0.5 * (obj.a.xyz + obj.b.xyz);
            let q = (pl - centre) / (0.5 * (obj.b.xyz - obj.a.xyz));
            let aq = abs(q);
            var nl = vec3<f32>(0.0, 0.0, sign(q.z));
            if (aq.x >= aq.y && aq.x >= aq.z) {
                nl = vec3<f32>(sign(q.x), 0.0, 0.0);
            } else if (aq.y >= aq.z) {
                nl = vec3<f32>(0.0, sign(q.y), 0.0);
            }
            return rotate_y(nl, obj.a.w, obj.b.w);
        }
        case KIND_QUAD: { return normalize(obj.d.xyz); }
        default: { return (p - obj.a.xyz) / obj.a.w; }
    }
}

// Distance to move a new ray's origin off the surface at p: relative to p's magnitude, because
// the rounding error of a computed hit point grows with it (about 2^-23 |p| per operation).
fn spawn_offset(p: vec3<f32>) -> f32 {
    let m = max(max(abs(p.x), abs(p.y)), abs(p.z));
    return 3.0e-5 * max(m, 1.0e-3);
}

// Next-event estimation: radiance arriving at p from one point sampled uniformly on the lights,
// already divided by its pdf (1 / A_total) and multiplied by cos(theta_x); the caller multiplies
// by albedo / pi.
fn direct_light(p: vec3<f32>, n: vec3<f32>, rng: ptr<function, u32>) -> vec3<f32> {
    let pick = rng_f32(rng) * params.light_area;
    let u1 = rng_f32(rng);
    let u2 = rng_f32(rng);
    var li = 0u;
    for (; li + 1u < params.num_lights; li++) {
        if (pick < lights[li].corner.w) {
            break;
        }
    }
    let light = lights[li];
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
fn radiance(origin: vec3<f32>, direction: vec3<f32>, rng: ptr<function, u32>) -> vec3<f32> {
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
        radiance += throughput * albedo * INV_PI * direct_light(p_spawn, n, rng);

        if (params.bounces != UNBOUNDED && depth >= params.bounces) {
            break;
        }
        if (depth >= UNBOUNDED_DEPTH_CAP) {
            break;
        }
        let u1 = rng_f32(rng);
        let u2 = rng_f32(rng);
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
            if (rng_f32(rng) >= q) {
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
        var rng = rng_seed(params.seed, pixel, params.sample_base + i);
        // Jitter uniformly inside the pixel; row 0 is the top of the image.
        let sx = (2.0 * (f32(x) + rng_f32(&rng)) * inv_width - 1.0) * params.aspect * params.tan_half_fov;
        let sy = (1.0 - 2.0 * (f32(y) + rng_f32(&rng)) * inv_height) * params.tan_half_fov;
        let d = normalize(params.forward + sx * params.right + sy * params.up);
        let l = radiance(params.eye, d, &rng);
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
