#define_import_path illum::pathtrace::caustic_buffers

// What the caustic's two passes share (shader def CAUSTIC): the light tracer (caustic.wgsl) and,
// with a delta sun, the photon gather (gather.wgsl, shader def CAUSTIC_GATHER): their parameters,
// the frames' fixed-point splat buffer, and the photon maps with their hash grid.
//
// Splatting: WGSL has no float atomics, so each value is rounded to a 64-bit fixed-point
// integer q = round(v S) (S = caustic.fixed_scale, a power of two) added as two u32 words with
// an explicit carry: exact integer addition, in any order, so the image does not depend on the
// scheduling. A value whose q would reach caustic.fixed_cap is dropped and counted instead.
// Each of a frame's N particles adds to one pixel once, and the gather adds once to each pixel:
// the cap is 2^64 / 2^ceil(log2 N), or 2^64 / 2^ceil(log2 2N) with the gather, so no pixel's
// sum can reach 2^64 (docs/caustics.md).
//
// Photon maps (CAUSTIC_GATHER): frame f's particle i stores its photon in slot f N + i, three
// vec4 (position and the next photon of its bucket's list, weight and scatterings, normal), and
// links itself at the head of its grid bucket's list with one atomicExchange: lists built in one
// pass, in any order, with no capacity to overflow. A bucket holds the photons of every cell that
// hashes to it; a lookup walks each bucket it needs once and keeps the photons within r.

#import illum::rtcore::geometry::Surface
#import illum::pathtrace::scene::params
#import illum::pathtrace::bindings::{BINDING_CAUSTIC, BINDING_DISCS, BINDING_SPLAT, BINDING_PHOTONS, BINDING_HEADS}

const TWO_POW_32: f32 = 4294967296.0;

// Mirrored by tracer/caustic.rs's CausticParams.
struct CausticParams {
    // Particles per frame (N) and the invocations per row of the dispatch.
    particles: u32,
    row_stride: u32,
    // The sample index of frame 0 of this dispatch, and how many frames it traces.
    frame_base: u32,
    frame_count: u32,
    num_discs: u32,
    seed: u32,
    // A_p: a pixel's area on the image plane at distance 1.
    pixel_area: f32,
    // A / N: the plane area each particle stands for (times 1 / c(x)).
    area_per_particle: f32,
    // The whole scene's bounding sphere: particles start outside it; the photon grid's origin.
    scene_centre: vec3<f32>,
    scene_radius: f32,
    fixed_scale: f32,
    fixed_cap: f32,
    // A: the discs' total area.
    disc_area: f32,
    // r_1, the photon gather's kernel radius at sample index 0 (0 without the gather).
    gather_radius: f32,
    // Grid buckets per frame: a power of two.
    buckets: u32,
    // The particles (or, in the gather, pixels) of this dispatch: first_index..index_end. A frame
    // may be traced in pieces, each a range of them (tracer/caustic/schedule.rs).
    first_index: u32,
    index_end: u32,
    // The sample index the gather's radius counts from: the render's first (gather_radius).
    radius_origin: u32,
}

@group(0) @binding(BINDING_CAUSTIC) var<uniform> caustic: CausticParams;
// Per specular object: the centre and radius of its bounding sphere.
@group(0) @binding(BINDING_DISCS) var<storage, read> discs: array<vec4<f32>>;
// Frame f's pixel p, channel c: words (lo, hi) at 6 (f N_pixels + p) + 2 c; after the frames,
// one counter of dropped values per frame.
@group(0) @binding(BINDING_SPLAT) var<storage, read_write> splat: array<atomic<u32>>;
#ifdef CAUSTIC_GATHER
// Photon slot s: photons[3 s] = (position, bitcast next slot + 1, 0 = none), photons[3 s + 1] =
// (weight = flux x albedo / pi, scatterings), photons[3 s + 2] = (normal on the particle's side, 0).
@group(0) @binding(BINDING_PHOTONS) var<storage, read_write> photons: array<vec4<f32>>;
// Frame f's bucket b: the first photon slot + 1 of its list (0 = empty), at f buckets + b.
@group(0) @binding(BINDING_HEADS) var<storage, read_write> heads: array<atomic<u32>>;
#endif

