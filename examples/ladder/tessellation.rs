//! The tessellation rows (`--tessellate`, `--tessellate-flat`): the scene's spheres replaced by
//! icospheres, path traced at one sample count, against the truth of the analytic scene, so that what
//! the rows measure beyond the analytic sphere's own row is what the tessellation costs.
//!
//! Convention: the icosphere of subdivision k is `scenes/models/icosphere-K.obj` (written by
//! scripts/icosphere.py), whose vertices lie on the unit sphere, placed with the sphere's centre
//! as its translation and the sphere's radius as its scale. Its vertices are on the sphere and
//! its faces inside it (the icosphere is inscribed). Shaded smoothly, each vertex's normal is
//! the sphere's there (`illum_scene::testing::obj::icosphere_obj`); flat, each face's own.
//!
//! The sphere's pixels get regions of their own, cut by its true normal n at the point the
//! pixel's centre ray meets it (view direction v towards the camera, l towards the scene's first
//! light, the one the object-ID image's shadows are taken from): its rim (n.v < sin 20 deg, the
//! outer 6% of its radius as seen, where an inscribed polygon's outline falls inside the
//! sphere's), its shadow terminator (|n.l| < sin 20 deg, where the light grazes the surface and
//! a low-poly mesh's facets shadow one another against their shading normals), and the lit and
//! dark sides beyond it.

use std::collections::BTreeMap;

use anyhow::bail;
use glam::DVec3;

use illum::gpu::GpuContext;
use illum::scene::{MaterialKind, Scene, Shape, Sphere};
use illum::whitted::ObjectIds;
use illum_lab::regions::{Comparison, Regions, compare};
use illum_lab::report::{load_average, markdown_table};
use illum_scene::testing::obj::{icosphere_obj, scene_with_files};

use crate::rungs::{PathTraceRow, Rung, Series, print_rung};

/// The subdivisions scenes/models holds (scripts/icosphere.py).
pub(crate) const SUBDIVISIONS: std::ops::RangeInclusive<u32> = 0..=4;

/// The sheet of the tessellation rows, in the output folder.
pub(crate) const SHEET: &str = "tessellation-sheet.png";

/// A region whose share of a row's difference is this many times its share of the pixels is
/// where the difference concentrates.
const CONCENTRATED: f64 = 5.0;

/// The cut between the rim or the terminator and the rest: sin 20 degrees.
const BAND: f64 = 0.342;

/// What stands in a tessellation row's scene where the analytic scene has its spheres.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Geometry {
    Analytic,
    Icosphere { subdivision: u32, smooth: bool },
}

impl Geometry {
    fn label(self) -> String {
        match self {
            Geometry::Analytic => "analytic sphere".to_owned(),
            Geometry::Icosphere { subdivision: k, smooth } => format!(
                "icosphere-{k} ({} triangles), {}",
                triangles(k),
                if smooth { "smooth" } else { "flat" }
            ),
        }
    }
}

/// The icosphere of subdivision k has 20 4^k triangles.
fn triangles(k: u32) -> u32 {
    20 * 4u32.pow(k)
}

/// The geometries of the rows, the analytic sphere first; refused for a scene without a sphere.
pub(crate) fn geometries(scene: &Scene, smooth: &[u32], flat: &[u32]) -> anyhow::Result<Vec<Geometry>> {
    if !scene.objects.iter().any(|o| matches!(o.shape, Shape::Sphere(_))) {
        bail!("--tessellate: scene {} has no sphere to tessellate", scene.name);
    }
    if let Some(k) = smooth.iter().chain(flat).find(|k| !SUBDIVISIONS.contains(k)) {
        bail!("--tessellate {k}: scenes/models holds the icospheres of subdivision 0 to 4");
    }
    let icospheres = |list: &[u32], smooth: bool| {
        list.iter().map(move |&subdivision| Geometry::Icosphere { subdivision, smooth }).collect::<Vec<_>>()
    };
    let mut all = vec![Geometry::Analytic];
    all.extend(icospheres(smooth, true));
    all.extend(icospheres(flat, false));
    Ok(all)
}

/// `scene` with every sphere replaced by `geometry` (see the module's comment).
pub(crate) fn tessellated(scene: &Scene, geometry: Geometry) -> anyhow::Result<Scene> {
    let Geometry::Icosphere { subdivision: k, smooth } = geometry else { return Ok(scene.clone()) };
    let file = format!("icosphere-{k}.obj");
    let obj = icosphere_obj(k, smooth);
    let mut out = scene.clone();
    for object in &mut out.objects {
        let Shape::Sphere(Sphere { center: c, radius }) = object.shape else { continue };
        // The mesh loader places it: a scene holding only the mesh, its eye at the origin so that
        // its positions are measured from where this scene's are.
        let holder = format!(
            "[camera]\neye = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, 1.0]\nup = [0.0, 1.0, 0.0]\nvfov = 45.0\n\
             width = 1\nheight = 1\n[materials.m]\nalbedo = [0.5, 0.5, 0.5]\n[[objects]]\nmaterial = \"m\"\n\
             mesh = {{ file = \"{file}\", translate = [{:?}, {:?}, {:?}], scale = {radius:?}, flat = {} }}\n",
            c.x, c.y, c.z, !smooth
        );
        let holder = scene_with_files(&holder, "tessellation.toml", &[(&file, &obj)])?;
        object.shape = holder.objects[0].shape.clone();
    }
    out.name = format!("{}, {}", scene.name, geometry.label());
    Ok(out)
}

