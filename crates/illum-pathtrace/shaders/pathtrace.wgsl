// The Cornell box path tracer: one invocation per pixel and chunk of samples (see main);
// `sample_count` samples per pixel per dispatch.
//
// Estimator (docs/theory.md): at every diffuse hit x the direct light is estimated by next-event
// estimation on the rectangular lights,
//     L_direct(x) = (albedo / pi) * Le * cos(theta_x) cos(theta_y) / |x - y|^2 * A_total / p(s, t) * V(x, y),
// with a light chosen in proportion to its area and y = corner + s u + t v on it, (s, t) uniform
// (p = 1: pdf 1 / A_total over area) or, with shader def BILINEAR_LIGHT (the low-discrepancy
// sequence, options.rs), drawn with the density p of the bilinear fit to the geometric term
// (sampling.wgsl, sample_light_bilinear). Bounce directions are
// drawn from the cosine or the uniform hemisphere pdf; a bounce ray that reaches a light adds
// nothing, because that light was already counted by next-event estimation at the previous hit.
// A camera ray that hits a light sees its emitted radiance.
//
// A smooth mesh (shader def SMOOTH_SHADING) is shaded with its interpolated normal ns: the
// cosines of next-event estimation, the bounce's lobe and the specular directions use ns, while
// the geometric normal s.n decides sides, spawns rays and stops light leaks (a light or a
// bounce below the geometric surface counts nothing), by the rules stated in illum-rtcore's
// mesh_shading.wgsl. Elsewhere ns is s.n. The integrand at a diffuse point is then
// albedo / pi x L(w) x max(ns.w, 0) x [s.n.w > 0], which both estimators of it share.

#import illum::constants::{PI, TWO_PI, INV_PI}
#import illum::sampler::{Sampler, sampler_new, sample_1d, sample_2d, REPLICATES, REPLICATE_RUN, replicate_of}
#import illum::sampling::{sample_cosine_hemisphere, sample_uniform_hemisphere, to_world, sample_parallelogram, sample_light_bilinear}
#import illum::rtcore::spawn::{spawn_point, spawn_error, max_abs}
#import illum::rtcore::codes::{MATERIAL_CHECKER, MATERIAL_DIELECTRIC, MATERIAL_MIRROR}
#import illum::rtcore::geometry::{NO_HIT, FAR, Surface}
#import illum::rtcore::camera::camera_ray
#import illum::pathtrace::scene::{params, lights, batch_sum, batch_sum_sq}
#ifdef ADAPTIVE
#import illum::pathtrace::scene::block_samples
#endif
#import illum::rtcore::materials::material_at
#import illum::rtcore::traversal::{closest_hit, occluded, scattering_surface_at, object_at}
#import illum::pathtrace::light_choice::choose_light
#import illum::pathtrace::surfaces::{UNBOUNDED, RR_START, RR_MAX_SURVIVAL, UNBOUNDED_DEPTH_CAP, max3}
#ifdef SUN
#import illum::pathtrace::surfaces::sample_sun
#endif
#ifdef SPECULAR
#import illum::pathtrace::surfaces::scatter_dielectric
#endif
#ifdef MANIFOLD
#import illum::pathtrace::manifold::Receiver
#import illum::pathtrace::manifold_spheres::manifold_light
#endif
#ifdef CHECKER
#import illum::rtcore::optics::checker_albedo
#endif
#ifdef SMOOTH_SHADING
#import illum::rtcore::traversal::KIND_TRIANGLE
#import illum::rtcore::mesh_shading::{triangle_shading_normal, mirror_normal, dielectric_normal}
#endif

// Adaptive sampling's blocks: 8 x 8 pixels, the workgroup (allocation.rs, BLOCK).
const ADAPTIVE_BLOCK: u32 = 8u;

