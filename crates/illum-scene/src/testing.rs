//! Helpers for tests of scene validation, shared by every crate's error tests (the scene
//! crate's own, and the renderers' checks of what they refuse), so that each rule is checked
//! the same way: a panic with the error when it does not match.

use serde::Deserialize;

pub mod obj;

use crate::error::SceneError;

/// `text` with its one occurrence of `from` replaced by `to`; panics unless `from` occurs
/// exactly once (an edit that silently missed would test the unedited scene).
pub fn edit_once(text: &str, from: &str, to: &str) -> String {
    edited(text, from, to).unwrap_or_else(|problem| panic!("{problem}"))
}

/// [`edit_once`], with the problem as an error instead of a panic.
fn edited(text: &str, from: &str, to: &str) -> Result<String, String> {
    match text.matches(from).count() {
        1 => Ok(text.replacen(from, to, 1)),
        n => Err(format!("{from:?} must occur once, occurs {n} times")),
    }
}

/// `text` without each of `cuts`, each of which must occur exactly once (see [`edit_once`]).
pub fn without(text: &str, cuts: &[&str]) -> String {
    cuts.iter().fold(text.to_owned(), |text, cut| edit_once(&text, cut, ""))
}

/// Asserts that `err` is [`SceneError::Invalid`] for `file` and `field` with the shown `value`,
/// that what it allows contains `allowed`, and that the displayed message starts with
/// `FILE: FIELD = VALUE: ` and contains all four parts.
pub fn check_invalid(err: &SceneError, file: &str, field: &str, value: &str, allowed: &str) {
    if let Err(problem) = invalid_mismatch(err, file, field, value, allowed) {
        panic!("{problem}");
    }
}

/// What [`check_invalid`] asserts, with the first mismatch as an error.
fn invalid_mismatch(
    err: &SceneError,
    file: &str,
    field: &str,
    value: &str,
    allowed: &str,
) -> Result<(), String> {
    let SceneError::Invalid { file: f, field: fd, value: v, allowed: a } = err else {
        return Err(format!("expected Invalid on {field}, got {err:?}"));
    };
    if (f.as_str(), fd.as_str(), v.as_str()) != (file, field, value) {
        return Err(format!("expected {file}: {field} = {value}, got {err}"));
    }
    if !a.contains(allowed) {
        return Err(format!("allowed {a:?} lacks {allowed:?}"));
    }
    let shown = err.to_string();
    if let Some(part) = [file, field, value, allowed].into_iter().find(|part| !shown.contains(part)) {
        return Err(format!("{shown:?} lacks {part:?}"));
    }
    if !shown.starts_with(&format!("{file}: {field} = {value}: ")) {
        return Err(format!("{shown:?} does not start with {file}: {field} = {value}: "));
    }
    Ok(())
}

/// A shipped scene file (`scenes/NAME`, found from any crate's tests) at a test's resolution;
/// panics with the loader's message if it does not load.
pub fn shipped_scene(name: &str, width: u32, height: u32) -> crate::Scene {
    let path = crate::resolve_scene_path(&std::path::Path::new("scenes").join(name));
    let mut scene = crate::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    scene.camera.width = width;
    scene.camera.height = height;
    scene
}

