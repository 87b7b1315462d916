#define_import_path illum::raster::sphere

// Analytic sphere impostors. A sphere is drawn as one camera-facing square (two triangles) that
// encloses its silhouette; the fragment shader intersects the pixel's ray with the exact sphere,
// discards misses and writes the hit's depth. The silhouette is therefore a true circle at any
// resolution, and MSAA edges come from an analytic per-sample coverage mask.

// Two unit vectors that complete unit `w` to an orthonormal frame. The helper axis is +Y unless
// w is nearly vertical, where +X is used, so the cross product never degenerates.
fn perpendicular_frame(w: vec3<f32>) -> mat2x3<f32> {
    var helper = vec3<f32>(0.0, 1.0, 0.0);
    if abs(w.y) > 0.9 {
        helper = vec3<f32>(1.0, 0.0, 0.0);
    }
    let u = normalize(cross(w, helper));
    return mat2x3<f32>(u, cross(u, w));
}

// A corner of the square, through the centre c and facing the eye, that encloses the silhouette
// of the sphere (c, r) seen from `eye` in perspective. The rays grazing the sphere form a cone of
// half-angle a with sin(a) = r / d (d = |c - eye|); at distance d along the axis that cone has
// radius d tan(a) = r d / sqrt(d^2 - r^2), the square's half-side. The eye is outside every
// sphere (scene validation guarantees it), so d > r.
fn billboard_perspective(sphere: vec4<f32>, eye: vec3<f32>, corner: vec2<f32>) -> vec3<f32> {
    let axis = sphere.xyz - eye;
    let d = length(axis);
    let r = sphere.w;
    let half_side = r * d / sqrt(max(d * d - r * r, 1e-12));
    let frame = perpendicular_frame(axis / d);
    return sphere.xyz + half_side * (corner.x * frame[0] + corner.y * frame[1]);
}

// The same for a parallel (orthographic) projection along unit `direction`: the silhouette is
// the great circle of radius r, so the square's half-side is r.
fn billboard_parallel(sphere: vec4<f32>, direction: vec3<f32>, corner: vec2<f32>) -> vec3<f32> {
    let frame = perpendicular_frame(direction);
    return sphere.xyz + sphere.w * (corner.x * frame[0] + corner.y * frame[1]);
}

// True when the ray origin + t dir (dir unit) meets the sphere. |o + t d - c|^2 = r^2 has a real
// root when the squared distance from c to the ray's line, |oc|^2 - (oc.d)^2, is at most r^2;
// the eye is outside the sphere and the impostor faces it, so the root lies in front.
fn ray_meets_sphere(origin: vec3<f32>, dir: vec3<f32>, sphere: vec4<f32>) -> bool {
    let oc = origin - sphere.xyz;
    let b = dot(oc, dir);
    return dot(oc, oc) - b * b <= sphere.w * sphere.w;
}

// The visible surface point for the ray origin + t dir (dir unit): the nearer intersection, or,
// for a ray that just misses (a pixel whose centre lies outside the silhouette but some of whose
// MSAA samples lie inside), the silhouette point nearest to the ray. That point is used only to
// shade an edge pixel, whose coverage comes from the sample mask.
fn visible_point(origin: vec3<f32>, dir: vec3<f32>, sphere: vec4<f32>) -> vec3<f32> {
    let oc = origin - sphere.xyz;
    let b = dot(oc, dir);
    let closest_sq = dot(oc, oc) - b * b;
    let r2 = sphere.w * sphere.w;
    if closest_sq <= r2 {
        // t = -b - sqrt(b^2 - (|oc|^2 - r^2)) = -b - sqrt(r^2 - closest_sq).
        return origin + (-b - sqrt(r2 - closest_sq)) * dir;
    }
    let nearest_on_ray = origin - b * dir;
    return sphere.xyz + sphere.w * normalize(nearest_on_ray - sphere.xyz);
}

// Offset of MSAA sample i from the pixel centre, in pixels (y down). These are Vulkan's standard
// sample locations; with one sample per pixel the sample is the centre.
fn sample_offset(count: u32, i: u32) -> vec2<f32> {
    if count == 4u {
        var standard = array<vec2<f32>, 4>(
            vec2<f32>(-0.125, -0.375), vec2<f32>(0.375, -0.125),
            vec2<f32>(-0.375, 0.125), vec2<f32>(0.125, 0.375),
        );
        return standard[min(i, 3u)];
    }
    return vec2<f32>(0.0, 0.0);
}

// Bit i set when the ray through MSAA sample i meets the sphere. `point` is the impostor's
// surface point at the pixel centre and dx, dy its screen derivatives: the impostor is a plane,
// so moving by a fraction of a pixel moves the point by that fraction of the derivatives.
fn coverage_mask(eye: vec3<f32>, point: vec3<f32>, dx: vec3<f32>, dy: vec3<f32>, sphere: vec4<f32>, count: u32) -> u32 {
    var mask = 0u;
    for (var i = 0u; i < count; i++) {
        let offset = sample_offset(count, i);
        let p = point + offset.x * dx + offset.y * dy;
        if ray_meets_sphere(eye, normalize(p - eye), sphere) {
            mask |= 1u << i;
        }
    }
    return mask;
}