// Shadow rays end this fraction of their length short of the light (on top of the light's own
// error band, see direct_light). It covers rounding only: the computed length of the segment and
// the distance at which the slab or quad test finds a surface lying in the light's plane each
// carry a few units of roundoff (u = 2^-24) relative to the true distance, about 7 u together;
// 2^-20 = 16 u. Relative, so it scales with the scene; a blocker under the light is found
// whenever its gap to the light's plane exceeds the light's error band plus 2^-20 of the distance.
const SHADOW_SHORTEN: f32 = 9.5367431640625e-7;

// Next-event estimation at the surface point s (normal s.n facing the incoming ray, shading
// normal ns): radiance arriving from one point sampled on the lights, already divided by its pdf
// (p(s, t) / A_total) and multiplied by cos(theta_x) = ns.wi; the caller multiplies by
// albedo / pi. The geometry uses the surface point itself; only visibility is tested from the
// spawned origin.
fn direct_light(s: Surface, ns: vec3<f32>, origin: vec3<f32>, own: u32, sampler: ptr<function, Sampler>) -> vec3<f32> {
#ifdef LIGHT_CHOICE
    let light = lights[choose_light(sample_1d(sampler) * params.light_area)];
#else
    // One light: nothing to choose, and no number drawn for it.
    let light = lights[0];
#endif
    let u = sample_2d(sampler);
#ifdef BILINEAR_LIGHT
    // (s, t) on the light and 1 / pdf(s, t), the density following the geometric term.
    let st = sample_light_bilinear(s.p, ns, light.corner.xyz, light.edge_u.xyz, light.edge_v.xyz, light.normal.xyz, u.x, u.y);
#else
    // Uniform over the light's area.
    let st = vec3<f32>(u, 1.0);
#endif
    let y = sample_parallelogram(light.corner.xyz, light.edge_u.xyz, light.edge_v.xyz, st.x, st.y);
    let to_light = y - s.p;
    let dist2 = dot(to_light, to_light);
    let wi = to_light / sqrt(dist2);
    let cos_x = dot(ns, wi);
    let cos_y = -dot(light.normal.xyz, wi);
    // Only a point in front of the light, facing it, receives light. Written as a positive test
    // so that a NaN cosine (a point on the light itself: dist2 = 0) fails it as well, whatever a
    // compiler does with negated comparisons.
#ifdef SMOOTH_SHADING
    let lit = cos_x > 0.0 && cos_y > 0.0 && dot(s.n, wi) > 0.0;
#else
    let lit = cos_x > 0.0 && cos_y > 0.0;
#endif
    // The light's plane, and any surface lying in it such as the ceiling around the light, is
    // known only to within the light's error bound err_l; along a ray arriving at angle theta_y
    // that band is err_l / cos(theta_y) long, so the shadow ray stops that much short of y, and
    // SHADOW_SHORTEN more for rounding. Computed whether or not the point is lit (straight code,
    // see path_step): an unlit point's t_max may be meaningless, and `lit` discards it.
    let err_l = spawn_error(max_abs(light.corner.xyz) + max_abs(light.edge_u.xyz) + max_abs(light.edge_v.xyz));
    let segment = y - origin;
    let length_to_light = length(segment);
    let t_max = length_to_light * (1.0 - SHADOW_SHORTEN) - err_l / cos_y;
    let visible = lit && !occluded(origin, segment / length_to_light, t_max, own);
    return select(vec3<f32>(0.0), light.emission.xyz * (cos_x * cos_y / dist2 * params.light_area * st.z), visible);
}

#ifdef SUN
// Next-event estimation toward the directional light from s (rays leave from `origin`): its
// contribution to the integral of incoming radiance x cos(theta_x), divided by its pdf (see
// surfaces.wgsl's sample_sun). A sun disc draws two numbers; a delta sun none. Every object
// blocks it.
fn sun_light(s: Surface, ns: vec3<f32>, origin: vec3<f32>, own: u32, sampler: ptr<function, Sampler>) -> vec3<f32> {
#ifdef SUN_DISC
    let u = sample_2d(sampler);
    let sun = sample_sun(u.x, u.y);
#else
    let sun = sample_sun(0.0, 0.0);
#endif
    let w = sun.w;
    let weight = sun.weight;
    let cos_x = dot(ns, w);
#ifdef SMOOTH_SHADING
    let facing = cos_x > 0.0 && dot(s.n, w) > 0.0;
#else
    let facing = cos_x > 0.0;
#endif
    if (facing && !occluded(origin, w, FAR, own)) {
        return weight * cos_x;
    }
    return vec3<f32>(0.0);
}
#endif