/// `scene` with `count` spheres of radius 0.3 added, resting on the plane y = 0 in rows of nine
/// one unit apart (x from 5 toward -x, z from -6 to 2), clear of the scene's own spheres, their
/// materials cycling through the scene's `glass` and `metal` (the Whitted scene's) and an added
/// diffuse white: a scene of many objects, past the traversal's literal limit, for the
/// renderers' agreement tests.
pub fn with_small_spheres(mut scene: crate::Scene, count: usize) -> crate::Scene {
    use crate::{Material, MaterialKind, Object, Shape, Sphere};
    let material = |name: &str| {
        scene.materials.iter().position(|m| m.name == name).unwrap_or_else(|| panic!("no material {name:?}"))
    };
    let materials = [material("glass"), material("metal"), scene.materials.len()];
    scene.materials.push(Material {
        name: "small white".to_owned(),
        kind: MaterialKind::Lambertian { albedo: glam::Vec3::splat(0.8) },
    });
    let own: Vec<Sphere> = scene
        .objects
        .iter()
        .filter_map(|o| match o.shape {
            Shape::Sphere(s) => Some(s),
            _ => None,
        })
        .collect();
    let radius = 0.3;
    let mut added = 0;
    for cell in 0.. {
        if added == count {
            break;
        }
        let centre = glam::Vec3::new(5.0 - (cell / 9) as f32, radius, -6.0 + (cell % 9) as f32);
        let clear = own.iter().all(|s| {
            let d = glam::Vec2::new(s.center.x - centre.x, s.center.z - centre.z);
            d.length() > s.radius + radius + 0.1
        });
        if clear {
            scene.objects.push(Object {
                name: format!("small sphere {added}"),
                material: materials[added % materials.len()],
                shape: Shape::Sphere(Sphere { center: centre, radius }),
            });
            added += 1;
        }
    }
    scene
}

/// [`with_small_spheres`] with every other added sphere replaced by an object of another kind in
/// its place, cycling through a sphere, a quad (a 0.6 square on its lower edge, tilted back, 0.05
/// above the plane), a box rotated by 30 degrees about +Y and an axis-aligned box (0.5 wide,
/// from y = 0.05): a scene of many objects of every analytic kind, for the renderers' agreement
/// tests.
pub fn with_small_objects(scene: crate::Scene, count: usize) -> crate::Scene {
    use crate::{BoxShape, Quad, Shape};
    let first = scene.objects.len();
    let mut scene = with_small_spheres(scene, count);
    for (k, object) in scene.objects[first..].iter_mut().enumerate() {
        let Shape::Sphere(s) = object.shape else { unreachable!("with_small_spheres adds spheres") };
        let base = glam::Vec3::new(s.center.x, 0.05, s.center.z);
        let (name, shape) = match k % 4 {
            0 => continue,
            1 => (
                "quad",
                Shape::Quad(Quad {
                    corner: base - glam::Vec3::new(0.0, 0.0, 0.3),
                    edge_u: glam::Vec3::new(0.0, 0.0, 0.6),
                    edge_v: glam::Vec3::new(-0.2, 0.55, 0.0),
                }),
            ),
            k => (
                "box",
                Shape::Box(BoxShape {
                    min: glam::Vec3::new(-0.25, 0.0, -0.25),
                    max: glam::Vec3::new(0.25, 0.5, 0.25),
                    rotate_y_deg: if k == 2 { 30.0 } else { 0.0 },
                    pivot: glam::Vec3::ZERO,
                    translate: base,
                }),
            ),
        };
        object.name = format!("small {name} {k}");
        object.shape = shape;
    }
    scene
}

/// What an error test edits and how it loads the result: a valid scene text, the file label
/// its errors name, and the loader (`Scene::from_toml_str`, or a renderer's view of a scene).
/// The error tests of every crate share it, so that each checks a rule the same way.
pub struct Edits<T> {
    /// The valid scene every edit starts from.
    pub base: &'static str,
    /// The file label given to the loader, which every error must name.
    pub file: &'static str,
    /// Loads a scene text under a file label.
    pub load: fn(&str, &str) -> Result<T, SceneError>,
}

impl<T: std::fmt::Debug> Edits<T> {
    /// The base with `from` replaced by `to`; `from` must occur exactly once (see [`edit_once`]).
    pub fn edit(&self, from: &str, to: &str) -> String {
        edit_once(self.base, from, to)
    }

    /// `text` loaded under the file label.
    pub fn parse(&self, text: &str) -> Result<T, SceneError> {
        (self.load)(text, self.file)
    }

    /// Asserts `text` fails validation on `field` with the shown `value`, and that the allowed
    /// text contains `allowed`; the displayed message must contain all four parts.
    pub fn expect_invalid(&self, text: &str, field: &str, value: &str, allowed: &str) {
        match self.parse(text) {
            Ok(_) => panic!("expected an error on {field} = {value}, but the scene loaded"),
            Err(e) => check_invalid(&e, self.file, field, value, allowed),
        }
    }

