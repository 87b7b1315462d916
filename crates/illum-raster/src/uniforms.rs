//! The uniform blocks as the shaders see them: plain-old-data structs laid out like `Scene` and
//! `View` in crates/illum-raster/shaders/scene.wgsl (every member a vec4 or mat4, so no hidden padding).

use crate::scene::RasterScene;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::shadow_fit::ShadowFit;

/// Shadow-map depth bias, in map depth units: only a guard against rounding, since no surface
/// in the map is a receiver that could shadow itself (see lighting.wgsl).
const SHADOW_DEPTH_BIAS: f32 = 1e-5;

/// Mirrors `struct Scene` in scene.wgsl (see there for what each member holds).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct SceneUniform {
    pub to_light: [f32; 4],
    pub light_radiance: [f32; 4],
    pub ambient: [f32; 4],
    pub background: [f32; 4],
    pub floor_rect: [f32; 4],
    pub floor_params: [f32; 4],
    pub receiver: [f32; 4],
    pub receiver_v: [f32; 4],
    pub floor_color_a: [f32; 4],
    pub floor_color_b: [f32; 4],
    pub glass_sphere: [f32; 4],
    pub glass_color: [f32; 4],
    pub glass_params: [f32; 4],
    pub metal_sphere: [f32; 4],
    pub metal_color: [f32; 4],
    pub metal_specular: [f32; 4],
    pub shadow_view_proj: [[f32; 4]; 4],
    pub shadow_params: [f32; 4],
    pub env_params: [f32; 4],
    pub floor_edges: [[f32; 4]; 4],
}

/// Mirrors `struct View` in scene.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct ViewUniform {
    pub view_proj: [[f32; 4]; 4],
    pub eye: [f32; 4],
}

fn v4(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

/// Schlick's reflectance at normal incidence, ((n1 - n2) / (n1 + n2))^2, from the ratio
/// eta = n1 / n2 (the same value either way round).
pub fn schlick_f0(eta: f32) -> f32 {
    let f = (eta - 1.0) / (eta + 1.0);
    f * f
}

/// Side of the coarse copy of the glass's cube map for a cube map of side `size`: an eighth,
/// where a pixel's environment lookups span eight fine texels or more.
pub fn coarse_cube_size(size: u32) -> u32 {
    (size / 8).max(1)
}

/// `Scene.env_params`: the angle one fine texel spans at a face's centre (a face is 2 units of
/// tangent wide over `size` texels, and d(tan) = d(angle) there) and log2 of the fine-to-coarse
/// side ratio (kept above zero: the shader divides by it).
fn env_params(size: u32) -> [f32; 4] {
    let ratio = size as f32 / coarse_cube_size(size) as f32;
    [2.0 / size as f32, ratio.log2().max(1e-3), 0.0, 0.0]
}

/// The frame's scene constants.
pub fn scene_uniform(scene: &RasterScene, shadow: &ShadowFit) -> SceneUniform {
    let floor = &scene.floor;
    let (lo, hi) = (floor.min_corner(), floor.max_corner());
    // An absent sphere's constants stay zero: nothing draws it or looks it up (plan.rs).
    let zero = [0.0; 4];
    let (glass_sphere, glass_color, glass_params) = match &scene.glass {
        Some(glass) => (
            v4(glass.center, glass.radius),
            v4(glass.color, glass.reflectivity),
            [glass.refraction_ratio, glass.shininess, schlick_f0(glass.refraction_ratio), 0.0],
        ),
        None => (zero, zero, zero),
    };
    let (metal_sphere, metal_color, metal_specular) = match &scene.metal {
        Some(metal) => (
            v4(metal.center, metal.radius),
            v4(metal.color, metal.mirror),
            v4(metal.specular, metal.shininess),
        ),
        None => (zero, zero, zero),
    };
    // A sphere's shadow lookup moves outward along its normal by the kernel's reach plus a
    // texel: then every PCF tap samples from outside the sphere, on the light's side, so the
    // sphere never shadows its own lit half (see shadow_visibility in lighting.wgsl).
    let normal_offset = shadow.texel * (crate::shadow_fit::PCF_REACH_TEXELS + 1.0);
    SceneUniform {
        to_light: v4(scene.light.to_light(), 0.0),
        light_radiance: v4(scene.light.radiance(), 0.0),
        ambient: v4(scene.ambient, 0.0),
        background: v4(scene.background, 1.0),
        floor_rect: [lo.x, lo.y, hi.x, hi.y],
        floor_params: [floor.height(), floor.tile, 0.0, 0.0],
        receiver: [shadow.receiver[0].x, shadow.receiver[0].y, shadow.receiver[1].x, shadow.receiver[1].y],
        receiver_v: [shadow.receiver[2].x, shadow.receiver[2].y, 0.0, 0.0],
        floor_color_a: v4(floor.colors[0], 1.0),
        floor_color_b: v4(floor.colors[1], 1.0),
        glass_sphere,
        glass_color,
        glass_params,
        metal_sphere,
        metal_color,
        metal_specular,
        shadow_view_proj: shadow.view_proj.to_cols_array_2d(),
        shadow_params: [normal_offset, SHADOW_DEPTH_BIAS, shadow.texel, 0.0],
        env_params: env_params(scene.quality.cube_size),
        floor_edges: floor_edges(scene),
    }
}

/// `Scene.floor_edges`: for each edge of the floor's rectangle, the normal of the plane through
/// the main view's eye and that edge, pointing to the rectangle's side (zero when the eye is on
/// the edge's line). A floor point p is inside the rectangle when n . (p - eye) >= 0 for all
/// four; divided by p's clip w (its distance along the view axis, so constant along each pixel's
/// ray) this is an affine function of the pixel position, whose value and screen derivatives
/// give each edge's exact coverage (floor.wgsl). Computed in f64 from the scene's numbers.
fn floor_edges(scene: &RasterScene) -> [[f32; 4]; 4] {
    let floor = &scene.floor;
    let (lo, hi) = (floor.min_corner().as_dvec2(), floor.max_corner().as_dvec2());
    let h = f64::from(floor.height());
    let eye = scene.camera.eye.as_dvec3();
    let corner = |x: f64, z: f64| glam::DVec3::new(x, h, z) - eye;
    let centre = corner(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y));
    let edges = [
        (corner(lo.x, lo.y), corner(lo.x, hi.y)),
        (corner(hi.x, lo.y), corner(hi.x, hi.y)),
        (corner(lo.x, lo.y), corner(hi.x, lo.y)),
        (corner(lo.x, hi.y), corner(hi.x, hi.y)),
    ];
    edges.map(|(a, b)| {
        let n = a.cross(b);
        let n = if n.dot(centre) < 0.0 { -n } else { n };
        // Scaled to unit length: only the sign and the ratio to clip w matter.
        let n = n.normalize_or_zero().as_vec3();
        [n.x, n.y, n.z, 0.0]
    })
}

