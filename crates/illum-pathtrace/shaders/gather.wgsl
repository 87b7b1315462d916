// The photon gather (shader def CAUSTIC_GATHER, a delta sun): paths E (S|D)* D S+ L other than
// E D S+ L, the caustic seen through mirrors and glass and the caustic's light scattered again by
// diffuse surfaces, by probabilistic progressive photon mapping (Knaus and Zwicker 2011). One
// invocation traces one camera path of one pixel and frame, after the light tracer
// (caustic.wgsl) has stored that frame's photons; its estimate goes into the frame's splat like
// a particle's, so frame k's sample of the pixel pairs with the camera's sample k
// (tracer/caustic.rs). The mathematics is in docs/caustics-gather.md; in short:
//
// The path: a camera ray through the pixel, jittered, followed through mirrors and glass (the
// camera path tracer's weights: reflectance; 1 with the Fresnel choice) and diffuse surfaces
// (a cosine-distributed bounce, weight the albedo), with the camera paths' length rule and
// roulette (caustic_walk.wgsl). A path that leaves the scene or reaches an emitter ends.
//
// The gather at each diffuse vertex D of depth m >= 1 (m scatterings before it; m = 0, the
// camera ray's own hit, is the light tracer's connection L S+ D E): the photons of the frame
// within r_k of D on the same side (photon normal . D's normal > 0) whose s scatterings let the
// path E ... D S^s L count under `bounces` = n (m + s + 1 <= n continuation rays), weight
// (flux x albedo / pi) summed and divided by pi r_k^2: the radiance leaving D toward the path,
// blurred over the kernel. Each frame has its own photons and radius r_k = r_1 (k + 1)^(-1/6)
// (sample index k), so frames are independent and the mean over frames converges.
//
// No other estimator counts these paths with a delta sun: next-event estimation's shadow ray
// from D toward the sun meets the specular object (L S+ D is not L D), and no camera path
// reaches a light of zero size.

#import illum::constants::PI
#import illum::sampler::{sampler_new, sample_2d}
#import illum::sampling::{sample_cosine_hemisphere, to_world}
#import illum::rtcore::spawn::spawn_point
#import illum::rtcore::geometry::NO_HIT
#import illum::rtcore::camera::camera_ray
#import illum::pathtrace::scene::params
#import illum::pathtrace::surfaces::{UNBOUNDED, max3}
#import illum::pathtrace::caustic_buffers::{caustic, photons, heads, fits, splat_add, drop_particle, gather_radius, photon_cell, photon_bucket}
#import illum::pathtrace::caustic_walk::{next_vertex, is_specular, specular_weight, diffuse_albedo, may_continue, scatter_specular}

// Mixed into the caustic's seed for the gathering paths, so that they draw no numbers a particle
// or a camera path draws.
const GATHER_SEED_KEY: u32 = 0x6a7e4ca5u;

// The sum of the weights of frame `frame`'s photons within r of x (normal n) that a path of
// `depth` scatterings may join. The disc of radius r about x meets at most two cells of side
// 2 r per axis; each bucket they hash to is walked once (two cells may share one), and a photon
// of any other cell in it lies farther than r or belongs to a visited cell: the distance alone
// decides, and no photon is counted twice. Most photons walked are farther than r (the cells
// cover 16 r^2 of a plane, the disc pi r^2): only their positions are read.
fn photon_sum(frame: u32, x: vec3<f32>, n: vec3<f32>, r: f32, depth: u32) -> vec3<f32> {
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
                        let joins = params.bounces == UNBOUNDED || depth + u32(b.w) + 1u <= params.bounces;
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
    if (pixel >= min(caustic.particles, caustic.index_end) || frame >= caustic.frame_count) {
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
    // Scatterings so far: the next vertex's depth.
    var depth = 0u;
    var total = vec3<f32>(0.0);
    loop {
        let v = next_vertex(o, d, own);
        own = v.index;
        if (v.missed || v.emitter) {
            break;
        }
        if (is_specular(v)) {
            if (!may_continue(depth + 1u, depth, &throughput, specular_weight(v), &sampler)) {
                break;
            }
            let next = scatter_specular(v, d, &sampler);
            o = next.o;
            d = next.d;
        } else {
            if (depth > 0u) {
                let r = gather_radius(frame);
                total += throughput * photon_sum(frame, v.s.p, v.s.n, r, depth) / (PI * r * r);
            }
            // A gather after this bounce is at depth m + 1 or more and joins photons of s >= 1
            // scatterings: it needs m + 3 <= n continuation rays.
            if (!may_continue(depth + 3u, depth, &throughput, diffuse_albedo(v), &sampler)) {
                break;
            }
            let u = sample_2d(&sampler);
            d = to_world(v.s.n, sample_cosine_hemisphere(u.x, u.y));
            o = spawn_point(v.s.p, v.s.n, v.s.err);
        }
        depth += 1u;
    }
    if (max3(total) > 0.0) {
        if (!fits(total)) {
            drop_particle(frame);
            return;
        }
        splat_add(frame, pixel, total);
    }
}
