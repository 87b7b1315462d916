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
// floor(alpha_j * 2^32) for d = 16 (phi_16 = 1.0429177323017866); checked by the Rust test
// `ld_alphas_match_roberts_definition` in crates/illum-pathtrace/src/tracer.rs.
const LD_ALPHA = array<u32, 16>(
    4118222524u, 3948751082u, 3786253661u, 3630443268u, 3481044723u, 3337794166u, 3200438599u,
    3068735433u, 2942452063u, 2821365456u, 2705261756u, 2593935909u, 2487191299u, 2384839400u,
    2286699445u, 2192598107u,
);

struct Sampler {
    // PCG state for the independent stream (and the fallback dimensions).
    state: u32,
    // Hash of (seed, pixel), the source of the per-dimension shifts.
    pixel_key: u32,
    sample_index: u32,
    dimension: u32,
}

fn sampler_new(seed: u32, pixel: u32, sample_index: u32) -> Sampler {
    return Sampler(rng_seed(seed, pixel, sample_index), pcg_hash(seed ^ pcg_hash(pixel)), sample_index, 0u);
}

// The next dimension's value, in [0, 1).
fn sample_1d(s: ptr<function, Sampler>) -> f32 {
#ifdef LOW_DISCREPANCY
    let d = (*s).dimension;
    (*s).dimension = d + 1u;
    if (d < LD_DIMENSIONS) {
        let shift = pcg_hash((*s).pixel_key ^ pcg_hash(d + 0x9e3779b9u));
        let x = shift + (*s).sample_index * LD_ALPHA[d];
        return f32(x >> 8u) * 5.9604644775390625e-8;
    }
#endif
    // Through a local: naga's SPIR-V writer mishandles a pointer to a field of a pointee.
    var state = (*s).state;
    let value = rng_f32(&state);
    (*s).state = state;
    return value;
}
