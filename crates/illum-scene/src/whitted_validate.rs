//! From the raw Whitted scene file to a validated [`WhittedScene`].
//!
//! Checks run in file order and stop at the first problem, with the path tracer's helpers
//! (`validate::Check`), so a NaN, an infinite f32, a degenerate camera or a bad resolution is
//! reported in exactly the same words in both formats.

use glam::{Vec2, Vec3};

use crate::camera::robust_normalize;
use crate::error::SceneError;
use crate::file::{Num, RawCamera, RawVec3};
use crate::validate::{Check, fmt_num, fmt_vec, fmt_vec32};
use crate::whitted::{
    AmbientLight, CheckerFloor, ClipPlanes, DirectionalLight, Effects, GlassSphere, LOOK_ALLOWED, Look,
    MetalSphere, RasterQuality, WhittedScene,
};
use crate::whitted_file::{RawEffects, RawFloor, RawGlass, RawLight, RawMetal, RawWhitted};

/// More tiles than this along one side and the f32 tile coordinate of the far edge loses its
/// fraction (2^24 / 100000 ~ 168 steps per tile remain), so the checker would break up.
const MAX_TILES_PER_SIDE: f64 = 100_000.0;

pub(crate) fn whitted_from_raw(
    raw: RawWhitted,
    file: &str,
    default_name: &str,
) -> Result<WhittedScene, SceneError> {
    let check = Check { file };
    let look = match &raw.look {
        None => Look::default(),
        Some(s) => s.parse().map_err(|_| check.invalid("look", format!("{s:?}"), LOOK_ALLOWED))?,
    };
    let c = &raw.camera;
    let camera = check.camera(&RawCamera {
        eye: c.eye,
        target: c.target,
        up: c.up,
        vfov: c.vfov,
        width: c.width,
        height: c.height,
    })?;
    let clip = clip_planes(&check, c.near, c.far)?;
    let background = non_negative(&check, "background.color", raw.background.color)?;
    let light = light(&check, &raw.light)?;
    let ambient = AmbientLight {
        color: non_negative(&check, "ambient.color", raw.ambient.color)?,
        intensity: at_least_zero(&check, "ambient.intensity", raw.ambient.intensity)?,
    };
    let floor = floor(&check, &raw.floor)?;
    let glass = raw.glass.as_ref().map(|g| glass(&check, g)).transpose()?;
    let metal = raw.metal.as_ref().map(|m| metal(&check, m)).transpose()?;
    placement(&check, &camera, glass.as_ref(), metal.as_ref())?;
    let RawEffects { shadows, pcf, refraction, reflection, fresnel, msaa } = raw.effects;
    let effects = Effects { shadows, pcf, refraction, reflection, fresnel, msaa };
    let pcf_radius = positive(&check, "quality.pcf_radius", raw.quality.pcf_radius)?;
    let cube_size = check.u32_at_least("quality.cube_size", raw.quality.cube_size, 1)?;
    Ok(WhittedScene {
        name: raw.name.unwrap_or_else(|| default_name.to_owned()),
        camera,
        clip,
        background,
        light,
        ambient,
        floor,
        glass,
        metal,
        look,
        effects,
        quality: RasterQuality { pcf_radius, cube_size },
    })
}

fn clip_planes(check: &Check, near: Num, far: Num) -> Result<ClipPlanes, SceneError> {
    let near32 = positive(check, "camera.near", near)?;
    let far32 = check.number("camera.far", far)?;
    if far32 <= near32 {
        return Err(check.invalid(
            "camera.far",
            fmt_num(far.0),
            format!("must be greater than camera.near = {}", fmt_num(near.0)),
        ));
    }
    Ok(ClipPlanes { near: near32, far: far32 })
}

fn light(check: &Check, raw: &RawLight) -> Result<DirectionalLight, SceneError> {
    let position = check.vec3("light.position", raw.position)?;
    let target = check.vec3("light.target", raw.target)?;
    if robust_normalize(target - position).is_none() {
        return Err(check.invalid(
            "light.target",
            fmt_vec32(target),
            format!(
                "must differ from light.position = {} (the light shines from position toward target)",
                fmt_vec32(position)
            ),
        ));
    }
    Ok(DirectionalLight {
        position,
        target,
        color: non_negative(check, "light.color", raw.color)?,
        intensity: at_least_zero(check, "light.intensity", raw.intensity)?,
        casts_shadows: raw.casts_shadows,
    })
}

fn floor(check: &Check, raw: &RawFloor) -> Result<CheckerFloor, SceneError> {
    let center = check.vec3("floor.center", raw.center)?;
    let &[size_x, size_z] = raw.size.as_slice() else {
        let shown: Vec<String> = raw.size.iter().map(|n| fmt_num(n.0)).collect();
        return Err(check.invalid(
            "floor.size",
            format!("[{}]", shown.join(", ")),
            "must be two numbers: [extent along X, extent along Z]",
        ));
    };
    let [raw_x, raw_z] = [size_x.0, size_z.0];
    let size_x = positive(check, "floor.size[0]", size_x)?;
    let size_z = positive(check, "floor.size[1]", size_z)?;
    let tile = positive(check, "floor.tile", raw.tile)?;
    let tiles = (raw_x / raw.tile.0).max(raw_z / raw.tile.0);
    if tiles > MAX_TILES_PER_SIDE {
        return Err(check.invalid(
            "floor.tile",
            fmt_num(raw.tile.0),
            format!(
                "must give at most {MAX_TILES_PER_SIDE} tiles along each side of the floor (size = [{}, {}] \
                 gives {tiles:.0}); f32 tile coordinates lose their fraction beyond that",
                fmt_num(raw_x),
                fmt_num(raw_z)
            ),
        ));
    }
    let &[even, odd] = raw.colors.as_slice() else {
        let shown: Vec<String> = raw.colors.iter().map(|c| fmt_vec(c.0)).collect();
        return Err(check.invalid(
            "floor.colors",
            format!("[{}]", shown.join(", ")),
            "must be two colours: [[r, g, b] of the tile at the minimum corner, [r, g, b] of its neighbours]",
        ));
    };
    let colors = [albedo(check, "floor.colors[0]", even)?, albedo(check, "floor.colors[1]", odd)?];
    Ok(CheckerFloor { center, size: Vec2::new(size_x, size_z), tile, colors })
}

