//! Where the shadow map looks: an orthographic view along the light, fitted to the casters.
//!
//! Only the spheres and the meshes cast shadows, so the map covers just their footprint as seen
//! from the light (plus a margin for the PCF kernel), a mesh's by its bounding sphere, which
//! spends every texel where a shadow can be. Its depth
//! range spans the casters and the receivers (floor and spheres); the shader clamps receivers
//! outside it. The texel size follows from the scene's `pcf_radius`: the PCF kernel reaches
//! [`PCF_REACH_TEXELS`] texels, so texel = pcf_radius / PCF_REACH_TEXELS makes the soft edge
//! exactly pcf_radius wide on either side, whatever the scene's scale.

use crate::scene::RasterScene;
use glam::{Mat2, Mat4, Vec2, Vec3, Vec4};

/// How far the PCF kernel of lighting.wgsl reaches, in texels: taps half a texel either side of
/// the centre, each a bilinear 2 x 2 comparison reaching one texel further.
pub const PCF_REACH_TEXELS: f32 = 1.5;

/// Empty texels kept around the casters' footprint beyond the kernel's reach, so clamped taps
/// at the map's edge read "no caster".
const MARGIN_TEXELS: f32 = 2.0;

/// The smallest and largest shadow maps the fit produces.
pub const MIN_SHADOW_MAP: u32 = 16;
pub const MAX_SHADOW_MAP: u32 = 4096;

/// The light's view of the frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowFit {
    /// World -> shadow clip space: x, y in [-1, 1] over the map, depth in [0, 1].
    pub view_proj: Mat4,
    /// Side of the (square) shadow map in texels.
    pub size: u32,
    /// Side of one texel in scene units.
    pub texel: f32,
    /// The light's travel direction (unit).
    pub direction: Vec3,
    /// Scene units per unit of shadow-map depth.
    pub depth_range: f32,
    /// The floor under the map, where shadows can fall: a parallelogram in (x, z) given as
    /// corner, edge u, edge v. When the light runs nearly parallel to the floor it would be
    /// unbounded, and this is the whole floor rectangle instead.
    pub receiver: [Vec2; 3],
    /// Whether the glass (metal) sphere can receive any shadow, even a soft edge: only the
    /// other sphere or a mesh can cast one on it (a sphere never shadows its own lit half), so a
    /// scene with one sphere and no mesh has neither.
    pub glass_shadowed: bool,
    pub metal_shadowed: bool,
    /// Whether the floor's shadows may be drawn as rings and discs (floor.wgsl, PART 1 and 2):
    /// the light comes from above, every sphere lies wholly above the floor (so it is in front
    /// of every floor point it covers in the map), no mesh casts a shadow of another shape, and
    /// `receiver` is the map's own footprint (the rings are placed through it).
    pub rings: bool,
}

/// Whether sphere `receiver` (centre, radius) can lie in the shadow of sphere `caster` under
/// light travelling along unit `direction`, or within `margin` of it. The caster's shadow is the
/// half-cylinder of radius r_c whose axis starts at the caster's centre and runs along the light.
/// With a the receiver centre's distance along the axis and b its distance from the axis, the
/// nearest point of that half-cylinder is max(b - r_c, 0) away sideways, plus |a| lengthwise when
/// the receiver lies upstream (a < 0, toward the light); the receiver can be touched when that
/// distance is at most r_r + margin.
pub fn can_shadow(caster: (Vec3, f32), receiver: (Vec3, f32), direction: Vec3, margin: f32) -> bool {
    let d = receiver.0 - caster.0;
    let a = d.dot(direction);
    let sideways = ((d - a * direction).length() - caster.1).max(0.0);
    let lengthwise = (-a).max(0.0);
    sideways.hypot(lengthwise) <= receiver.1 + margin
}

/// Two unit vectors completing unit `w` to an orthonormal frame (the same choice as
/// `perpendicular_frame` in sphere.wgsl, though nothing depends on them agreeing).
fn perpendicular_frame(w: Vec3) -> (Vec3, Vec3) {
    let helper = if w.y.abs() > 0.9 { Vec3::X } else { Vec3::Y };
    let u = w.cross(helper).normalize();
    (u, u.cross(w))
}

