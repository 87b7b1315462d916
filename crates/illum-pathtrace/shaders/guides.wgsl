// A denoiser's guide buffers (tracer/guides.rs): per pixel, the albedo and the normal of the
// first non-specular surface each of its camera paths meets, averaged over its samples.
//
// A path is followed through mirrors and glass the way Open Image Denoise's documentation asks
// for perfectly specular surfaces: the albedo is the next diffuse surface's, times what the
// specular chain passed on, and the normal is that surface's. A mirror passes on its
// reflectance. A dielectric passes on its likelier branch only (likelier_dielectric_branch:
// the refraction where the Fresnel reflectance is below 1/2), weighted by that branch's
// probability: the expected guide with the other branch's albedo taken as 0. Deterministic, so
// that neighbours behind the same glass get the same guide; a guide that sampled the branch
// the way the image does averages a noisy mix of the reflected and refracted surfaces, and
// the filter's albedo stop then keeps every such pixel apart (docs/denoising.md measures it).
// Each sample draws the pixel jitter of pathtrace.wgsl's path of the same (seed, pixel, sample
// index), so the guides see the image's camera rays.
//
// What a path that meets no diffuse surface records: an emitter it sees, albedo 1 and its
// normal (OIDN: a light's albedo may be 1); a ray that leaves the scene, albedo and normal 0.
// Normals are world-space unit vectors facing the incoming ray (a smooth mesh's shading normal,
// pathtrace.wgsl's ns); their average over a pixel's samples is shorter than 1 where the pixel
// straddles an edge, as OIDN expects.

#import illum::sampler::{sampler_new, sample_2d}
#import illum::rtcore::spawn::spawn_point
#import illum::rtcore::codes::{MATERIAL_CHECKER, MATERIAL_DIELECTRIC, MATERIAL_MIRROR}
#import illum::rtcore::geometry::NO_HIT
#import illum::rtcore::camera::camera_ray
#import illum::pathtrace::scene::params
#import illum::rtcore::materials::material_at
#import illum::rtcore::traversal::{closest_hit, scattering_surface_at, object_at}
#import illum::pathtrace::surfaces::{UNBOUNDED, UNBOUNDED_DEPTH_CAP}
#import illum::pathtrace::bindings::{BINDING_GUIDE_ALBEDO, BINDING_GUIDE_NORMAL}
#ifdef SPECULAR
#import illum::pathtrace::surfaces::likelier_dielectric_branch
#endif
#ifdef CHECKER
#import illum::rtcore::optics::checker_albedo
#endif
#ifdef SMOOTH_SHADING
#import illum::rtcore::traversal::KIND_TRIANGLE
#import illum::rtcore::mesh_shading::{triangle_shading_normal, mirror_normal, dielectric_normal}
#endif

// Per pixel (row-major, the whole image): xyz = the mean albedo, w = the samples averaged.
@group(0) @binding(BINDING_GUIDE_ALBEDO) var<storage, read_write> guide_albedo: array<vec4<f32>>;
// Per pixel: xyz = the mean normal, w = 0.
@group(0) @binding(BINDING_GUIDE_NORMAL) var<storage, read_write> guide_normal: array<vec4<f32>>;

struct Guide {
    albedo: vec3<f32>,
    normal: vec3<f32>,
}

// The first non-specular surface along the camera ray from the eye along d.
fn first_diffuse(d_camera: vec3<f32>) -> Guide {
    var o = params.camera.eye;
    // The object whose surface o lies on: closest_hit's `own`.
    var own = NO_HIT;
    var d = d_camera;
    var weight = vec3<f32>(1.0);
    var depth = 0u;
    loop {
        let hit = closest_hit(o, d, own);
        own = hit.index;
        if (hit.index == NO_HIT) {
            return Guide(vec3<f32>(0.0), vec3<f32>(0.0));
        }
        let obj = object_at(hit.index);
        var s = scattering_surface_at(obj, o + hit.t * d);
        let front = dot(s.n, d) < 0.0;
        s.n = select(-s.n, s.n, front);
        if (obj.emitter != 0u) {
            return Guide(weight, s.n);
        }
        var ns = s.n;
#ifdef SMOOTH_SHADING
        if (obj.kind == KIND_TRIANGLE) {
            ns = triangle_shading_normal(obj, s.p, s.n);
        }
#endif
        let m = material_at(obj.material);
        // The path tracer takes no specular bounce beyond its last one: neither do the guides.
        let last = (params.bounces != UNBOUNDED && depth >= params.bounces) || depth >= UNBOUNDED_DEPTH_CAP;
#ifdef SPECULAR
        if (!last && m.kind == MATERIAL_MIRROR) {
#ifdef SMOOTH_SHADING
            let optic = mirror_normal(d, s.n, ns);
#else
            let optic = s.n;
#endif
            weight *= m.a.xyz;
            d = reflect(d, optic);
            o = spawn_point(s.p, s.n, s.err);
            depth += 1u;
            continue;
        }
        if (!last && m.kind == MATERIAL_DIELECTRIC) {
#ifdef SMOOTH_SHADING
            let optic = dielectric_normal(d, s.n, ns, select(m.a.w, 1.0 / m.a.w, front));
#else
            let optic = s.n;
#endif
            let branch = likelier_dielectric_branch(s, optic, d, m.a.w, front);
            weight *= branch.probability;
            o = branch.scattered.o;
            d = branch.scattered.d;
            depth += 1u;
            continue;
        }
        if (m.kind == MATERIAL_MIRROR || m.kind == MATERIAL_DIELECTRIC) {
            // Out of bounces on a specular surface: the path ends here, with nothing diffuse.
            return Guide(vec3<f32>(0.0), ns);
        }
#endif
        var albedo = m.a.xyz;
#ifdef CHECKER
        if (m.kind == MATERIAL_CHECKER) {
            albedo = checker_albedo(obj, m, s.p);
        }
#endif
        return Guide(weight * albedo, ns);
    }
    // Not reached (every iteration returns or continues); naga wants a function to end in one.
    return Guide(vec3<f32>(0.0), vec3<f32>(0.0));
}

// One invocation per pixel: samples sample_base .. sample_base + sample_count - 1 of it.
@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    let inv_size = vec2<f32>(1.0 / f32(params.width), 1.0 / f32(params.height));
    var albedo = vec3<f32>(0.0);
    var normal = vec3<f32>(0.0);
    for (var i = 0u; i < params.sample_count; i++) {
        var sampler = sampler_new(params.seed, pixel, params.sample_base + i);
        // pathtrace.wgsl's pixel_ray: the first two numbers jitter the point in the pixel.
        let jitter = sample_2d(&sampler);
        let d = camera_ray(params.camera, vec2<f32>(f32(gid.x) + jitter.x, f32(gid.y) + jitter.y), inv_size);
        let g = first_diffuse(d);
        albedo += g.albedo;
        normal += g.normal;
    }
    let n = f32(max(params.sample_count, 1u));
    guide_albedo[pixel] = vec4<f32>(albedo / n, f32(params.sample_count));
    guide_normal[pixel] = vec4<f32>(normal / n, 0.0);
}
