#define_import_path illum::sampler

// The path tracer's source of sample values: dimension d of sample i in a pixel.
//
// Independent (default): a PCG stream seeded from (seed, pixel, sample index).
//
// LOW_DISCREPANCY: dimensions come in pairs (2k, 2k + 1), and each pair is its own copy of the
// two-dimensional Kronecker sequence R_2 of Roberts ("The unreasonable effectiveness of
// quasirandom sequences", 2018):
//     x_j = frac(s + j (1 / phi, 1 / phi^2)),  phi = 1.3247... the plastic number (phi^3 = phi + 1),
// whose points spread evenly over the unit square for any number of samples. Per pixel, each
// pair visits the points in its own order j = shuffle(i) ("padding"), a nested random
// permutation of the sample index with a seed of its own (see `shuffle`). It maps the first 2^m
// indices onto one aligned block of 2^m consecutive ones, b 2^m + [0, 2^m), and a run of
// consecutive points of a Kronecker sequence is the sequence shifted: x_(b 2^m + t) = x_t +
// b 2^m (1 / phi, 1 / phi^2). So
//   - each pair's first 2^m samples stay evenly spread, while different pairs (a path's light
//     sample, its bounce direction, the next bounce) are paired at random, not in lockstep;
//   - the block's random start is the random shift (Cranley-Patterson rotation) that makes the
//     estimator unbiased: for any fixed i, shuffle(i) is uniform over all 2^32 indices when
//     its seed is (adding the seed and each round of the shuffle are bijections), so every
//     sample is uniform over the 2^32 points of the sequence's full period, a rank-1 lattice
//     whose own integration error (of order 2^-32, up to logarithms) lies far below the f32
//     sums' rounding. No shift is added on top: it would cost two hashes per pair (about half
//     of the sequence's arithmetic) and add nothing to that uniformity.
// Callers draw two-dimensional integrands (pixel, light point, direction) with sample_2d, which
// starts on an even dimension so that the two numbers are one pair.
//
// Why not one sequence of many dimensions (R_d): its quality hangs on how the dimensions' steps
// relate, so some dimension counts do worse than independent numbers; pairs of R_2 do not
// (docs/accuracy.md has the measured relMSE of both). Arithmetic is in 32-bit fixed point (wrapping),
// exact for any sample index; any number of dimensions is as good as the first.

#import illum::rng::{pcg_hash, rng_seed, rng_f32}

// 1 / phi and 1 / phi^2 times 2^32, rounded; checked by the Rust test
// `r2_steps_match_the_plastic_number` in crates/illum-pathtrace/src/shaders.rs.
const R2_STEP_X: u32 = 3242174889u;
const R2_STEP_Y: u32 = 2447445414u;

struct Sampler {
    // PCG state for the independent stream.
    state: u32,
    // LOW_DISCREPANCY: hash of (seed, pixel, replicate), the source of the pairs' shuffles.
    pixel_key: u32,
    // LOW_DISCREPANCY: the sample's index in its replicate's sequence, its bits reversed once
    // here for every pair's shuffle (which works on reversed bits); unused otherwise.
    reversed_index: u32,
    dimension: u32,
}

// Replicates (LOW_DISCREPANCY only): the sample indices of a pixel are dealt, in runs of
// REPLICATE_RUN consecutive indices, to REPLICATES independently randomised copies of the
// sequence: run q = i / REPLICATE_RUN goes to replicate q mod REPLICATES, at index
// (q / REPLICATES) REPLICATE_RUN + i mod REPLICATE_RUN of that copy. Each replicate has its own
// shuffles (its own pixel key), so the R replicate means are independent and
// identically distributed, and their spread estimates the variance of the pixel's mean
// (src/replicates.rs); each replicate's first indices are still a prefix of its padded sequence.
// The replicate is a function of the sample index alone, so a chunk of any length and start
// keeps its replicates apart: pathtrace.wgsl's main sums each replicate's samples into a slot
// of its own. Mirrored by src/replicates.rs (checked there by a test). Without REPLICATED
// (TracerOptions::replicates off) there is one: sample index i is index i of one sequence.
#ifdef REPLICATED
const REPLICATES: u32 = 4u;
#else
const REPLICATES: u32 = 1u;
#endif
const REPLICATE_RUN: u32 = 4u;

// The replicate that sample index i of a pixel belongs to.
fn replicate_of(i: u32) -> u32 {
    return (i / REPLICATE_RUN) % REPLICATES;
}

fn sampler_new(seed: u32, pixel: u32, sample_index: u32) -> Sampler {
#ifdef LOW_DISCREPANCY
    let replicate = replicate_of(sample_index);
    let index = (sample_index / (REPLICATE_RUN * REPLICATES)) * REPLICATE_RUN + sample_index % REPLICATE_RUN;
    let key = pcg_hash(seed ^ pcg_hash(pixel) ^ pcg_hash(replicate * 0x85ebca6bu + 0x27d4eb2fu));
    return Sampler(0u, key, reverseBits(index), 0u);
#else
    return Sampler(rng_seed(seed, pixel, sample_index), 0u, 0u, 0u);
#endif
}

// A nested random permutation of the sample index: Owen scrambling in base 2, the way Burley
// ("Practical Hash-based Owen Scrambling", JCGT 2020) shuffles a padded sequence. Bit b of the
// result is bit b of i flipped by a function of the bits above it (and of the seed): so indices
// that agree above bit m stay together, and [0, 2^m) maps onto one aligned block. The flips are
// the Laine-Karras permutation of the reversed bits: adding the seed, and XOR with the product
// by an even constant, change each bit only as a function of the bits below it.
// Takes i with its bits already reversed (`reversed`, see Sampler).
fn shuffle(reversed: u32, seed: u32) -> u32 {
    var x = reversed;
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return reverseBits(x);
}

// Dimensions 2k and 2k + 1 of the sample, in [0, 1)^2 (only the components asked for are used).
fn pair_values(s: ptr<function, Sampler>, k: u32) -> vec2<f32> {
    // The pair's seed: the pixel key plus the pair times an odd constant, mixed.
    let seed = pcg_hash((*s).pixel_key + k * 0x9e3779b9u);
    let j = shuffle((*s).reversed_index, seed);
    let x = j * vec2<u32>(R2_STEP_X, R2_STEP_Y);
    return vec2<f32>(x >> vec2<u32>(8u)) * 5.9604644775390625e-8;
}

// The next dimension's value, in [0, 1).
fn sample_1d(s: ptr<function, Sampler>) -> f32 {
#ifdef LOW_DISCREPANCY
    let d = (*s).dimension;
    (*s).dimension = d + 1u;
    let values = pair_values(s, d >> 1u);
    return select(values.x, values.y, (d & 1u) == 1u);
#else
    // Through a local: naga's SPIR-V writer mishandles a pointer to a field of a pointee.
    var state = (*s).state;
    let value = rng_f32(&state);
    (*s).state = state;
    return value;
#endif
}

// The next two dimensions' values, for a two-dimensional integrand: with LOW_DISCREPANCY, one
// pair of the sequence (a dimension left odd by a sample_1d is skipped), its index shuffled once.
fn sample_2d(s: ptr<function, Sampler>) -> vec2<f32> {
#ifdef LOW_DISCREPANCY
    let k = ((*s).dimension + 1u) >> 1u;
    (*s).dimension = 2u * k + 2u;
    return pair_values(s, k);
#else
    let u = sample_1d(s);
    let v = sample_1d(s);
    return vec2<f32>(u, v);
#endif
}
