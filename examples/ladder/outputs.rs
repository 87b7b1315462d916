//! The ladder's outputs: the CSV, the Markdown tables, the plots, the contact sheet and the
//! region map.

use std::path::Path;

use illum::image::{Encoding, RgbImage32, save_exr, save_rgba8_png, to_rgba8};
use illum::scene::Scene;
use illum_lab::contact_sheet::contact_sheet;
use illum_lab::plot::{self, Line, Style};
use illum_lab::regions::{Comparison, Regions, flip_heat_map};
use illum_lab::report::{csv_text, host_cpu, markdown_table, write_text};

use crate::rungs::{Rung, Series};

pub(crate) struct Row {
    pub(crate) rung: Rung,
    pub(crate) errors: Comparison,
}

pub(crate) struct Header<'a> {
    pub(crate) scene: &'a Scene,
    pub(crate) adapter: &'a str,
    pub(crate) truth_spp: u64,
    pub(crate) truth_bounces: String,
    pub(crate) truth_error: f64,
    /// The truth's own metadata, written with its copy `truth.exr`.
    pub(crate) truth_metadata: illum::image::ExrMetadata,
}

fn number(x: f64) -> String {
    if x.is_nan() { "n/a".to_owned() } else { format!("{x:.3e}") }
}

/// Efficiency, 1 / (relMSE x seconds): for an unbiased renderer (relMSE falling as 1/time) the
/// same at any spp, so settings compare by it; a biased one's falls as its time grows.
fn efficiency(rel_mse: f64, wall_ms: f64) -> f64 {
    1.0 / (rel_mse * wall_ms * 1e-3)
}

fn ratio(x: f64) -> String {
    if x.is_nan() { "n/a".to_owned() } else { format!("{x:.3}") }
}