    /// Checks every case of a refusals file (`cases`, the text of the TOML file `cases_file`): the
    /// base edited as a case says must be refused as it says. The file is a list of `[[rule]]`
    /// tables, each with a `name` and its `[[rule.case]]`s (or a `case = [...]` array). A case is
    /// an edit of the base, `from` (text that must occur in it once) replaced by `to`, and the
    /// error it must give: `field`, `value` and `allowed` as for [`check_invalid`], or `syntax`,
    /// text the syntax error's message must contain. A rule's `from`, `field` and `allowed`
    /// stand for each of its cases that does not give its own. A failure names the rule and the
    /// edit of every failing case, not only the first.
    pub fn expect_refusals(&self, cases: &str, cases_file: &str) {
        let refusals: Refusals = toml::from_str(cases).unwrap_or_else(|e| panic!("{cases_file}: {e}"));
        let cases = refusals.rule.iter().flat_map(|rule| rule.case.iter().map(move |case| (rule, case)));
        let failures: Vec<String> = cases
            .clone()
            .filter_map(|(rule, case)| {
                let problem = self.refusal(rule, case).err()?;
                let from = case.from.as_ref().or(rule.from.as_ref());
                Some(format!("rule {:?}, {from:?} -> {:?}: {problem}", rule.name, case.to))
            })
            .collect();
        let checked = cases.count();
        assert!(checked > 0, "{cases_file} has no cases");
        assert!(
            failures.is_empty(),
            "{cases_file}: {} of {checked} cases failed:\n{}",
            failures.len(),
            failures.join("\n")
        );
    }

    /// Checks one case of [`Edits::expect_refusals`].
    fn refusal(&self, rule: &Rule, case: &Case) -> Result<(), String> {
        let given = |own: &Option<String>, default: &Option<String>, key: &str| {
            own.clone().or_else(|| default.clone()).ok_or_else(|| format!("the case gives no {key}"))
        };
        let text = edited(self.base, &given(&case.from, &rule.from, "from")?, &case.to)?;
        let Err(err) = self.parse(&text) else { return Err("the scene loaded".to_owned()) };
        match &case.syntax {
            Some(_) if case.field.is_some() || case.value.is_some() || case.allowed.is_some() => {
                Err("a syntax case gives a field, value or allowed text".to_owned())
            }
            Some(needle) => match &err {
                SceneError::Syntax { message, .. } if message.contains(needle.as_str()) => Ok(()),
                _ => Err(format!("expected a syntax error containing {needle:?}, got {err:?}")),
            },
            None => invalid_mismatch(
                &err,
                self.file,
                &given(&case.field, &rule.field, "field")?,
                &given(&case.value, &None, "value")?,
                &given(&case.allowed, &rule.allowed, "allowed")?,
            ),
        }
    }
}

/// A refusals file, as [`Edits::expect_refusals`] describes it.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Refusals {
    rule: Vec<Rule>,
}

/// One rule of a [`Refusals`] file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Rule {
    /// What the rule is, as a failure names it.
    name: String,
    from: Option<String>,
    field: Option<String>,
    allowed: Option<String>,
    case: Vec<Case>,
}

/// One case of a [`Rule`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Case {
    from: Option<String>,
    to: String,
    field: Option<String>,
    value: Option<String>,
    allowed: Option<String>,
    syntax: Option<String>,
}