/// Fits the shadow map to `scene`'s casters ([`RasterScene::casters`]), at most `max_size` texels on a side (the device's
/// texture limit, capped at [`MAX_SHADOW_MAP`]). When the wanted resolution exceeds that, the
/// texel grows and the soft edge with it.
pub fn fit_shadow(scene: &RasterScene, max_size: u32) -> ShadowFit {
    let direction = scene.light.direction();
    let (u, v) = perpendicular_frame(direction);
    // Without a caster nothing casts a shadow and no shadow pass runs (plan.rs); the map is then
    // fitted around the floor's centre only so that every number stays finite.
    let mut casters = scene.casters();
    if casters.is_empty() {
        casters.push((scene.floor.center, scene.quality.pcf_radius));
    }

    // The casters' discs in the light's (u, v) plane.
    let mut lo = glam::Vec2::splat(f32::INFINITY);
    let mut hi = glam::Vec2::splat(f32::NEG_INFINITY);
    for &(c, r) in &casters {
        let p = glam::Vec2::new(c.dot(u), c.dot(v));
        lo = lo.min(p - r);
        hi = hi.max(p + r);
    }
    let extent = (hi - lo).max_element();
    let wanted_texel = scene.quality.pcf_radius / PCF_REACH_TEXELS;
    let pad = PCF_REACH_TEXELS + MARGIN_TEXELS;
    let max_size = max_size.clamp(MIN_SHADOW_MAP, MAX_SHADOW_MAP);
    let wanted = (extent / wanted_texel + 2.0 * pad).ceil();
    let (size, texel) = if wanted <= max_size as f32 {
        let size = (wanted as u32).max(MIN_SHADOW_MAP);
        (size, wanted_texel)
    } else {
        (max_size, extent / (max_size as f32 - 2.0 * pad))
    };
    let half = 0.5 * size as f32 * texel;
    let middle = 0.5 * (lo + hi);

    // Depth along the light over everything that casts or receives.
    let floor = &scene.floor;
    let (fmin, fmax) = (floor.min_corner(), floor.max_corner());
    let y = floor.height();
    let mut near = f32::INFINITY;
    let mut far = f32::NEG_INFINITY;
    for corner in [
        Vec3::new(fmin.x, y, fmin.y),
        Vec3::new(fmax.x, y, fmin.y),
        Vec3::new(fmin.x, y, fmax.y),
        Vec3::new(fmax.x, y, fmax.y),
    ] {
        let z = corner.dot(direction);
        near = near.min(z);
        far = far.max(z);
    }
    for &(c, r) in &casters {
        let z = c.dot(direction);
        near = near.min(z - r);
        far = far.max(z + r);
    }
    // A little slack so that surfaces exactly at the ends are not clipped by rounding.
    let slack = 1e-3 * (far - near).max(1.0);
    near -= slack;
    far += slack;
    let depth_range = far - near;

    // clip = ((p.u - middle.x) / half, (p.v - middle.y) / half, (p.d - near) / depth_range, 1).
    let view_proj = Mat4::from_rows(
        (u / half).extend(-middle.x / half),
        (v / half).extend(-middle.y / half),
        (direction / depth_range).extend(-near / depth_range),
        Vec4::W,
    );
    let receiver = receiver_on_floor(&view_proj, floor);
    let rings = receiver.is_some()
        && direction.y < 0.0
        && scene.meshes.is_empty()
        && scene.spheres().iter().all(|&(c, r)| c.y - r > floor.height());
    let receiver = receiver.unwrap_or_else(|| {
        let (lo, hi) = (floor.min_corner(), floor.max_corner());
        [lo, Vec2::new(hi.x - lo.x, 0.0), Vec2::new(0.0, hi.y - lo.y)]
    });
    // The soft edge reaches pcf_radius beyond the sharp one, and a sphere's lookup point moves a
    // kernel and a texel along its normal: twice the kernel plus two texels covers both.
    let margin = 2.0 * (PCF_REACH_TEXELS + 1.0) * texel;
    let glass = scene.glass.map(|g| (g.center, g.radius));
    let metal = scene.metal.map(|m| (m.center, m.radius));
    let meshes: Vec<(Vec3, f32)> = scene.meshes.iter().map(|m| m.bounding_sphere()).collect();
    // Whether `receiver` can be shadowed by `other` (the other sphere) or by a mesh.
    let shadowed = |receiver: Option<(Vec3, f32)>, other: Option<(Vec3, f32)>| {
        receiver.is_some_and(|r| {
            other
                .into_iter()
                .chain(meshes.iter().copied())
                .any(|caster| can_shadow(caster, r, direction, margin))
        })
    };
    ShadowFit {
        view_proj,
        size,
        texel,
        direction,
        depth_range,
        receiver,
        glass_shadowed: shadowed(glass, metal),
        metal_shadowed: shadowed(metal, glass),
        rings,
    }
}

