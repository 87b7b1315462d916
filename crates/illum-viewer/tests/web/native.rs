//! Each rendered cell against a native render of the same scene, size and samples.

use std::collections::HashMap;
use std::path::Path;

use illum_gpu::GpuContext;
use illum_pathtrace::PathTracer;
use illum_scene::Scene;

use crate::matrix::Cell;
use crate::page::get;

/// The largest relative difference of an image mean (per channel) between the page and the
/// native render of the same samples, path-traced or Whitted: the same samples on two drivers
/// differ only by f32 rounding (measured 4e-10 to 3e-5 over the matrix), while another seed at
/// these spp and sizes differs by 7e-4 to 8e-3 (printed beside each cell), so a page that drew
/// other samples fails.
pub(crate) const MEAN_TOLERANCE: f64 = 2e-4;
/// The same for the raster's image, whose edges, shadow-map texels and anti-aliasing each driver
/// rasterises its own way (measured 5e-4).
pub(crate) const RASTER_MEAN_TOLERANCE: f64 = 1e-3;

/// The built-in scene at `path` at `width` x `height` (its own camera otherwise, as the page's
/// camera before any drag).
pub(crate) fn sized_scene(root: &Path, path: &str, width: u32, height: u32) -> Scene {
    let mut scene = Scene::load(&root.join(path)).unwrap_or_else(|e| panic!("{e}"));
    scene.camera.width = width;
    scene.camera.height = height;
    scene
}

/// The image mean of a native path-traced render of `scene` with `seed`, at `spp`.
pub(crate) fn native_pathtrace_mean(gpu: &GpuContext, scene: &Scene, seed: u32, spp: u32) -> [f64; 3] {
    let mut scene = scene.clone();
    scene.pathtrace.seed = seed;
    let mut tracer = PathTracer::new(gpu, &scene).unwrap_or_else(|e| panic!("{e}"));
    tracer.render_to_spp(spp).unwrap_or_else(|e| panic!("{e}"));
    tracer.accumulator().mean_image().mean()
}

/// "WxH" as numbers.
pub(crate) fn size_of(text: &str) -> (u32, u32) {
    let (w, h) = text.split_once('x').unwrap_or_else(|| panic!("{text:?} is not WxH"));
    (w.parse().unwrap(), h.parse().unwrap())
}

/// Three numbers separated by spaces.
pub(crate) fn mean_of(text: &str) -> [f64; 3] {
    let values: Vec<f64> = text.split(' ').map(|v| v.parse().unwrap_or(f64::NAN)).collect();
    assert_eq!(values.len(), 3, "{text:?} is not three numbers");
    [values[0], values[1], values[2]]
}

/// The largest relative difference over the channels of two image means.
pub(crate) fn relative_difference(web: [f64; 3], native: [f64; 3]) -> f64 {
    (0..3).map(|c| (web[c] - native[c]).abs() / native[c].abs().max(1e-12)).fold(0.0, f64::max)
}

/// The path tracer's cell: the page's image mean against the native render's.
pub(crate) fn check_pathtrace_cell(
    root: &Path,
    gpu: &GpuContext,
    cell: &Cell,
    status: &HashMap<String, String>,
) -> f64 {
    let name = &cell.name;
    let spp = cell.spp;
    assert_eq!(get(status, "pathtraceSpp"), spp.to_string(), "{name}: {status:?}");
    let expected = cell.caustics.map_or("off", |on| if on { "on" } else { "off" });
    assert_eq!(get(status, "pathtraceCaustics"), expected, "{name}: the light tracer: {status:?}");
    let (width, height) = size_of(get(status, "pathtraceSize"));
    let web = mean_of(get(status, "pathtraceMean"));
    let mut scene = sized_scene(root, cell.scene, width, height);
    if let Some(on) = cell.caustics {
        scene.pathtrace.caustics = on;
    }
    let seed = scene.pathtrace.seed;
    let native = native_pathtrace_mean(gpu, &scene, seed, spp);
    let other_seed = native_pathtrace_mean(gpu, &scene, seed + 1, spp);
    let relative = relative_difference(web, native);
    println!(
        "{name} ({width}x{height}, {spp} spp): web {web:.6?}, native {native:.6?}: relative difference {relative:.2e} \
         (another seed: {:.2e})",
        relative_difference(other_seed, native)
    );
    assert!(
        relative < MEAN_TOLERANCE,
        "{name}: web {web:?} vs native {native:?} ({width}x{height}, {spp} spp)"
    );
    relative
}

