#define_import_path illum::raster::sphere

#import illum::raster::scene::edge_coverage

// Analytic sphere impostors. A sphere is drawn as one camera-facing square (two triangles) that
// encloses its silhouette; the fragment shader intersects the pixel's ray with the exact sphere,
// discards misses and writes the hit's depth. The silhouette is therefore a true circle at any
// resolution; in the main view its edge is anti-aliased by the exact fraction of each pixel it
// covers (silhouette_coverage), used as alpha over what was drawn behind.

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
// sphere (scene validation guarantees it), so d > r. The square grows by `grow_angle` x d on each
// side: seen from the eye, a length L on the square (which faces the eye) spans about L / d, so
// this is about grow_angle in angle (0 for the exact square).
fn billboard_perspective(sphere: vec4<f32>, eye: vec3<f32>, corner: vec2<f32>, grow_angle: f32) -> vec3<f32> {
    let axis = sphere.xyz - eye;
    let d = length(axis);
    let half_side = silhouette_radius(sphere, d) + grow_angle * d;
    let frame = perpendicular_frame(axis / d);
    return sphere.xyz + half_side * (corner.x * frame[0] + corner.y * frame[1]);
}

// The radius r d / sqrt(d^2 - r^2) of the silhouette's circle in the plane through the centre
// facing the eye, d away (see billboard_perspective).
fn silhouette_radius(sphere: vec4<f32>, d: f32) -> f32 {
    let r = sphere.w;
    return r * d / sqrt(max(d * d - r * r, 1e-12));
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
// for a ray that just misses (a pixel whose centre lies outside the silhouette but which the
// silhouette partly covers), the silhouette point nearest to the ray. That point is used only to
// shade an edge pixel, whose coverage is its alpha.
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

// The fraction of the pixel that the sphere covers. `point` is the pixel centre's point on the
// impostor's plane (through the centre, facing the eye) and dx, dy its screen derivatives. In that
// plane the cone of rays grazing the sphere cuts a circle of radius R (silhouette_radius), so the
// signed distance R - |point - c| is the pixel's depth inside the silhouette, in scene units;
// its screen derivatives along the radial direction make it a straight edge across the pixel,
// whose exact coverage edge_coverage gives. Dropping the circle's curvature within one pixel
// errs by about 1 / (8 R) of a pixel (R in pixels), under 0.2% for the shipped scene's spheres.
// A disc smaller than a pixel covers at most its area.
fn silhouette_coverage(eye: vec3<f32>, point: vec3<f32>, dx: vec3<f32>, dy: vec3<f32>, sphere: vec4<f32>) -> f32 {
    let radius = silhouette_radius(sphere, distance(sphere.xyz, eye));
    let offset = point - sphere.xyz;
    let rho = length(offset);
    let radial = offset / max(rho, 1e-30);
    let covered = edge_coverage(radius - rho, dot(radial, dx), dot(radial, dy));
    let pixel_area = length(cross(dx, dy));
    return min(covered, 3.14159265 * radius * radius / max(pixel_area, 1e-30));
}
