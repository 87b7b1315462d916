#define_import_path illum::pathtrace::caustic_walk

// How the caustic's two passes walk through the scene (shader def CAUSTIC): the light tracer's
// particles from the sun (caustic.wgsl) and the photon gather's camera paths (gather.wgsl). One
// copy of the step from a ray to the surface it meets, of the path-length rule with Russian
// roulette, and of the specular scatterings, so that both follow mirrors and glass alike.

#ifdef CAUSTIC
#import illum::sampler::{Sampler, sample_1d}
#import illum::rtcore::spawn::spawn_point
#import illum::rtcore::codes::{MATERIAL_CHECKER, MATERIAL_DIELECTRIC, MATERIAL_MIRROR}
#import illum::rtcore::geometry::{NO_HIT, Object, Surface}
#import illum::rtcore::material::Material
#import illum::pathtrace::scene::{params, objects, materials}
#import illum::rtcore::traversal::{closest_hit, scattering_surface_at}
#import illum::pathtrace::surfaces::{UNBOUNDED, RR_START, RR_MAX_SURVIVAL, UNBOUNDED_DEPTH_CAP, max3, Scattered, scatter_dielectric}
#ifdef CHECKER
#import illum::rtcore::optics::checker_albedo
#endif

// What a ray meets next. `missed`: it left the scene; `emitter`: it reached an emitter; else a
// surface, with s.n turned to face the ray (`front`: the ray met the side the normal points to).
// `index`: the object met (NO_HIT when missed), the `own` of the next ray leaving it.
struct Vertex {
    index: u32,
    missed: bool,
    emitter: bool,
    front: bool,
    s: Surface,
    obj: Object,
    m: Material,
}

// The ray from o, on the surface of object `own` (NO_HIT: on none), along d.
fn next_vertex(o: vec3<f32>, d: vec3<f32>, own: u32) -> Vertex {
    var v: Vertex;
    let hit = closest_hit(o, d, own);
    v.index = hit.index;
    v.missed = hit.index == NO_HIT;
    if (v.missed) {
        return v;
    }
    v.obj = objects[hit.index];
    v.emitter = v.obj.emitter != 0u;
    if (v.emitter) {
        return v;
    }
    v.s = scattering_surface_at(v.obj, o + hit.t * d);
    v.front = dot(v.s.n, d) < 0.0;
    if (!v.front) {
        v.s.n = -v.s.n;
    }
    v.m = materials[v.obj.material];
    return v;
}

fn is_specular(v: Vertex) -> bool {
    return v.m.kind == MATERIAL_MIRROR || v.m.kind == MATERIAL_DIELECTRIC;
}

// A specular vertex's weight: a mirror's reflectance; 1 for glass (the Fresnel choice).
fn specular_weight(v: Vertex) -> vec3<f32> {
    return select(vec3<f32>(1.0), v.m.a.xyz, v.m.kind == MATERIAL_MIRROR);
}

// A diffuse vertex's albedo: a checker's tile colour there, else the material's.
fn diffuse_albedo(v: Vertex) -> vec3<f32> {
#ifdef CHECKER
    if (v.m.kind == MATERIAL_CHECKER) {
        return checker_albedo(v.obj, v.m, v.s.p);
    }
#endif
    return v.m.a.xyz;
}

// Whether a path whose vertex number `depth` scatters with `weight` goes on, so that it will
// have taken `rays` continuation rays by its next use (the length rule of the camera paths:
// rays <= `bounces`); multiplies the throughput by the weight. Unbounded: Russian roulette from
// depth RR_START on (survive with q = min(max channel, RR_MAX_SURVIVAL), divide by q).
fn may_continue(rays: u32, depth: u32, throughput: ptr<function, vec3<f32>>, weight: vec3<f32>, sampler: ptr<function, Sampler>) -> bool {
    if (params.bounces != UNBOUNDED) {
        if (rays > params.bounces) {
            return false;
        }
    } else {
        if (depth >= UNBOUNDED_DEPTH_CAP) {
            return false;
        }
        if (depth >= RR_START) {
            let q = min(max3(*throughput * weight), RR_MAX_SURVIVAL);
            if (!(sample_1d(sampler) < q)) {
                return false;
            }
            *throughput /= q;
        }
    }
    *throughput *= weight;
    return max3(*throughput) > 0.0;
}

// The ray leaving specular vertex v met along d: a mirror reflects; a dielectric reflects or
// refracts with the Fresnel probability (surfaces.wgsl). Radiance and flux alike cross with no
// eta^2 factor (docs/caustics.md).
fn scatter_specular(v: Vertex, d: vec3<f32>, sampler: ptr<function, Sampler>) -> Scattered {
    if (v.m.kind == MATERIAL_MIRROR) {
        return Scattered(spawn_point(v.s.p, v.s.n, v.s.err), reflect(d, v.s.n));
    }
    // No mesh reaches the caustic's estimators (estimators.rs): the geometric normal is the optic one.
    return scatter_dielectric(v.s, v.s.n, d, v.m.a.w, v.front, sampler);
}
#endif