#ifdef SUN_DISC
// irradiance / (pi sin^2 a), with sin^2 a = (1 - cos a)(1 + cos a).
fn sun_radiance() -> vec3<f32> {
    let one_minus_cos_max = params.sun.w;
    return params.sun_irradiance.xyz / (PI * one_minus_cos_max * (2.0 - one_minus_cos_max));
}
#endif

// What a ray leaving the scene along d sees: the sky, and a sun disc where light straight from
// it counts (camera and specular rays: next-event estimation already counted it for diffuse
// ones), unless the caustic's light tracer owns the path (`caustic_owned`: E D S+ L with D the
// camera ray's own hit, see caustic.wgsl). A delta sun is never seen.
fn escaped(d: vec3<f32>, direct_counts: bool, caustic_owned: bool) -> vec3<f32> {
    var l = vec3<f32>(0.0);
#ifdef SKY
    l += params.sky.xyz;
#endif
#ifdef SUN_DISC
    if (direct_counts && !caustic_owned && 1.0 - dot(d, params.sun.xyz) <= params.sun.w) {
        l += sun_radiance();
    }
#endif
    return l;
}



// One path: its state between two vertices.
struct Path {
    o: vec3<f32>,
    d: vec3<f32>,
    throughput: vec3<f32>,
    radiance: vec3<f32>,
    // Bounces taken so far (each diffuse or specular scattering counts as one).
    depth: u32,
    // False once the path has ended: it left the scene, reached a light, took its last bounce
    // or lost the roulette.
    alive: bool,
    // Light that reaches a ray straight from an emitter or a sun disc counts for the camera ray
    // and after specular scattering, not after a diffuse bounce, whose point already sampled the
    // lights.
    direct_counts: bool,
    // Set at the camera ray's own diffuse hit when the caustic estimator is on, kept through
    // specular scattering: the path E D S+ L it would complete belongs to the light tracer.
    caustic_owned: bool,
    // The object whose surface o lies on (NO_HIT for the camera ray): closest_hit's `own`.
    own: u32,
}

// A path starting with the camera ray from the eye along d.
fn camera_path(d: vec3<f32>) -> Path {
    return Path(params.camera.eye, d, vec3<f32>(1.0), vec3<f32>(0.0), 0u, true, true, false, NO_HIT);
}