// Whether value v >= 0 can be added in fixed point (false if too large or not a number).
fn fits(v: vec3<f32>) -> bool {
    let q = floor(v * caustic.fixed_scale + 0.5);
    return all(q < vec3<f32>(caustic.fixed_cap));
}

// Adds value v (fits(v)) to pixel `pixel` of frame `frame` in fixed point.
fn splat_add(frame: u32, pixel: u32, v: vec3<f32>) {
    let pixels = params.width * params.height;
    let base = 6u * (frame * pixels + pixel);
    for (var c = 0u; c < 3u; c++) {
        let q = floor(v[c] * caustic.fixed_scale + 0.5);
        // q < 2^64 is an integer in f32: its high word is exact, and so is the remainder
        // q - hi 2^32 (a multiple of q's ulp below 2^32 <= q, or q itself when q < 2^32).
        let hi = u32(floor(q / TWO_POW_32));
        let lo = u32(q - f32(hi) * TWO_POW_32);
        if (lo != 0u) {
            let old = atomicAdd(&splat[base + 2u * c], lo);
            // old + lo wrapped past 2^32 exactly when old > 2^32 - 1 - lo: carry one.
            let carry = select(0u, 1u, old > 0xffffffffu - lo);
            if (hi + carry != 0u) {
                atomicAdd(&splat[base + 2u * c + 1u], hi + carry);
            }
        } else if (hi != 0u) {
            atomicAdd(&splat[base + 2u * c + 1u], hi);
        }
    }
}

fn drop_particle(frame: u32) {
    atomicAdd(&splat[6u * caustic.frame_count * params.width * params.height + frame], 1u);
}

#ifdef CAUSTIC_GATHER
// Knaus and Zwicker's (alpha - 1) / 2 with alpha = 2/3: r_k = r_1 (k + 1)^(-1/6).
const RADIUS_EXPONENT: f32 = -0.16666667;

// The kernel radius of frame `frame` of this dispatch (sample index k = frame_base + frame):
// r_1 (j + 1)^(-1/6) with j = k - radius_origin, the sample's place in its own render. A render of
// sample indices A..B (a part of a split render, the denoiser's second half) then has the radii,
// the bias and the variance of a render of 0..B-A, so its error estimate is as honest as that
// one's (docs/caustics-gather.md, "Radius"). The absolute index would shrink a part's radius with A,
// and a part's 16 samples at a radius 36 times smaller find a photon so rarely that their
// spread no longer shows the variance.
fn gather_radius(frame: u32) -> f32 {
    let j = caustic.frame_base + frame - caustic.radius_origin;
    return caustic.gather_radius * pow(f32(j) + 1.0, RADIUS_EXPONENT);
}

// The grid cell (cubes of side `side` from the scene's centre) holding p. Clamped far beyond
// any cell of the scene so that the conversion is defined for any p.
fn photon_cell(p: vec3<f32>, side: f32) -> vec3<i32> {
    let c = clamp(floor((p - caustic.scene_centre) / side), vec3<f32>(-1.0e9), vec3<f32>(1.0e9));
    return vec3<i32>(c);
}

// The index in `heads` of cell c's bucket in frame `frame`.
fn photon_bucket(frame: u32, c: vec3<i32>) -> u32 {
    let u = bitcast<vec3<u32>>(c);
    let h = (u.x * 73856093u) ^ (u.y * 19349663u) ^ (u.z * 83492791u);
    return frame * caustic.buckets + (h & (caustic.buckets - 1u));
}

// Stores particle `particle`'s photon of frame `frame` at surface s and links it into its
// cell's bucket (cells of side 2 r, so that a disc of radius r meets at most 2 per axis).
fn store_photon(frame: u32, particle: u32, s: Surface, weight: vec3<f32>, scatterings: u32) {
    let slot = frame * caustic.particles + particle;
    let bucket = photon_bucket(frame, photon_cell(s.p, 2.0 * gather_radius(frame)));
    let next = atomicExchange(&heads[bucket], slot + 1u);
    photons[3u * slot] = vec4<f32>(s.p, bitcast<f32>(next));
    photons[3u * slot + 1u] = vec4<f32>(weight, f32(scatterings));
    photons[3u * slot + 2u] = vec4<f32>(s.n, 0.0);
}
#endif