/// The rows: each geometry path traced at `spp` with the scene's bounces, and the host's load
/// average before and after them (", load average A before them, B after"). The runs are
/// interleaved (every geometry once, then again), so that a change in the machine's load
/// weighs on every row alike and the times' ratios hold.
pub(crate) fn tessellation_rungs(
    gpu: &GpuContext,
    scene: &Scene,
    geometries: &[Geometry],
    spp: u32,
    runs: u32,
) -> anyhow::Result<(Vec<(Geometry, Rung)>, String)> {
    let setting = (spp, scene.pathtrace.bounces);
    let load = load_average().map_or(String::new(), |l| format!(", load average {l} before them"));
    let mut rows = Vec::new();
    for &geometry in geometries {
        rows.push((
            geometry,
            PathTraceRow::new(gpu, &tessellated(scene, geometry)?, setting, Default::default())?,
        ));
    }
    for _ in 0..runs.max(1) {
        for (_, row) in &mut rows {
            row.run()?;
        }
    }
    let load = format!("{load}{}", load_average().map_or(String::new(), |l| format!(", {l} after")));
    let rungs = rows
        .into_iter()
        .map(|(geometry, row)| {
            let mut rung = row.rung(Series::Tessellation);
            rung.settings = format!("{}, {}", geometry.label(), rung.settings);
            print_rung(&rung);
            (geometry, rung)
        })
        .collect();
    Ok((rungs, load))
}

/// Which band of a sphere a pixel's centre ray meets it in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Band {
    Rim,
    Terminator,
    Lit,
    Dark,
}

impl Band {
    fn name(self) -> &'static str {
        match self {
            Band::Rim => "rim (its outline's band)",
            Band::Terminator => "shadow terminator",
            Band::Lit => "lit side",
            Band::Dark => "dark side",
        }
    }
}

/// `regions` with the pixels of each diffuse sphere cut into its bands (the module's comment).
pub(crate) fn with_sphere_bands(scene: &Scene, regions: &Regions, ids: &ObjectIds) -> Regions {
    let light = first_light(scene);
    let camera = &scene.camera;
    let eye = camera.eye.as_dvec3();
    #[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
    enum Key {
        Base(usize),
        Band(usize, Band),
    }
    let keys: Vec<Key> = (0..ids.hit.len())
        .map(|i| {
            let base = Key::Base(regions.of_pixel[i]);
            let Some(object) = ids.hit[i] else { return base };
            let o = &scene.objects[object];
            let diffuse = matches!(
                scene.materials[o.material].kind,
                MaterialKind::Lambertian { .. } | MaterialKind::Checker(_)
            );
            let Shape::Sphere(Sphere { center, radius }) = o.shape else { return base };
            if !diffuse {
                return base;
            }
            let (x, y) = ((i as u32 % ids.width) as f32 + 0.5, (i as u32 / ids.width) as f32 + 0.5);
            let d = camera.ray_direction(x, y).as_dvec3();
            Key::Band(object, band(eye, d, center.as_dvec3(), f64::from(radius), light))
        })
        .collect();
    let mut order: BTreeMap<Key, usize> = keys.iter().map(|&k| (k, 0)).collect();
    let mut names = Vec::new();
    for (key, index) in order.iter_mut() {
        *index = names.len();
        names.push(match *key {
            Key::Base(r) => regions.names[r].clone(),
            Key::Band(o, band) => format!("{}, {}", scene.objects[o].name, band.name()),
        });
    }
    Regions { names, of_pixel: keys.iter().map(|k| order[k]).collect() }
}

/// Where the scene's first light is, as the object-ID image's shadows take it: the sun's
/// direction, else the centre of the first emitting quad.
#[derive(Clone, Copy)]
enum Light {
    Direction(DVec3),
    Point(DVec3),
    None,
}

fn first_light(scene: &Scene) -> Light {
    if let Some(sun) = &scene.directional_light {
        return Light::Direction(sun.to_light().as_dvec3());
    }
    match scene.emitters().next() {
        Some((_, _, q)) => Light::Point((q.corner + 0.5 * (q.edge_u + q.edge_v)).as_dvec3()),
        None => Light::None,
    }
}