// Traces one vertex of the path: its radiance estimate gains what this vertex adds, and the
// path moves on to its next ray or ends (alive = false).
//
// Estimator: at a diffuse vertex, next-event estimation (direct) and a bounce drawn from the
// cosine or the uniform pdf; a bounce ray that reaches a light adds nothing, because that light
// was already counted by next-event estimation at the previous vertex. Specular scattering
// (shader def SPECULAR): a mirror reflects with weight its reflectance; a dielectric reflects
// with probability F (exact Fresnel) and else refracts, weight 1 either way, with no eta^2
// scaling (every light and diffuse surface is outside, so the factors of entering and leaving
// cancel). Each scattering counts as a bounce.
//
// Written with few branches: the vertex is computed for every path, ended or not, and `select`
// keeps what a path may not add. lavapipe runs a branch's body, under a lane mask, whenever one
// of the 8 lanes of a group takes it, so branches save little here; straight code is what let
// the CPU overlap the two paths of a pair (see main: a pair written with a branch per `break`
// runs slower than one path at a time, docs/performance.md, "Levers"). An ended path (its ray missed,
// or it reached a light) computes a meaningless vertex, perhaps with infinities or NaN, that no
// select lets through. A live path draws the same numbers in the same order as it would alone:
// the ones drawn after its end are never used.
fn path_step(path: ptr<function, Path>, sampler: ptr<function, Sampler>) {
    let o = (*path).o;
    let d = (*path).d;
    let depth = (*path).depth;
    let direct_counts = (*path).direct_counts;
    let throughput = (*path).throughput;
    let caustic_owned = (*path).caustic_owned;
    let was_alive = (*path).alive;
    var radiance = (*path).radiance;

    let hit = closest_hit(o, d, (*path).own);
    let missed = hit.index == NO_HIT;
    // object_at and material_at: literals in a specialised pipeline (illum-rtcore). A missed
    // ray looks at object 0, whose vertex is never used.
    let obj = object_at(select(hit.index, 0u, missed));
    let emitter = !missed && obj.emitter != 0u;
    radiance += select(vec3<f32>(0.0), throughput * escaped(d, direct_counts, caustic_owned), was_alive && missed);
    // One-sided emitter: visible only from its front, the side its normal edge_u x edge_v (obj.d;
    // emitters are quads) points to. No surface is rebuilt for it.
    let sees_emitter = was_alive && emitter && direct_counts && dot(obj.d.xyz, d) < 0.0;
    radiance += select(vec3<f32>(0.0), throughput * material_at(obj.material).b.xyz, sees_emitter);

    var s = scattering_surface_at(obj, o + hit.t * d);
    let front = dot(s.n, d) < 0.0;
    s.n = select(-s.n, s.n, front);
    var ns = s.n;
#ifdef SMOOTH_SHADING
    if (obj.kind == KIND_TRIANGLE) {
        ns = triangle_shading_normal(obj, s.p, s.n);
    }
#endif
    let last = (params.bounces != UNBOUNDED && depth >= params.bounces) || depth >= UNBOUNDED_DEPTH_CAP;
    let at_surface = was_alive && !missed && !emitter;
    var next = Path(o, d, throughput, radiance, depth + 1u, false, false, caustic_owned, hit.index);
#ifdef SPECULAR
    let m = material_at(obj.material);
    let kind = m.kind;
    let specular = kind == MATERIAL_MIRROR || kind == MATERIAL_DIELECTRIC;
    // Its only continuation is the bounce it may not take.
    if (at_surface && specular && !last) {
        if (kind == MATERIAL_MIRROR) {
#ifdef SMOOTH_SHADING
            let optic = mirror_normal(d, s.n, ns);
#else
            let optic = s.n;
#endif
            next.throughput *= m.a.xyz;
            next.d = reflect(d, optic);
            next.o = spawn_point(s.p, s.n, s.err);
        } else {
#ifdef SMOOTH_SHADING
            let optic = dielectric_normal(d, s.n, ns, select(m.a.w, 1.0 / m.a.w, front));
#else
            let optic = s.n;
#endif
            let scattered = scatter_dielectric(s, optic, d, m.a.w, front, sampler);
            next.o = scattered.o;
            next.d = scattered.d;
        }
        next.direct_counts = true;
        var scattered_throughput = next.throughput;
        next.alive = roulette(depth, &scattered_throughput, sampler);
        next.throughput = scattered_throughput;
    }
    if (at_surface && !specular) {
        diffuse_vertex(obj.material, hit.index, s, ns, depth, last, true, &next, sampler);
    }
#else
    diffuse_vertex(obj.material, hit.index, s, ns, depth, last, at_surface, &next, sampler);
#endif
    *path = next;
}

