#define_import_path illum::pathtrace::surfaces

// What the path tracer's two estimators (pathtrace.wgsl from the camera, caustic.wgsl from the
// sun) both need: the sun's sampled direction, the paths' length rule, and the sampled choice
// between reflection and refraction at a dielectric.

#import illum::sampler::{Sampler, sample_1d}
#import illum::sampling::{sample_uniform_cone, to_world}
#import illum::rtcore::spawn::spawn_point
#import illum::rtcore::geometry::Surface
#import illum::rtcore::optics::{transmitted_cos2, refracted, fresnel}
#import illum::pathtrace::scene::params

#ifdef SUN
// A direction toward the directional light and its weight, radiance / pdf. A delta light: its
// direction and irradiance (u1, u2 unused). A disc of half-angle a: a direction uniform in its
// cone (pdf 1 / (2 pi (1 - cos a))) of radiance L = irradiance / (pi sin^2 a), so L / pdf =
// irradiance x 2 / (1 + cos a), finite however small the disc; params.sun.w holds 1 - cos a
// (see sample_uniform_cone). Next-event estimation weighs a surface's cos by it; the caustic's
// light tracer uses it as the flux density crossing the plane across the sun's direction.
struct SunSample {
    w: vec3<f32>,
    weight: vec3<f32>,
}

fn sample_sun(u1: f32, u2: f32) -> SunSample {
#ifdef SUN_DISC
    let one_minus_cos_max = params.sun.w;
    let w = normalize(to_world(params.sun.xyz, sample_uniform_cone(one_minus_cos_max, u1, u2)));
    return SunSample(w, params.sun_irradiance.xyz * (2.0 / (2.0 - one_minus_cos_max)));
#else
    return SunSample(params.sun.xyz, params.sun_irradiance.xyz);
#endif
}
#endif

// How long paths get, for the camera's paths and the caustic's particles alike: `bounces` or
// UNBOUNDED, where Russian roulette starts after RR_START bounces with survival capped below 1
// so that even an albedo-1 closed box terminates (expected extra length <= 1 / (1 - 0.95) = 20
// bounces), and UNBOUNDED_DEPTH_CAP is a safety net whose 0.95^1000 ~ 5e-23 survival odds bias
// nothing f32 can resolve.
const UNBOUNDED: u32 = 0xffffffffu;
const RR_START: u32 = 3u;
const RR_MAX_SURVIVAL: f32 = 0.95;
const UNBOUNDED_DEPTH_CAP: u32 = 1024u;

fn max3(v: vec3<f32>) -> f32 {
    return max(max(v.x, v.y), v.z);
}

#ifdef SPECULAR
// A ray leaving a smooth surface: its origin and direction.
struct Scattered {
    o: vec3<f32>,
    d: vec3<f32>,
}

// The smooth dielectric of index `ior` (inside; 1 outside) met by direction d at s, whose
// normal s.n faces d (`front`: d enters). Reflect or refract about `optic` (s.n, or a smooth
// mesh's shading normal where illum-rtcore's dielectric_normal keeps it), chosen with the
// Fresnel probability (one number from the sampler, none under total internal reflection,
// where everything reflects); the new ray starts on s.n's side it leaves to. No weight: choosing by the reflectance makes it 1 for radiance from
// the camera and for flux from the light alike; radiance's eta^2 across the interface cancels
// over the two crossings every path through a closed dielectric makes (docs/caustics.md).
fn scatter_dielectric(s: Surface, optic: vec3<f32>, d: vec3<f32>, ior: f32, front: bool, sampler: ptr<function, Sampler>) -> Scattered {
    let eta = select(ior, 1.0 / ior, front);
    let cos_i = -dot(d, optic);
    let k = transmitted_cos2(cos_i, eta);
    if (k >= 0.0) {
        let cos_t = sqrt(k);
        if (sample_1d(sampler) >= fresnel(cos_i, cos_t, eta)) {
            return Scattered(spawn_point(s.p, -s.n, s.err), refracted(d, optic, eta, cos_i, cos_t));
        }
    }
    return Scattered(spawn_point(s.p, s.n, s.err), reflect(d, optic));
}

// scatter_dielectric's likelier choice (`optic` as there), taken without a random number, and
// its probability:
// the refraction where the Fresnel reflectance is below 1/2, else the reflection (all of it
// under total internal reflection). The denoiser's guides follow it (guides.wgsl).
fn likelier_dielectric_branch(s: Surface, optic: vec3<f32>, d: vec3<f32>, ior: f32, front: bool) -> LikelierBranch {
    let eta = select(ior, 1.0 / ior, front);
    let cos_i = -dot(d, optic);
    let k = transmitted_cos2(cos_i, eta);
    if (k >= 0.0) {
        let cos_t = sqrt(k);
        let r = fresnel(cos_i, cos_t, eta);
        if (r < 0.5) {
            return LikelierBranch(Scattered(spawn_point(s.p, -s.n, s.err), refracted(d, optic, eta, cos_i, cos_t)), 1.0 - r);
        }
        return LikelierBranch(Scattered(spawn_point(s.p, s.n, s.err), reflect(d, optic)), r);
    }
    return LikelierBranch(Scattered(spawn_point(s.p, s.n, s.err), reflect(d, optic)), 1.0);
}

struct LikelierBranch {
    scattered: Scattered,
    probability: f32,
}
#endif