/// The band of the sphere (centre c, radius r) where the ray from `eye` along unit `d` meets it;
/// a ray that grazes past it in f64 (the object-ID image's f32 ray met it) is on the rim.
fn band(eye: DVec3, d: DVec3, c: DVec3, r: f64, light: Light) -> Band {
    let oc = eye - c;
    let b = oc.dot(d);
    let disc = b * b - (oc.length_squared() - r * r);
    if disc < 0.0 {
        return Band::Rim;
    }
    let t = -b - disc.sqrt();
    let p = eye + t * d;
    let n = (p - c) / r;
    if n.dot(-d) < BAND {
        return Band::Rim;
    }
    let cos_light = match light {
        Light::Direction(l) => n.dot(l),
        Light::Point(q) => n.dot((q - p).normalize()),
        Light::None => return Band::Lit,
    };
    if cos_light.abs() < BAND {
        Band::Terminator
    } else if cos_light > 0.0 {
        Band::Lit
    } else {
        Band::Dark
    }
}

/// The part of the image the sheet of the tessellation rows shows: the box of the pixels that
/// see a sphere, widened by half its size on each side (for its shadow and its neighbours'
/// reflected light), clipped to the image; as (x0, y0, width, height).
pub(crate) fn sphere_crop(scene: &Scene, ids: &ObjectIds) -> Option<[u32; 4]> {
    let on_sphere = |i: usize| ids.hit[i].is_some_and(|o| matches!(scene.objects[o].shape, Shape::Sphere(_)));
    let (mut lo, mut hi) = ([u32::MAX; 2], [0u32; 2]);
    for i in (0..ids.hit.len()).filter(|&i| on_sphere(i)) {
        let p = [i as u32 % ids.width, i as u32 / ids.width];
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    if lo[0] > hi[0] {
        return None;
    }
    let size = [ids.width, ids.height];
    let margin = [0, 1].map(|a| (hi[a] - lo[a]).div_ceil(2));
    let [x0, y0] = [0, 1].map(|a| lo[a].saturating_sub(margin[a]));
    let [x1, y1] = [0, 1].map(|a| (hi[a] + margin[a]).min(size[a] - 1));
    Some([x0, y0, x1 - x0 + 1, y1 - y0 + 1])
}

/// `image`'s part `crop`, enlarged by repeating each pixel so that it is about 240 pixels wide.
fn zoomed(image: &image::RgbaImage, [x0, y0, w, h]: [u32; 4]) -> image::RgbaImage {
    let zoom = (240 / w).max(1);
    image::RgbaImage::from_fn(w * zoom, h * zoom, |x, y| *image.get_pixel(x0 + x / zoom, y0 + y / zoom))
}

/// The sheet of the tessellation rows: for each, its image around the sphere and FLIP's map of
/// its difference from the analytic row's image (black: none), enlarged.
pub(crate) fn sheet(rows: &[TessellationRow], crop: [u32; 4]) -> image::RgbaImage {
    let png = |i: &illum::image::RgbImage32| illum::image::to_rgba8(i, 0.0, illum::image::Encoding::Srgb);
    let mut panels = Vec::new();
    for row in rows {
        let (w, h) = (row.rung.image.width, row.rung.image.height);
        panels.push((
            format!("{}, {:.0} ms", row.geometry.label(), row.rung.wall_ms),
            zoomed(&png(&row.rung.image), crop),
        ));
        panels.push((
            format!("FLIP against the analytic sphere's image: {:.4}", row.against.overall.flip),
            zoomed(&illum_lab::regions::flip_heat_map(&row.against.flip_map, w, h), crop),
        ));
    }
    illum_lab::contact_sheet::contact_sheet(&panels, 4)
}

/// A tessellation row with its errors against the truth and against the analytic row's image.
pub(crate) struct TessellationRow<'a> {
    pub(crate) geometry: Geometry,
    pub(crate) rung: &'a Rung,
    pub(crate) truth: &'a Comparison,
    pub(crate) against: Comparison,
}

/// The rows with their comparison against the analytic row's image (none without that row).
pub(crate) fn compared<'a>(
    rows: &[(Geometry, &'a Rung, &'a Comparison)],
    regions: &Regions,
) -> Vec<TessellationRow<'a>> {
    let Some(&(_, analytic, _)) = rows.iter().find(|(g, ..)| *g == Geometry::Analytic) else {
        return Vec::new();
    };
    rows.iter()
        .map(|&(geometry, rung, truth)| TessellationRow {
            geometry,
            rung,
            truth,
            against: compare(&rung.image, &analytic.image, regions),
        })
        .collect()
}