/// The Whitted cell: the page's image mean against a native Whitted render of the same size.
pub(crate) fn check_whitted_cell(
    root: &Path,
    gpu: &GpuContext,
    cell: &Cell,
    status: &HashMap<String, String>,
) -> f64 {
    let name = &cell.name;
    let (width, height) = size_of(get(status, "whittedSize"));
    let web = mean_of(get(status, "whittedMean"));
    let scene = sized_scene(root, cell.scene, width, height);
    let tracer = illum_whitted::WhittedTracer::new(gpu, &scene).unwrap_or_else(|e| panic!("{e}"));
    let native = tracer.render().unwrap_or_else(|e| panic!("{e}")).mean();
    let relative = relative_difference(web, native);
    println!(
        "{name} ({width}x{height}): web {web:.6?}, native {native:.6?}: relative difference {relative:.2e}"
    );
    // Deterministic: the two drivers differ by f32 rounding, which may move a ray across an
    // object's edge in a few pixels.
    assert!(relative < MEAN_TOLERANCE, "{name}: web {web:?} vs native {native:?} ({width}x{height})");
    relative
}

/// The raster's cell: the image in the page's screenshot (cropped to where the page says it
/// drew it) against a native raster render of the same size, pixel by pixel; returns the
/// relative difference of the image means.
pub(crate) fn check_raster_cell(
    root: &Path,
    gpu: &GpuContext,
    cell: &Cell,
    status: &HashMap<String, String>,
    shot: &image::RgbaImage,
) -> f64 {
    let name = &cell.name;
    let rect: Vec<u32> = get(status, "viewRect").split(' ').map(|v| v.parse().unwrap()).collect();
    let [x, y, width, height] = rect[..] else { panic!("{name}: view-rect {rect:?}") };
    let shown = image::imageops::crop_imm(shot, x, y, width, height).to_image();
    let scene = sized_scene(root, cell.scene, width, height);
    let raster = illum_raster::RasterScene::from_scene(&scene).unwrap_or_else(|e| panic!("{e}"));
    let mut renderer =
        illum_raster::RasterRenderer::new(gpu, &raster, width, height).unwrap_or_else(|e| panic!("{e}"));
    let native =
        renderer.render(&illum_raster::Options::from_scene(&raster)).unwrap_or_else(|e| panic!("{e}"));
    // The native image's 8-bit levels (exactly the output's bytes, see RasterRenderer::render).
    let level = |v: f32| (v * 255.0).round() as i32;
    let (mut web_sum, mut native_sum, mut off) = ([0f64; 3], [0f64; 3], 0usize);
    for (i, p) in shown.pixels().enumerate() {
        let q = native.pixels[i];
        let mut differs = false;
        for c in 0..3 {
            web_sum[c] += f64::from(p.0[c]);
            native_sum[c] += f64::from(level(q[c]));
            differs |= (i32::from(p.0[c]) - level(q[c])).abs() > 2;
        }
        off += usize::from(differs);
    }
    let pixels = f64::from(width * height);
    let relative = relative_difference(web_sum.map(|s| s / pixels), native_sum.map(|s| s / pixels));
    let fraction = off as f64 / pixels;
    println!(
        "{name} ({width}x{height}): image mean relative difference {relative:.2e}; {off} pixels ({:.3}%) differ by more than 2 levels",
        100.0 * fraction
    );
    // The picture is the same when the means agree and all but a sliver of edge pixels do
    // (measured 0.86% of the pixels beyond 2 levels).
    assert!(relative < RASTER_MEAN_TOLERANCE, "{name}: image means differ by {relative:.2e}");
    assert!(fraction < 0.02, "{name}: {off} of {pixels} pixels differ by more than 2 levels");
    relative
}
