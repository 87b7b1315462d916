//! The rasterizer's view of a scene: what it can draw, checked and pulled out of the physical
//! [`Scene`].
//!
//! The rasterizer draws one kind of scene, the assignment's task 1: a checkerboard (or plain)
//! floor quad, at most one glass (dielectric) sphere and at most one metal (mirror) sphere,
//! any number of Lambertian triangle meshes, lit by one delta directional light, with the
//! environment's radiance as its background and `[shading] ambient` in place of the sky's
//! light. Glass and mirrors are drawn through a cube map each, captured from a sphere's centre,
//! so a mesh may not be glass or a mirror. Anything else is refused with an error that
//! names what and where ([`Scene::require`] for the features, [`RasterScene::from_scene`] for
//! the arrangement); nothing is silently left out.

use std::path::Path;

use glam::{Vec2, Vec3};
use illum_scene::{
    ClipPlanes, Effects, Feature, Look, MaterialKind, MeshRef, RendererKind, Scene, SceneError, Shape,
    Sphere, fmt_f32, toml_key,
};

/// Whether the rasterizer implements `feature`. A match rather than a list, so that a feature
/// added to the scene model does not compile until it is decided for the rasterizer.
pub fn implements(feature: Feature) -> bool {
    match feature {
        Feature::QuadShape
        | Feature::SphereShape
        | Feature::Lambertian
        | Feature::Checker
        | Feature::Dielectric
        | Feature::Mirror
        | Feature::DeltaDirectionalLight
        | Feature::MeshShape
        | Feature::SmoothShading
        | Feature::Environment => true,
        Feature::BoxShape | Feature::AreaLight | Feature::SunDisc => false,
    }
}

/// A scene the rasterizer can draw.
#[derive(Clone, Debug, PartialEq)]
pub struct RasterScene {
    /// Scene name (the file's `name`, or its file stem).
    pub name: String,
    /// The file it came from, for error messages.
    pub source: String,
    /// Perspective camera and output resolution.
    pub camera: illum_scene::Camera,
    /// Near and far clip distances of the camera.
    pub clip: ClipPlanes,
    /// Linear RGB clear colour: the environment's radiance (black without one).
    pub background: Vec3,
    pub light: RasterLight,
    /// `[shading] ambient`: unshadowed light from everywhere.
    pub ambient: Vec3,
    pub floor: CheckerFloor,
    /// The refracting sphere, if the scene has one (without it no glass cube map is captured).
    pub glass: Option<GlassSphere>,
    /// The Phong-lit (and, in the enhanced look, mirroring) sphere, if the scene has one.
    pub metal: Option<MetalSphere>,
    /// The Lambertian triangle meshes, in file order.
    pub meshes: Vec<RasterMesh>,
    /// The look used when the caller does not choose one.
    pub look: Look,
    /// The effect toggles used when the caller does not choose them.
    pub effects: Effects,
    pub quality: RasterQuality,
}

/// The directional light as the rasterizer shades with it: colour x (ambient + N.L x radiance).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterLight {
    /// Unit vector along which the light travels.
    pub direction: Vec3,
    /// Irradiance / pi: the radiance a white Lambertian surface facing the light reflects.
    pub radiance: Vec3,
}

impl RasterLight {
    /// Unit vector along which the light travels.
    pub fn direction(&self) -> Vec3 {
        self.direction
    }

    /// Unit vector from a surface toward the light: the L of N.L.
    pub fn to_light(&self) -> Vec3 {
        -self.direction
    }

    /// The light's colour x intensity in three.js's terms.
    pub fn radiance(&self) -> Vec3 {
        self.radiance
    }
}

/// A horizontal rectangle at height `center.y`, `size.x` long along X and `size.y` along Z,
/// tiled with squares of side `tile`. The tile (i, j), counted from the minimum corner, has
/// colour `colors[(i + j) % 2]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckerFloor {
    pub center: Vec3,
    pub size: Vec2,
    pub tile: f32,
    pub colors: [Vec3; 2],
}

impl CheckerFloor {
    /// (x, z) of the corner with the smallest coordinates.
    pub fn min_corner(&self) -> Vec2 {
        Vec2::new(self.center.x, self.center.z) - 0.5 * self.size
    }