pub(crate) fn write_outputs(
    out: &Path,
    header: &Header,
    truth: &RgbImage32,
    regions: &Regions,
    rows: &[Row],
    tessellation: &str,
) -> anyhow::Result<()> {
    let sizes = regions.sizes();
    // CSV: one line per row and region ("all" for the whole image).
    let mut lines = Vec::new();
    for row in rows {
        let r = &row.rung;
        let all = std::iter::once(("all", &row.errors.overall));
        let each = regions.names.iter().map(String::as_str).zip(&row.errors.regions);
        for (region, e) in all.chain(each) {
            lines.push(vec![
                r.renderer.to_owned(),
                r.settings.clone(),
                format!("{:.4}", r.wall_ms),
                r.gpu_ms.map_or(String::new(), |g| format!("{g:.4}")),
                region.to_owned(),
                e.pixels.to_string(),
                format!("{:e}", e.rel_mse),
                format!("{}", e.luminance_ratio),
                format!("{}", e.flip),
                format!("{:e}", efficiency(e.rel_mse, r.wall_ms)),
            ]);
        }
    }
    let csv_header = [
        "renderer",
        "settings",
        "wall_ms",
        "gpu_ms",
        "region",
        "pixels",
        "rel_mse",
        "luminance_ratio",
        "flip",
        "efficiency",
    ];
    write_text(&out.join("ladder.csv"), &csv_text(&csv_header, &lines)?)?;

    // Markdown: the overall table, then one table per metric with a column per region.
    let s = header.scene;
    // The command that made the page, less where its files went.
    let mut command = vec!["cargo run --release --example ladder --".to_owned()];
    let mut given = std::env::args().skip(1);
    while let Some(arg) = given.next() {
        match arg.as_str() {
            "--out" => _ = given.next(),
            a if a.starts_with("--out=") => {}
            _ => command.push(arg),
        }
    }
    let mut md = format!(
        "# The ladder: `{}`\n\n\
         Every renderer and setting on one scene, timed, and compared with a converged path-traced \
         truth, overall and per region. Made by `{}`.\n\n\
         Scene `{}` at {}x{}, {} on {}. Truth: path traced, {} spp, bounces {}, its own estimated relMSE {}. \
         Times are medians over frames; errors are against the truth (relMSE with epsilon 0.01; \
         efficiency = 1 / (relMSE x wall seconds), the same at any spp for an unbiased renderer; \
         luminance ratio = mean luminance / the truth's; FLIP = mean LDR-FLIP, sRGB, exposure 0).\n\n",
        s.name,
        command.join(" "),
        s.name,
        s.camera.width,
        s.camera.height,
        header.adapter,
        host_cpu(),
        header.truth_spp,
        header.truth_bounces,
        number(header.truth_error)
    );
    let overall: Vec<Vec<String>> = rows
        .iter()
        .map(|row| {
            let (r, e) = (&row.rung, &row.errors.overall);
            vec![
                r.renderer.to_owned(),
                r.settings.clone(),
                format!("{:.2}", r.wall_ms),
                r.gpu_ms.map_or("-".to_owned(), |g| format!("{g:.2}")),
                number(e.rel_mse),
                number(efficiency(e.rel_mse, r.wall_ms)),
                ratio(e.luminance_ratio),
                ratio(e.flip),
            ]
        })
        .collect();
    md.push_str(&markdown_table(
        &["renderer", "settings", "wall ms", "GPU ms", "relMSE", "efficiency", "luminance ratio", "FLIP"],
        &overall,
    ));
    md.push_str(tessellation);
    let region_header: Vec<String> = std::iter::once("renderer, settings".to_owned())
        .chain(regions.names.iter().zip(&sizes).map(|(n, px)| format!("{n} ({px} px)")))
        .collect();
    let region_header: Vec<&str> = region_header.iter().map(String::as_str).collect();
    type Metric = (&'static str, fn(&illum_lab::regions::Errors) -> String);
    let metrics: [Metric; 3] = [
        ("relMSE per region", |e| number(e.rel_mse)),
        ("Luminance ratio per region (1 = the truth's brightness)", |e| ratio(e.luminance_ratio)),
        ("FLIP per region", |e| ratio(e.flip)),
    ];
    for (title, show) in metrics {
        let table: Vec<Vec<String>> = rows
            .iter()
            .map(|row| {
                std::iter::once(format!("{}, {}", row.rung.renderer, row.rung.settings))
                    .chain(row.errors.regions.iter().map(show))
                    .collect()
            })
            .collect();
        md.push_str(&format!("\n{title}:\n\n"));
        md.push_str(&markdown_table(&region_header, &table));
    }
    write_text(&out.join("ladder.md"), &md)?;

    // Plots: error against time, one series per renderer.
    for (file, title, label, value) in [
        ("error-vs-time.png", "relMSE against time per frame", "relMSE", 0),
        ("flip-vs-time.png", "FLIP against time per frame", "mean FLIP", 1),
    ] {
        let series = [
            ("rasterizer", Series::Raster, Style::Markers),
            ("Whitted ray tracer", Series::Whitted, Style::Markers),
            ("path tracer, more spp", Series::PathTraceSpp, Style::Joined),
            ("path tracer + caustic estimator, more spp", Series::PathTraceCaustics, Style::Joined),
            ("path tracer + manifold NEE, more spp", Series::PathTraceManifold, Style::Joined),
            (
                "path tracer + manifold NEE, low-discrepancy (one randomisation), more spp",
                Series::PathTraceManifoldLowDiscrepancy,
                Style::Joined,
            ),
            ("path tracer, more bounces", Series::PathTraceBounces, Style::Joined),
            ("path tracer + à-trous, more spp", Series::PathTraceAtrous, Style::Joined),
            ("path tracer + OIDN, more spp", Series::PathTraceOidn, Style::Joined),
            ("path tracer, the sphere and icospheres", Series::Tessellation, Style::Markers),
        ];
        let lines: Vec<Line> = series
            .iter()
            .map(|&(label, series, style)| Line {
                label: label.to_owned(),
                points: rows
                    .iter()
                    .filter(|r| r.rung.series == series)
                    .map(|r| {
                        let e = &r.errors.overall;
                        (r.rung.wall_ms, if value == 0 { e.rel_mse } else { e.flip })
                    })
                    .collect(),
                style,
            })
            .filter(|l| !l.points.is_empty())
            .collect();
        plot::log_log(&out.join(file), title, "wall time per frame (ms)", label, &lines)?;
    }

    // Images: the truth, the regions, then each row's image and FLIP map.
    let (w, h) = (truth.width, truth.height);
    let png = |i: &RgbImage32| to_rgba8(i, 0.0, Encoding::Srgb);
    let region_map = region_colours(regions, w, h);
    save_rgba8_png(out.join("regions.png"), &region_map)?;
    // With the metadata of the render it is (renderer, scene, time, spp, settings).
    save_exr(out.join("truth.exr"), truth, &header.truth_metadata)?;
    let legend = regions.names.join("; ");
    let mut panels = vec![
        (format!("truth: path traced, {} spp", header.truth_spp), png(truth)),
        (format!("regions: {legend}"), region_map),
    ];
    for row in rows {
        let (r, e) = (&row.rung, &row.errors.overall);
        panels.push((format!("{} {}: {:.2} ms", r.renderer, r.settings, r.wall_ms), png(&r.image)));
        panels.push((
            format!("FLIP {:.3}, relMSE {}, luminance x{:.3}", e.flip, number(e.rel_mse), e.luminance_ratio),
            flip_heat_map(&row.errors.flip_map, w, h),
        ));
    }
    save_rgba8_png(out.join("contact-sheet.png"), &contact_sheet(&panels, 4))?;
    println!(
        "wrote {}/ladder.csv, ladder.md, error-vs-time.png, flip-vs-time.png, contact-sheet.png",
        out.display()
    );
    Ok(())
}

/// The regions drawn in distinct colours, in the order of their names.
fn region_colours(regions: &Regions, w: u32, h: u32) -> image::RgbaImage {
    const PALETTE: [[u8; 3]; 8] = [
        [120, 170, 230],
        [230, 200, 60],
        [120, 60, 160],
        [200, 80, 60],
        [80, 180, 120],
        [220, 220, 220],
        [160, 100, 40],
        [60, 60, 60],
    ];
    image::RgbaImage::from_fn(w, h, |x, y| {
        let c = PALETTE[regions.of_pixel[(y * w + x) as usize] % PALETTE.len()];
        image::Rgba([c[0], c[1], c[2], 255])
    })
}
