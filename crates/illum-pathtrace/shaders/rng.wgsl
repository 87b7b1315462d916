#define_import_path illum::rng

// Counter-based random numbers. A sample's stream is a pure function of (seed, pixel, sample
// index), so an image does not depend on how its samples were split into batches.
//
// pcg_hash is the PCG-RXS-M-XS 32-bit permutation recommended as a GPU hash by Jarzynski and
// Olano, "Hash Functions for GPU Rendering" (JCGT 2020). Chaining it over the three keys gives a
// well-mixed starting state; the stream then advances with the PCG LCG step.

fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn rng_seed(seed: u32, pixel: u32, sample_index: u32) -> u32 {
    return pcg_hash(seed ^ pcg_hash(pixel ^ pcg_hash(sample_index)));
}

// Advances the state and returns 32 random bits.
fn rng_next(state: ptr<function, u32>) -> u32 {
    let old = *state;
    *state = old * 747796405u + 2891336453u;
    let word = ((old >> ((old >> 28u) + 4u)) ^ old) * 277803737u;
    return (word >> 22u) ^ word;
}

// A float in [0, 1): the top 24 bits scaled by 2^-24, so 1.0 is never produced (a float with
// more bits could round up to 1.0).
fn rng_f32(state: ptr<function, u32>) -> f32 {
    return f32(rng_next(state) >> 8u) * 5.9604644775390625e-8;
}
