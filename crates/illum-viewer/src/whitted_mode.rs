//! The Whitted ray tracer mode's state: depth and anti-aliasing, the orbit camera, and the frame
//! time (its panel: `whitted_panel.rs`).
//!
//! Whitted's algorithm is deterministic, so a frame is rendered only when something that
//! changes it changes (the camera, the size, a setting); the image is read back and shown as an
//! egui texture, in linear values like the rasterizer's (the assignment's figure 1 is linear).

use std::path::{Path, PathBuf};
use web_time::Instant;

use illum_gpu::GpuContext;
use illum_image::RgbImage32;
use illum_scene::Scene;
use illum_whitted::{PendingImage, WhittedTracer};

use crate::camera::OrbitCamera;
use crate::difference_view::{DifferenceView, PathTracerTruth};
use crate::mode::ViewMode;
use crate::plural::count;

/// What a frame depends on: when it is unchanged, the last image stands.
#[derive(Clone, Copy, Debug, PartialEq)]
struct FrameKey {
    camera: illum_scene::Camera,
    depth: u32,
    aa: u32,
}

pub struct WhittedMode {
    scene_path: PathBuf,
    scene: Scene,
    pub camera: OrbitCamera,
    /// Recursion depth (0..=64) and n of the n x n rays per pixel (1..=16).
    pub depth: u32,
    pub aa: u32,
    texture: Option<egui::TextureHandle>,
    drawn: Option<FrameKey>,
    /// Wall-clock milliseconds of the last frame (pipeline, upload, dispatch, readback).
    pub frame_ms: Option<f64>,
    /// Frames rendered since the scene was opened.
    pub frames: u64,
    /// The last frame's mean (linear RGB, before the display's clamp) and size: a summary a
    /// check can compare with a headless render of the same scene.
    pub image_mean: Option<([f64; 3], [u32; 2])>,
    pub message: Option<String>,
    /// A frame being read back (polled readback, in the browser): its key, start and image.
    pending: Option<(FrameKey, Instant, PendingImage)>,
    /// The last frame's image and the scene it is of (camera at its size), for the difference.
    last: Option<(RgbImage32, Scene)>,
    pub difference: DifferenceView,
}

impl WhittedMode {
    pub fn new(scene_path: PathBuf, scene: Scene) -> Self {
        WhittedMode {
            camera: OrbitCamera::new(scene.camera),
            depth: scene.whitted.depth,
            aa: scene.whitted.aa,
            scene_path,
            scene,
            texture: None,
            drawn: None,
            frame_ms: None,
            frames: 0,
            image_mean: None,
            message: None,
            pending: None,
            last: None,
            difference: DifferenceView::default(),
        }
    }

    pub fn set_scene(&mut self, scene_path: PathBuf, scene: Scene) {
        let difference = std::mem::take(&mut self.difference);
        *self =
            WhittedMode { texture: self.texture.take(), difference, ..WhittedMode::new(scene_path, scene) };
    }

    /// The size the mode renders a view of `view_pixels` at: a quarter of its pixels (half each
    /// way), since Whitted at depth 8 costs more per pixel than the rasterizer.
    pub fn render_size(view_pixels: [u32; 2]) -> [u32; 2] {
        view_pixels.map(|v| (v / 2).max(1))
    }

