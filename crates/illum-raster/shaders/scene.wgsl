#define_import_path illum::raster::scene

// The uniforms every raster pass reads, mirrored by crates/illum-raster/src/uniforms.rs.
// Group 0 holds them: the frame's scene constants and, at a dynamic offset, the current view.

// What a pipeline draws, fixed when the pipeline is created: the entry files declare override
// constants and pass them down in this struct. The renderer makes one pipeline per combination
// it uses, so the branches not taken are compiled out. On a CPU rasterizer such as lavapipe that
// matters: it runs both sides of a branch under a lane mask, so a uniform flag would cost every
// path on every pixel.
struct Switches {
    // The enhanced look (else the figure look).
    enhanced: bool,
    shadows: bool,
    pcf: bool,
    refraction: bool,
    reflection: bool,
    fresnel: bool,
    // The metal sphere's cube map may be read: only in the main pass, and only when it was
    // captured (enhanced look with reflection). The glass's cube map is readable wherever the
    // glass is drawn, since no pass that renders it draws the glass.
    metal_env: bool,
}

// Instance index of each sphere in draw calls.
const SPHERE_GLASS: u32 = 0u;
const SPHERE_METAL: u32 = 1u;

struct Scene {
    // xyz: unit vector from a surface toward the light (the L of N.L).
    to_light: vec4<f32>,
    // rgb: light colour x intensity.
    light_radiance: vec4<f32>,
    // rgb: ambient colour x intensity.
    ambient: vec4<f32>,
    // rgb: the clear colour.
    background: vec4<f32>,
    // (x_min, z_min, x_max, z_max) of the floor rectangle.
    floor_rect: vec4<f32>,
    // x: floor height, y: tile side.
    floor_params: vec4<f32>,
    // The part of the floor the shadow map covers (outside it nothing is shadowed), as a
    // parallelogram in (x, z): corner (x, y), edge u (z, w); edge v in receiver_v.xy.
    receiver: vec4<f32>,
    receiver_v: vec4<f32>,
    // Tile colours: a on tiles whose indices from the minimum corner sum to an even number.
    floor_color_a: vec4<f32>,
    floor_color_b: vec4<f32>,
    // Centre xyz and radius w.
    glass_sphere: vec4<f32>,
    // rgb: glass colour; w: figure-look reflectivity (weight of the environment).
    glass_color: vec4<f32>,
    // x: refraction ratio n_outside / n_inside, y: highlight exponent, z: Schlick's F0.
    glass_params: vec4<f32>,
    metal_sphere: vec4<f32>,
    // rgb: metal colour; w: enhanced-look mirror fraction.
    metal_color: vec4<f32>,
    // rgb: specular colour; w: Phong exponent.
    metal_specular: vec4<f32>,
    // World -> shadow-map clip space (orthographic: w = 1, z in [0, 1] over the casters'
    // and receivers' depth range).
    shadow_view_proj: mat4x4<f32>,
    // x: distance a sphere's lookup point moves along its normal (the normal-offset bias),
    // y: depth bias in shadow-map depth units, z: the side of one shadow-map texel in scene
    // units.
    shadow_params: vec4<f32>,
    // x: the angle (radians) one texel of the glass's cube map spans at a face's centre,
    // y: log2 of the side ratio between that cube map and its coarse copy.
    env_params: vec4<f32>,
    // Column i, xyz: the normal of the plane through the main view's eye and the floor
    // rectangle's edge i, pointing inward (uniforms.rs floor_edges), for the floor's anti-aliased
    // outline.
    floor_edges: mat4x4<f32>,
}

struct View {
    // World -> clip space of this view.
    view_proj: mat4x4<f32>,
    // Perspective views: xyz = the eye. The shadow view: xyz = the light's travel direction.
    // w: the main view: the angle one pixel spans at the image centre (2 tan(vfov / 2) / height),
    // by which the drawn shapes grow to reach every pixel an edge partly covers; other views: 0.
    eye: vec4<f32>,
}

@group(0) @binding(0) var<uniform> scene: Scene;
@group(0) @binding(1) var<uniform> view: View;

// What the floor's and the spheres' vertex shaders pass on: a world point (on the floor, or on
// a sphere's billboard) and its clip position in the view.
struct WorldVertex {
    @builtin(position) position: vec4<f32>,
    @location(0) world: vec3<f32>,
}

fn world_vertex(world: vec3<f32>) -> WorldVertex {
    var out: WorldVertex;
    out.position = view.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    return out;
}

// Centre (xyz) and radius (w) of sphere `index` (SPHERE_GLASS or SPHERE_METAL).
fn sphere_of(index: u32) -> vec4<f32> {
    if index == SPHERE_GLASS {
        return scene.glass_sphere;
    }
    return scene.metal_sphere;
}

// Depth in [0, 1] of world point p in this view (the value a rasterized surface there writes).
fn view_depth(p: vec3<f32>) -> f32 {
    let clip = view.view_proj * vec4<f32>(p, 1.0);
    return clip.z / clip.w;
}

// Corner `i` (0..6) of the two triangles of the square [-1, 1]^2, for drawing quads without a
// vertex buffer.
fn quad_corner(i: u32) -> vec2<f32> {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    );
    return corners[min(i, 5u)];
}

// The fraction of a pixel's square on the positive side of a straight edge, exactly. Across the
// pixel the edge's function is f + a u + b v (u, v in [-1/2, 1/2]: the offset from the pixel
// centre in pixels; f the value at the centre, a and b its screen derivatives, in any one unit).
// u and v are uniform and independent, so a u + b v has a trapezoidal density (two boxes of widths
// |a| and |b| convolved): flat at 1 / max over the middle |a| - |b| wide, falling linearly over
// min on either side. Its distribution function is linear on the flat part and quadratic on the
// ramps. This is the exact box-filtered coverage of a half-plane, not the common clamp(0.5 + f /
// |grad|), which is exact only for edges along a pixel axis (off by up to 1/8 at 45 degrees).
fn edge_coverage(f: f32, a: f32, b: f32) -> f32 {
    let wide = max(abs(a), abs(b));
    let narrow = min(abs(a), abs(b));
    if wide <= 0.0 {
        return select(0.0, 1.0, f > 0.0);
    }
    let half_width = 0.5 * (wide + narrow);
    let flat = 0.5 * (wide - narrow);
    let y = min(abs(f), half_width);
    var covered: f32;
    if y <= flat {
        covered = 0.5 + y / wide;
    } else {
        // On a ramp, so narrow > 0: y - flat <= narrow.
        let g = half_width - y;
        covered = 1.0 - g * g / (2.0 * wide * narrow);
    }
    return select(1.0 - covered, covered, f >= 0.0);
}

// How far, in pixels, the main view's shapes grow past their exact outline so that every pixel an
// edge crosses gets a fragment (it needs half a pixel's diagonal, 0.71; the rest is slack for the
// estimate of a pixel's size).
const EDGE_REACH_PIXELS: f32 = 1.5;
