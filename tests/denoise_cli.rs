//! `render --denoise` as a user runs it: the files it writes, the error it reports and stops
//! at, and the flags it refuses.

#[path = "common/binary.rs"]
mod binary;

use binary::{assert_refused, field, metadata, run, text, words};

/// The EXR holds the denoised image with layers `noisy`, `albedo` and `normal`, and metadata
/// saying which denoiser ran, the total spp (an odd target rounded up to even) and the
/// denoised image's estimated error, below the raw image's (64 x 64: at 32 x 32 the light's
/// edge and the box's outline are so large a share of the pixels that the filter gains
/// nothing, and the estimate says so); the PNG is written too. For à-trous always, and for
/// Open Image Denoise in builds that have it (`--features illum-denoise/oidn`), whose
/// estimate is only required to be finite: the halves' estimate overstates OIDN's error, at
/// 16 spp beyond the raw image's (docs/denoising-oidn.md).
#[test]
fn denoise_writes_the_image_its_guide_layers_and_its_estimated_error() {
    let denoisers: &[&str] = if illum_denoise::OIDN_BUILT { &["atrous", "oidn"] } else { &["atrous"] };
    for &denoiser in denoisers {
        let dir = tempfile::tempdir().unwrap();
        let (exr, png) = (dir.path().join("d.exr"), dir.path().join("d.png"));
        let out = run(&words(
            "--width 64 --height 64 --spp 15 --denoise",
            &[denoiser, "-o", exr.to_str().unwrap(), "-o", png.to_str().unwrap()],
        ));
        assert!(out.status.success(), "{denoiser}: {}", text(&out.stderr));
        assert!(png.exists());
        let meta = metadata(&exr);
        assert_eq!(field(&meta, "denoiser"), denoiser);
        assert_eq!(field(&meta, "spp"), "16");
        let denoised: f64 = field(&meta, "estimated_relative_error").parse().unwrap();
        let raw: f64 = field(&meta, "raw_estimated_relative_error").parse().unwrap();
        println!("{denoiser}: estimated relative error {denoised:.4} denoised, {raw:.4} raw");
        assert!(denoised.is_finite(), "{denoiser}: denoised {denoised}");
        assert!(denoiser == "oidn" || denoised < raw, "{denoiser}: denoised {denoised}, raw {raw}");
        let header = illum::image::load_exr_header(&exr).unwrap();
        for layer in ["noisy", "albedo", "normal"] {
            assert!(header.layers.iter().any(|l| l == layer), "no layer {layer}: {:?}", header.layers);
        }
    }
}

/// `--target-error` with `--denoise` stops at the denoised image's estimated error, which is
/// reached with fewer samples than the raw image would need.
#[test]
fn the_error_target_applies_to_the_denoised_image() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("t.exr");
    let out = run(&words(
        "--width 64 --height 64 --target-error 0.09 --denoise atrous -o",
        &[exr.to_str().unwrap()],
    ));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let meta = metadata(&exr);
    assert_eq!(field(&meta, "stopped_by"), "target_error");
    let denoised: f64 = field(&meta, "estimated_relative_error").parse().unwrap();
    let raw: f64 = field(&meta, "raw_estimated_relative_error").parse().unwrap();
    assert!(denoised <= 0.09, "stopped at {denoised}");
    assert!(raw > 0.09, "the raw image alone ({raw}) had reached the target: the test shows nothing");
}

#[test]
fn bad_denoise_flags_are_clear_errors() {
    let small = ["--width", "16", "--height", "16", "--spp", "4"];
    let with = |extra: &[&str]| -> Vec<String> { small.iter().chain(extra).map(|s| s.to_string()).collect() };
    let case = |extra: &[&str]| {
        let args = with(extra);
        run(&args.iter().map(String::as_str).collect::<Vec<_>>())
    };
    assert_refused(&case(&["--denoise", "blur"]), "--denoise blur", &["blur", "atrous or oidn"]);
    assert_refused(
        &case(&["--denoise", "atrous", "--adaptive"]),
        "--denoise --adaptive",
        &["--denoise", "--adaptive"],
    );
    if !illum_denoise::OIDN_BUILT {
        assert_refused(
            &case(&["--denoise", "oidn"]),
            "--denoise oidn",
            &["Open Image Denoise", "--features illum-denoise/oidn", "OIDN_DIR", "--denoise atrous"],
        );
    }
    let raster = ["scenes/whitted.toml", "--renderer", "raster", "--denoise", "atrous"];
    assert_refused(&run(&raster), "--denoise with the rasterizer", &["--denoise"]);
    let auto = ["--renderer", "auto", "--target-error", "0.1", "--denoise", "atrous"];
    assert_refused(&run(&auto), "--denoise with --renderer auto", &["--renderer auto", "--denoise"]);
}