    /// (x, z) of the corner with the largest coordinates.
    pub fn max_corner(&self) -> Vec2 {
        Vec2::new(self.center.x, self.center.z) + 0.5 * self.size
    }

    /// The floor's height.
    pub fn height(&self) -> f32 {
        self.center.y
    }
}

/// The transparent sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlassSphere {
    pub center: Vec3,
    pub radius: f32,
    /// Figure look: the colour mixed with the environment; enhanced look: the transmission tint.
    pub color: Vec3,
    /// n_outside / n_inside = 1 / ior (0.7 in the assignment: glass of index 1.43), in (0, 1].
    pub refraction_ratio: f32,
    /// Figure look: pixel = (1 - reflectivity) color + reflectivity environment, in [0, 1].
    pub reflectivity: f32,
    /// Enhanced look: exponent of the white highlight, > 0.
    pub shininess: f32,
}

/// The Phong-lit sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetalSphere {
    pub center: Vec3,
    pub radius: f32,
    /// The mirror's reflectance, used as the Phong colour.
    pub color: Vec3,
    pub specular: Vec3,
    /// Phong exponent, > 0.
    pub shininess: f32,
    /// Enhanced look: the fraction of light mirrored (tinted by `color`), in [0, 1].
    pub mirror: f32,
}

/// A Lambertian triangle mesh, shaded as the Whitted ray tracer's local model shades it:
/// albedo x (ambient + light x N.L x visibility), smoothly with its vertex normals unless flat.
#[derive(Clone, Debug, PartialEq)]
pub struct RasterMesh {
    pub mesh: MeshRef,
    pub albedo: Vec3,
}

impl RasterMesh {
    /// A sphere around every vertex (centre and radius): what the shadow map and the cube
    /// maps' clip planes are fitted to.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        let (lo, hi) = self.mesh.bounds();
        (0.5 * (lo + hi), 0.5 * (hi - lo).length())
    }
}

/// Quality settings that trade speed for fidelity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterQuality {
    /// Half-width of the soft shadow edge in scene units (> 0); also sets the shadow map's texel.
    pub pcf_radius: f32,
    /// Side of each cube-map face in texels (>= 1).
    pub cube_size: u32,
}

impl RasterScene {
    /// Reads a scene file and checks that the rasterizer can draw it.
    pub fn load(path: &Path) -> Result<RasterScene, SceneError> {
        Self::from_scene(&Scene::load(path)?)
    }

    /// Parses scene text (see [`Scene::from_toml_str`]) and checks that the rasterizer can draw it.
    pub fn from_toml_str(text: &str, file_label: &str) -> Result<RasterScene, SceneError> {
        Self::from_scene(&Scene::from_toml_str(text, file_label)?)
    }

