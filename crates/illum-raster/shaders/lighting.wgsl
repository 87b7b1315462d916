#define_import_path illum::raster::lighting

// Shading of the three surfaces: the shadow-map lookup with percentage-closer filtering, the
// anti-aliased procedural checkerboard, the environment lookups in the cube maps, and the two
// looks of the spheres. Group 1 holds the textures (a cube map is bound as a 1 x 1 placeholder
// in the pass that renders it). `sw` says which effects this pipeline draws (see Switches).

#import illum::raster::scene::{scene, Switches}

@group(1) @binding(0) var shadow_map: texture_depth_2d;
// Linear filtering of a comparison sampler returns the bilinear blend of the four nearest
// depth tests: a 2x2 PCF per tap.
@group(1) @binding(1) var shadow_filtered: sampler_comparison;
// Nearest filtering: one hard depth test (PCF off).
@group(1) @binding(2) var shadow_point: sampler_comparison;
@group(1) @binding(3) var glass_env: texture_cube<f32>;
@group(1) @binding(4) var metal_env: texture_cube<f32>;
@group(1) @binding(5) var env_sampler: sampler;
// The glass's environment captured again at 1/8 of the side: a prefiltered level for lookups
// whose directions spread over many texels within one pixel (see glass_environment).
@group(1) @binding(6) var glass_env_coarse: texture_cube<f32>;

// PCF: four bilinear comparison taps at (+-1/2, +-1/2) texel. A bilinear tap weighs the depth
// tests of its 2 x 2 texels with a tent of half-width one texel, so the four together form a
// smooth kernel reaching 1.5 texels either side (PCF_REACH_TEXELS in shadow_fit.rs). The renderer
// sizes the texel so that this reach equals the scene's pcf_radius. Four taps, not more: a CPU
// rasterizer pays for every tap on every pixel (it cannot skip work per pixel), and the soft edge
// comes from the texel size, not from the tap count.
const PCF_TAPS = array<vec2<f32>, 4>(
    vec2<f32>(-0.5, -0.5), vec2<f32>(0.5, -0.5), vec2<f32>(-0.5, 0.5), vec2<f32>(0.5, 0.5),
);

// Fraction of the directional light reaching p (1 lit, 0 in shadow, between in the penumbra).
//
// The shadow map holds only the casters (the spheres), rendered with exact impostor depth, so
// the floor cannot shadow itself and needs no bias: its shadows start exactly under the casters
// (no gap). A sphere does test against its own depth; its lookup point moves `normal_offset`
// along the normal, which puts it strictly outside the sphere, so the lit side never shadows
// itself (no acne), even for PCF taps a kernel's reach away.
fn shadow_visibility(sw: Switches, p: vec3<f32>, n: vec3<f32>, normal_offset: f32) -> f32 {
    if !sw.shadows {
        return 1.0;
    }
    let clip = scene.shadow_view_proj * vec4<f32>(p + normal_offset * n, 1.0);
    // NDC y points up, texture rows down.
    let uv = vec2<f32>(0.5 + 0.5 * clip.x, 0.5 - 0.5 * clip.y);
    // The map covers the casters' footprint plus a margin; nothing outside it is shadowed.
    if any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) {
        return 1.0;
    }
    // Receivers beyond the far plane compare as far (a caster in front still shadows them).
    let depth = clamp(clip.z - scene.shadow_params.y, 0.0, 1.0);
    if !sw.pcf {
        return textureSampleCompareLevel(shadow_map, shadow_point, uv, depth);
    }
    let texel = 1.0 / vec2<f32>(textureDimensions(shadow_map));
    var sum = 0.0;
    for (var i = 0; i < 4; i++) {
        sum += textureSampleCompareLevel(shadow_map, shadow_filtered, uv + PCF_TAPS[i] * texel, depth);
    }
    return 0.25 * sum;
}

