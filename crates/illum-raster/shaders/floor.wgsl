// The checkerboard floor, shaded procedurally (lighting.wgsl's shade_floor). Used by the main
// pass and by the cube-map captures.
//
// With shadows it is drawn in two parts. First the receiver: the parallelogram of floor under
// the shadow map (outside it nothing can be in shadow), with the shadow lookup, its fragments
// outside the floor's rectangle discarded. Then the whole rectangle without any lookup, in a
// pipeline with a small depth bias, so that it fails the depth test wherever the receiver
// already drew and fills in only the rest. A CPU rasterizer pays for a shader's every texture
// tap on every pixel it shades, so the taps are spent only where a shadow can be. In the main
// pass, when the light comes from above and the spheres stand above the floor, the receiver is
// narrowed further to each shadow's penumbra ring (PART 1), the only place where the lookup can
// return anything but 0 or 1; the umbra inside a ring (PART 2) is drawn dark without a lookup,
// with a bias between the ring's and the rest's, and the rest as above. The taps' cost is in
// proportion to the floor that runs them (docs/performance-raster.md).
//
// In the main view with anti-aliasing on (EDGE_AA), the rectangle's outline is anti-aliased like
// the spheres' silhouettes: the rectangle reaches past it by EDGE_REACH_PIXELS, and each pixel is
// the floor's colour mixed with the background by the fraction of the pixel inside the rectangle.
// The renderer draws the floor first, over nothing but the background, so the shader mixes with
// the background colour itself and needs no blending. (Either part may draw an outline pixel;
// the other then fails the depth test there, as everywhere.) Only a band along the outline can be
// partly covered, so the rest of the floor is drawn in two pieces: its interior (PART 3, the
// rectangle shrunk by EDGE_REACH_PIXELS) without the coverage, and the band between the shrunk
// and the grown outline with it: the coverage of four edges on every floor pixel would cost the
// whole floor (docs/performance-raster.md). Without the coverage's `discard` the
// interior's depth test may also run before its shading, which then skips the floor where the
// shadows' rings and discs have drawn.

#import illum::raster::scene::{scene, view, quad_corner, Switches, WorldVertex, world_vertex, edge_coverage, EDGE_REACH_PIXELS}
#import illum::raster::lighting::{shade_floor, floor_albedo}

// Set per pipeline (see Switches in scene.wgsl). RECEIVER: draw the receiver parallelogram with
// shadows; otherwise the whole floor without.
override RECEIVER: bool = true;
override PCF: bool = true;
override EDGE_AA: bool = false;
// Which part of the floor (variants.rs, Surface): 0 the receiver parallelogram (RECEIVER) or
// the whole floor; 1 each sphere's penumbra ring, with the shadow lookup (RECEIVER); 2 each
// sphere's umbra disc inside its ring, dark, without the lookup. Rings and discs are drawn
// instead of the receiver in the main pass when the light comes from above and the spheres
// stand above the floor (shadow_fit.rs, rings); instance 0 is the glass's, 1 the metal's.
// 3: the interior of the floor, inside the band that EDGE_AA draws along the outline (drawn
// with EDGE_AA off). With EDGE_AA on, PART 0 without RECEIVER draws that band alone.
override PART: u32 = 0u;

// Sides of the polygons that stand for the circles of a ring: the outer one circumscribes the
// outer circle, the inner one is inscribed in the inner circle, so the ring holds every point
// within the reach of the outline and the disc only points farther inside. frame.rs draws
// RING_SIDES of its own, which a test keeps equal to this.
const RING_SIDES: u32 = 32u;
// How far from a sphere's outline in the shadow map a lookup can still see it, in texels: the
// four bilinear taps at +-1/2 texel read texels whose centres lie within 1.5 texels along each
// axis, 1.5 sqrt(2) = 2.12 at the corners; 2.5 leaves room for rounding. Inside the outline by
// more than this every texel read holds the sphere (the lookup returns exactly 0); outside by
// more, none does (exactly 1).
const RING_REACH_TEXELS: f32 = 2.5;

