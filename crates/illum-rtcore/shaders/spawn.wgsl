#define_import_path illum::rtcore::spawn

// Robust ray spawning: moving a new ray's origin off the surface it leaves, by an amount derived
// from a bound on the rounding error of the surface point (the approach of pbrt-v4's
// OffsetRayOrigin, Pharr, Jakob and Humphreys, "Physically Based Rendering", 4th ed., sec. 6.8.6).
//
// A computed surface point p lies within `err` of the true surface, measured along the unit
// normal n. Moving p by err along n then puts it on n's side of the surface, except that the
// addition p + err n is rounded too. So, as pbrt does, every coordinate the offset moves is then
// stepped one more float in the offset's direction: the rounding of a sum is at most half a
// float step, so after the extra step each coordinate has moved strictly more than |err n_i|
// toward n's side, and n . (p' - p) > err |n|^2. Hence:
//   - p' is strictly on n's side of the true surface (its own surface is never hit again);
//   - each coordinate moves at most err |n_i| plus 1.5 float steps of p'_i, so a surface further
//     than err + 2^-22 |p| (plus a subnormal step) away along n is never skipped.
// crates/illum-rtcore/src/spawn.rs mirrors this function on the CPU and tests both claims.
//
// The error bounds themselves come from the surface routines (geometry.wgsl): 0 for points snapped
// onto an axis-aligned face, SPAWN_REL_ERROR times the magnitude of the numbers a point was
// computed from otherwise.

// Relative error bound: 32 machine epsilons (2^-18). geometry.wgsl bounds the error of a
// rebuilt surface point, and of the same shape's intersection test run again from the spawned
// origin, by 17 u = 8.5 epsilons of the shape's magnitude for every kind; 32 leaves a margin.
const SPAWN_REL_ERROR: f32 = 3.814697265625e-6;
// Smallest offset used, 2^-100: keeps p + err n away from subnormals (which GPUs may flush to
// zero) when err is 0 and p is 0. Far below any representable scene feature.
const SPAWN_MIN_OFFSET: f32 = 7.888609052210118e-31;

// The float next to x in the direction of `towards` (x itself when towards == 0). x is finite.
fn step_float(x: f32, towards: f32) -> f32 {
    if (towards == 0.0) {
        return x;
    }
    if (x == 0.0) {
        // Either zero steps to the smallest subnormal of the wanted sign.
        return select(bitcast<f32>(0x80000001u), bitcast<f32>(1u), towards > 0.0);
    }
    // The bit pattern of a float, read as an integer, grows with its magnitude: moving away from
    // zero adds one, moving toward zero subtracts one.
    let bits = bitcast<u32>(x);
    let away = (x > 0.0) == (towards > 0.0);
    return bitcast<f32>(select(bits - 1u, bits + 1u, away));
}

// The origin of a ray leaving the surface at p toward n's side (n: unit normal on the side the
// ray leaves by; err: bound on p's distance from the true surface along n).
fn spawn_point(p: vec3<f32>, n: vec3<f32>, err: f32) -> vec3<f32> {
    let offset = max(err, SPAWN_MIN_OFFSET) * n;
    let q = p + offset;
    return vec3<f32>(step_float(q.x, offset.x), step_float(q.y, offset.y), step_float(q.z, offset.z));
}

// The error bound of a point computed from numbers of magnitude at most `magnitude`.
fn spawn_error(magnitude: f32) -> f32 {
    return SPAWN_REL_ERROR * magnitude;
}

// The largest absolute coordinate of v (the magnitude that rounding errors scale with).
fn max_abs(v: vec3<f32>) -> f32 {
    let a = abs(v);
    return max(max(a.x, a.y), a.z);
}