// The diffuse part of path_step at surface s (shading normal ns) of object `index` (its
// material `material`), the path's vertex number
// `depth`: next-event estimation, then, unless this is the last vertex, the bounce. `next` holds
// the path as it arrived, with its depth already increased; this adds the vertex's light (if
// `live`: without SPECULAR it is called for ended paths too) and sets the next ray and `alive`.
fn diffuse_vertex(material: u32, index: u32, s: Surface, ns: vec3<f32>, depth: u32, last: bool, live: bool, next: ptr<function, Path>, sampler: ptr<function, Sampler>) {
#ifdef CHECKER
    let checker = material_at(material);
    var albedo = checker.a.xyz;
    if (checker.kind == MATERIAL_CHECKER) {
        albedo = checker_albedo(object_at(index), checker, s.p);
    }
#else
    let albedo = material_at(material).a.xyz;
#endif
    // Every ray leaving this point (shadow and bounce) starts here, off the surface.
    let spawned = spawn_point(s.p, s.n, s.err);
    var throughput = (*next).throughput;
    var incident = direct(s, ns, spawned, index, sampler);
#ifdef MANIFOLD
    // The sun's light through each specular sphere, solved (manifold.wgsl): a chain of k events
    // counts when depth + k + 1 <= bounces (docs/caustics.md, "Path length").
    let events = select(i32(params.bounces) - i32(depth) - 1, 3, params.bounces == UNBOUNDED);
    incident += manifold_light(Receiver(s.p, spawned, s.n, ns, index), events, sample_1d(sampler));
#endif
    let light = throughput * albedo * INV_PI * incident;
    (*next).radiance += select(vec3<f32>(0.0), light, live);
    let u = sample_2d(sampler);
    // Lambertian f = albedo / pi. Cosine pdf cos/pi: f cos / pdf = albedo.
    // Uniform pdf 1/(2 pi): f cos / pdf = 2 albedo cos. A shader def, not a branch on
    // params: on lavapipe code costs time by being in the shader, even where no lane runs it
    // (docs/performance.md, "What lavapipe does with a branch").
#ifdef UNIFORM_SAMPLING
    let local = sample_uniform_hemisphere(u.x, u.y);
    (*next).d = to_world(ns, local);
    throughput *= albedo * (2.0 * local.z);
#else
    (*next).d = to_world(ns, sample_cosine_hemisphere(u.x, u.y));
    throughput *= albedo;
#endif
#ifdef SMOOTH_SHADING
    // A bounce drawn around ns below the geometric surface would leak: the path ends.
    let survives = roulette(depth, &throughput, sampler) && dot((*next).d, s.n) > 0.0;
#else
    let survives = roulette(depth, &throughput, sampler);
#endif
    (*next).throughput = throughput;
    (*next).o = spawned;
    (*next).direct_counts = false;
#ifdef CAUSTIC
    (*next).caustic_owned = depth == 0u;
#endif
    (*next).alive = live && !last && survives;
}

// Next-event estimation at a diffuse point: the area lights and the directional light.
fn direct(s: Surface, ns: vec3<f32>, origin: vec3<f32>, own: u32, sampler: ptr<function, Sampler>) -> vec3<f32> {
    var l = vec3<f32>(0.0);
#ifdef AREA_LIGHTS
    l += direct_light(s, ns, origin, own, sampler);
#endif
#ifdef SUN
    l += sun_light(s, ns, origin, own, sampler);
#endif
    return l;
}

// Russian roulette in unbounded mode (shader def UNBOUNDED_BOUNCES; compiled out otherwise: on
// lavapipe code present costs time even where no lane runs it) from bounce RR_START on: survive
// with probability q = min(max channel, 0.95) and divide by q, so E[throughput] is unchanged.
// False: the path ends (also when nothing more can be added).
fn roulette(depth: u32, throughput: ptr<function, vec3<f32>>, sampler: ptr<function, Sampler>) -> bool {
#ifdef UNBOUNDED_BOUNCES
    if (depth >= RR_START) {
        let q = min(max3(*throughput), RR_MAX_SURVIVAL);
        if (sample_1d(sampler) >= q) {
            return false;
        }
        *throughput /= q;
    }
#endif
    return max3(*throughput) > 0.0;
}

// The camera ray through a point of pixel (x, y) jittered uniformly inside it (row 0 is the top
// of the image): its direction from the eye. inv_size = 1 / the image's size in pixels.
fn pixel_ray(x: u32, y: u32, inv_size: vec2<f32>, sampler: ptr<function, Sampler>) -> vec3<f32> {
    let jitter = sample_2d(sampler);
    return camera_ray(params.camera, vec2<f32>(f32(x) + jitter.x, f32(y) + jitter.y), inv_size);
}