    /// The image for a view of `view_pixels`, rendered again only when it changed.
    fn render_frame(
        &mut self,
        gpu: &GpuContext,
        ctx: &egui::Context,
        view_pixels: [u32; 2],
    ) -> Option<egui::TextureId> {
        let [width, height] = Self::render_size(view_pixels);
        let key = FrameKey { camera: self.camera.camera(width, height), depth: self.depth, aa: self.aa };
        if let Some((pending_key, started, pending)) = &self.pending {
            match pending.poll(gpu) {
                None => return self.texture.as_ref().map(egui::TextureHandle::id),
                Some(result) => {
                    let (pending_key, started) = (*pending_key, *started);
                    self.pending = None;
                    self.show(ctx, pending_key, started, result);
                }
            }
        }
        if self.drawn != Some(key) {
            let mut scene = self.scene.clone();
            scene.camera = key.camera;
            scene.whitted.depth = key.depth;
            scene.whitted.aa = key.aa;
            let started = Instant::now();
            let tracer = WhittedTracer::new(gpu, &scene);
            // In the browser the frame is read back over the next frames (platform.rs);
            // natively it waits.
            #[cfg(target_arch = "wasm32")]
            match tracer {
                Ok(tracer) => {
                    self.pending = Some((key, started, tracer.render_polled()));
                    self.drawn = Some(key);
                }
                Err(e) => self.show(ctx, key, started, Err(e)),
            }
            #[cfg(not(target_arch = "wasm32"))]
            self.show(ctx, key, started, tracer.and_then(|t| t.render()));
        }
        self.texture.as_ref().map(egui::TextureHandle::id)
    }

    /// The last frame's image (linear RGB) and the scene it is of, camera at its size.
    pub fn image(&self) -> Option<(&RgbImage32, &Scene)> {
        self.last.as_ref().map(|(image, scene)| (image, scene))
    }

    /// True while a frame is being read back (the window must keep repainting to finish it).
    pub fn is_busy(&self) -> bool {
        self.pending.is_some()
    }

    /// Shows a rendered frame (or its error) and records it as drawn.
    fn show(
        &mut self,
        ctx: &egui::Context,
        key: FrameKey,
        started: Instant,
        result: Result<RgbImage32, illum_whitted::WhittedError>,
    ) {
        match result {
            Ok(image) => {
                let pixels: Vec<egui::Color32> = image
                    .pixels
                    .iter()
                    .map(|p| {
                        let [r, g, b] = p.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
                        egui::Color32::from_rgb(r, g, b)
                    })
                    .collect();
                self.image_mean = Some((image.mean(), [image.width, image.height]));
                let mut scene = self.scene.clone();
                scene.camera = key.camera;
                let size = [image.width as usize, image.height as usize];
                let color = egui::ColorImage::new(size, pixels);
                match &mut self.texture {
                    Some(handle) => handle.set(color, egui::TextureOptions::LINEAR),
                    None => {
                        self.texture = Some(ctx.load_texture("whitted", color, egui::TextureOptions::LINEAR))
                    }
                }
                self.frame_ms = Some(started.elapsed().as_secs_f64() * 1e3);
                self.frames += 1;
                self.last = Some((image, scene));
                self.message = None;
            }
            Err(e) => self.message = Some(e.to_string()),
        }
        self.drawn = Some(key);
    }
}

impl ViewMode for WhittedMode {
    fn scene_path(&self) -> &Path {
        &self.scene_path
    }

    fn camera(&mut self) -> &mut OrbitCamera {
        &mut self.camera
    }

    fn panel(&mut self, ui: &mut egui::Ui) {
        self.controls(ui);
    }

    /// The image for a view of `view_pixels`, rendered again only when it changed; with the
    /// Difference view on, its difference from a truth (`path_tracer`: the path tracer's
    /// accumulation, one of the truths it may use).
    fn frame(
        &mut self,
        gpu: &GpuContext,
        ctx: &egui::Context,
        _: &egui_wgpu::RenderState,
        view_pixels: [u32; 2],
        path_tracer: Option<PathTracerTruth<'_>>,
    ) -> Option<egui::TextureId> {
        let image = self.render_frame(gpu, ctx, view_pixels);
        if let Some((last, scene)) = &self.last {
            self.difference.update(ctx, last, self.frames, scene, 0.5, path_tracer);
        }
        self.difference.texture().or(image)
    }

    /// Redraws only when the view changes, and while its frame is read back (in a web page).
    fn busy(&self) -> bool {
        self.is_busy()
    }

    fn summary(&self) -> String {
        let ms = self.frame_ms.map_or("n/a".to_owned(), |ms| format!("{ms:.1} ms"));
        format!("whitted: {} rendered, last frame {ms}", count(self.frames, "frame", "frames"))
    }
}
