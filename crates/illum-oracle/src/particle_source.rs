//! Where the caustic's light-tracer particles (`caustic.rs`) start, and the random numbers each
//! draws: shared by the light tracer and the photon gather (`gather.rs`), which traces the same
//! particles again.

use std::f64::consts::PI;

use glam::DVec3;
use illum_scene::MaterialKind;

use crate::geometry::Surface;
use crate::rng::Rng;
use crate::scene::{Primitive, TraceScene};

/// Key mixed into the particles' seed so that particle i of frame k never shares its random
/// numbers with sample k of pixel i.
const PARTICLE_SEED_KEY: u64 = 0xc0ff_ee00_ca05_71c5;

/// The random numbers of particle `particle` of frame `frame` under `seed`.
pub(crate) fn particle_rng(seed: u64, particle: u64, frame: u32) -> Rng {
    Rng::for_sample(seed ^ PARTICLE_SEED_KEY, particle, u64::from(frame))
}

/// The bounding sphere (centre, radius) of a primitive.
fn bounding_sphere(p: &Primitive) -> (DVec3, f64) {
    match p.surface {
        Surface::Ball(b) => (b.center, b.radius),
        Surface::Parallelogram(q) => {
            let centre = q.corner + 0.5 * (q.u + q.v);
            (centre, 0.5 * (q.u + q.v).length().max((q.u - q.v).length()))
        }
        Surface::Box(b) => (b.rotation * (0.5 * (b.lo + b.hi)) + b.offset, 0.5 * (b.hi - b.lo).length()),
        Surface::Triangle(t) => t.bounding_sphere(),
    }
}

fn is_specular(material: MaterialKind) -> bool {
    matches!(material, MaterialKind::Mirror { .. } | MaterialKind::Dielectric { .. })
}

/// Where particles start and what they carry: the specular objects' bounding spheres and the
/// scene's bounding sphere (particles start outside it).
#[derive(Clone, Debug)]
pub(crate) struct ParticleSource {
    /// The specular objects' bounding spheres (centre, radius): the discs particles cross.
    pub(crate) discs: Vec<(DVec3, f64)>,
    /// The sum of the discs' areas.
    pub(crate) total_area: f64,
    pub(crate) scene_centre: DVec3,
    pub(crate) scene_radius: f64,
    /// The largest disc's radius, R_max (the photon gather's radii are fractions of it).
    pub(crate) largest_radius: f64,
}

impl ParticleSource {
    /// The particles' source in `scene`, or `None` without a sun or a mirror or dielectric, or
    /// with a smooth mesh: the particles follow geometric normals, and light carried through
    /// shading normals needs the adjoint's correction (Veach 1996), which they do not make.
    /// Without them the camera's paths estimate the caustic themselves.
    pub(crate) fn new(scene: &TraceScene) -> Option<ParticleSource> {
        scene.sun?;
        let smooth = |p: &Primitive| matches!(p.surface, Surface::Triangle(t) if t.vertex_normals.is_some());
        if scene.surfaces.iter().any(smooth) {
            return None;
        }
        let discs: Vec<(DVec3, f64)> =
            scene.surfaces.iter().filter(|p| is_specular(p.material)).map(bounding_sphere).collect();
        if discs.is_empty() {
            return None;
        }
        let total_area = discs.iter().map(|(_, r)| PI * r * r).sum();
        let spheres: Vec<(DVec3, f64)> =
            scene.surfaces.iter().chain(&scene.emitters).map(bounding_sphere).collect();
        let scene_centre = spheres.iter().map(|(c, _)| *c).sum::<DVec3>() / spheres.len() as f64;
        let scene_radius = spheres.iter().map(|(c, r)| (*c - scene_centre).length() + r).fold(0.0, f64::max);
        let largest_radius = discs.iter().map(|(_, r)| *r).fold(0.0, f64::max);
        Some(ParticleSource { discs, total_area, scene_centre, scene_radius, largest_radius })
    }
}