// The sums of a group of samples of one pixel: what one slot holds.
struct Sums {
    sum: vec3<f32>,
    sum_sq: vec3<f32>,
    finite: u32,
    dropped: u32,
}

fn no_sums() -> Sums {
    return Sums(vec3<f32>(0.0), vec3<f32>(0.0), 0u, 0u);
}

// Adds a sample's radiance l to the sums when it is finite; counts it as dropped otherwise.
fn accumulate(l: vec3<f32>, sums: ptr<function, Sums>) {
    if (is_finite3(l)) {
        (*sums).sum += l;
        (*sums).sum_sq += l * l;
        (*sums).finite += 1u;
    } else {
        (*sums).dropped += 1u;
    }
}

#ifdef REPLICATED
// a plus b where `take`, else a: adds a finished run's sums to one replicate's without a branch.
fn add_if(a: Sums, b: Sums, take: bool) -> Sums {
    let c = Sums(a.sum + b.sum, a.sum_sq + b.sum_sq, a.finite + b.finite, a.dropped + b.dropped);
    return Sums(select(a.sum, c.sum, take), select(a.sum_sq, c.sum_sq, take), select(a.finite, c.finite, take), select(a.dropped, c.dropped, take));
}

// Per replicate (sampler.wgsl), the sums of the chunk's samples: slot layer r holds replicate r.
struct ReplicateSums {
    r0: Sums,
    r1: Sums,
    r2: Sums,
    r3: Sums,
}

// Ends the run of sample index i, the run's sums so far `run`, when i is the run's last index
// or the chunk's (`last`): the run's sums join its replicate and start again. The sample index
// is the same for every invocation of a workgroup (gid.z alone sets it), so the branch is
// uniform; the replicate is picked with selects.
fn end_run(i: u32, last: bool, run: ptr<function, Sums>, replicates: ptr<function, ReplicateSums>) {
    if (last || (i + 1u) % REPLICATE_RUN == 0u) {
        let r = replicate_of(i);
        let sums = *run;
        (*replicates).r0 = add_if((*replicates).r0, sums, r == 0u);
        (*replicates).r1 = add_if((*replicates).r1, sums, r == 1u);
        (*replicates).r2 = add_if((*replicates).r2, sums, r == 2u);
        (*replicates).r3 = add_if((*replicates).r3, sums, r == 3u);
        *run = no_sums();
    }
}
#endif

// Writes the sums to layer `layer` of this invocation's chunk (see main).
fn write_slot(gid: vec3<u32>, layer: u32, sums: Sums) {
    let slot = ((gid.z * SLOT_LAYERS + layer) * params.rows + gid.y) * params.width + gid.x;
    batch_sum[slot] = vec4<f32>(sums.sum, f32(sums.finite));
    batch_sum_sq[slot] = vec4<f32>(sums.sum_sq, f32(sums.dropped));
}

// True when no component is Inf or NaN (exponent bits all ones), tested on the bits so no
// compiler fast-math assumption can remove the check.
fn is_finite3(v: vec3<f32>) -> bool {
    let exponent = bitcast<vec3<u32>>(v) & vec3<u32>(0x7f800000u);
    return all(exponent != vec3<u32>(0x7f800000u));
}

// Slot layers per chunk: one, or one per replicate with the low-discrepancy sequence (whose
// error comes from the spread of its replicates, src/replicates.rs). Mirrored by
// src/batch.rs's `Layers` (checked there by a test).
#ifdef REPLICATED
const SLOT_LAYERS: u32 = REPLICATES;
#else
const SLOT_LAYERS: u32 = 1u;
#endif

