// The checkerboard floor, shaded procedurally (lighting.wgsl's shade_floor). Used by the main
// pass and by the cube-map captures.
//
// With shadows it is drawn in two parts. First the receiver: the parallelogram of floor under
// the shadow map (outside it nothing can be in shadow), with the shadow lookup, its fragments
// outside the floor's rectangle discarded. Then the whole rectangle without any lookup, in a
// pipeline with a small depth bias, so that it fails the depth test wherever the receiver
// already drew and fills in only the rest. A CPU rasterizer pays for a shader's every texture
// tap on every pixel it shades, so the taps are spent only where a shadow can be.

#import illum::raster::scene::{scene, view, quad_corner, Switches, WorldVertex, world_vertex}
#import illum::raster::lighting::shade_floor

// Set per pipeline (see Switches in scene.wgsl). RECEIVER: draw the receiver parallelogram with
// shadows; otherwise the whole floor without.
override RECEIVER: bool = true;
override PCF: bool = true;

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32) -> WorldVertex {
    let corner = 0.5 * quad_corner(vertex) + vec2<f32>(0.5);
    var xz: vec2<f32>;
    if RECEIVER {
        xz = scene.receiver.xy + corner.x * scene.receiver.zw + corner.y * scene.receiver_v.xy;
    } else {
        xz = mix(scene.floor_rect.xy, scene.floor_rect.zw, corner);
    }
    let world = vec3<f32>(xz.x, scene.floor_params.x, xz.y);
    return world_vertex(world);
}

@fragment
fn fs_main(in: WorldVertex) -> @location(0) vec4<f32> {
    let tile_coord = (in.world.xz - scene.floor_rect.xy) / scene.floor_params.y;
    // The pixel's footprint in tiles, from screen-space derivatives (taken here, in uniform
    // control flow): it sets the width of the checker's box filter.
    let footprint = fwidth(tile_coord);
    if RECEIVER && (any(in.world.xz < scene.floor_rect.xy) || any(in.world.xz > scene.floor_rect.zw)) {
        discard;
    }
    let sw = Switches(false, RECEIVER, PCF, false, false, false, false);
    // The side of the floor the view sees: its top from above, its underside from below.
    let n = vec3<f32>(0.0, select(-1.0, 1.0, view.eye.y >= scene.floor_params.x), 0.0);
    return vec4<f32>(shade_floor(sw, in.world, n, tile_coord, footprint), 1.0);
}