// The checker is filtered with a tent (a box convolved with itself): the tent-weighted average
// of a function p over [x - w, x + w] is (Q(x + w) - 2 Q(x) + Q(x - w)) / w^2, with Q'' = p. A
// tent's spectrum falls off as sinc^2, against a box's sinc, so far less of the checker's
// contrast leaks through at the horizon as moire (which refraction through the glass would
// magnify into stripes).
//
// For the tile parity p(x) = floor(x) mod 2 (0 on even tiles, 1 on odd ones):
// P(x) = integral of p = x / 2 + g(x) with g(x) = -x / 2 on [0, 1), x / 2 - 1 on [1, 2), and
// Q(x) = integral of P = x^2 / 4 - x / 4 + H(x) with H periodic (period 2, H(0) = H(1) = 0):
//     H(f) = (f - f^2) / 4             for f in [0, 1],
//     H(f) = f^2 / 4 - 3 f / 4 + 1 / 2  for f in [1, 2].
// The second difference of x^2 / 4 is w^2 / 2 and that of the linear term is 0, so the average
// is 1/2 + (H(x + w) - 2 H(x) + H(x - w)) / w^2. Only H is evaluated, on x reduced mod 2, so the
// values stay small and exact enough in f32 however far the tile coordinate runs.
fn parity_tent_part(x: vec2<f32>) -> vec2<f32> {
    let f = x - 2.0 * floor(0.5 * x);
    let low = 0.25 * f * (1.0 - f);
    let high = 0.25 * f * f - 0.75 * f + 0.5;
    return select(high, low, f < vec2<f32>(1.0));
}

// The fraction of odd-parity colour seen by a pixel whose footprint on the floor measures
// `width` tiles per axis, around tile coordinate t: the checker filtered by a tent of that
// half-width, exactly. The checker's parity is px XOR pz = px + pz - 2 px pz, and because the
// tent is separable the average of the product is the product of the averages. Toward the
// horizon the footprint grows and the average tends to 1/2, an even blend, instead of aliasing.
// Footprints below 1/1000 of a tile are widened to that: point sampling for any display, and it
// keeps the second difference above f32 rounding.
fn filtered_checker(t: vec2<f32>, width: vec2<f32>) -> f32 {
    let w = max(width, vec2<f32>(1e-3));
    let second_difference = parity_tent_part(t + w) - 2.0 * parity_tent_part(t) + parity_tent_part(t - w);
    let average = vec2<f32>(0.5) + second_difference / (w * w);
    return average.x + average.y - 2.0 * average.x * average.y;
}

// The floor at world point p: tile colour x (ambient + light x N.L x visibility). `n` is the
// normal of the side being seen: +Y from above; from below (an eye under the floor) -Y, which
// faces away from any light above, so the underside is ambient-only.
// `tile_coord` is p's position in tiles from the floor's minimum corner and `footprint` the
// pixel's extent in the same units (from screen-space derivatives, taken by the caller).
fn shade_floor(sw: Switches, p: vec3<f32>, n: vec3<f32>, tile_coord: vec2<f32>, footprint: vec2<f32>) -> vec3<f32> {
    let albedo = floor_albedo(tile_coord, footprint);
    // No `if n_dot_l > 0.0` around the lookup: a branch on uniforms alone makes lavapipe (Mesa
    // 22.3) specialise the shader on the uniforms' values at every draw (its uniform inlining,
    // docs/performance-raster.md), and a fragment shader
    // runs both sides of a branch anyway. Where n_dot_l is 0 the product is 0.
    let n_dot_l = max(dot(n, scene.to_light.xyz), 0.0);
    let direct = n_dot_l * shadow_visibility(sw, p, n, 0.0);
    return albedo * (scene.ambient.rgb + scene.light_radiance.rgb * direct);
}

// A mesh's Lambertian surface at p, as the Whitted ray tracer's local model shades it:
// albedo x (ambient + light x max(ns.L, 0) x visibility). `n` is the geometric normal of the
// side being seen, `ns` the shading normal on that side: a light behind the geometric surface
// lights nothing, whatever ns says (no light leaks through a mesh). The lookup point moves
// `normal_offset` along n, as a sphere's does, so that a lit face never shadows itself (the mesh
// is in the shadow map); a face turned away from the light needs no lookup.
fn shade_mesh(sw: Switches, p: vec3<f32>, n: vec3<f32>, ns: vec3<f32>, albedo: vec3<f32>) -> vec3<f32> {
    let l = scene.to_light.xyz;
    let n_dot_l = select(0.0, max(dot(ns, l), 0.0), dot(n, l) > 0.0);
    var visibility = 0.0;
    if n_dot_l > 0.0 {
        visibility = shadow_visibility(sw, p, n, scene.shadow_params.x);
    }
    return albedo * (scene.ambient.rgb + scene.light_radiance.rgb * n_dot_l * visibility);
}

