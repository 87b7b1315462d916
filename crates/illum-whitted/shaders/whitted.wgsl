// Whitted's 1980 ray tracer, one invocation per pixel (see crates/illum-whitted/src/lib.rs for
// the model; crates/illum-oracle/src/whitted.rs is its independent f64 copy).
//
// The ray tree is walked depth-first with an explicit stack (WGSL has no recursion): the walk
// goes on with a hit's one child (a mirror's reflection, a total internal reflection) or, of a
// dielectric's two, with the refracted ray, pushing the reflected one; with none it takes the
// last ray pushed. A ray pushed at remaining depth k has depth k - 1 and everything pushed in its
// sibling's subtree is shallower, so the stack's depths fall strictly from bottom to top: at most
// depth entries. The pipeline is built for the scene's depth (shader def WHITTED_STACK = depth,
// at least 1, at most 64 for the deepest recursion the scene format accepts): WGSL zero-fills a
// function's arrays on every call, so a stack sized for the deepest recursion would cost every
// shallow render that much more, and lavapipe's compile time grows with the stack's size and
// with the places that write it, so there is one.
//
// The traversal (closest_hit, occluded, surface_at, object_at) and the materials (material_at)
// are illum-rtcore's, generated for the scene with its numbers as constants, as the path
// tracer's are: one copy of intersection, optics and camera for both ray tracers. Shadow rays
// test only the objects that can block a light; a Whitted point light lies inside the area
// light it stands for, so the same occluders serve.
//
// A smooth mesh (shader def SMOOTH_SHADING) is shaded with its interpolated normal ns and
// keeps its geometric normal n for sides, spawning and light leaks, by the rules stated in
// illum-rtcore's mesh_shading.wgsl; elsewhere ns is n.

#import illum::rtcore::spawn::spawn_point
#import illum::rtcore::codes::{MATERIAL_CHECKER, MATERIAL_DIELECTRIC, MATERIAL_MIRROR, MATERIAL_EMITTER}
#import illum::rtcore::geometry::{FAR, NO_HIT}
#import illum::rtcore::camera::{Camera, camera_ray}
#import illum::rtcore::optics::{checker_albedo, transmitted_cos2, refracted, fresnel}
#import illum::rtcore::traversal::{closest_hit, occluded, surface_at, object_at}
#import illum::rtcore::materials::material_at
#ifdef SMOOTH_SHADING
#import illum::rtcore::traversal::KIND_TRIANGLE
#import illum::rtcore::mesh_shading::{triangle_shading_normal, mirror_normal, dielectric_normal}
#endif

const MAX_STACK: u32 = #{WHITTED_STACK}u;

const LIGHT_DIRECTIONAL: u32 = 0u;

struct Params {
    camera: Camera,
    background: vec4<f32>,
    ambient: vec4<f32>,
    // rgb: the mirror's highlight colour, w: its shininess
    mirror_specular: vec4<f32>,
    // x: the mirror's weight, y: the dielectric's shininess
    shading: vec4<f32>,
    // width, height, first emitter (objects before it can cast shadows), row-major index of
    // this dispatch's top-left pixel (a long render is dispatched in parts, each its own
    // submission)
    sizes: vec4<u32>,
    // number of lights, depth, aa (n of n x n), output (0: radiance, OUTPUT_OBJECT_IDS)
    counts: vec4<u32>,
}

