// Shadow pass: the casters' depth as seen from the directional light, into a depth-only target:
// the spheres (vs_main, fs_main) and the triangle meshes (vs_mesh, rasterized depth, no fragment
// stage).
//
// Each sphere is a square facing the light (parallel projection, so its half-side is the radius).
// The fragment keeps texels inside the sphere's disc and writes the depth of the sphere's
// surface facing the light: for a texel at distance rho from the centre's line, that surface lies
// sqrt(r^2 - rho^2) toward the light from the square's plane. The floor is not drawn: it casts no
// shadow on anything, and leaving it out is what lets it receive shadows without bias.

#import illum::raster::scene::{view, sphere_of, view_depth, quad_corner}
#import illum::raster::sphere::billboard_parallel

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) sphere: u32,
}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> VertexOut {
    // In the shadow view, view.eye.xyz is the light's travel direction.
    let world = billboard_parallel(sphere_of(instance), view.eye.xyz, quad_corner(vertex));
    var out: VertexOut;
    out.position = view.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    out.sphere = instance;
    return out;
}

// A mesh corner from the vertex buffer (src/mesh.rs; only its position is read).
@vertex
fn vs_mesh(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return view.view_proj * vec4<f32>(position, 1.0);
}

@fragment
fn fs_main(in: VertexOut) -> @builtin(frag_depth) f32 {
    let sphere = sphere_of(in.sphere);
    let offset = in.world - sphere.xyz;
    let rho_sq = dot(offset, offset);
    let r_sq = sphere.w * sphere.w;
    if rho_sq > r_sq {
        discard;
    }
    return view_depth(in.world - view.eye.xyz * sqrt(r_sq - rho_sq));
}