// Vertex `vertex` of sphere `instance`'s ring (PART 1: RING_SIDES quads, 6 vertices each) or
// disc (PART 2: RING_SIDES triangles around the centre), on the floor. Built in the shadow map's
// coordinates, where the sphere is a circle about its centre's image, and taken to the floor
// through the map's footprint there (scene.receiver: the map's corner (-1, -1) and its two
// edges' images, an affine map).
fn ring_vertex(vertex: u32, instance: u32) -> vec2<f32> {
    let sphere = select(scene.metal_sphere, scene.glass_sphere, instance == 0u);
    let m = scene.shadow_view_proj;
    let centre = (m * vec4<f32>(sphere.xyz, 1.0)).xy;
    // Map units per scene unit across the light (the projection is orthographic and square).
    let scale = length(vec3<f32>(m[0].x, m[1].x, m[2].x));
    let reach = RING_REACH_TEXELS * scene.shadow_params.z * scale;
    let radius = sphere.w * scale;
    let inner = max(radius - reach, 0.0);
    let outer = (radius + reach) / cos(3.14159265 / f32(RING_SIDES));
    var side: u32;
    var r: f32;
    if PART == 1u {
        // Quad `side`: inner and outer corners at angles side and side + 1.
        side = vertex / 6u;
        let corner = vertex % 6u;
        let next = corner == 2u || corner == 4u || corner == 5u;
        side += select(0u, 1u, next);
        // The ring's inner edge a little inside the disc's (which is at `inner`), so that the
        // two overlap rather than leave a crack through rounding; in the overlap the ring is
        // drawn and its lookup returns the umbra's 0.
        r = select(0.999 * inner, outer, corner == 1u || corner == 2u || corner == 4u);
    } else {
        side = vertex / 3u + select(0u, 1u, vertex % 3u == 2u);
        r = select(inner, 0.0, vertex % 3u == 0u);
    }
    let angle = 6.2831853 * f32(side % RING_SIDES) / f32(RING_SIDES);
    let map = centre + r * vec2<f32>(cos(angle), sin(angle));
    let to_unit = 0.5 * (map + vec2<f32>(1.0));
    return scene.receiver.xy + to_unit.x * scene.receiver.zw + to_unit.y * scene.receiver_v.xy;
}

// Corner `corner` ((0 or 1, 0 or 1): min or max along x and z) of the floor rectangle, moved
// diagonally outward (`outward` true) or inward by EDGE_REACH_PIXELS of the corner's own pixel
// footprint along the floor: a pixel at distance D spans about D x view.eye.w across the view,
// stretched by 1 / sin(elevation) along a floor seen at a grazing angle (capped near the
// horizon). The footprint grows faster than linearly with distance, so the straight line between
// two moved corners is at least as far from the outline as needed between them, outward and
// inward. Inward, a corner stops at the rectangle's centre lines, so the interior never turns
// inside out (a floor seen edge-on is then all band).
fn floor_corner(corner: vec2<f32>, outward: bool) -> vec3<f32> {
    let xz = mix(scene.floor_rect.xy, scene.floor_rect.zw, corner);
    let world = vec3<f32>(xz.x, scene.floor_params.x, xz.y);
    let to_eye = view.eye.xyz - world;
    let distance = length(to_eye);
    let sin_elevation = max(abs(to_eye.y) / max(distance, 1e-30), 0.02);
    let reach = EDGE_REACH_PIXELS * distance * view.eye.w / sin_elevation;
    let half_side = 0.5 * (scene.floor_rect.zw - scene.floor_rect.xy);
    let move_by = select(-min(reach, min(half_side.x, half_side.y)), reach, outward);
    let away = select(vec2<f32>(-1.0), vec2<f32>(1.0), corner > vec2<f32>(0.5));
    return world + move_by * vec3<f32>(away.x, 0.0, away.y);
}