// The checkerboard's colour at `tile_coord`, box-filtered over the pixel's `footprint`.
fn floor_albedo(tile_coord: vec2<f32>, footprint: vec2<f32>) -> vec3<f32> {
    let odd = filtered_checker(tile_coord, footprint);
    return mix(scene.floor_color_a.rgb, scene.floor_color_b.rgb, odd);
}

// Radiance arriving along `dir` at the glass sphere's centre, and, below, at the metal sphere's.
// Looking up from the centre rather than from the surface point is the cube-map approximation:
// exact for a distant environment, slightly off for the nearby floor.
//
// `dir_dx` and `dir_dy` are the direction's screen derivatives, its change to the next pixel
// across and down: their length is the pixel's footprint in the environment. Near the glass's rim
// refraction sweeps many texels across one pixel, and a single bilinear lookup would alias into
// moire; there the lookup blends toward the coarse copy, by the log2 of the footprint in fine
// texels (a two-level mip chain whose coarse level is rendered, not downsampled: the floor's own
// box filter prefilters it).
fn glass_environment(dir: vec3<f32>, dir_dx: vec3<f32>, dir_dy: vec3<f32>) -> vec3<f32> {
    let spread = max(length(dir_dx), length(dir_dy));
    let level = log2(max(spread / scene.env_params.x, 1.0));
    let coarse_weight = clamp(level / scene.env_params.y, 0.0, 1.0);
    let fine = textureSampleLevel(glass_env, env_sampler, dir, 0.0).rgb;
    let coarse = textureSampleLevel(glass_env_coarse, env_sampler, dir, 0.0).rgb;
    return mix(fine, coarse, coarse_weight);
}

fn metal_environment(dir: vec3<f32>) -> vec3<f32> {
    return textureSampleLevel(metal_env, env_sampler, dir, 0.0).rgb;
}

// Blinn-Phong highlight (N.H)^shininess, H the half vector of L and V, for a surface facing the
// light; zero on the side facing away.
fn highlight(n: vec3<f32>, v: vec3<f32>, shininess: f32) -> f32 {
    let l = scene.to_light.xyz;
    if dot(n, l) <= 0.0 {
        return 0.0;
    }
    return pow(max(dot(n, normalize(l + v)), 0.0), shininess);
}

// The metal sphere at p (unit normal n) seen from `eye`. Both looks: Phong, colour x (ambient +
// light x N.L x visibility) plus a specular highlight. The enhanced look with reflection on also
// mirrors the metal's cube map, tinted by the metal's colour (a metal's reflectance is coloured),
// taking the fraction `mirror` from the diffuse part.
fn shade_metal(sw: Switches, p: vec3<f32>, n: vec3<f32>, eye: vec3<f32>) -> vec3<f32> {
    let v = normalize(eye - p);
    let n_dot_l = dot(n, scene.to_light.xyz);
    var visibility = 0.0;
    if n_dot_l > 0.0 {
        visibility = shadow_visibility(sw, p, n, scene.shadow_params.x);
    }
    let diffuse = scene.metal_color.rgb * (scene.ambient.rgb + scene.light_radiance.rgb * max(n_dot_l, 0.0) * visibility);
    let specular = scene.metal_specular.rgb * scene.light_radiance.rgb
        * (highlight(n, v, scene.metal_specular.w) * visibility);
    if sw.enhanced && sw.reflection && sw.metal_env {
        let mirror = scene.metal_color.w;
        let reflected = metal_environment(reflect(-v, n));
        return (1.0 - mirror) * diffuse + mirror * scene.metal_color.rgb * reflected + specular;
    }
    return diffuse + specular;
}

// The refracted direction of unit `incident` at a surface with unit normal `n` (against the
// ray) and ratio eta = n_from / n_to; on total internal reflection, where refract() returns the
// zero vector (sin of the refracted angle would exceed 1, possible only for eta > 1), the mirror
// direction, as a real dielectric reflects everything there. A zero vector must never reach a
// cube-map lookup: its face and texel are undefined.
fn refract_or_reflect(incident: vec3<f32>, n: vec3<f32>, eta: f32) -> vec3<f32> {
    let out = refract(incident, n, eta);
    if dot(out, out) == 0.0 {
        return reflect(incident, n);
    }
    return out;
}

// Whether light along unit `incident` is totally reflected at normal n (against the ray) with
// ratio eta: 1 - eta^2 (1 - cos^2) < 0.
fn total_internal_reflection(incident: vec3<f32>, n: vec3<f32>, eta: f32) -> bool {
    let c = dot(n, incident);
    return 1.0 - eta * eta * (1.0 - c * c) < 0.0;
}