/// Scene text with `offset` added to every position it gives: the camera's eye and target,
/// each sphere's centre, each quad's corner, and each box's centre (a box given by min and max
/// moves by its translation). Directions and lengths stay, so a renderer whose image does not
/// depend on where the scene sits draws the same image. Panics on text that is not TOML.
pub fn moved(text: &str, offset: [f64; 3]) -> String {
    let mut table: toml::Table = text.parse().unwrap_or_else(|e| panic!("scene text is not TOML: {e}"));
    let shift = |value: &mut toml::Value| {
        let array = value.as_array_mut().expect("a position is an array");
        for (x, d) in array.iter_mut().zip(offset) {
            let v = x.as_float().or_else(|| x.as_integer().map(|i| i as f64)).expect("a number");
            *x = toml::Value::Float(v + d);
        }
    };
    let camera = table.get_mut("camera").and_then(toml::Value::as_table_mut).expect("a [camera]");
    shift(camera.get_mut("eye").expect("camera.eye"));
    shift(camera.get_mut("target").expect("camera.target"));
    let objects = table.get_mut("objects").and_then(toml::Value::as_array_mut);
    for object in objects.into_iter().flatten().filter_map(toml::Value::as_table_mut) {
        if let Some(s) = object.get_mut("sphere").and_then(toml::Value::as_table_mut) {
            shift(s.get_mut("center").expect("sphere.center"));
        }
        if let Some(q) = object.get_mut("quad").and_then(toml::Value::as_table_mut) {
            shift(q.get_mut("corner").expect("quad.corner"));
        }
        if let Some(b) = object.get_mut("box").and_then(toml::Value::as_table_mut) {
            match b.get_mut("center") {
                Some(center) => shift(center),
                None => shift(b.entry("translate").or_insert(toml::Value::Array(vec![0.0.into(); 3]))),
            }
        }
    }
    toml::to_string(&table).expect("a table serialises")
}

/// Scene text with the whole scene scaled by `scale` about the world origin: every position
/// and every length it gives (the camera's eye, target and clip planes, each shape's place and
/// size, a checkerboard's tile, the rasterizer's PCF radius). Angles, directions, radiance and
/// irradiance stay, so a renderer whose image does not depend on the scene's unit draws the same
/// image. Panics on text that is not TOML.
pub fn scaled(text: &str, scale: f64) -> String {
    let mut table: toml::Table = text.parse().unwrap_or_else(|e| panic!("scene text is not TOML: {e}"));
    let times = |value: &mut toml::Value| {
        let number = |x: &toml::Value| x.as_float().or_else(|| x.as_integer().map(|i| i as f64));
        match value {
            toml::Value::Array(array) => {
                for x in array.iter_mut() {
                    *x = toml::Value::Float(number(x).expect("a number") * scale);
                }
            }
            x => *x = toml::Value::Float(number(x).expect("a number") * scale),
        }
    };
    let scale_keys = |table: &mut toml::Table, keys: &[&str]| {
        for key in keys {
            if let Some(value) = table.get_mut(*key) {
                times(value);
            }
        }
    };
    let camera = table.get_mut("camera").and_then(toml::Value::as_table_mut).expect("a [camera]");
    scale_keys(camera, &["eye", "target", "near", "far"]);
    let objects = table.get_mut("objects").and_then(toml::Value::as_array_mut);
    for object in objects.into_iter().flatten().filter_map(toml::Value::as_table_mut) {
        for (shape, keys) in [
            ("sphere", &["center", "radius"][..]),
            ("quad", &["corner", "edge_u", "edge_v"][..]),
            ("box", &["center", "half_extent", "min", "max", "pivot", "translate"][..]),
        ] {
            if let Some(s) = object.get_mut(shape).and_then(toml::Value::as_table_mut) {
                scale_keys(s, keys);
            }
        }
    }
    let materials = table.get_mut("materials").and_then(toml::Value::as_table_mut);
    for material in
        materials.into_iter().flat_map(|m| m.iter_mut().map(|(_, v)| v)).filter_map(toml::Value::as_table_mut)
    {
        if let Some(checker) = material.get_mut("checker").and_then(toml::Value::as_table_mut) {
            scale_keys(checker, &["tile"]);
        }
    }
    if let Some(raster) = table.get_mut("raster").and_then(toml::Value::as_table_mut) {
        scale_keys(raster, &["pcf_radius"]);
    }
    toml::to_string(&table).expect("a table serialises")
}

