// The display sum: a running per-pixel (sum of finite samples, number of finite samples) of the
// whole image, kept on the GPU so that a viewer can show the image without a copy through the
// CPU (see crates/illum-pathtrace/src/display_sum.rs). It runs right after the path-tracing pass
// of a band, in the same submission, and adds that band's slots into it.
//
// f32 is enough here because the result is only ever shown in 8 bits: every slot is already an
// f32 sum (as the CPU receives it), and each addition into the running sum rounds by at most
// u = 2^-24 relative, so after n additions the sum is within (n - 1) u of the exact one (and
// typically within sqrt(n) u, rounding errors being as often up as down); one 8-bit level is
// 1/255 ~ 2^-8. The count is exact up to 2^24 samples per pixel. The CPU's f64 fold of the same
// slots stays the source of truth for saved images and statistics.

struct DisplayParams {
    // Image width in pixels (the band is whole rows).
    width: u32,
    // Rows in this band, and the image row it starts at.
    rows: u32,
    row_offset: u32,
    // Slot layers in the band's slots (its chunks, times the replicates with the
    // low-discrepancy sequence: crates/illum-pathtrace/src/batch.rs, `Layers`).
    layers: u32,
}

@group(0) @binding(0) var<uniform> params: DisplayParams;
// The path-tracing pass's slots (pathtrace.wgsl's main): (sum of finite samples, finite count)
// per slot layer and pixel of the band, at layer * band_pixels + pixel_in_band.
@group(0) @binding(1) var<storage, read> batch_sum: array<vec4<f32>>;
// One per pixel of the whole image, row-major: (running sum of finite samples, running count).
@group(0) @binding(2) var<storage, read_write> display_sum: array<vec4<f32>>;

// One invocation per pixel of the band: it alone writes its pixel, so no atomics are needed.
@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.rows) {
        return;
    }
    let band_pixels = params.rows * params.width;
    let in_band = gid.y * params.width + gid.x;
    // Sum the layers first and add once: one rounding of the running sum per band, not per layer.
    var band = vec4<f32>(0.0);
    for (var k = 0u; k < params.layers; k++) {
        band += batch_sum[k * band_pixels + in_band];
    }
    let pixel = (params.row_offset + gid.y) * params.width + gid.x;
    display_sum[pixel] += band;
}