/// The floor points whose shadow-map coordinates lie in [-1, 1]^2. On the plane y = h the map's
/// (X, Y) are affine in (x, z): (X, Y) = A (x, z) + b, with A and b read off the matrix. The
/// map's corners (-1, -1), (1, -1), (-1, 1) map back through A^-1 to the parallelogram's corner
/// and the ends of its two edges. `None` for a nearly singular A (light grazing the floor),
/// whose parallelogram would be unbounded: the caller takes the whole floor rectangle.
fn receiver_on_floor(view_proj: &Mat4, floor: &crate::scene::CheckerFloor) -> Option<[Vec2; 3]> {
    let rows = [view_proj.row(0), view_proj.row(1)];
    let a = Mat2::from_cols(Vec2::new(rows[0].x, rows[1].x), Vec2::new(rows[0].z, rows[1].z));
    let h = floor.height();
    let b = Vec2::new(rows[0].y * h + rows[0].w, rows[1].y * h + rows[1].w);
    // |det A| relates map area to floor area: a map a million times smaller than its floor
    // footprint means light nearly parallel to the floor.
    if a.determinant().abs() < 1e-6 * a.abs().to_cols_array().iter().fold(0.0f32, |m, v| m.max(*v)).powi(2) {
        return None;
    }
    let inverse = a.inverse();
    let corner = inverse * (Vec2::splat(-1.0) - b);
    let u = inverse * Vec2::new(2.0, 0.0);
    let v = inverse * Vec2::new(0.0, 2.0);
    if !(corner.is_finite() && u.is_finite() && v.is_finite()) {
        return None;
    }
    Some([corner, u, v])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> RasterScene {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/whitted.toml"))
            .unwrap();
        RasterScene::from_toml_str(&text, "whitted.toml").unwrap()
    }

    fn glass(s: &RasterScene) -> crate::scene::GlassSphere {
        s.glass.expect("whitted.toml has a glass sphere")
    }

    fn clip(fit: &ShadowFit, p: Vec3) -> Vec3 {
        let c = fit.view_proj * p.extend(1.0);
        c.truncate() / c.w
    }

    #[test]
    fn casters_fit_inside_the_map_with_the_kernel_margin() {
        let s = scene();
        let fit = fit_shadow(&s, 8192);
        assert!((fit.texel - s.quality.pcf_radius / PCF_REACH_TEXELS).abs() < 1e-7);
        let margin_ndc = 2.0 * PCF_REACH_TEXELS / fit.size as f32;
        let (u, v) = perpendicular_frame(fit.direction);
        for (c, r) in s.spheres() {
            for edge in [u, -u, v, -v] {
                let p = clip(&fit, c + r * edge);
                assert!(p.x.abs() <= 1.0 - margin_ndc && p.y.abs() <= 1.0 - margin_ndc, "{p:?}");
            }
            // The lit pole (toward the light) is nearer than the centre, which is nearer than the floor.
            let pole = clip(&fit, c - r * fit.direction).z;
            assert!(pole > 0.0 && pole < clip(&fit, c).z);
        }
        let under_glass = clip(&fit, Vec3::new(2.2, 0.0, -3.8)).z;
        assert!(under_glass > clip(&fit, glass(&s).center).z && under_glass < 1.0);
    }

    #[test]
    fn points_along_the_light_share_a_texel() {
        let s = scene();
        let fit = fit_shadow(&s, 8192);
        let a = clip(&fit, glass(&s).center);
        let b = clip(&fit, glass(&s).center + 2.5 * fit.direction);
        assert!((a.x - b.x).abs() < 1e-5 && (a.y - b.y).abs() < 1e-5);
        // One scene unit across the light is size / (2 half) texels = 1 / texel.
        let (u, _) = perpendicular_frame(fit.direction);
        let c = clip(&fit, glass(&s).center + u);
        let texels = 0.5 * (c.x - a.x) * fit.size as f32;
        assert!((texels - 1.0 / fit.texel).abs() < 1e-2, "{texels}");
    }

    #[test]
    fn the_receiver_is_where_the_map_meets_the_floor() {
        let s = scene();
        let fit = fit_shadow(&s, 8192);
        let [corner, u, v] = fit.receiver;
        for (a, b, expected) in [
            (0.0, 0.0, (-1.0, -1.0)),
            (1.0, 0.0, (1.0, -1.0)),
            (0.0, 1.0, (-1.0, 1.0)),
            (1.0, 1.0, (1.0, 1.0)),
        ] {
            let xz = corner + a * u + b * v;
            let p = clip(&fit, Vec3::new(xz.x, s.floor.height(), xz.y));
            assert!((p.x - expected.0).abs() < 1e-4 && (p.y - expected.1).abs() < 1e-4, "{p:?}");
        }
        // Both shadow centres (where the light projects the sphere centres) lie inside it.
        for (c, _) in s.spheres() {
            let d = fit.direction;
            let on_floor = c + (s.floor.height() - c.y) / d.y * d;
            let p = clip(&fit, on_floor);
            assert!(p.x.abs() < 1.0 && p.y.abs() < 1.0, "{p:?}");
        }
        // A light grazing the floor gives the whole floor.
        let mut grazing = s.clone();
        // From (10, 0, -2) toward (0, 0, -2): level with the floor.
        grazing.light.direction = Vec3::NEG_X;
        let whole = fit_shadow(&grazing, 8192).receiver;
        assert_eq!(whole[0], s.floor.min_corner());
    }

    /// Rings and discs (floor.wgsl) only where a disc is sure to be shadow: a light from above,
    /// spheres wholly above the floor, and a map whose footprint on the floor is bounded.
    #[test]
    fn shadows_are_drawn_as_rings_only_where_the_discs_are_sure() {
        let s = scene();
        assert!(fit_shadow(&s, 8192).rings, "the shipped scene");
        let mut grazing = s.clone();
        grazing.light.direction = Vec3::NEG_X;
        assert!(!fit_shadow(&grazing, 8192).rings, "a light level with the floor");
        let mut below = s.clone();
        below.light.direction = Vec3::new(-10.0, 13.0, 2.0).normalize();
        assert!(!fit_shadow(&below, 8192).rings, "a light from below the floor");
        let mut dipping = s.clone();
        let h = s.floor.height();
        dipping.metal.as_mut().unwrap().center.y = h + 0.5 * dipping.metal.unwrap().radius;
        assert!(!fit_shadow(&dipping, 8192).rings, "a sphere through the floor");
    }

    #[test]
    fn spheres_shadow_each_other_only_where_the_light_lines_them_up() {
        let s = scene();
        let fit = fit_shadow(&s, 8192);
        // docs/scenes.md's light: nothing lies between the glass and the light, while light reaching
        // the metal's right side passes within 0.1 of the glass, inside the soft edge's reach.
        assert!(!fit.glass_shadowed && fit.metal_shadowed);
        // Metal straight below the glass along the light: shadowed, and the glass not.
        let mut under = s.clone();
        under.metal.as_mut().unwrap().center = glass(&s).center + 2.5 * fit.direction;
        let fit = fit_shadow(&under, 8192);
        assert!(fit.metal_shadowed && !fit.glass_shadowed);
        // A light low enough to graze the metal past the glass.
        let mut low = s.clone();
        // From (10, 2.5, -2) toward the origin.
        low.light.direction = Vec3::new(-10.0, -2.5, 2.0).normalize();
        assert!(fit_shadow(&low, 8192).metal_shadowed);
        let d = Vec3::X;
        assert!(!can_shadow((Vec3::ZERO, 1.0), (Vec3::new(5.0, 2.5, 0.0), 1.0), d, 0.1));
        assert!(can_shadow((Vec3::ZERO, 1.0), (Vec3::new(5.0, 1.9, 0.0), 1.0), d, 0.0));
        assert!(
            !can_shadow((Vec3::ZERO, 1.0), (Vec3::new(-5.0, 0.0, 0.0), 1.0), d, 0.0),
            "on the light's side"
        );
    }

    #[test]
    fn one_sphere_shadows_nothing_but_the_floor_and_none_keeps_the_fit_finite() {
        let s = scene();
        let mut glass_only = s.clone();
        glass_only.metal = None;
        let fit = fit_shadow(&glass_only, 8192);
        assert!(!fit.glass_shadowed && !fit.metal_shadowed);
        let (c, r) = (glass(&s).center, glass(&s).radius);
        assert!(clip(&fit, c + r * perpendicular_frame(fit.direction).0).x.abs() < 1.0);
        let mut bare = s.clone();
        bare.glass = None;
        bare.metal = None;
        let fit = fit_shadow(&bare, 8192);
        assert!(fit.view_proj.is_finite() && fit.texel.is_finite() && fit.size >= MIN_SHADOW_MAP);
        assert!(!fit.glass_shadowed && !fit.metal_shadowed);
    }

    #[test]
    fn a_small_device_limit_coarsens_the_texel() {
        let s = scene();
        let fine = fit_shadow(&s, 8192);
        let coarse = fit_shadow(&s, 64);
        assert_eq!(coarse.size, 64);
        assert!(coarse.texel > fine.texel);
        // Below the minimum the map stays at the minimum size.
        assert_eq!(fit_shadow(&s, 1).size, MIN_SHADOW_MAP);
    }
}