/// Scene text with the whole scene turned by `angle_deg` about the axis `axis` through the world
/// origin (right-handed), in f64: every position (the camera's eye and target, each sphere's
/// centre, each quad's corner) and every direction (the camera's up, each quad's edges, the
/// directional light's direction). Lengths, angles and radiance stay, so a renderer whose image
/// does not depend on the scene's orientation draws the same image (the sky is uniform, so it
/// turns with the scene). A box turns only about +Y in the file format: its turn is added to the
/// box's `rotate_y` (a box given by centre and half-extent becomes min, max and that turn), and
/// an axis other than +Y with a box in the scene is `Err` naming the box. Panics on text that is
/// not TOML.
pub fn rotated(text: &str, axis: [f64; 3], angle_deg: f64) -> Result<String, String> {
    let mut table: toml::Table = text.parse().unwrap_or_else(|e| panic!("scene text is not TOML: {e}"));
    let rotation = glam::DMat3::from_axis_angle(glam::DVec3::from(axis).normalize(), angle_deg.to_radians());
    let number =
        |x: &toml::Value| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)).expect("a number");
    let vector = |value: &toml::Value| {
        let array = value.as_array().expect("a vector is an array");
        glam::DVec3::new(number(&array[0]), number(&array[1]), number(&array[2]))
    };
    let to_value = |v: glam::DVec3| toml::Value::Array(v.to_array().map(toml::Value::Float).to_vec());
    let turn = |value: &mut toml::Value| *value = to_value(rotation * vector(value));
    let turn_keys = |table: &mut toml::Table, keys: &[&str]| {
        for key in keys {
            if let Some(value) = table.get_mut(*key) {
                turn(value);
            }
        }
    };
    let camera = table.get_mut("camera").and_then(toml::Value::as_table_mut).expect("a [camera]");
    camera.entry("up").or_insert(to_value(glam::DVec3::Y));
    turn_keys(camera, &["eye", "target", "up"]);
    if let Some(light) = table.get_mut("directional_light").and_then(toml::Value::as_table_mut) {
        turn_keys(light, &["direction"]);
    }
    let about_y = glam::DVec3::from(axis).normalize().abs_diff_eq(glam::DVec3::Y, 1e-15);
    let objects = table.get_mut("objects").and_then(toml::Value::as_array_mut);
    for object in objects.into_iter().flatten().filter_map(toml::Value::as_table_mut) {
        let name = object.get("name").and_then(toml::Value::as_str).unwrap_or("an object").to_owned();
        if let Some(s) = object.get_mut("sphere").and_then(toml::Value::as_table_mut) {
            turn_keys(s, &["center"]);
        }
        if let Some(q) = object.get_mut("quad").and_then(toml::Value::as_table_mut) {
            turn_keys(q, &["corner", "edge_u", "edge_v"]);
        }
        if let Some(b) = object.get_mut("box").and_then(toml::Value::as_table_mut) {
            if !about_y {
                return Err(format!("box {name:?} turns only about +Y, not about {axis:?}"));
            }
            // world = R_a (R_b (local - pivot) + pivot + translate)
            //       = R_(a+b) (local - pivot) + pivot + (R_a (pivot + translate) - pivot).
            if let (Some(center), Some(half)) = (b.remove("center"), b.remove("half_extent")) {
                let (center, half) = (vector(&center), vector(&half));
                b.insert("min".into(), to_value(center - half));
                b.insert("max".into(), to_value(center + half));
            }
            let pivot = b.get("pivot").map_or(glam::DVec3::ZERO, vector);
            let translate = b.get("translate").map_or(glam::DVec3::ZERO, vector);
            let rotate_y = b.get("rotate_y").map_or(0.0, number);
            b.insert("pivot".into(), to_value(pivot));
            b.insert("translate".into(), to_value(rotation * (pivot + translate) - pivot));
            b.insert("rotate_y".into(), toml::Value::Float(rotate_y + angle_deg));
        }
    }
    Ok(toml::to_string(&table).expect("a table serialises"))
}