/// A perspective view from `eye`; `pixel_angle`: the angle one pixel spans at the image centre,
/// by which anti-aliased shapes grow (the main view), or 0 (cube faces, drawn without).
pub fn perspective_view(view_proj: Mat4, eye: Vec3, pixel_angle: f32) -> ViewUniform {
    ViewUniform { view_proj: view_proj.to_cols_array_2d(), eye: v4(eye, pixel_angle) }
}

/// The light's view for the shadow pass; `eye` carries the light's travel direction.
pub fn shadow_view(shadow: &ShadowFit) -> ViewUniform {
    ViewUniform { view_proj: shadow.view_proj.to_cols_array_2d(), eye: v4(shadow.direction, 0.0) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The uniform structs have naga's size and member offsets of `Scene` and `View` in
    /// scene.wgsl (16 vec4 + mat4 + 2 vec4 + mat4 = 416 bytes; mat4 + vec4 = 80 bytes).
    #[test]
    fn layouts_match_the_wgsl_structs() {
        use illum_gpu::members;
        use std::mem::size_of;
        assert_eq!(size_of::<SceneUniform>(), 416);
        assert_eq!(size_of::<ViewUniform>(), 80);
        let module = crate::shaders::compose(&crate::shaders::FLOOR_SHADER).unwrap_or_else(|e| panic!("{e}"));
        let wgsl = |name: &str| {
            illum_gpu::shader::wgsl_struct(&module, "illum::raster::scene", name)
                .unwrap_or_else(|| panic!("no struct {name} in scene.wgsl"))
        };
        wgsl("Scene").assert_matches(
            size_of::<SceneUniform>(),
            &members!(SceneUniform: to_light, light_radiance, ambient, background, floor_rect, floor_params,
                receiver, receiver_v, floor_color_a, floor_color_b, glass_sphere, glass_color, glass_params,
                metal_sphere, metal_color, metal_specular, shadow_view_proj, shadow_params, env_params,
                floor_edges),
        );
        wgsl("View").assert_matches(size_of::<ViewUniform>(), &members!(ViewUniform: view_proj, eye));
    }

    #[test]
    fn the_coarse_cube_is_an_eighth() {
        assert_eq!(coarse_cube_size(256), 32);
        assert_eq!(env_params(256)[1], 3.0);
        assert_eq!(coarse_cube_size(4), 1);
        assert!(env_params(1)[1] > 0.0);
    }

    #[test]
    fn schlick_f0_of_the_assignments_glass() {
        // eta = 0.7: ((0.7 - 1) / 1.7)^2 = 0.031142.
        assert!((schlick_f0(0.7) - 0.031_142).abs() < 1e-6);
        assert_eq!(schlick_f0(1.0), 0.0);
    }
}
