// The caustic estimator (shader def CAUSTIC): light tracing from the directional light for the
// paths L S+ D E that the camera path tracer cannot find with a delta sun. One invocation traces
// one particle of one frame; frame k pairs with sample index k of every pixel (tracer/caustic.rs
// folds it in). The mathematics is in docs/caustics.md; in short:
//
// Emission: a disc of radius R_k about the centre of each specular object's bounding sphere,
// perpendicular to the light's direction w, covers every line of light that can meet it. A
// particle picks disc k with probability A_k / A (A = sum of the disc areas), a point x uniform
// on it, so its density on the plane is c(x) / A (c(x) = number of discs covering x), and
// carries the flux (irradiance across the plane) x A / (c(x) N), N particles per frame. A sun
// disc first draws w uniform in its cone: irradiance across the plane L 2 pi (1 - cos_max).
//
// Transport: a mirror multiplies the flux by its reflectance; a dielectric reflects with
// probability F (exact Fresnel), else refracts, weight 1, no eta^2 factor: flux is the adjoint
// quantity of radiance, and the power an interface passes on is (1 - F) of what arrives
// whatever the indices (Veach 1997, 5.2). A particle whose first hit is diffuse is discarded:
// it carries an L D path, which next-event estimation counts.
//
// Connection at the first diffuse point x (albedo rho, normal n toward the particle's side)
// to the pinhole at the eye: the pixel's value is the mean radiance over its rectangle of area
// A_p on the image plane at distance 1, so a particle of flux Phi adds
//     Phi rho / pi x cos(theta_x) / (A_p cos^3(theta) r^2)
// (the pinhole's importance 1 / (A_p cos^4 theta) times the geometry term cos theta cos theta_x
// / r^2) to the pixel through which the eye sees x, if nothing hides x from the eye.
//
// Photons (shader def CAUSTIC_GATHER, a delta sun): the same point and weight are also stored
// as frame k's photon for the gather of E (S|D)* D S+ L (gather.wgsl).
//
// Splatting (caustic_buffers.wgsl): WGSL has no float atomics, so each value is rounded to a 64-bit fixed-point
// integer q = round(v S) (S = caustic.fixed_scale, a power of two) added as two u32 words with
// an explicit carry: exact integer addition, in any order, so the image does not depend on the
// scheduling. A particle whose q would reach caustic.fixed_cap = 2^64 / 2^ceil(log2 N) is
// dropped and counted instead; with at most N particles per frame, each adding to one pixel
// once, no pixel's sum can then reach 2^64 (the proof is in docs/caustics.md).

#import illum::constants::{PI, TWO_PI, INV_PI}
#import illum::sampler::{sampler_new, sample_1d}
#import illum::sampling::sample_disc
#import illum::rtcore::spawn::spawn_point
#import illum::rtcore::geometry::{NO_HIT, Surface}
#import illum::rtcore::camera::camera_film_point
#import illum::pathtrace::scene::params
#import illum::rtcore::traversal::closest_hit
#import illum::pathtrace::surfaces::sample_sun
#import illum::pathtrace::caustic_buffers::{caustic, discs, fits, splat_add, drop_particle}
#import illum::pathtrace::caustic_walk::{next_vertex, is_specular, specular_weight, diffuse_albedo, may_continue, scatter_specular}
#ifdef CAUSTIC_GATHER
#import illum::pathtrace::caustic_buffers::store_photon
#endif

