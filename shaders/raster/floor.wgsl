// The checkerboard floor, shaded procedurally (lighting.wgsl's shade_floor). Used by the main
// pass and by the cube-map captures.
//
// With shadows it is drawn in two parts. First the receiver: the parallelogram of floor under
// the shadow map (outside it nothing can be in shadow), with the shadow lookup, its fragments
// outside the floor's rectangle discarded. Then the whole rectangle without any lookup, in a
// pipeline with a small depth bias, so that it fails the depth test wherever the receiver
// already drew and fills in only the rest. A CPU rasterizer pays for a shader's every texture
// tap on every pixel it shades, so the taps are spent only where a shadow can be.
//
// In the main view with anti-aliasing on (EDGE_AA), the rectangle's outline is anti-aliased like
// the spheres' silhouettes: the rectangle reaches past it by EDGE_REACH_PIXELS, and each pixel is
// the floor's colour mixed with the background by the fraction of the pixel inside the rectangle.
// The renderer draws the floor first, over nothing but the background, so the shader mixes with
// the background colour itself and needs no blending. (Either part may draw an outline pixel;
// the other then fails the depth test there, as everywhere.)

#import illum::raster::scene::{scene, view, quad_corner, Switches, WorldVertex, world_vertex, edge_coverage, EDGE_REACH_PIXELS}
#import illum::raster::lighting::shade_floor

// Set per pipeline (see Switches in scene.wgsl). RECEIVER: draw the receiver parallelogram with
// shadows; otherwise the whole floor without.
override RECEIVER: bool = true;
override PCF: bool = true;
override EDGE_AA: bool = false;

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32) -> WorldVertex {
    let corner = 0.5 * quad_corner(vertex) + vec2<f32>(0.5);
    var xz: vec2<f32>;
    if RECEIVER {
        xz = scene.receiver.xy + corner.x * scene.receiver.zw + corner.y * scene.receiver_v.xy;
    } else {
        xz = mix(scene.floor_rect.xy, scene.floor_rect.zw, corner);
    }
    var world = vec3<f32>(xz.x, scene.floor_params.x, xz.y);
    if EDGE_AA && !RECEIVER {
        // Grow the rectangle at this corner by EDGE_REACH_PIXELS of the corner's own pixel
        // footprint along the floor: a pixel at distance D spans about D x view.eye.w across the
        // view, stretched by 1 / sin(elevation) along a floor seen at a grazing angle (capped
        // near the horizon). The footprint grows faster than linearly with distance, so the
        // straight line between two grown corners reaches at least as far as needed between them.
        let to_eye = view.eye.xyz - world;
        let distance = length(to_eye);
        let sin_elevation = max(abs(to_eye.y) / max(distance, 1e-30), 0.02);
        let grow = EDGE_REACH_PIXELS * distance * view.eye.w / sin_elevation;
        let outward = vec2<f32>(select(-1.0, 1.0, corner.x > 0.5), select(-1.0, 1.0, corner.y > 0.5));
        world += grow * vec3<f32>(outward.x, 0.0, outward.y);
    }
    return world_vertex(world);
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
    } else if RECEIVER && (any(in.world.xz < scene.floor_rect.xy) || any(in.world.xz > scene.floor_rect.zw)) {
        discard;
    }
    let sw = Switches(false, RECEIVER, PCF, false, false, false, false);
    // The side of the floor the view sees: its top from above, its underside from below.
    let n = vec3<f32>(0.0, select(-1.0, 1.0, view.eye.y >= scene.floor_params.x), 0.0);
    let colour = shade_floor(sw, in.world, n, tile_coord, footprint);
    return vec4<f32>(mix(scene.background.rgb, colour, coverage), 1.0);
}
