// The scene's Lambertian triangle meshes (src/mesh.rs builds their vertex buffer), shaded by
// lighting.wgsl's shade_mesh. Used by the main pass and by the cube-map captures. Opaque and
// depth-tested: the main pass draws them after the floor and before the spheres, whose
// anti-aliased silhouettes blend over them. Their own edges are not anti-aliased (one sample per
// pixel, and no analytic outline to measure coverage against).

#import illum::raster::scene::{view, Switches}
#import illum::raster::lighting::shade_mesh

// Set per pipeline (see Switches in scene.wgsl).
override SHADOWS: bool = true;
override PCF: bool = true;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) face_normal: vec3<f32>,
    @location(3) albedo: vec3<f32>,
}

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    // The same at the three corners of a triangle.
    @location(2) @interpolate(flat) face_normal: vec3<f32>,
    @location(3) @interpolate(flat) albedo: vec3<f32>,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.position = view.view_proj * vec4<f32>(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.face_normal = v.face_normal;
    out.albedo = v.albedo;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    // Both sides are drawn: the geometric normal of the side the eye sees, and the interpolated
    // shading normal flipped onto that side (illum-rtcore's mesh_shading.wgsl has the rules).
    let n = select(-in.face_normal, in.face_normal, dot(in.face_normal, view.eye.xyz - in.world) >= 0.0);
    var ns = normalize(in.normal);
    ns = select(ns, -ns, dot(ns, n) < 0.0);
    let sw = Switches(false, SHADOWS, PCF, false, false, false, false);
    return vec4<f32>(shade_mesh(sw, in.world, n, ns, in.albedo), 1.0);
}
