//! Frame timing for the benchmark: wall time per frame and GPU time per pass.
//!
//! A frame is timed from the change that starts it (a camera step, a moved sphere) to the moment
//! the GPU reports it finished (its pass times are mapped back), without reading the image
//! back: what an interactive viewer pays per frame. Warm-up frames first absorb pipeline and
//! allocation costs. [`Motion`] says what changes between frames: the camera alone (a viewer
//! being dragged: the shadow and cube maps are reused) or the scene too (every map made again).

use std::time::Instant;

use crate::scene::RasterScene;
use illum_gpu::GpuContext;
use illum_image::median;

use crate::{Options, PassTimes, RasterError, RasterRenderer};

/// What changes from one frame to the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    /// The camera orbits its target by half a degree a frame; the scene stays.
    CameraOrbit,
    /// The camera orbits and the metal sphere (or else the glass one) moves up and down: the
    /// shadow map and every cube map are made again each frame.
    SceneChange,
    /// The same, with the cube maps captured at a quarter of their side while the scene changes
    /// (`RasterRenderer::set_reduced_cubes_while_changing`, what the viewer does).
    SceneChangeReducedCubes,
}

impl Motion {
    pub fn describe(self) -> &'static str {
        match self {
            Motion::CameraOrbit => "camera moving, scene unchanged",
            Motion::SceneChange => "scene changing every frame",
            Motion::SceneChangeReducedCubes => {
                "scene changing every frame, cube maps at 1/4 side while it changes"
            }
        }
    }

    /// `scene` at frame `i`.
    fn frame(self, scene: &RasterScene, i: u32) -> RasterScene {
        let mut s = scene.clone();
        let angle = (i as f32 * 0.5).to_radians();
        let offset = s.camera.eye - s.camera.target;
        s.camera.eye = s.camera.target + glam::Quat::from_rotation_y(angle) * offset;
        if self != Motion::CameraOrbit {
            let bob = 0.05 * (i as f32 * 0.3).sin() + 0.06;
            if let Some(metal) = &mut s.metal {
                metal.center.y += bob;
            } else if let Some(glass) = &mut s.glass {
                glass.center.y += bob;
            }
        }
        s
    }
}

/// What [`bench_frames`] measured (what it was asked to render, the caller has).
#[derive(Clone, Debug)]
pub struct BenchReport {
    /// Wall time of each measured frame, in milliseconds, in the order they ran.
    pub frame_ms: Vec<f64>,
    /// Per-frame pass times (empty without timestamp queries).
    pub pass_ms: Vec<PassTimes>,
    /// Shadow-map side in texels and cube-map face side, as rendered.
    pub shadow_map_size: u32,
    pub cube_size: u32,
}

impl BenchReport {
    /// The median frame time in milliseconds.
    pub fn median_frame_ms(&self) -> f64 {
        median(&mut self.frame_ms.clone())
    }

    /// Frames per second at the median frame time.
    pub fn fps(&self) -> f64 {
        1000.0 / self.median_frame_ms()
    }

    /// The median of each pass's GPU time, when the adapter has timestamp queries.
    pub fn median_pass_ms(&self) -> Option<PassTimes> {
        if self.pass_ms.is_empty() {
            return None;
        }
        let pick = |f: fn(&PassTimes) -> f64| median(&mut self.pass_ms.iter().map(f).collect::<Vec<_>>());
        Some(PassTimes {
            shadow_ms: pick(|t| t.shadow_ms),
            cube_ms: pick(|t| t.cube_ms),
            main_ms: pick(|t| t.main_ms),
        })
    }
}

/// Renders untimed frames (at least `warmup`, and every state the timed frames will show), then
/// `frames` timed ones, of `scene` at `width` x `height`, changing it between frames as `motion`
/// says.
#[allow(clippy::too_many_arguments)]
pub fn bench_frames(
    gpu: &GpuContext,
    scene: &RasterScene,
    width: u32,
    height: u32,
    options: &Options,
    motion: Motion,
    warmup: u32,
    frames: u32,
) -> Result<BenchReport, RasterError> {
    let mut renderer = RasterRenderer::new(gpu, scene, width, height)?;
    renderer.set_reduced_cubes_while_changing(motion == Motion::SceneChangeReducedCubes);
    // The warm-up draws every state the timed frames will (at least `warmup` frames): a moved
    // sphere can change which pipeline variants a frame needs, and their compilation must not
    // land in a timed frame.
    for i in 0..warmup.max(frames) {
        renderer.set_scene(&motion.frame(scene, i))?;
        renderer.draw(options)?;
    }
    let mut frame_ms = Vec::with_capacity(frames as usize);
    let mut pass_ms = Vec::with_capacity(frames as usize);
    for i in 0..frames {
        let started = Instant::now();
        renderer.set_scene(&motion.frame(scene, i))?;
        let times = renderer.draw(options)?;
        frame_ms.push(started.elapsed().as_secs_f64() * 1e3);
        pass_ms.extend(times);
    }
    Ok(BenchReport {
        frame_ms,
        pass_ms,
        shadow_map_size: renderer.shadow_map_resolution().0,
        cube_size: renderer.scene().quality.cube_size,
    })
}

/// What the reduced cube maps of a changing scene cost in the image: the frame after a moved
/// sphere, drawn with cube maps at `crate::renderer::moving_cube_size` and at full size, compared
/// in 8-bit levels of each pixel's largest channel difference: (mean over all pixels, the 99th
/// percentile, the largest).
pub fn reduced_cube_error(
    gpu: &GpuContext,
    scene: &RasterScene,
    width: u32,
    height: u32,
    options: &Options,
) -> Result<(f64, f64, f64), RasterError> {
    let motion = Motion::SceneChangeReducedCubes;
    let mut frames = Vec::new();
    for reduced in [false, true] {
        let mut renderer = RasterRenderer::new(gpu, &motion.frame(scene, 0), width, height)?;
        renderer.set_reduced_cubes_while_changing(reduced);
        renderer.render(options)?;
        renderer.set_scene(&motion.frame(scene, 1))?;
        frames.push(renderer.render(options)?);
    }
    let mut levels: Vec<f64> = frames[0]
        .pixels
        .iter()
        .zip(&frames[1].pixels)
        .map(|(a, b)| (0..3).map(|c| (f64::from(a[c]) - f64::from(b[c])).abs() * 255.0).fold(0.0, f64::max))
        .collect();
    let mean = levels.iter().sum::<f64>() / levels.len().max(1) as f64;
    levels.sort_by(f64::total_cmp);
    let p99 = levels.get(levels.len() * 99 / 100).copied().unwrap_or(0.0);
    Ok((mean, p99, levels.last().copied().unwrap_or(0.0)))
}