    /// The rasterizer's view of `scene`, or why it cannot draw it.
    pub fn from_scene(scene: &Scene) -> Result<RasterScene, SceneError> {
        scene.require(RendererKind::Raster.noun(), implements)?;
        let file = scene.source.as_str();
        let needs = |field: &str, what: &str| {
            SceneError::invalid(file, field, "(missing)", format!("the rasterizer needs {what}"))
        };
        let clip = scene.clip.ok_or_else(|| needs("camera.near", "the camera's clip planes near and far"))?;
        let sun = scene.directional_light.ok_or_else(|| needs("directional_light", "a directional light"))?;

        let mut floor = None;
        let (mut glass, mut metal) = (None, None);
        let mut meshes = Vec::new();
        for (i, object) in scene.objects.iter().enumerate() {
            let material = scene.material_of(object);
            match (&object.shape, material.kind) {
                (Shape::Quad(quad), kind) => {
                    only_one(
                        floor.is_some(),
                        file,
                        &scene.object_label(i),
                        "a second quad",
                        "the rasterizer draws one quad, the floor",
                    )?;
                    floor = Some(checker_floor(file, &scene.object_label(i), *quad, kind)?);
                }
                (Shape::Sphere(sphere), MaterialKind::Dielectric { ior }) => {
                    let field = scene.object_label(i);
                    only_one(
                        glass.is_some(),
                        file,
                        &field,
                        "a second dielectric sphere",
                        "the rasterizer draws at most one glass sphere (one refraction cube map)",
                    )?;
                    if ior < 1.0 {
                        return Err(SceneError::invalid(
                            file,
                            format!("materials.{}.dielectric.ior", toml_key(&material.name)),
                            fmt_f32(ior),
                            "the rasterizer refracts only into a denser medium: ior must be >= 1",
                        ));
                    }
                    glass = Some((
                        i,
                        GlassSphere {
                            center: sphere.center,
                            radius: sphere.radius,
                            color: scene.raster.glass_color,
                            refraction_ratio: 1.0 / ior,
                            reflectivity: scene.raster.glass_reflectivity,
                            shininess: scene.shading.dielectric.shininess,
                        },
                    ));
                }
                (Shape::Sphere(sphere), MaterialKind::Mirror { reflectance }) => {
                    only_one(
                        metal.is_some(),
                        file,
                        &scene.object_label(i),
                        "a second mirror sphere",
                        "the rasterizer draws at most one metal sphere (one mirror cube map)",
                    )?;
                    let shading = scene.shading.mirror;
                    metal = Some((
                        i,
                        MetalSphere {
                            center: sphere.center,
                            radius: sphere.radius,
                            color: reflectance,
                            specular: shading.specular,
                            shininess: shading.shininess,
                            mirror: shading.weight,
                        },
                    ));
                }
                (Shape::Mesh(mesh), MaterialKind::Lambertian { albedo }) => {
                    meshes.push(RasterMesh { mesh: mesh.clone(), albedo });
                }
                (shape, _) => {
                    return Err(SceneError::invalid(
                        file,
                        format!("{}.material", scene.object_label(i)),
                        format!("{:?}", material.name),
                        format!(
                            "the rasterizer draws a {} only with a {}",
                            shape.kind(),
                            match shape {
                                Shape::Sphere(_) => "dielectric or mirror material",
                                // Glass and mirrors look up a cube map captured from a sphere's centre.
                                Shape::Mesh(_) => {
                                    "Lambertian material (glass and mirrors are spheres only, each drawn \
                                     through a cube map)"
                                }
                                _ => "Lambertian or checker material",
                            }
                        ),
                    ));
                }
            }
        }
        let floor = floor.ok_or_else(|| needs("objects", "a floor: one horizontal quad"))?;
        placement(
            scene,
            glass.map(|(i, g)| (i, Sphere { center: g.center, radius: g.radius })),
            metal.map(|(i, m)| (i, Sphere { center: m.center, radius: m.radius })),
        )?;

        Ok(RasterScene {
            name: scene.name.clone(),
            source: scene.source.clone(),
            camera: scene.camera,
            clip,
            background: scene.environment.map_or(Vec3::ZERO, |e| e.radiance),
            light: RasterLight { direction: sun.direction, radiance: sun.irradiance / std::f32::consts::PI },
            ambient: scene.shading.ambient,
            floor,
            glass: glass.map(|(_, g)| g),
            metal: metal.map(|(_, m)| m),
            meshes,
            look: scene.raster.look,
            effects: scene.raster.effects,
            quality: RasterQuality { pcf_radius: scene.raster.pcf_radius, cube_size: scene.raster.cube_size },
        })
    }

    /// Centre and radius of each sphere the scene has: the glass's first, then the metal's.
    pub fn spheres(&self) -> Vec<(Vec3, f32)> {
        let glass = self.glass.map(|g| (g.center, g.radius));
        glass.into_iter().chain(self.metal.map(|m| (m.center, m.radius))).collect()
    }

    /// A sphere around each shadow caster: the spheres ([`Self::spheres`]), then each mesh's
    /// bounding sphere.
    pub fn casters(&self) -> Vec<(Vec3, f32)> {
        let mut casters = self.spheres();
        casters.extend(self.meshes.iter().map(RasterMesh::bounding_sphere));
        casters
    }

