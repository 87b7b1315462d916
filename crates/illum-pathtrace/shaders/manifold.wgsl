#define_import_path illum::pathtrace::manifold

// Manifold next-event estimation through one sphere (docs/caustics-manifold.md): the irradiance
// a delta sun sends to a diffuse point x through a chain of specular events on one sphere, found
// by solving for the chain instead of sampling it. It owns the paths L S+ D (S|D)* E whose
// specular chain stays on one sphere.
//
// The reduction. A line of sunlight meeting the sphere (centre c, radius R), and everything it
// does inside, stays in the meridional plane through the axis {c + s w_s} (w_s the light's
// direction of travel) and the line. In that plane, in units of R, with coordinates (r, z) along
// e (the unit radial direction of x from the axis) and w_s, the line at impact parameter
// b = sin(a), a in [0, pi/2], travels along (0, 1) and meets the circle at p1 = (b, -cos a).
// Writing v(chi) = (sin chi, cos chi):
//   - R (reflection at p1): it leaves p1 = v(pi - a) along v(pi - 2a);
//   - T R^k T (in, k reflections inside, out): inside, every chord meets the circle at the same
//     angle a_t = asin(b / n), so each chord turns the point about the centre by
//     -(pi - 2 a_t) and the direction by the same, and each refraction turns the direction by
//     -(a - a_t): it leaves v(pi - a - (k + 1)(pi - 2 a_t)) along v(-2 (a - a_t) - k (pi - 2 a_t)).
// The side of the axis opposite to x (b < 0) is the mirror image: it is the same chain aimed at
// x' = (-r, z). The chain reaches x' when g(a) = cross(u, x' - q) = 0 with u.(x' - q) > 0.
//
// The weight. Sunlight of irradiance E_sun crosses the source area b db dphi; at x, rotating the
// plane by dphi moves the point by r dphi and the root's neighbours pass at the distance
// |dg/db| db, so the irradiance across the arriving direction is E_sun T b / (|dg/db| r), T the
// chain's Fresnel factors or the mirror's tint: the concentration C = b / (|dg/db| r) is the
// generalised geometry term of Hanika, Droske and Fascione's manifold next-event estimation, in
// closed form for a sphere. C diverges at a fold of the chain (dg/db = 0) and on the axis
// (r = 0); it is bounded by `max_concentration`, illum-scene's specular_spheres::MAX_CONCENTRATION
// (the oracle's bound too), whose bias docs/caustics-manifold.md measures.
//
// The roots. Every chain of a sphere leaves from the same entry points, and both sides of the
// axis share them, so one pass over a grid of GRID intervals in a evaluates g for every chain
// and side at once. Each interval where g changes sign is refined from its secant by Newton's
// method kept inside the interval (bisection when a step leaves it). Two roots inside one
// interval (near a fold) are missed: that band's light is what the grid's bias is made of.
//
// Visibility. A root's light needs two shadow rays (the sun to its entry point, its exit point
// to x). A root whose unshadowed light c is below VISIBLE_LIGHT of the sun's irradiance traces
// them with probability c / (VISIBLE_LIGHT E_sun) and divides by it (Russian roulette on the
// rays, unbiased): the glass's outer reflection, a few per cent of the sun, then costs few rays.
// All roots at one vertex use the same uniform number, one dimension drawn per diffuse vertex.

#import illum::rtcore::optics::fresnel
#import illum::rtcore::spawn::{spawn_error, max_abs}
#import illum::rtcore::traversal::occluded
#import illum::pathtrace::scene::params

// Intervals of the grid in a on each side of the axis.
const GRID: u32 = 24u;
// Newton steps refining one bracketed root from its secant: the interval is pi / 48 wide, and
// each step near a simple root squares the error (a bisection, where a step leaves the
// interval, halves it).
const NEWTON_STEPS: u32 = 1u;
// See "Visibility" above.
const VISIBLE_LIGHT: f32 = 0.25;
// The segment from x to the chain's exit ends at least this fraction short of the sphere, which
// it reaches there (see root_light for the exit point's own error).
const EXIT_SHORTEN: f32 = 1.0e-4;
const HALF_PI: f32 = 1.57079632679489661923;

// A chain on the unit circle: k < 0 for R, else T R^k T with index n (n unused for R).
struct Chain {
    k: i32,
    n: f32,
}

// Where the chain leaves the circle and along which direction, with their derivatives in a.
struct Exit {
    q: vec2<f32>,
    u: vec2<f32>,
    dq: vec2<f32>,
    du: vec2<f32>,
}

// v(chi + alpha) from v(chi) and w = v(alpha).
fn turn(v: vec2<f32>, w: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(v.x * w.y + v.y * w.x, v.y * w.y - v.x * w.x);
}