// One invocation traces one chunk of at most `chunk_samples` samples of one pixel and writes
// their f32 sums to its own slots (one per layer, see SLOT_LAYERS); the CPU folds the slots in
// f64. Chunks keep two things small:
// the rounding of an f32 sum of n terms, at most (n - 1) u of the sum of their magnitudes
// (with n = 16: 15 x 2^-24 < 1e-6 relative), and the work of one invocation (lavapipe stops an
// invocation's loops after 65535 iterations; GPUs have watchdogs). Slot index: chunk-major, then
// the chunk's layers, then the band's rows, then columns.
@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let first = gid.z * params.chunk_samples;
    if (gid.x >= params.width || gid.y >= params.rows || first >= params.sample_count) {
        return;
    }
    var count = min(params.chunk_samples, params.sample_count - first);
    let x = gid.x;
    let y = gid.y + params.row_offset;
    let start = params.sample_base + first;
#ifdef ADAPTIVE
    // The pixel's block ends at sample index `limit`: this chunk takes the part of its samples
    // below it (none once the block is done; the slot then holds zeros, as the fold expects).
    let limit = block_samples[(y / ADAPTIVE_BLOCK) * ((params.width + ADAPTIVE_BLOCK - 1u) / ADAPTIVE_BLOCK) + x / ADAPTIVE_BLOCK];
    count = select(0u, min(count, limit - start), limit > start);
#endif
    let pixel = y * params.width + x;
    // The sums of the samples since the last slot boundary: the whole chunk's, or with
    // replicates the current run's (end_run moves them to their replicate's).
    var sums = no_sums();
#ifdef REPLICATED
    var replicates = ReplicateSums(no_sums(), no_sums(), no_sums(), no_sums());
#endif
    let inv_size = vec2<f32>(1.0 / f32(params.width), 1.0 / f32(params.height));
#ifdef PAIRED_PATHS
    // Two samples at a time, traced in lockstep, vertex by vertex: lavapipe runs each 8-lane
    // group's instructions as one stream on one core, and a second independent path in that
    // stream gives the CPU work to overlap with the first one's chains of dependent operations
    // (square roots, divisions); four paths gain nothing over two (docs/performance.md,
    // "Levers"). Each path keeps its own sampler, so every sample is what it
    // would be traced alone, and the sums take them in order: the image is bit for bit the same.
    for (var i = 0u; i < count; i += 2u) {
        var first_sampler = sampler_new(params.seed, pixel, start + i);
        var second_sampler = sampler_new(params.seed, pixel, start + i + 1u);
        var a = camera_path(pixel_ray(x, y, inv_size, &first_sampler));
        var b = camera_path(pixel_ray(x, y, inv_size, &second_sampler));
        // An odd count: the last pair has no second sample. Its path is traced all the same and
        // discarded, so the planner gives passes an even spp where it can: a separate one-path
        // loop for the odd sample would cost every invocation by being in the shader
        // (docs/performance.md, "Levers").
        let second = i + 1u < count;
        b.alive = second;
        loop {
            path_step(&a, &first_sampler);
            path_step(&b, &second_sampler);
            if (!(a.alive || b.alive)) {
                break;
            }
        }
        accumulate(a.radiance, &sums);
#ifdef REPLICATED
        end_run(start + i, i + 1u == count, &sums, &replicates);
#endif
        if (second) {
            accumulate(b.radiance, &sums);
#ifdef REPLICATED
            end_run(start + i + 1u, i + 2u == count, &sums, &replicates);
#endif
        }
    }
#else
    // One sample at a time (TracerOptions::paired_paths off: the browser).
    for (var i = 0u; i < count; i++) {
        var sampler = sampler_new(params.seed, pixel, start + i);
        var a = camera_path(pixel_ray(x, y, inv_size, &sampler));
        loop {
            path_step(&a, &sampler);
            if (!a.alive) {
                break;
            }
        }
        accumulate(a.radiance, &sums);
#ifdef REPLICATED
        end_run(start + i, i + 1u == count, &sums, &replicates);
#endif
    }
#endif
#ifdef REPLICATED
    write_slot(gid, 0u, replicates.r0);
    write_slot(gid, 1u, replicates.r1);
    write_slot(gid, 2u, replicates.r2);
    write_slot(gid, 3u, replicates.r3);
#else
    write_slot(gid, 0u, sums);
#endif
}
