#define_import_path illum::rtcore::traversal

// Generic traversal: loops over the path tracer's object buffer, so one pipeline serves every
// scene. (The specialised pipelines, the path tracer's by default and the Whitted ray
// tracer's always, replace this module with code generated from the scene: illum-rtcore's
// traversal.rs.)

#import illum::rtcore::codes::{KIND_AABB, KIND_BOX, KIND_QUAD}
#import illum::rtcore::geometry::{Hit, Object, FAR, NO_HIT, EMITTER_TIE, safe_inverse, hit_slabs, hit_box, hit_quad, hit_sphere, Surface, surface_aabb, surface_box, surface_quad, surface_sphere}
#import illum::pathtrace::scene::{params, objects}

// Closest hit over all objects. `d` must be unit length. Only the fields a shape's test needs are
// loaded: on a CPU driver each storage-buffer read is a per-lane memory access. `own`: the object
// whose surface the ray leaves (NO_HIT for none); its root at o is never taken (hit_sphere).
fn closest_hit(o: vec3<f32>, d: vec3<f32>, own: u32) -> Hit {
    var best = Hit(FAR, NO_HIT);
    let inv_d = safe_inverse(d);
    for (var i = 0u; i < params.num_objects; i++) {
        let t = hit_object_at(o, d, inv_d, i, own);
        // Emitters are stored last; they win ties with the surface they are set into.
        // (Capped at FAR: a missed emitter reports FAR, which must not count as a hit.)
        let limit = select(best.t, min(best.t * (1.0 + EMITTER_TIE), FAR), i >= params.first_emitter);
        if (t < limit) {
            best = Hit(t, i);
        }
    }
    return best;
}

// The object at `index`.
fn object_at(index: u32) -> Object {
    return objects[index];
}

fn hit_object_at(o: vec3<f32>, d: vec3<f32>, inv_d: vec3<f32>, i: u32, own: u32) -> f32 {
    switch objects[i].kind {
        case KIND_AABB: { return hit_slabs(o, inv_d, objects[i].a.xyz, objects[i].b.xyz); }
        case KIND_BOX: {
            let obj = objects[i];
            return hit_box(o, d, obj.a.xyz, obj.b.xyz, obj.a.w, obj.b.w, obj.c.xyz);
        }
        case KIND_QUAD: {
            let obj = objects[i];
            return hit_quad(o, d, obj.a.xyz, obj.b.xyz, obj.c.xyz, obj.d.xyz);
        }
        default: { return hit_sphere(o, d, objects[i].a.xyz, objects[i].a.w, i == own); }
    }
}

// True when a non-emitting object lies on the ray strictly between 0 and t_max.
fn occluded(o: vec3<f32>, d: vec3<f32>, t_max: f32, own: u32) -> bool {
    let inv_d = safe_inverse(d);
    for (var i = 0u; i < params.first_emitter; i++) {
        if (hit_object_at(o, d, inv_d, i, own) < t_max) {
            return true;
        }
    }
    return false;
}

// The surface at the computed hit point p on the object (see geometry.wgsl's surface functions).
fn surface_at(obj: Object, p: vec3<f32>) -> Surface {
    switch obj.kind {
        case KIND_AABB: { return surface_aabb(obj, p); }
        case KIND_BOX: { return surface_box(obj, p); }
        case KIND_QUAD: { return surface_quad(obj, p); }
        default: { return surface_sphere(obj, p); }
    }
}

// The surface of a non-emitter; the generic pipeline reconstructs every kind.
fn scattering_surface_at(obj: Object, p: vec3<f32>) -> Surface {
    return surface_at(obj, p);
}