/// The Markdown section on the tessellation rows: each against the truth and against the
/// analytic row's image, which had the same samples (the same seed: pixels whose paths never
/// meet the sphere come out the same, so what differs is the geometry's doing), and the
/// regions that hold most of that difference.
pub(crate) fn section(rows: &[TessellationRow], regions: &Regions, timing: &str) -> String {
    let Some(analytic) = rows.iter().find(|r| r.geometry == Geometry::Analytic) else {
        return String::new();
    };
    let sizes = regions.sizes();
    let total: usize = sizes.iter().sum();
    let mut table = Vec::new();
    let mut notes = Vec::new();
    for row in rows {
        let (geometry, rung, against) = (row.geometry, row.rung, &row.against);
        let (t, a) = (&row.truth.overall, &against.overall);
        // Each region's share of the squared difference: relMSE is a mean over its pixels.
        let weight: Vec<f64> =
            against.regions.iter().zip(&sizes).map(|(e, &n)| e.rel_mse * n as f64).collect();
        let sum: f64 = weight.iter().sum();
        let mut ranked: Vec<usize> = (0..weight.len()).collect();
        ranked.sort_by(|&i, &j| weight[j].total_cmp(&weight[i]));
        let share = |i: usize| {
            format!(
                "{}: {:.0}% of it in {:.1}% of the pixels",
                regions.names[i],
                100.0 * weight[i] / sum,
                100.0 * sizes[i] as f64 / total as f64
            )
        };
        let where_ = if geometry == Geometry::Analytic || sum <= 0.0 {
            "-".to_owned()
        } else {
            ranked.iter().take(2).map(|&i| share(i)).collect::<Vec<_>>().join("; ")
        };
        // The terminator is named where the difference concentrates there: one of the two
        // regions holding the most of it, with at least CONCENTRATED times its share of the pixels.
        let terminator = ranked
            .iter()
            .take(2)
            .copied()
            .find(|&i| regions.names[i].ends_with(Band::Terminator.name()))
            .filter(|_| geometry != Geometry::Analytic && sum > 0.0);
        if let Some(i) = terminator {
            let (part, pixels) = (weight[i] / sum, sizes[i] as f64 / total as f64);
            if part >= CONCENTRATED * pixels {
                notes.push(format!(
                    "- {}: the shadow terminator holds {:.0}% of its difference from the analytic \
                     sphere's image in {:.1}% of the pixels, {:.0} times their share.",
                    geometry.label(),
                    100.0 * part,
                    100.0 * pixels,
                    part / pixels
                ));
            }
        }
        table.push(vec![
            geometry.label(),
            format!("{:.1}", rung.wall_ms),
            format!("{:.2}", rung.wall_ms / analytic.rung.wall_ms),
            format!("{:.3e}", t.rel_mse),
            format!("{:+.3e}", t.rel_mse - analytic.truth.overall.rel_mse),
            format!("{:.3}", t.flip),
            format!("{:.3e}", a.rel_mse),
            format!("{:.3}", a.flip),
            where_,
        ]);
    }
    let mut md = format!(
        "\n## Tessellation: what replacing the sphere by an icosphere costs\n\n\
         Each row path traces the scene at {} with its spheres replaced (the first row keeps them), \
         with the same seed; its time is the median of its runs, the rows' runs taken in turn{timing}. The icosphere of subdivision k (scenes/models/icosphere-k.obj) is \
         inscribed: its vertices lie on the sphere, its faces inside it. Smooth rows shade with \
         the sphere's normal at each vertex, interpolated; flat rows with each face's normal. \
         Against the truth (of the analytic scene) each row's error is its noise plus what the \
         tessellation changes, so the excess over the analytic row is the tessellation's. Against \
         the analytic row's image, which had the same samples, most of the noise cancels (a pixel \
         whose paths never meet the sphere comes out the same), and what is left is where the \
         tessellation changes the image; the last column names the two regions holding the most \
         of that difference. The sphere's regions are cut by its true normal: its rim \
         (n.v < sin 20 deg), its shadow terminator (|n.l| < sin 20 deg, l towards the light's \
         centre), its lit and its dark side.\n\n",
        analytic.rung.settings.trim_start_matches("analytic sphere, ")
    );
    md.push_str(&markdown_table(
        &[
            "geometry",
            "wall ms",
            "time / analytic",
            "relMSE vs truth",
            "excess over analytic",
            "FLIP vs truth",
            "relMSE vs analytic image",
            "FLIP vs analytic image",
            "where the difference from the analytic image lies",
        ],
        &table,
    ));
    if !notes.is_empty() {
        md.push_str(&format!("\nThe shadow terminator:\n\n{}\n", notes.join("\n")));
    }
    md.push_str(&format!(
        "\nAround the sphere, each row's image and FLIP's map of its difference from the analytic \
         row's image (black: none), enlarged:\n\n![{SHEET}]({SHEET})\n\n\
         The ladder's tables below hold these rows too, with every region.\n"
    ));
    md
}