// Direction in which a ray entering the glass sphere at p1 (outward normal n1) along `incident`
// leaves it: refraction into the glass, the chord to the far side, refraction out. A ratio
// above 1 (a sphere less dense than its surroundings, allowed only through the API) reflects
// totally at the front face beyond the critical angle: then the ray never enters and the mirror
// direction is returned.
fn refract_through_sphere(p1: vec3<f32>, n1: vec3<f32>, incident: vec3<f32>, eta: f32) -> vec3<f32> {
    let sphere = scene.glass_sphere;
    if total_internal_reflection(incident, n1, eta) {
        return reflect(incident, n1);
    }
    let inside = refract(incident, n1, eta);
    // The refracted ray p1 + s inside meets the sphere again where |p1 + s inside - c|^2 = r^2.
    // With |p1 - c| = r this is s^2 + 2 s (p1 - c).inside = 0, so the chord is
    // s = -2 (p1 - c).inside (>= 0 since the ray points inward).
    let chord = max(-2.0 * dot(p1 - sphere.xyz, inside), 0.0);
    let n2 = normalize(p1 + chord * inside - sphere.xyz);
    // Leaving the glass the ratio inverts, and refract() wants the normal against the ray: -n2.
    let out = refract(inside, -n2, 1.0 / eta);
    if dot(out, out) == 0.0 {
        // Total internal reflection. On a perfect sphere the exit angle equals the entry angle,
        // so it cannot happen; rounding at grazing incidence could reach it.
        return reflect(inside, -n2);
    }
    return out;
}

// The glass sphere seen from `eye` at point p with unit normal n.
//
// Figure look (the assignment's figure 1): unlit; (1 - reflectivity) x colour + reflectivity x
// the environment along the view ray refracted once at the front face (refraction off: along
// the unbent view ray).
//
// Enhanced look: Schlick's Fresnel weight F = F0 + (1 - F0)(1 - cos)^5 between the mirror
// reflection and the refraction through both faces of the sphere, plus a white highlight.
// Without Fresnel F is F0 (normal incidence) everywhere; without reflection F is 0.
//
// The environment lookups take their footprint from the screen derivatives of their directions
// (within each 2 x 2 block of pixels), which the caller keeps in uniform control flow: no second
// and third refraction for the neighbours' points is traced (docs/performance-raster.md).
fn shade_glass(sw: Switches, p: vec3<f32>, n: vec3<f32>, eye: vec3<f32>) -> vec3<f32> {
    let eta = scene.glass_params.x;
    let incident = normalize(p - eye);
    var through = incident;
    if sw.refraction {
        if sw.enhanced {
            through = refract_through_sphere(p, n, incident, eta);
        } else {
            through = refract_or_reflect(incident, n, eta);
        }
    }
    let transmitted = glass_environment(through, dpdx(through), dpdy(through));
    if !sw.enhanced {
        let r = scene.glass_color.w;
        return (1.0 - r) * scene.glass_color.rgb + r * transmitted;
    }
    let v = -incident;
    var fresnel = 0.0;
    var reflected = vec3<f32>(0.0);
    if sw.reflection {
        let mirrored = reflect(incident, n);
        reflected = glass_environment(mirrored, dpdx(mirrored), dpdy(mirrored));
        let f0 = scene.glass_params.z;
        fresnel = f0;
        if sw.fresnel {
            // Schlick's approximation takes the cosine on the less dense side: for eta > 1 the
            // refracted angle's, and under total internal reflection everything is reflected.
            // (A select, not an `if`: see shade_floor on branches on uniforms alone.)
            let c_outside = clamp(dot(n, v), 0.0, 1.0);
            let k = 1.0 - eta * eta * (1.0 - c_outside * c_outside);
            let c = select(c_outside, sqrt(max(k, 0.0)), eta > 1.0);
            fresnel = f0 + (1.0 - f0) * pow(1.0 - c, 5.0);
        }
    }
    var spark = highlight(n, v, scene.glass_params.y);
    if spark > 0.0 {
        spark *= shadow_visibility(sw, p, n, scene.shadow_params.x);
    }
    return fresnel * reflected + (1.0 - fresnel) * scene.glass_color.rgb * transmitted + scene.light_radiance.rgb * spark;
}