// The particle of outgoing factor `weight` (flux rho / pi) at surface s, seen from the eye.
fn connect(frame: u32, s: Surface, own: u32, weight: vec3<f32>) {
    let to_eye = params.camera.eye - s.p;
    let r2 = dot(to_eye, to_eye);
    let w = to_eye / sqrt(r2);
    let cos_x = dot(s.n, w);
    let film = camera_film_point(params.camera, w, vec2<f32>(f32(params.width), f32(params.height)));
    let cos_theta = film.z;
    if (!(cos_x > 0.0 && cos_theta > 0.0)) {
        return;
    }
    let px = film.x;
    let py = film.y;
    if (!(px >= 0.0 && px < f32(params.width) && py >= 0.0 && py < f32(params.height))) {
        return;
    }
    let ix = min(u32(px), params.width - 1u);
    let iy = min(u32(py), params.height - 1u);
    // Visibility: the nearest surface (emitters included: a camera ray would see them) from x
    // toward the eye must lie beyond it.
    let origin = spawn_point(s.p, s.n, s.err);
    let segment = params.camera.eye - origin;
    let distance = length(segment);
    let hit = closest_hit(origin, segment / distance, own);
    if (hit.index != NO_HIT && hit.t < distance) {
        return;
    }
    let v = weight * (cos_x / (caustic.pixel_area * cos_theta * cos_theta * cos_theta * r2));
    if (!fits(v)) {
        drop_particle(frame);
        return;
    }
    splat_add(frame, iy * params.width + ix, v);
}

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let particle = caustic.first_index + gid.y * caustic.row_stride + gid.x;
    let frame = gid.z;
    if (particle >= min(caustic.particles, caustic.index_end) || frame >= caustic.frame_count) {
        return;
    }
    var sampler = sampler_new(caustic.seed, particle, caustic.frame_base + frame);
    let u1 = sample_1d(&sampler);
    let u2 = sample_1d(&sampler);
    // The flux density across the plane normal to the sun: L 2 pi (1 - cos_max) for a disc,
    // the irradiance for a delta sun (surfaces.wgsl's sample_sun).
    let sun = sample_sun(u1, u2);
    let to_light = sun.w;
    let flux_density = sun.weight;
    let d0 = -to_light;
    // A disc with probability proportional to its area, a point uniform on it.
    let pick = sample_1d(&sampler) * caustic.disc_area;
    var k = 0u;
    var acc = 0.0;
    for (; k + 1u < caustic.num_discs; k++) {
        acc += PI * discs[k].w * discs[k].w;
        if (pick < acc) {
            break;
        }
    }
    let u3 = sample_1d(&sampler);
    let u4 = sample_1d(&sampler);
    let x = sample_disc(discs[k].xyz, d0, discs[k].w, u3, u4);
    var covering = 0u;
    for (var j = 0u; j < caustic.num_discs; j++) {
        let m = x - discs[j].xyz;
        let across = m - d0 * dot(m, d0);
        covering += select(0u, 1u, dot(across, across) <= discs[j].w * discs[j].w);
    }
    var throughput = flux_density * (caustic.area_per_particle / f32(max(covering, 1u)));
    // The particle starts one scene radius outside the bounding sphere, a margin relative to the
    // scene's size: an absolute one would put it many scene sizes away in a scene of small units,
    // where its hits lose precision (tests/transforms.rs scales the scene from 1e-4 to 1e4).
    var o = x + d0 * (dot(caustic.scene_centre - x, d0) - 2.0 * caustic.scene_radius);
    // The object whose surface o lies on: closest_hit's `own`.
    var own = NO_HIT;
    var d = d0;
    var scatterings = 0u;
    loop {
        let v = next_vertex(o, d, own);
        own = v.index;
        if (v.missed || v.emitter) {
            return;
        }
        if (is_specular(v)) {
            // The camera path E D S^k L this particle mirrors takes k + 1 continuation rays, so
            // with `bounces` = n a particle may scatter k <= n - 1 times. Flux crosses glass
            // without an eta^2 factor (see the top of this file).
            if (!may_continue(scatterings + 2u, scatterings, &throughput, specular_weight(v), &sampler)) {
                return;
            }
            let next = scatter_specular(v, d, &sampler);
            o = next.o;
            d = next.d;
        } else {
            if (scatterings == 0u) {
                return;
            }
            let weight = throughput * diffuse_albedo(v) * INV_PI;
#ifdef CAUSTIC_GATHER
            store_photon(frame, particle, v.s, weight, scatterings);
#endif
            connect(frame, v.s, own, weight);
            return;
        }
        scatterings += 1u;
    }
}
