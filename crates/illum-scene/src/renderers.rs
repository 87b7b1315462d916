//! The per-renderer sections of a scene file: settings that only one renderer has.
//!
//! | section | renderer | what |
//! |---|---|---|
//! | `[pathtrace]` | path tracer | [`PathTraceSettings`]: spp, bounces, seed, sampling, sequence, caustics |
//! | `[raster]` | rasterizer | [`RasterSettings`]: look, effect toggles, PCF radius, cube-map size, the figure look's glass mix |
//! | `[whitted]` | Whitted ray tracer | [`WhittedSettings`]: recursion depth, anti-aliasing pattern |
//! | `[shading]` | rasterizer and Whitted ray tracer | [`Shading`]: the local Phong model (ambient, highlights, mirror weight) |
//!
//! `[shading]` is shared because the rasterizer's enhanced look and the Whitted ray tracer
//! shade each hit point with the same local model; they differ only in what ray tracing
//! changes. The path tracer ignores it: it solves the rendering equation with the physical
//! materials and lights.

use glam::Vec3;

/// Most fixed bounces a scene may ask for (the viewer offers 0..=64; the extremes tests use 64).
pub const MAX_BOUNCES: u32 = 256;

/// Deepest recursion the Whitted ray tracer accepts.
pub const MAX_WHITTED_DEPTH: u32 = 64;

/// Largest n of the Whitted ray tracer's n x n anti-aliasing pattern.
pub const MAX_WHITTED_AA: u32 = 16;

/// The renderers of illum.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RendererKind {
    /// Wgpu render pipelines faking Whitted's look (illum-raster).
    Raster,
    /// The Monte Carlo path tracer (illum-pathtrace).
    PathTrace,
    /// Whitted's 1980 ray tracer (illum-whitted).
    Whitted,
}

impl RendererKind {
    pub const ALL: [RendererKind; 3] = [RendererKind::Raster, RendererKind::PathTrace, RendererKind::Whitted];

    /// The name used in sentences ("the rasterizer cannot render ...").
    pub fn noun(self) -> &'static str {
        match self {
            RendererKind::Raster => "rasterizer",
            RendererKind::PathTrace => "path tracer",
            RendererKind::Whitted => "Whitted ray tracer",
        }
    }
}

/// How many bounces of indirect light a path takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bounces {
    /// 0 = direct illumination only, 1 = one bounce of global illumination, ...
    Fixed(u32),
    /// Unbounded depth, terminated without bias by Russian roulette.
    Unbounded,
}

/// Which pdf the path tracer draws bounce directions from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sampling {
    /// pdf = cos(theta) / pi (default; lower variance on Lambertian surfaces).
    Cosine,
    /// pdf = 1 / (2 pi) (the assignment's question 2b).
    Uniform,
}

/// Where a path's random sample values come from (see crates/illum-pathtrace/shaders/sampler.wgsl).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Sequence {
    /// Independent uniform numbers from a PCG stream per (seed, pixel, sample index).
    #[default]
    Independent,
    /// Low-discrepancy numbers: each pair of dimensions a randomly shifted R_2 sequence, visited
    /// in its own shuffled order per pixel (see crates/illum-pathtrace/shaders/sampler.wgsl).
    LowDiscrepancy,
}

/// How the path tracer finds the sun's caustic (with `caustics = true`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum CausticMethod {
    /// Particles traced from the sun, connected to the eye, and with a delta sun gathered as
    /// photons (docs/caustics.md): every specular chain, through any number of objects.
    #[default]
    LightTracer,
    /// Manifold next-event estimation: at every diffuse vertex the chains through one specular
    /// sphere are solved (docs/caustics-manifold.md). Where the scene is not solvable sphere by
    /// sphere (`specular_spheres::solvable_spheres`) the light tracer runs instead, and says so.
    Manifold,
}

/// The denoisers `render --denoise` knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DenoiserKind {
    /// The edge-avoiding à-trous filter (illum-denoise's `atrous`): runs wherever illum runs.
    Atrous,
    /// Intel Open Image Denoise's RT filter (only in builds with the cargo feature `oidn`).
    Oidn,
}

impl std::str::FromStr for DenoiserKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "atrous" => Ok(DenoiserKind::Atrous),
            "oidn" => Ok(DenoiserKind::Oidn),
            other => Err(format!("'{other}' is not a denoiser: use atrous or oidn")),
        }
    }
}

impl std::fmt::Display for DenoiserKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            DenoiserKind::Atrous => "atrous",
            DenoiserKind::Oidn => "oidn",
        })
    }
}

/// `[pathtrace]`: the path tracer's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathTraceSettings {
    /// Samples per pixel, >= 1.
    pub spp: u32,
    pub bounces: Bounces,
    pub seed: u32,
    pub sampling: Sampling,
    pub sequence: Sequence,
    /// Light tracing for the caustic (`caustics = true`): particles from the directional light
    /// through mirrors and dielectrics to the first diffuse surface, connected to the camera.
    /// It covers the paths L S+ D E that next-event estimation cannot find (see
    /// docs/caustics.md); off by default.
    pub caustics: bool,
    /// Which estimator finds the caustic when `caustics` is on.
    pub caustic_method: CausticMethod,
}

