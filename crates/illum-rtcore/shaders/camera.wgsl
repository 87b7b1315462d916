#define_import_path illum::rtcore::camera

// The pinhole camera of both compute ray tracers (mirrored by illum-rtcore's camera.rs, filled
// from the scene camera's basis): the eye, unit right, up and forward vectors, tan of half the
// vertical field of view, and the image's aspect ratio (width / height).
struct Camera {
    eye: vec3<f32>,
    tan_half_fov: f32,
    right: vec3<f32>,
    aspect: f32,
    up: vec3<f32>,
    up_padding: f32,
    forward: vec3<f32>,
    forward_padding: f32,
}

// The unit direction from the eye through the image point `film`, in pixels from the image's
// top-left corner (row 0 is the top); inv_size = 1 / the image's size in pixels.
fn camera_ray(c: Camera, film: vec2<f32>, inv_size: vec2<f32>) -> vec3<f32> {
    let sx = (2.0 * film.x * inv_size.x - 1.0) * c.aspect * c.tan_half_fov;
    let sy = (1.0 - 2.0 * film.y * inv_size.y) * c.tan_half_fov;
    return normalize(c.forward + sx * c.right + sy * c.up);
}

// The inverse of camera_ray: for the unit direction w from a point toward the eye, the image
// point it is seen at (xy, in pixels as camera_ray's `film`) and the cosine between the view
// direction and the camera's axis (z). xy is meaningful only where z > 0 (in front of the eye).
fn camera_film_point(c: Camera, w: vec3<f32>, size: vec2<f32>) -> vec3<f32> {
    let cos_theta = -dot(w, c.forward);
    // Where the eye's ray toward the point crosses the image plane at distance 1.
    let sx = -dot(w, c.right) / cos_theta;
    let sy = -dot(w, c.up) / cos_theta;
    let px = (sx / (c.aspect * c.tan_half_fov) + 1.0) * 0.5 * size.x;
    let py = (1.0 - sy / c.tan_half_fov) * 0.5 * size.y;
    return vec3<f32>(px, py, cos_theta);
}