// At b = sin a (so cos a = sqrt(1 - b^2): no trigonometry).
fn exit_of(chain: Chain, b: f32) -> Exit {
    let ca = sqrt(max(1.0 - b * b, 0.0));
    let p1 = vec2<f32>(b, -ca);
    if (chain.k < 0) {
        // v(pi - 2a) = (sin 2a, -cos 2a); d(pi - a)/da = -1, d(pi - 2a)/da = -2.
        let u = vec2<f32>(2.0 * b * ca, b * b - ca * ca);
        return Exit(p1, u, vec2<f32>(-p1.y, p1.x), vec2<f32>(-2.0 * u.y, 2.0 * u.x));
    }
    let st = b / chain.n;
    let ct = sqrt(max(1.0 - st * st, 0.0));
    // v(-(pi - 2 a_t)) = (-sin 2a_t, -cos 2a_t), one chord's turn.
    let chord = vec2<f32>(-2.0 * st * ct, st * st - ct * ct);
    // v(-(a - a_t)), one refraction's turn: the first chord's direction.
    let bend = vec2<f32>(ca * st - b * ct, ca * ct + b * st);
    var q = turn(p1, chord);
    var u = turn(bend, bend);
    for (var i = 0; i < chain.k; i++) {
        q = turn(q, chord);
        u = turn(u, chord);
    }
    // d a_t / da = cos a / (n cos a_t).
    let dt = ca / (chain.n * ct);
    let steps = 2.0 * f32(chain.k + 1);
    let dpsi = -1.0 + steps * dt;
    let dphi = -2.0 + steps * dt;
    // d v(chi) = (cos chi, -sin chi) dchi = (v.y, -v.x) dchi.
    return Exit(q, u, vec2<f32>(q.y, -q.x) * dpsi, vec2<f32>(u.y, -u.x) * dphi);
}

fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

// g(a) = cross(u, x' - q).
fn miss(e: Exit, aim: vec2<f32>) -> f32 {
    return cross2(e.u, aim - e.q);
}

// dg/da.
fn miss_slope(e: Exit, aim: vec2<f32>) -> f32 {
    return cross2(e.du, aim - e.q) - cross2(e.u, e.dq);
}

// The chain's factor at angle of incidence a (b = sin a): a mirror's tint for R, or a dielectric's Fresnel
// terms (the same at every event of the chain, see above).
fn chain_weight(chain: Chain, b: f32, tint: vec3<f32>) -> vec3<f32> {
    if (chain.n == 0.0) {
        return tint;
    }
    let ca = sqrt(max(1.0 - b * b, 0.0));
    let st = b / chain.n;
    let ct = sqrt(max(1.0 - st * st, 0.0));
    let f = fresnel(ca, ct, 1.0 / chain.n);
    if (chain.k < 0) {
        return vec3<f32>(f);
    }
    var w = (1.0 - f) * (1.0 - f);
    for (var i = 0; i < chain.k; i++) {
        w *= f;
    }
    return vec3<f32>(w);
}

// The receiving point and its frame about one sphere.
struct Receiver {
    // x and the spawned origin of its rays.
    x: vec3<f32>,
    origin: vec3<f32>,
    // Geometric and shading normals, facing the side the path arrived from.
    ng: vec3<f32>,
    ns: vec3<f32>,
    // The object x lies on (occluded's `own`).
    own: u32,
}

struct Sphere {
    centre: vec3<f32>,
    radius: f32,
    index: u32,
    // A mirror's reflectance (unused for glass).
    tint: vec3<f32>,
    // The bound on the concentration (see above).
    max_concentration: f32,
}