/// The two looks of the rasterizer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Look {
    /// The assignment's figure 1: one refraction into a cube map, unlit glass, plain Phong metal.
    #[default]
    Figure,
    /// What a rasterizer can add toward Whitted's image: mirror metal, Fresnel-weighted
    /// reflection plus refraction through both faces of the glass, specular highlights.
    Enhanced,
}

/// Effect toggles of the rasterizer. Reflection and Fresnel belong to the enhanced look (the
/// figure has neither); the others apply to both looks. In a file (`[raster.effects]`) each
/// absent key is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Effects {
    /// Shadows from the directional light (a shadow map; off: no shadow pass at all).
    pub shadows: bool,
    /// Soft shadow edges by percentage-closer filtering; off: one hard depth comparison.
    pub pcf: bool,
    /// Bend the view through the glass; off: the glass shows the environment straight behind it.
    pub refraction: bool,
    /// Enhanced look: mirror reflections on the metal and glass.
    pub reflection: bool,
    /// Enhanced look: Schlick's Fresnel weight between reflection and refraction on the glass;
    /// off: the normal-incidence weight everywhere.
    pub fresnel: bool,
    /// Anti-aliased edges: the spheres' silhouettes and the floor's outline are blended by the
    /// fraction of each pixel they cover, computed analytically, at one sample per pixel; off:
    /// each pixel shows what the ray through its centre meets (jagged edges). In a file the key
    /// is `antialiasing`; `msaa`, its name when the edges were 4x multisampled, is still read.
    #[serde(alias = "msaa")]
    pub antialiasing: bool,
}

/// Turns one effect off.
pub type EffectOff = fn(&mut Effects);

impl Effects {
    /// Every effect on (the default).
    pub const ALL_ON: Effects = Effects {
        shadows: true,
        pcf: true,
        refraction: true,
        reflection: true,
        fresnel: true,
        antialiasing: true,
    };

    /// Each effect's name (its key in `[raster.effects]`) and how to turn it off.
    pub const TOGGLES: [(&'static str, EffectOff); 6] = [
        ("shadows", |e| e.shadows = false),
        ("pcf", |e| e.pcf = false),
        ("refraction", |e| e.refraction = false),
        ("reflection", |e| e.reflection = false),
        ("fresnel", |e| e.fresnel = false),
        ("antialiasing", |e| e.antialiasing = false),
    ];
}

impl Default for Effects {
    fn default() -> Self {
        Effects::ALL_ON
    }
}

/// `[raster]`: the rasterizer's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterSettings {
    /// The look used when the caller does not choose one.
    pub look: Look,
    /// The effect toggles used when the caller does not choose them.
    pub effects: Effects,
    /// Half-width of the soft shadow edge in scene units (> 0); also sets the shadow map's texel.
    pub pcf_radius: f32,
    /// Side of each cube-map face in texels (>= 1).
    pub cube_size: u32,
    /// Figure look: the glass's pixel is (1 - glass_reflectivity) x glass_color +
    /// glass_reflectivity x the refracted environment (the skeleton's unlit glass).
    /// Enhanced look: `glass_color` tints what the glass transmits.
    pub glass_color: Vec3,
    pub glass_reflectivity: f32,
}

/// `[whitted]`: the Whitted ray tracer's settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WhittedSettings {
    /// Recursion depth: reflected and refracted rays are followed this many times (0..=64).
    pub depth: u32,
    /// Anti-aliasing: an n x n stratified pattern of rays per pixel (1..=16).
    pub aa: u32,
}

/// `[shading]`: the local (Phong) shading model of the rasterizer and the Whitted ray tracer.
/// At a hit point: ambient x colour, plus colour x N.L and a highlight where the light reaches
/// it, plus what mirror and glass add. "colour" is a Lambertian or checker albedo, or a mirror's
/// reflectance; the physical renderers do not use any of this.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shading {
    /// Radiance arriving equally from every direction, unshadowed (the fake for indirect light).
    pub ambient: Vec3,
    /// Highlights on every dielectric material.
    pub dielectric: DielectricShading,
    /// Highlights and mirror weight of every mirror material.
    pub mirror: MirrorShading,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DielectricShading {
    /// Exponent of the white highlight, > 0.
    pub shininess: f32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MirrorShading {
    /// Colour of the Phong highlight, each channel in [0, 1].
    pub specular: Vec3,
    /// Phong exponent, > 0.
    pub shininess: f32,
    /// Fraction of light mirrored (tinted by the reflectance), in [0, 1]; the rest is the
    /// Phong-lit colour.
    pub weight: f32,
}