// A directional light: a = (unit vector toward it, 0), power = (irradiance / pi, 0). A point
// light at an emitting quad's centre: a = (position, 1), normal = (the quad's front normal, 0),
// power = (radiance x area, 0).
struct Light {
    kind: u32,
    pad: array<u32, 3>,
    a: vec4<f32>,
    normal: vec4<f32>,
    power: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read_write> image: array<vec4<f32>>;

struct Ray {
    o: vec3<f32>,
    d: vec3<f32>,
    weight: vec3<f32>,
    depth: u32,
    // The object whose surface the ray leaves (NO_HIT for the camera's): closest_hit's `own`.
    own: u32,
}

// Light from every light at p on object `own` (geometric normal n toward the viewer, shading
// normal ns, spawn error err), for a white Lambertian surface (sum E_l max(ns.l, 0) V_l) and for
// a Blinn-Phong highlight of `shininess` seen along v (sum E_l max(ns.h, 0)^shininess V_l where
// ns.l > 0). A light behind the geometric surface (n.l <= 0) lights nothing.
struct Lit {
    diffuse: vec3<f32>,
    highlight: vec3<f32>,
}

fn light_at(p: vec3<f32>, n: vec3<f32>, ns: vec3<f32>, err: f32, own: u32, v: vec3<f32>, shininess: f32) -> Lit {
    var lit = Lit(vec3<f32>(0.0), vec3<f32>(0.0));
    let origin = spawn_point(p, n, err);
    for (var li = 0u; li < params.counts.x; li++) {
        let light = lights[li];
        var l: vec3<f32>;
        var e: vec3<f32>;
        var t_max = FAR;
#ifdef DIRECTIONAL_LIGHT
        let directional = light.kind == LIGHT_DIRECTIONAL;
#else
        let directional = false;
#endif
        if (directional) {
            l = light.a.xyz;
            e = light.power.xyz;
        } else {
#ifdef POINT_LIGHTS
            let to = light.a.xyz - p;
            let r2 = dot(to, to);
            let r = sqrt(r2);
            l = to / r;
            let cos_light = max(dot(-l, light.normal.xyz), 0.0);
            e = light.power.xyz * (cos_light / (3.14159265358979 * r2));
            t_max = r * (1.0 - 1.0e-5);
#endif
        }
        let cos_n = dot(ns, l);
#ifdef SMOOTH_SHADING
        let behind = dot(n, l) <= 0.0;
#else
        let behind = false;
#endif
        if (cos_n <= 0.0 || behind || all(e == vec3<f32>(0.0)) || occluded(origin, l, t_max, own)) {
            continue;
        }
        lit.diffuse += e * cos_n;
        lit.highlight += e * pow(max(dot(ns, normalize(l + v)), 0.0), shininess);
    }
    return lit;
}

fn trace(eye: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    var stack: array<Ray, MAX_STACK>;
    var top = 0u;
    var ray = Ray(eye, dir, vec3<f32>(1.0), params.counts.y, NO_HIT);
    var colour = vec3<f32>(0.0);
    loop {
        // The ray the walk takes next: a child of this hit (the transmitted one of two), or else
        // the last one pushed.
        var next = ray;
        var spawned = false;
        let hit = closest_hit(ray.o, ray.d, ray.own);
        if (hit.index == NO_HIT) {
            colour += ray.weight * params.background.rgb;
        } else {
            let obj = object_at(hit.index);
            let m = material_at(obj.material);
            let s = surface_at(obj, ray.o + hit.t * ray.d);
            let front = dot(s.n, ray.d) < 0.0;
            let n = select(-s.n, s.n, front);
            var ns = n;
#ifdef SMOOTH_SHADING
            if (obj.kind == KIND_TRIANGLE) {
                ns = triangle_shading_normal(obj, s.p, n);
            }
#endif
            let v = -ray.d;
            // The lights at the hit, for every material but an emitter: one call, so that its
            // shadow rays (the traversal, inlined) are compiled once, not once per material.
            var shininess = 1.0;
#ifdef MIRRORS
            if (m.kind == MATERIAL_MIRROR) {
                shininess = params.mirror_specular.w;
            }
#endif
#ifdef DIELECTRICS
            if (m.kind == MATERIAL_DIELECTRIC) {
                shininess = params.shading.y;
            }
#endif
            var lit = Lit(vec3<f32>(0.0), vec3<f32>(0.0));
            if (m.kind != MATERIAL_EMITTER) {
                lit = light_at(s.p, n, ns, s.err, hit.index, v, shininess);
            }
            // Only the kinds of material the scene has are compiled (shader defs EMITTERS,
            // MIRRORS, DIELECTRICS, CHECKER): Lambertian and checker surfaces take the default.
            switch m.kind {
#ifdef EMITTERS
                case MATERIAL_EMITTER: {
                    colour += select(vec3<f32>(0.0), ray.weight * m.b.rgb, front);
                }
#endif
#ifdef MIRRORS
                case MATERIAL_MIRROR: {
                    let c = m.a.rgb;
                    let w = params.shading.x;
                    colour += ray.weight
                        * ((1.0 - w) * c * (params.ambient.rgb + lit.diffuse) + params.mirror_specular.rgb * lit.highlight);
#ifdef SMOOTH_SHADING
                    let nr = mirror_normal(ray.d, n, ns);
#else
                    let nr = n;
#endif
                    if (ray.depth > 0u) {
                        next = Ray(spawn_point(s.p, n, s.err), reflect(ray.d, nr), ray.weight * w * c, ray.depth - 1u, hit.index);
                        spawned = true;
                    }
                }
#endif
#ifdef DIELECTRICS
                case MATERIAL_DIELECTRIC: {
                    // Entering through the front or leaving.
                    let ior = m.a.w;
                    let eta = select(ior, 1.0 / ior, front);
                    colour += ray.weight * lit.highlight;
#ifdef SMOOTH_SHADING
                    let nd = dielectric_normal(ray.d, n, ns, eta);
#else
                    let nd = n;
#endif
                    if (ray.depth > 0u) {
                        let cos_i = dot(v, nd);
                        let k = transmitted_cos2(cos_i, eta);
                        let reflected = reflect(ray.d, nd);
                        if (k < 0.0) {
                            next = Ray(spawn_point(s.p, n, s.err), reflected, ray.weight, ray.depth - 1u, hit.index);
                            spawned = true;
                        } else {
                            let cos_t = sqrt(k);
                            let transmitted = refracted(ray.d, nd, eta, cos_i, cos_t);
                            let f = fresnel(cos_i, cos_t, eta);
                            if (top < MAX_STACK) {
                                stack[top] = Ray(spawn_point(s.p, n, s.err), reflected, ray.weight * f, ray.depth - 1u, hit.index);
                                top += 1u;
                                next = Ray(spawn_point(s.p, -n, s.err), transmitted, ray.weight * (1.0 - f), ray.depth - 1u, hit.index);
                                spawned = true;
                            }
                        }
                    }
                }
#endif
                default: {
                    var c = m.a.rgb;
#ifdef CHECKER
                    if (m.kind == MATERIAL_CHECKER) {
                        c = checker_albedo(obj, m, s.p);
                    }
#endif
                    colour += ray.weight * c * (params.ambient.rgb + lit.diffuse);
                }
            }
        }
        if (spawned) {
            ray = next;
        } else if (top > 0u) {
            top -= 1u;
            ray = stack[top];
        } else {
            break;
        }
    }
    return colour;
}

// The object-ID image (params.counts.w = OUTPUT_OBJECT_IDS), from which the ladder cuts its
// regions: for the ray through the pixel's centre, the index of the object it hits (NO_HIT for none), and from
// that point toward the first light: SHADOW_LIT, SHADOW_FACING_AWAY (the surface faces away
// from the light), or the index of the nearest object that blocks it. Indices are those of the
// traversal (the path tracer's object order); bit-cast into the image's floats.
const OUTPUT_OBJECT_IDS: u32 = 1u;
const SHADOW_LIT: u32 = 0xfffffffeu;
const SHADOW_FACING_AWAY: u32 = 0xfffffffdu;

fn object_ids(eye: vec3<f32>, d: vec3<f32>) -> vec2<u32> {
    let hit = closest_hit(eye, d, NO_HIT);
    if (hit.index == NO_HIT || params.counts.x == 0u) {
        return vec2<u32>(hit.index, SHADOW_LIT);
    }
    let s = surface_at(object_at(hit.index), eye + hit.t * d);
    let n = select(-s.n, s.n, dot(s.n, d) < 0.0);
    let light = lights[0];
    var l = light.a.xyz;
    var t_max = FAR;
    if (light.kind != LIGHT_DIRECTIONAL) {
        let to = light.a.xyz - s.p;
        t_max = length(to) * (1.0 - 1.0e-5);
        l = to / length(to);
    }
    if (dot(n, l) <= 0.0) {
        return vec2<u32>(hit.index, SHADOW_FACING_AWAY);
    }
    let blocker = closest_hit(spawn_point(s.p, n, s.err), l, hit.index);
    // Every object but an emitter blocks: the analytic ones before the first emitter and the
    // mesh triangles, numbered after every analytic object (illum-rtcore's traversal).
    let blocks = blocker.index != NO_HIT && blocker.t < t_max && object_at(blocker.index).emitter == 0u;
    return vec2<u32>(hit.index, select(SHADOW_LIT, blocker.index, blocks));
}

// The unit direction through the point (px, py) of the image, in pixels from its top-left.
fn pixel_ray(px: f32, py: f32) -> vec3<f32> {
    let inv_size = vec2<f32>(1.0 / f32(params.sizes.x), 1.0 / f32(params.sizes.y));
    return camera_ray(params.camera, vec2<f32>(px, py), inv_size);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let width = params.sizes.x;
    let height = params.sizes.y;
    let px = params.sizes.w % width + id.x;
    let py = params.sizes.w / width + id.y;
    if (px >= width || py >= height) {
        return;
    }
    if (params.counts.w == OUTPUT_OBJECT_IDS) {
        let ids = object_ids(params.camera.eye, pixel_ray(f32(px) + 0.5, f32(py) + 0.5));
        image[py * width + px] = vec4<f32>(bitcast<f32>(ids.x), bitcast<f32>(ids.y), 0.0, 0.0);
        return;
    }
    let n = max(params.counts.z, 1u);
    var sum = vec3<f32>(0.0);
    for (var j = 0u; j < n; j++) {
        for (var i = 0u; i < n; i++) {
            // The cell centres of an n x n grid over the pixel.
            sum += trace(params.camera.eye, pixel_ray(f32(px) + (f32(i) + 0.5) / f32(n), f32(py) + (f32(j) + 0.5) / f32(n)));
        }
    }
    image[py * width + px] = vec4<f32>(sum / f32(n * n), 1.0);
}