    /// Replaces the output resolution, after checking it by the same rules as the file.
    /// `origin` labels the errors (e.g. "command line"), whose fields are `--width` and
    /// `--height`. On error nothing is changed.
    pub fn set_resolution(
        &mut self,
        width: Option<u32>,
        height: Option<u32>,
        origin: &str,
    ) -> Result<(), SceneError> {
        for (field, value) in [("--width", width), ("--height", height)] {
            if value == Some(0) {
                return Err(SceneError::invalid(origin, field, "0", "must be at least 1"));
            }
        }
        self.camera.width = width.unwrap_or(self.camera.width);
        self.camera.height = height.unwrap_or(self.camera.height);
        Ok(())
    }
}

/// Refuses a second object of a kind the rasterizer draws once (`taken`: one was found already).
fn only_one(taken: bool, file: &str, field: &str, what: &str, allowed: &str) -> Result<(), SceneError> {
    if taken { Err(SceneError::invalid(file, field, what, allowed)) } else { Ok(()) }
}

/// The floor: a horizontal quad facing +Y, edges along X and Z, `corner` at its minimum (x, z)
/// (the rasterizer counts tiles from there, as the checker material counts them from the
/// corner). A plain Lambertian quad is a checkerboard of one colour.
fn checker_floor(
    file: &str,
    label: &str,
    quad: illum_scene::Quad,
    kind: MaterialKind,
) -> Result<CheckerFloor, SceneError> {
    let (u, v) = (quad.edge_u, quad.edge_v);
    let along_axis = |e: Vec3| (e.y == 0.0) && ((e.x == 0.0) != (e.z == 0.0));
    let faces_up = u.cross(v).y > 0.0;
    let from_min = (u.x + v.x) >= 0.0 && (u.z + v.z) >= 0.0;
    if !(along_axis(u) && along_axis(v) && faces_up && from_min) {
        return Err(SceneError::invalid(
            file,
            format!("{label}.quad"),
            format!("{{ corner = {}, edge_u = {u}, edge_v = {v} }}", quad.corner),
            "the rasterizer's floor is a horizontal rectangle facing up (+Y): one edge along +X, \
             the other along +Z, ordered so that edge_u x edge_v points up, and corner at its \
             minimum x and z",
        ));
    }
    let size = Vec2::new(u.x.abs() + v.x.abs(), u.z.abs() + v.z.abs());
    let center = quad.corner + 0.5 * (u + v);
    let (tile, colors) = match kind {
        MaterialKind::Checker(c) => (c.tile, [c.even, c.odd]),
        MaterialKind::Lambertian { albedo } => (size.max_element(), [albedo, albedo]),
        _ => {
            return Err(SceneError::invalid(
                file,
                format!("{label}.material"),
                kind.key(),
                "the rasterizer's floor needs a Lambertian or checker material",
            ));
        }
    };
    Ok(CheckerFloor { center, size, tile, colors })
}

/// The camera must be outside the spheres (a sphere around the eye would fill the view with its
/// inside), and two spheres must not intersect: each cube map is captured from its sphere's
/// centre and must see the other sphere from outside.
fn placement(
    scene: &Scene,
    glass: Option<(usize, Sphere)>,
    metal: Option<(usize, Sphere)>,
) -> Result<(), SceneError> {
    let file = scene.source.as_str();
    let eye = scene.camera.eye;
    for (i, s) in glass.into_iter().chain(metal) {
        let distance = eye.distance(s.center);
        if distance <= s.radius {
            return Err(SceneError::invalid(
                file,
                "camera.eye",
                format!("{eye}"),
                format!(
                    "must lie outside {} (centre {}, radius {}; the eye is {distance} from its centre) \
                     for the rasterizer",
                    scene.object_label(i),
                    s.center,
                    s.radius
                ),
            ));
        }
    }
    let (Some((i, g)), Some((j, m))) = (glass, metal) else { return Ok(()) };
    let distance = g.center.distance(m.center);
    if distance <= g.radius + m.radius {
        return Err(SceneError::invalid(
            file,
            format!("{}.sphere.center", scene.object_label(j)),
            format!("{}", m.center),
            format!(
                "the rasterizer's spheres must not touch or overlap: their centres are {distance} apart \
                 but the radii add up to {} ({:?} is at {}); each sphere's cube map is captured from \
                 its centre",
                g.radius + m.radius,
                scene.objects[i].name,
                g.center
            ),
        ));
    }
    Ok(())
}
