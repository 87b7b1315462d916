//! The render example's path for rasterizer scenes (`illum_cli::raster`): its errors and the
//! file it writes, on the test binary's one device.

use std::path::{Path, PathBuf};

use illum_cli::SceneArgs;
use illum_cli::raster::{RasterArgs, RasterRequest, render_raster_with};

use illum_gpu::testing::gpu;

fn request<'a>(settings: &'a SceneArgs, raster: &'a RasterArgs, outputs: &'a [PathBuf]) -> RasterRequest<'a> {
    RasterRequest {
        scene: Path::new("scenes/whitted.toml"),
        settings,
        args: raster,
        outputs,
        encoding: None,
        exposure: None,
        other_flags: Vec::new(),
        long: Default::default(),
        reference: None,
    }
}

fn error_of(request: &RasterRequest) -> String {
    match render_raster_with(gpu(), request) {
        Ok(()) => panic!("expected an error"),
        Err(e) => format!("{e:#}"),
    }
}

#[test]
fn a_raster_render_writes_a_linear_png() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = vec![dir.path().join("w.png")];
    let settings = SceneArgs { width: Some(96), height: Some(54), ..Default::default() };
    let raster =
        RasterArgs { look: Some(illum_raster::Look::Enhanced), no_antialiasing: true, ..Default::default() };
    render_raster_with(gpu(), &request(&settings, &raster, &out)).unwrap_or_else(|e| panic!("{e:#}"));
    let png = image::open(&out[0]).expect("the PNG exists").to_rgb8();
    assert_eq!(png.dimensions(), (96, 54));
    // Linear encoding by default: the background's 0.3, 0.5, 0.9 as plain 8-bit values (229.5 is
    // a tie between 229 and 230; see illum-raster's
    // tests/raster/figure.rs, the_background_is_76_128_229).
    let [r, g, b] = png.get_pixel(0, 0).0;
    assert!([r, g] == [76, 128] && (229..=230).contains(&b), "{:?}", [r, g, b]);
}

#[test]
fn a_resolution_beyond_the_device_is_a_clear_error() {
    let max = gpu().device.limits().max_texture_dimension_2d;
    let settings = SceneArgs { width: Some(max + 1), height: Some(16), ..Default::default() };
    let raster = RasterArgs::default();
    let out = vec![PathBuf::from("target/never-written.png")];
    let error = error_of(&request(&settings, &raster, &out));
    assert!(
        error.contains(&format!("camera.width = {}", max + 1)) && error.contains("max_texture_dimension_2d"),
        "{error}"
    );
    assert!(!Path::new("target/never-written.png").exists());

    let settings = SceneArgs { width: Some(0), ..Default::default() };
    let error = error_of(&request(&settings, &raster, &out));
    assert!(error.contains("command line: --width = 0: must be at least 1"), "{error}");
}

#[test]
fn path_tracer_flags_and_bad_outputs_are_refused_before_rendering() {
    let raster = RasterArgs::default();
    let out = vec![PathBuf::from("x.png")];
    let settings = SceneArgs { spp: Some(64), ..Default::default() };
    let error = error_of(&request(&settings, &raster, &out));
    assert!(error.contains("--spp applies only to the path tracer"), "{error}");
    let settings = SceneArgs::default();
    let mut req = request(&settings, &raster, &out);
    req.other_flags = vec!["--target-error"];
    assert!(error_of(&req).contains("--target-error"));
    let bad = vec![PathBuf::from("x.jpg")];
    let error = error_of(&request(&settings, &raster, &bad));
    assert!(error.contains("x.jpg: unknown extension; allowed: .png or .exr"), "{error}");
}

#[test]
fn raster_flags_are_refused_for_a_path_tracer_scene() {
    let raster =
        RasterArgs { no_antialiasing: true, look: Some(illum_raster::Look::Figure), ..Default::default() };
    let error = raster.reject_for_path_tracer(Path::new("scenes/cornell.toml")).unwrap_err().to_string();
    assert!(error.contains("--look, --no-antialiasing apply only to the rasterizer"), "{error}");
    RasterArgs::default().reject_for_path_tracer(Path::new("scenes/cornell.toml")).unwrap();
}
