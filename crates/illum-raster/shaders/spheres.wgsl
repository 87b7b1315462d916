// A sphere as an analytic impostor (sphere.wgsl), shaded by lighting.wgsl. Used by the main pass
// and by the cube-map captures; each pipeline draws one sphere, so a capture leaves out the
// sphere it is taken from by drawing only the other.

#import illum::raster::scene::{view, sphere_of, view_depth, quad_corner, Switches, SPHERE_GLASS, WorldVertex, world_vertex, EDGE_REACH_PIXELS}
#import illum::raster::sphere::{billboard_perspective, ray_meets_sphere, silhouette_coverage, visible_point}
#import illum::raster::lighting::{shade_glass, shade_metal}

// Set per pipeline (see Switches in scene.wgsl).
override SPHERE: u32 = 0u;
// Anti-aliased silhouette (the main view with anti-aliasing on): the impostor grows to reach
// every pixel the silhouette crosses, and its alpha is the fraction of the pixel covered, blended
// over what is behind (the renderer draws the spheres last, back to front). Otherwise a pixel is
// the sphere's when the ray through its centre meets it, and is opaque.
override EDGE_AA: bool = false;
override ENHANCED: bool = false;
override SHADOWS: bool = true;
override PCF: bool = true;
override REFRACTION: bool = true;
override REFLECTION: bool = true;
override FRESNEL: bool = true;
override METAL_ENV: bool = false;

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32) -> WorldVertex {
    var grow = 0.0;
    if EDGE_AA {
        grow = EDGE_REACH_PIXELS * view.eye.w;
    }
    let world = billboard_perspective(sphere_of(SPHERE), view.eye.xyz, quad_corner(vertex), grow);
    return world_vertex(world);
}

struct FragmentOut {
    @location(0) color: vec4<f32>,
    // The sphere's true depth, so it intersects the floor and the other sphere correctly.
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_main(in: WorldVertex) -> FragmentOut {
    let dx = dpdx(in.world);
    let dy = dpdy(in.world);
    let sphere = sphere_of(SPHERE);
    let eye = view.eye.xyz;
    var coverage = 1.0;
    if EDGE_AA {
        coverage = silhouette_coverage(eye, in.world, dx, dy, sphere);
        if coverage <= 0.0 {
            discard;
        }
    } else if !ray_meets_sphere(eye, normalize(in.world - eye), sphere) {
        discard;
    }
    let p = visible_point(eye, normalize(in.world - eye), sphere);
    let n = normalize(p - sphere.xyz);
    let sw = Switches(ENHANCED, SHADOWS, PCF, REFRACTION, REFLECTION, FRESNEL, METAL_ENV);
    var color: vec3<f32>;
    if SPHERE == SPHERE_GLASS {
        color = shade_glass(sw, p, n, eye);
    } else {
        color = shade_metal(sw, p, n, eye);
    }
    var out: FragmentOut;
    out.color = vec4<f32>(color, coverage);
    out.depth = view_depth(p);
    return out;
}
