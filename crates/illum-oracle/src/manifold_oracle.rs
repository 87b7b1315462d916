//! The oracle's side of manifold next-event estimation (`manifold.rs`): turning it on, and the
//! paths at a diffuse vertex through the oracle's own shadow test and offsets.

use glam::DVec3;

use crate::integrator::{Oracle, SHADOW_SHORTEN, SPAWN_OFFSET};
use crate::manifold::{Manifold, ManifoldPath, ManifoldSettings, Offsets};

impl Oracle {
    /// Turns MNEE on (`Some`) or off. On, every diffuse vertex of a camera path adds
    /// throughput x albedo / pi x [`Self::manifold_irradiance`], and the caustic's light tracer
    /// and photon gather are off (while MNEE is on, `with_caustics` has no effect): MNEE owns
    /// L S+ D (S|D)* E for chains inside one sphere; chains through two or more objects are not
    /// counted. Off does not turn the light tracer back on. The caller checks the scene with
    /// [`illum_scene::specular_spheres::solvable_spheres`]: the estimator is wrong where an object enters a sphere.
    pub fn with_manifold(mut self, settings: Option<ManifoldSettings>) -> Oracle {
        self.manifold = None;
        if let Some(settings) = settings {
            self.caustic = None;
            self.manifold = Some(Manifold::new(&self.scene.surfaces, settings));
        }
        self
    }

    /// Whether MNEE is on.
    pub fn manifold(&self) -> bool {
        self.manifold.is_some()
    }

    /// The irradiance-like sum E w C max(n_s.(-u3), 0) over every path MNEE finds at x (already
    /// offset off its surface), facing normal `normal`, shading normal `shading`, for a
    /// diffuse vertex of depth `depth` (module documentation). Zero when MNEE is off or the
    /// sun is not delta.
    pub fn manifold_irradiance(&self, x: DVec3, normal: DVec3, shading: DVec3, depth: u32) -> DVec3 {
        self.manifold_paths(x, normal, shading, depth).iter().map(|p| p.irradiance).sum()
    }

    /// Every path of [`Self::manifold_irradiance`] with a nonzero contribution.
    pub fn manifold_paths(&self, x: DVec3, normal: DVec3, shading: DVec3, depth: u32) -> Vec<ManifoldPath> {
        let (Some(manifold), Some(sun)) = (&self.manifold, self.scene.sun) else { return Vec::new() };
        let offsets = Offsets { spawn: SPAWN_OFFSET, shorten: SHADOW_SHORTEN };
        let blocked = |o: DVec3, d: DVec3, t_max: f64| self.blocked(o, d, t_max);
        manifold.paths(sun, self.bounces, offsets, &blocked, (x, normal, shading), depth)
    }
}