fn glass(check: &Check, raw: &RawGlass) -> Result<GlassSphere, SceneError> {
    let center = check.vec3("glass.center", raw.center)?;
    let radius = positive(check, "glass.radius", raw.radius)?;
    let color = albedo(check, "glass.color", raw.color)?;
    let refraction_ratio = check.number("glass.refraction_ratio", raw.refraction_ratio)?;
    if !(refraction_ratio > 0.0 && refraction_ratio <= 1.0) {
        return Err(check.invalid(
            "glass.refraction_ratio",
            fmt_num(raw.refraction_ratio.0),
            "must be in (0, 1]: n_outside / n_inside for glass denser than the air around it \
             (0.7 is glass of index 1.43)",
        ));
    }
    Ok(GlassSphere {
        center,
        radius,
        color,
        refraction_ratio,
        reflectivity: unit_interval(check, "glass.reflectivity", raw.reflectivity)?,
        shininess: positive(check, "glass.shininess", raw.shininess)?,
    })
}

fn metal(check: &Check, raw: &RawMetal) -> Result<MetalSphere, SceneError> {
    Ok(MetalSphere {
        center: check.vec3("metal.center", raw.center)?,
        radius: positive(check, "metal.radius", raw.radius)?,
        color: albedo(check, "metal.color", raw.color)?,
        specular: albedo(check, "metal.specular", raw.specular)?,
        shininess: positive(check, "metal.shininess", raw.shininess)?,
        mirror: unit_interval(check, "metal.mirror", raw.mirror)?,
    })
}

/// The camera must be outside the spheres (a sphere around the eye would fill the view with its
/// inside), and two spheres must not intersect: each cube map is captured from its sphere's
/// centre and must see the other sphere from outside.
fn placement(
    check: &Check,
    camera: &crate::Camera,
    glass: Option<&GlassSphere>,
    metal: Option<&MetalSphere>,
) -> Result<(), SceneError> {
    let spheres = glass
        .map(|g| ("glass", g.center, g.radius))
        .into_iter()
        .chain(metal.map(|m| ("metal", m.center, m.radius)));
    for (name, center, radius) in spheres {
        let distance = camera.eye.distance(center);
        if distance <= radius {
            return Err(check.invalid(
                "camera.eye",
                fmt_vec32(camera.eye),
                format!(
                    "must lie outside the {name} sphere (centre {}, radius {radius}; the eye is {distance} from its centre)",
                    fmt_vec32(center)
                ),
            ));
        }
    }
    let (Some(glass), Some(metal)) = (glass, metal) else { return Ok(()) };
    let distance = glass.center.distance(metal.center);
    if distance <= glass.radius + metal.radius {
        return Err(check.invalid(
            "metal.center",
            fmt_vec32(metal.center),
            format!(
                "the spheres must not touch or overlap: their centres are {distance} apart but the radii add up \
                 to {} (glass.center = {}); each sphere's cube map is captured from its centre",
                glass.radius + metal.radius,
                fmt_vec32(glass.center)
            ),
        ));
    }
    Ok(())
}

fn positive(check: &Check, field: &str, x: Num) -> Result<f32, SceneError> {
    let y = check.number(field, x)?;
    if y > 0.0 { Ok(y) } else { Err(check.invalid(field, fmt_num(x.0), "must be > 0")) }
}

fn at_least_zero(check: &Check, field: &str, x: Num) -> Result<f32, SceneError> {
    let y = check.number(field, x)?;
    if y >= 0.0 { Ok(y) } else { Err(check.invalid(field, fmt_num(x.0), "must be >= 0")) }
}

fn unit_interval(check: &Check, field: &str, x: Num) -> Result<f32, SceneError> {
    let y = check.number(field, x)?;
    if (0.0..=1.0).contains(&y) {
        Ok(y)
    } else {
        Err(check.invalid(field, fmt_num(x.0), "must be in [0, 1]"))
    }
}

/// A reflectance: every channel in [0, 1] (a surface reflects at most what it receives).
fn albedo(check: &Check, field: &str, v: RawVec3) -> Result<Vec3, SceneError> {
    let y = check.vec3(field, v)?;
    if y.cmpge(Vec3::ZERO).all() && y.cmple(Vec3::ONE).all() {
        Ok(y)
    } else {
        Err(check.invalid(
            field,
            fmt_vec(v.0),
            "every channel must be in [0, 1] (the fraction of light reflected)",
        ))
    }
}

/// A light or background colour: every channel >= 0 (values above 1 clip in the 8-bit output).
fn non_negative(check: &Check, field: &str, v: RawVec3) -> Result<Vec3, SceneError> {
    let y = check.vec3(field, v)?;
    if y.cmpge(Vec3::ZERO).all() {
        Ok(y)
    } else {
        Err(check.invalid(field, fmt_vec(v.0), "every channel must be >= 0"))
    }
}
