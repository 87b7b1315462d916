#define_import_path illum::sampler

// The path tracer's source of sample values: dimension d of sample i in a pixel.
//
// Independent (default): a PCG stream seeded from (seed, pixel, sample index).
//
// LOW_DISCREPANCY: the first LD_DIMENSIONS dimensions come from the Kronecker sequence R_d of
// Roberts ("The unreasonable effectiveness of quasirandom sequences", 2018):
//     x_i,j = frac(s_j + i alpha_j),  alpha_j = (1 / phi_d)^(j+1),
// phi_d the positive root of x^(d+1) = x + 1, with d = LD_DIMENSIONS. The shift s_j is a random
// number per (seed, pixel, dimension) (a Cranley-Patterson rotation): every sample is then
// uniform on [0, 1)^d, so the estimator stays unbiased, while the points of one pixel are
// spread more evenly than independent ones. Arithmetic is in 32-bit fixed point (alpha_j
// scaled by 2^32, wrapping), so it is exact for any sample index. Later dimensions fall back
// to the PCG stream.

#import illum::rng::{pcg_hash, rng_seed, rng_f32}

const LD_DIMENSIONS: u32 = 16u;
// 1 / phi_16, phi_16 = 1.0429177323017866 the positive root of x^17 = x + 1; checked by the
// Rust test `ld_alpha_matches_roberts_definition` in crates/illum-pathtrace/src/tracer.rs.
// alpha_j = (1/phi)^(j+1) is formed by repeated multiplication as dimensions are drawn (a
// constant table indexed at run time is copied to local memory on every call by some drivers).
const LD_INV_PHI: f32 = 0.958848401;

struct Sampler {
    // PCG state for the independent stream (and the fallback dimensions).
    state: u32,
    // Hash of (seed, pixel), the source of the per-dimension shifts.
    pixel_key: u32,
    sample_index: u32,
    dimension: u32,
    // alpha of the next low-discrepancy dimension.
    alpha: f32,
}

fn sampler_new(seed: u32, pixel: u32, sample_index: u32) -> Sampler {
    return Sampler(rng_seed(seed, pixel, sample_index), pcg_hash(seed ^ pcg_hash(pixel)), sample_index, 0u, LD_INV_PHI);
}

// The next dimension's value, in [0, 1).
fn sample_1d(s: ptr<function, Sampler>) -> f32 {
#ifdef LOW_DISCREPANCY
    let d = (*s).dimension;
    (*s).dimension = d + 1u;
    if (d < LD_DIMENSIONS) {
        // One hash per (pixel, dimension): the key times an odd constant spreads the
        // dimensions apart before the permutation mixes them.
        let shift = pcg_hash((*s).pixel_key + d * 0x9e3779b9u);
        // alpha in 32-bit fixed point: an f32 in (0, 1) times 2^32 is an exact integer.
        let alpha = u32((*s).alpha * 4294967296.0);
        (*s).alpha *= LD_INV_PHI;
        let x = shift + (*s).sample_index * alpha;
        return f32(x >> 8u) * 5.9604644775390625e-8;
    }
#endif
    // Through a local: naga's SPIR-V writer mishandles a pointer to a field of a pointee.
    var state = (*s).state;
    let value = rng_f32(&state);
    (*s).state = state;
    return value;
}
