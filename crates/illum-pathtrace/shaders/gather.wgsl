// The photon gather (shader def CAUSTIC_GATHER): the caustic seen through a specular surface,
// paths E S+ D S+ L with a delta sun, by probabilistic progressive photon mapping (Knaus and
// Zwicker 2011). One invocation traces one camera path of one pixel and frame, after the light
// tracer (caustic.wgsl) has stored that frame's photons; the estimate goes into the frame's
// splat like a particle's, so frame k's sample of the pixel pairs with the camera's sample k
// (tracer/caustic.rs). The mathematics is in docs/caustics.md; in short:
//
// The path: a camera ray through the pixel, jittered, followed through mirrors and glass (the
// camera path tracer's weights: reflectance; 1 with the Fresnel choice) to its first diffuse
// point D after j >= 1 specular scatterings. j = 0 is the light tracer's connection (L S+ D E);
// a path that leaves the scene or meets an emitter adds nothing.
//
// The estimate at D: the photons of the frame within r_k of D on the same side (photon normal
// . D's normal > 0) whose s scatterings let the path E S^j D S^s L count under `bounces` = n
// (j + s + 1 <= n continuation rays), weight (flux x albedo / pi) summed and divided by pi r_k^2:
// the radiance leaving D toward the path, blurred over the kernel. Each frame has its own
// photons and radius r_k = r_1 (k + 1)^(-1/6) (sample index k), so frames are independent and
// the mean over frames converges to the true radiance.

#import illum::constants::PI
#import illum::sampler::{Sampler, sampler_new, sample_1d, sample_2d}
#import illum::rtcore::spawn::spawn_point
#import illum::rtcore::codes::{MATERIAL_DIELECTRIC, MATERIAL_MIRROR}
#import illum::rtcore::geometry::NO_HIT
#import illum::rtcore::camera::camera_ray
#import illum::pathtrace::scene::{params, objects, materials}
#import illum::rtcore::traversal::{closest_hit, scattering_surface_at}
#import illum::pathtrace::surfaces::{UNBOUNDED, RR_START, RR_MAX_SURVIVAL, UNBOUNDED_DEPTH_CAP, max3, scatter_dielectric}
#import illum::pathtrace::caustic_buffers::{caustic, photons, heads, fits, splat_add, drop_particle, gather_radius, photon_cell, photon_bucket}

// Mixed into the caustic's seed for the gathering paths, so that they draw no numbers a particle
// or a camera path draws.
const GATHER_SEED_KEY: u32 = 0x6a7e4ca5u;

// The sum of the weights of frame `frame`'s photons within r of x (normal n) that a path of
// `specular` scatterings may join. The disc of radius r about x meets at most two cells of side
// 2 r per axis; each bucket they hash to is walked once (two cells may share one), and a photon
// of any other cell in it lies farther than r or belongs to a visited cell: the distance alone
// decides, and no photon is counted twice. Most photons walked are farther than r (the cells
// cover 16 r^2 of a plane, the disc pi r^2): only their positions are read.
fn photon_sum(frame: u32, x: vec3<f32>, n: vec3<f32>, r: f32, specular: u32) -> vec3<f32> {
    let side = 2.0 * r;
    let lo = photon_cell(x - vec3<f32>(r), side);
    let hi = photon_cell(x + vec3<f32>(r), side);
    var visited = array<u32, 8>();
    var count = 0u;
    var sum = vec3<f32>(0.0);
    for (var cz = lo.z; cz <= hi.z; cz++) {
        for (var cy = lo.y; cy <= hi.y; cy++) {
            for (var cx = lo.x; cx <= hi.x; cx++) {
                let bucket = photon_bucket(frame, vec3<i32>(cx, cy, cz));
                var seen = false;
                for (var i = 0u; i < count; i++) {
                    seen = seen || visited[i] == bucket;
                }
                if (seen) {
                    continue;
                }
                visited[count] = bucket;
                count += 1u;
                var next = atomicLoad(&heads[bucket]);
                // A list holds each photon of its bucket once: at most N steps.
                for (var steps = 0u; next != 0u && steps < caustic.particles; steps++) {
                    let slot = next - 1u;
                    let a = photons[3u * slot];
                    next = bitcast<u32>(a.w);
                    let d = a.xyz - x;
                    if (dot(d, d) < r * r) {
                        let b = photons[3u * slot + 1u];
                        let joins = params.bounces == UNBOUNDED || specular + u32(b.w) + 1u <= params.bounces;
                        if (joins && dot(photons[3u * slot + 2u].xyz, n) > 0.0) {
                            sum += b.xyz;
                        }
                    }
                }
            }
        }
    }
    return sum;
}

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let pixel = caustic.first_index + gid.y * caustic.row_stride + gid.x;
    let frame = gid.z;
    if (pixel >= caustic.particles || frame >= caustic.frame_count) {
        return;
    }
    var sampler = sampler_new(caustic.seed ^ GATHER_SEED_KEY, pixel, caustic.frame_base + frame);
    let x = pixel % params.width;
    let y = pixel / params.width;
    let jitter = sample_2d(&sampler);
    let inv_size = vec2<f32>(1.0 / f32(params.width), 1.0 / f32(params.height));
    var d = camera_ray(params.camera, vec2<f32>(f32(x) + jitter.x, f32(y) + jitter.y), inv_size);
    var o = params.camera.eye;
    // The object whose surface o lies on: closest_hit's `own`.
    var own = NO_HIT;
    var throughput = vec3<f32>(1.0);
    var specular = 0u;
    loop {
        let hit = closest_hit(o, d, own);
        own = hit.index;
        if (hit.index == NO_HIT) {
            return;
        }
        let obj = objects[hit.index];
        if (obj.emitter != 0u) {
            return;
        }
        var s = scattering_surface_at(obj, o + hit.t * d);
        let front = dot(s.n, d) < 0.0;
        if (!front) {
            s.n = -s.n;
        }
        let m = materials[obj.material];
        let kind = m.kind;
        if (kind != MATERIAL_MIRROR && kind != MATERIAL_DIELECTRIC) {
            if (specular == 0u) {
                return;
            }
            let r = gather_radius(frame);
            let v = throughput * photon_sum(frame, s.p, s.n, r, specular) / (PI * r * r);
            if (max3(v) > 0.0) {
                if (!fits(v)) {
                    drop_particle(frame);
                    return;
                }
                splat_add(frame, pixel, v);
            }
            return;
        }
        // The specular continuation: the camera path tracer's length rule and roulette.
        if (params.bounces != UNBOUNDED) {
            if (specular + 1u > params.bounces) {
                return;
            }
        } else if (specular >= UNBOUNDED_DEPTH_CAP) {
            return;
        }
        var weight = vec3<f32>(1.0);
        if (kind == MATERIAL_MIRROR) {
            weight = m.a.xyz;
        }
        if (params.bounces == UNBOUNDED && specular >= RR_START) {
            let q = min(max3(throughput * weight), RR_MAX_SURVIVAL);
            if (!(sample_1d(&sampler) < q)) {
                return;
            }
            throughput /= q;
        }
        throughput *= weight;
        if (kind == MATERIAL_MIRROR) {
            d = reflect(d, s.n);
            o = spawn_point(s.p, s.n, s.err);
        } else {
            let next = scatter_dielectric(s, d, m.a.w, front, &sampler);
            o = next.o;
            d = next.d;
        }
        if (!(max3(throughput) > 0.0)) {
            return;
        }
        specular += 1u;
    }
}