// One root of `chain` for b = sin a in [lo, hi] (g changes sign there: g_lo, g_hi) aimed at
// `aim`, on the side of the axis whose radial direction is e3; r = x's distance from the axis
// over R, `u` the vertex's uniform number for the visibility roulette. Newton's steps are taken
// in b, with dg/db = (dg/da) / cos a.
fn root_light(chain: Chain, lo_in: f32, hi_in: f32, g_lo: f32, g_hi: f32, aim: vec2<f32>, r: f32, e3: vec3<f32>, sphere: Sphere, rx: Receiver, u: f32) -> vec3<f32> {
    var lo = lo_in;
    var hi = hi_in;
    var b = lo + (hi - lo) * g_lo / (g_lo - g_hi);
    var e = exit_of(chain, b);
    for (var j = 0u; j < NEWTON_STEPS; j++) {
        let g = miss(e, aim);
        if ((g < 0.0) == (g_lo < 0.0)) {
            lo = b;
        } else {
            hi = b;
        }
        let next = b - g * sqrt(max(1.0 - b * b, 0.0)) / miss_slope(e, aim);
        b = select(0.5 * (lo + hi), next, next > lo && next < hi);
        e = exit_of(chain, b);
    }
    let ws = -params.sun.xyz;
    let ahead = dot(e.u, aim - e.q) > 0.0;
    let u3 = e.u.x * e3 + e.u.y * ws;
    let cos_x = -dot(rx.ns, u3);
    let facing = cos_x > 0.0 && -dot(rx.ng, u3) > 0.0;
    // |dg/db| = |dg/da| / cos a.
    let ca = sqrt(max(1.0 - b * b, 0.0));
    let concentration = min(b * ca / (abs(miss_slope(e, aim)) * r), sphere.max_concentration);
    let light = chain_weight(chain, b, sphere.tint) * params.sun_irradiance.xyz * (concentration * cos_x);
    let bright = max(max(light.x, light.y), light.z);
    let sun = max(max(params.sun_irradiance.x, params.sun_irradiance.y), params.sun_irradiance.z);
    let p = min(bright / (VISIBLE_LIGHT * sun), 1.0);
    if (!(ahead && facing && u < p)) {
        return vec3<f32>(0.0);
    }
    let q3 = sphere.centre + sphere.radius * (e.q.x * e3 + e.q.y * ws);
    let segment = q3 - rx.origin;
    let length_to_exit = length(segment);
    // Short of the sphere by the larger of the segment's rounding and the exit point's own error
    // bound, which grows with its distance from the origin (a scene at 1e4 rounds it by ~1e-3).
    let short = max(length_to_exit * EXIT_SHORTEN, spawn_error(max_abs(q3)));
    if (occluded(rx.origin, segment / length_to_exit, length_to_exit - short, rx.own)) {
        return vec3<f32>(0.0);
    }
    let p1 = sphere.centre + sphere.radius * (b * e3 - ca * ws);
    if (occluded(p1, params.sun.xyz, 3.0e38, sphere.index)) {
        return vec3<f32>(0.0);
    }
    return light / p;
}

// g of the chains R, T T, T R T at one grid angle for both aims (x, y, z: the chains; R's far
// side is never reached, see sphere_light), and whether x lies ahead of each exit point along
// its direction rather than behind it. n = 0: a mirror, R alone.
struct Misses {
    near: vec3<f32>,
    far: vec3<f32>,
    near_ahead: vec3<bool>,
    far_ahead: vec3<bool>,
}

// (sc: sin a and cos a.)
fn misses(sc: vec2<f32>, n: f32, near: vec2<f32>, far: vec2<f32>) -> Misses {
    let b = sc.x;
    let ca = sc.y;
    let p1 = vec2<f32>(b, -ca);
    let u_r = vec2<f32>(2.0 * b * ca, b * b - ca * ca);
    let g_r = cross2(u_r, near - p1);
    let ahead_r = dot(u_r, near - p1) > 0.0;
    if (n == 0.0) {
        return Misses(vec3<f32>(g_r, 0.0, 0.0), vec3<f32>(0.0), vec3<bool>(ahead_r, false, false), vec3<bool>(false));
    }
    let st = b / n;
    let ct = sqrt(max(1.0 - st * st, 0.0));
    let chord = vec2<f32>(-2.0 * st * ct, st * st - ct * ct);
    let bend = vec2<f32>(ca * st - b * ct, ca * ct + b * st);
    let q_tt = turn(p1, chord);
    let u_tt = turn(bend, bend);
    let q_trt = turn(q_tt, chord);
    let u_trt = turn(u_tt, chord);
    return Misses(
        vec3<f32>(g_r, cross2(u_tt, near - q_tt), cross2(u_trt, near - q_trt)),
        vec3<f32>(0.0, cross2(u_tt, far - q_tt), cross2(u_trt, far - q_trt)),
        vec3<bool>(ahead_r, dot(u_tt, near - q_tt) > 0.0, dot(u_trt, near - q_trt) > 0.0),
        vec3<bool>(false, dot(u_tt, far - q_tt) > 0.0, dot(u_trt, far - q_trt) > 0.0),
    );
}

// Records the bracket [b0, b1] (g0, g1 at its ends) in `first` if it is empty (x < 0), else in
// `last`, when `found`.
fn record(found: bool, b0: f32, b1: f32, g0: f32, g1: f32, first: ptr<function, vec4<f32>>, last: ptr<function, vec4<f32>>) {
    let bracket = vec4<f32>(b0, b1, g0, g1);
    let empty = (*first).x < 0.0;
    *last = select(*last, bracket, found && !empty);
    *first = select(*first, bracket, found && empty);
}