// Vertex `vertex` (0..24) of the band along the floor's outline: for each side of the rectangle,
// the quad between that side's grown and shrunk copies. The sides share their moved corners with
// each other and with the interior (PART 3), so together they tile the grown rectangle.
fn outline_vertex(vertex: u32) -> vec3<f32> {
    let side = vertex / 6u;
    let q = quad_corner(vertex % 6u);
    let corners = array<vec2<f32>, 4>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0), vec2<f32>(0.0, 1.0),
    );
    let index = (side + select(0u, 1u, q.x > 0.0)) % 4u;
    return floor_corner(corners[index], q.y < 0.0);
}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> WorldVertex {
    let corner = 0.5 * quad_corner(vertex) + vec2<f32>(0.5);
    if PART == 3u {
        return world_vertex(floor_corner(corner, false));
    }
    if EDGE_AA && !RECEIVER && PART == 0u {
        return world_vertex(outline_vertex(vertex));
    }
    var xz: vec2<f32>;
    if PART != 0u {
        xz = ring_vertex(vertex, instance);
    } else if RECEIVER {
        xz = scene.receiver.xy + corner.x * scene.receiver.zw + corner.y * scene.receiver_v.xy;
    } else {
        xz = mix(scene.floor_rect.xy, scene.floor_rect.zw, corner);
    }
    return world_vertex(vec3<f32>(xz.x, scene.floor_params.x, xz.y));
}

@fragment
fn fs_main(in: WorldVertex) -> @location(0) vec4<f32> {
    let tile_coord = (in.world.xz - scene.floor_rect.xy) / scene.floor_params.y;
    // The pixel's footprint in tiles, from screen-space derivatives (taken here, in uniform
    // control flow): it sets the width of the checker's box filter.
    let tile_dx = dpdx(tile_coord);
    let tile_dy = dpdy(tile_coord);
    let footprint = abs(tile_dx) + abs(tile_dy);
    // Each edge's plane through the eye, evaluated at this pixel's ray: n . (p - eye) / clip w
    // is an affine function of the pixel position (the ratio is constant along the ray), so its
    // derivatives are exact and edge_coverage gives the exact fraction of the pixel on the
    // rectangle's side of that edge.
    var coverage = 1.0;
    if EDGE_AA {
        let relative = in.world - view.eye.xyz;
        let along_view = (view.view_proj * vec4<f32>(in.world, 1.0)).w;
        let edges = (transpose(scene.floor_edges) * vec4<f32>(relative, 0.0)) / along_view;
        let edges_dx = dpdx(edges);
        let edges_dy = dpdy(edges);
        // The fraction of the pixel inside the rectangle: the product of its coverage by the
        // four edges (exact along an edge; at a corner exact when its edges run along the pixel's
        // axes, close otherwise).
        for (var i = 0; i < 4; i++) {
            coverage *= edge_coverage(edges[i], edges_dx[i], edges_dy[i]);
        }
        if coverage <= 0.0 {
            discard;
        }
    } else if (RECEIVER || PART == 1u || PART == 2u) && (any(in.world.xz < scene.floor_rect.xy) || any(in.world.xz > scene.floor_rect.zw)) {
        // The shadows' shapes may reach past the floor. (The interior, PART 3, cannot, and
        // without a discard its depth test comes before its shading.)
        discard;
    }
    let sw = Switches(false, RECEIVER, PCF, false, false, false, false);
    // The side of the floor the view sees: its top from above, its underside from below.
    let n = vec3<f32>(0.0, select(-1.0, 1.0, view.eye.y >= scene.floor_params.x), 0.0);
    var colour: vec3<f32>;
    if PART == 2u {
        // The umbra: what shade_floor gives where the lookup returns 0, the ambient term alone.
        colour = floor_albedo(tile_coord, footprint) * scene.ambient.rgb;
    } else {
        colour = shade_floor(sw, in.world, n, tile_coord, footprint);
    }
    return vec4<f32>(mix(scene.background.rgb, colour, coverage), 1.0);
}
