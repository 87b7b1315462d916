//! GPU time per part of a frame, from the timestamp queries of `FramePlan::pass_names`.

use illum_image::RgbImage32;

/// GPU time of each part of a frame, in milliseconds, from timestamp queries.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassTimes {
    /// The shadow map (0 when the frame has no shadow pass).
    pub shadow_ms: f64,
    /// The cube-map faces the frame captured: the glass's and its coarse copy's (twelve), and
    /// the metal's (six more, in the enhanced look with reflection).
    pub cube_ms: f64,
    /// The main view: the floor, then the spheres blended over it by their edge coverage.
    pub main_ms: f64,
}

impl PassTimes {
    /// Sums per-pass timings named as in `FramePlan::pass_names` (read back with a wait:
    /// native only).
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn from_named(named: &[(String, f64)]) -> Self {
        let mut t = PassTimes::default();
        for (name, ms) in named {
            match name.as_str() {
                "shadow" => t.shadow_ms += ms,
                "main" => t.main_ms += ms,
                _ => t.cube_ms += ms,
            }
        }
        t
    }

    pub fn total_ms(&self) -> f64 {
        self.shadow_ms + self.cube_ms + self.main_ms
    }
}

/// A rendered image with the GPU times of its passes (`None` without timestamp queries).
#[derive(Clone, Debug)]
pub struct Frame {
    pub image: RgbImage32,
    pub pass_times: Option<PassTimes>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::FramePlan;

    #[test]
    fn pass_times_sum_the_cube_faces() {
        let plan = FramePlan {
            glass: true,
            metal: true,
            shadow_pass: true,
            glass_shadowed: false,
            metal_shadowed: true,
            metal_cube: true,
            shadow_rings: true,
            meshes: false,
            reuse_views: false,
        };
        let named: Vec<(String, f64)> = plan.pass_names().into_iter().map(|n| (n, 0.5)).collect();
        let t = PassTimes::from_named(&named);
        assert_eq!((t.shadow_ms, t.cube_ms, t.main_ms), (0.5, 9.0, 0.5));
        assert_eq!(t.total_ms(), 10.0);
    }
}