// The light of every chain of one sphere (n = 0: a mirror, R only; else glass of index n: R,
// T T, T R T) reaching x, each within `events` specular events (the path-length rule,
// docs/caustics.md "Path length"); u: the vertex's uniform number.
//
// Roots kept: R's one root on x's side (a convex surface's reflected rays leave the axis on
// their own side, so none cross it, and they do not cross each other: one per point), and the
// first and the last bracket of T T and of T R T on each side (a fold puts two roots on one side;
// a third between them is not kept). Brackets are held in variables, not an array indexed per
// lane, and refined after the pass: refining inside it would run the refinement, under a lane
// mask, at every interval where any lane of a group has a root (lavapipe runs a branch's body
// whenever one of its 8 lanes takes it).
fn sphere_light(sphere: Sphere, n: f32, rx: Receiver, events: i32, u: f32) -> vec3<f32> {
    let chains = select(min(events, 3), min(events, 1), n == 0.0);
    if (chains < 1) {
        return vec3<f32>(0.0);
    }
    let ws = -params.sun.xyz;
    let v = (rx.x - sphere.centre) / sphere.radius;
    let z = dot(v, ws);
    let radial = v - z * ws;
    let r = length(radial);
    // On the axis any radial direction serves: C is then at its bound.
    let across = normalize(cross(ws, select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 0.0, 1.0), abs(ws.x) > 0.5)));
    let e = select(across, radial / r, r > 0.0);
    let near = vec2<f32>(r, z);
    let far = vec2<f32>(-r, z);
    let step = HALF_PI / f32(GRID);
    // (sin, cos) of the grid's angles by turning v(0) = (0, 1) a step at a time: no
    // trigonometry in the loop (the turn's rounding, a few units of 2^-24 per step, moves a
    // grid point, not a root).
    let turn_step = vec2<f32>(sin(step), cos(step));
    let none = vec4<f32>(-1.0);
    var reflected = none;
    var unused = none;
    var tt_near = none;
    var tt_near_last = none;
    var tt_far = none;
    var tt_far_last = none;
    var trt_near = none;
    var trt_near_last = none;
    var trt_far = none;
    var trt_far_last = none;
    var sc = vec2<f32>(0.0, 1.0);
    var b0 = 0.0;
    var g0 = misses(sc, n, near, far);
    for (var i = 1u; i <= GRID; i++) {
        sc = turn(sc, turn_step);
        let b1 = sc.x;
        let g1 = misses(sc, n, near, far);
        // A sign change of g where x lies behind the exit at both ends is the line's backward
        // half crossing x: no light.
        let flip_near = g0.near * g1.near < vec3<f32>(0.0) & (g0.near_ahead | g1.near_ahead);
        let flip_far = g0.far * g1.far < vec3<f32>(0.0) & (g0.far_ahead | g1.far_ahead);
        record(flip_near.x, b0, b1, g0.near.x, g1.near.x, &reflected, &unused);
        if (chains >= 2) {
            record(flip_near.y, b0, b1, g0.near.y, g1.near.y, &tt_near, &tt_near_last);
            record(flip_far.y, b0, b1, g0.far.y, g1.far.y, &tt_far, &tt_far_last);
        }
        if (chains >= 3) {
            record(flip_near.z, b0, b1, g0.near.z, g1.near.z, &trt_near, &trt_near_last);
            record(flip_far.z, b0, b1, g0.far.z, g1.far.z, &trt_far, &trt_far_last);
        }
        b0 = b1;
        g0 = g1;
    }
    var l = vec3<f32>(0.0);
    let slots = select(9u, 1u, chains == 1);
    for (var k = 0u; k < slots; k++) {
        var bracket = reflected;
        var c = -1;
        var far_side = false;
        switch k {
            case 1u: { bracket = tt_near; c = 0; }
            case 2u: { bracket = tt_near_last; c = 0; }
            case 3u: { bracket = tt_far; c = 0; far_side = true; }
            case 4u: { bracket = tt_far_last; c = 0; far_side = true; }
            case 5u: { bracket = trt_near; c = 1; }
            case 6u: { bracket = trt_near_last; c = 1; }
            case 7u: { bracket = trt_far; c = 1; far_side = true; }
            case 8u: { bracket = trt_far_last; c = 1; far_side = true; }
            default: {}
        }
        if (bracket.x >= 0.0) {
            let aim = select(near, far, far_side);
            let e3 = select(e, -e, far_side);
            l += root_light(Chain(c, n), bracket.x, bracket.y, bracket.z, bracket.w, aim, r, e3, sphere, rx, u);
        }
    }
    return l;
}
