//! Whitted's 1980 ray tracer in f64: the independent CPU copy the GPU Whitted ray tracer is to be
//! checked against, pixel by pixel.
//!
//! At each hit point p with unit normal n turned toward the arriving ray, view direction v and
//! colour c (a Lambertian or checker albedo, or a mirror's reflectance), with the `[shading]`
//! parameters of the scene (ambient a; the mirror's weight w, specular s and shininess; the
//! dielectric's shininess):
//!
//! - **Lambertian, checker**: c x (a + sum over lights of E_l x max(n.l, 0) x V_l);
//! - **mirror**: (1 - w) x c x (a + sum E_l x max(n.l, 0) x V_l) + w x c x trace(reflected)
//!   + s x sum E_l x H_l;
//! - **dielectric**: F x trace(reflected) + (1 - F) x trace(refracted) + sum E_l x H_l, with the
//!   exact unpolarised Fresnel reflectance F of the interface (F = 1 under total internal
//!   reflection, when no refracted ray exists);
//! - **emitter**: its radiance on its front side, black behind;
//! - a ray that leaves the scene sees the environment's radiance (black without one).
//!
//! E_l is what light l contributes to a white Lambertian surface facing it, per unit n.l: for the
//! directional light its irradiance / pi (a three.js intensity); V_l is 1 where a hard shadow ray
//! toward the light meets no object (every object blocks it, glass and mirror included; emitters
//! do not); H_l = max(n.h, 0)^shininess x V_l where n.l > 0 is the Blinn-Phong highlight with the
//! half vector h = normalize(l + v). An area light (an emitting quad, as in the Cornell box) is
//! treated as a point light at its centre with the quad's power pattern: radiant intensity
//! L x area x cos(theta_light) toward the point, so E_l = L x area x cos(theta_light) / (pi r^2).
//!
//! A smooth mesh is shaded with its shading normal n_s in place of n: in n.l, n.h and the
//! specular directions (n_s where those stay on their sides: [`mirror_normal`],
//! [`dielectric_normal`]), while the geometric normal decides sides, offsets new rays, and
//! keeps a light behind the geometric surface from lighting it (the GPU's rules, illum-rtcore's
//! mesh_shading.wgsl, written here apart).
//!
//! Recursion: reflected and refracted rays are followed `depth` times; past that they contribute
//! nothing (black). Anti-aliasing: an n x n grid of rays through each pixel at the cell centres
//! ((i + 0.5) / n), averaged: deterministic.

use std::f64::consts::PI;

use glam::DVec3;
use illum_scene::{Feature, MaterialKind, Scene, SceneError, Shape};

use crate::camera::PinholeCamera;
use crate::geometry::SurfaceHit;
use crate::geometry::{Ball, OrientedBox, Parallelogram, Surface, dvec, mesh_surfaces};
use crate::optics::{checker_albedo, dielectric_normal, fresnel, mirror_normal, reflect, refract};

/// One object: its surface and its material.
#[derive(Clone, Copy, Debug)]
struct Item {
    surface: Surface,
    material: MaterialKind,
}

/// A light as Whitted sees it: a direction at infinity or a point with a power pattern.
#[derive(Clone, Copy, Debug)]
enum Light {
    /// `to_light` is the unit vector toward the light; `radiance` = irradiance / pi.
    Directional { to_light: DVec3, radiance: DVec3 },
    /// The centre of an emitting quad with normal `normal` (its front side), radiance x area.
    Point { position: DVec3, normal: DVec3, power: DVec3 },
}

/// Whitted's algorithm on one scene, with the scene's `[whitted]` depth and anti-aliasing and
/// its `[shading]` parameters (which callers may change before rendering).
#[derive(Clone, Debug)]
pub struct WhittedOracle {
    items: Vec<Item>,
    lights: Vec<Light>,
    background: DVec3,
    camera: PinholeCamera,
    ambient: DVec3,
    mirror_specular: DVec3,
    mirror_shininess: f64,
    mirror_weight: f64,
    dielectric_shininess: f64,
    /// Reflected and refracted rays are followed this many times.
    pub depth: u32,
    /// Rays per pixel: `aa` x `aa`.
    pub aa: u32,
}

/// Below this distance, scaled by the size of the coordinates, a new ray's origin is moved off
/// its surface (f64 roundoff at p is about 1e-16 |p|; 1e-9 leaves a wide margin and is far
/// below any feature of the scenes).
const SPAWN_EPSILON: f64 = 1e-9;

impl WhittedOracle {
    /// Prepares `scene`, or says which of its features Whitted's algorithm does not model.
    pub fn new(scene: &Scene) -> Result<WhittedOracle, SceneError> {
        // Every shape and material of the scene model, a delta directional light, area lights
        // (as point lights) and a constant environment; not a sun of finite size, since
        // Whitted's shadow rays are hard.
        scene.require("Whitted ray tracer", |f| !matches!(f, Feature::SunDisc))?;
        let mut items = Vec::with_capacity(scene.objects.len());
        let mut lights = Vec::new();
        for object in &scene.objects {
            let material = scene.material_of(object).kind;
            let surface = match &object.shape {
                Shape::Box(b) => Surface::Box(OrientedBox::from_shape(b)),
                Shape::Quad(q) => {
                    let p = Parallelogram::new(dvec(q.corner), dvec(q.edge_u), dvec(q.edge_v));
                    if let MaterialKind::Emitter { radiance } = material {
                        lights.push(Light::Point {
                            position: p.point(0.5, 0.5),
                            normal: p.normal,
                            power: dvec(radiance) * p.area,
                        });
                    }
                    Surface::Parallelogram(p)
                }
                Shape::Sphere(s) => {
                    Surface::Ball(Ball { center: dvec(s.center), radius: f64::from(s.radius) })
                }
                Shape::Mesh(mesh) => {
                    items.extend(mesh_surfaces(mesh).map(|surface| Item { surface, material }));
                    continue;
                }
            };
            items.push(Item { surface, material });
        }
        if let Some(sun) = &scene.directional_light {
            lights.push(Light::Directional {
                to_light: -dvec(sun.direction).normalize(),
                radiance: dvec(sun.irradiance) / PI,
            });
        }
        let shading = &scene.shading;
        Ok(WhittedOracle {
            items,
            lights,
            background: scene.environment.map_or(DVec3::ZERO, |e| dvec(e.radiance)),
            camera: PinholeCamera::new(&scene.camera),
            ambient: dvec(shading.ambient),
            mirror_specular: dvec(shading.mirror.specular),
            mirror_shininess: f64::from(shading.mirror.shininess),
            mirror_weight: f64::from(shading.mirror.weight),
            dielectric_shininess: f64::from(shading.dielectric.shininess),
            depth: scene.whitted.depth,
            aa: scene.whitted.aa,
        })
    }

    /// The pixel (x, y): the mean of its `aa` x `aa` rays.
    pub fn pixel(&self, x: u32, y: u32) -> [f64; 3] {
        let rays = self.rays_moved(x, y, 0.0, 0.0);
        let sum = rays.iter().fold(DVec3::ZERO, |sum, &c| sum + DVec3::from_array(c));
        (sum / rays.len() as f64).to_array()
    }

    /// The colour of each of pixel (x, y)'s `aa` x `aa` rays, each moved by (dx, dy) pixels on
    /// the film. A ray whose colour changes when it moves by a small fraction of a pixel lies at
    /// an edge (a silhouette, a shadow's boundary, a tile's border, seen directly or after any
    /// bounce), where f32 rounding may send it to either side. (Per ray, not per pixel: moving
    /// all of a pixel's rays can carry one ray across an edge one way and another the other,
    /// leaving the pixel's mean as it was.)
    pub fn rays_moved(&self, x: u32, y: u32, dx: f64, dy: f64) -> Vec<[f64; 3]> {
        let n = self.aa.max(1);
        let mut rays = Vec::with_capacity((n * n) as usize);
        for j in 0..n {
            for i in 0..n {
                let (jx, jy) = ((f64::from(i) + 0.5) / f64::from(n), (f64::from(j) + 0.5) / f64::from(n));
                let d = self.camera.direction(x, y, jx + dx, jy + dy);
                rays.push(self.trace(self.camera.eye, d, self.depth).to_array());
            }
        }
        rays
    }

    /// The whole image, row-major from the top-left, on `threads` threads (the result does not
    /// depend on it).
    pub fn render(&self, threads: usize) -> Vec<[f64; 3]> {
        crate::parallel::rows_in_parallel(self.camera.width, self.camera.height, threads, |x, y| {
            self.pixel(x, y)
        })
    }

    /// The closest hit of o + t d, t > 0, and its item's index. An emitter wins a tie with a
    /// coplanar surface (the Cornell light set into its ceiling), whatever their order: it
    /// counts as closer unless the other surface is nearer by more than roundoff.
    fn closest(&self, o: DVec3, d: DVec3) -> Option<(SurfaceHit, usize)> {
        const TIE: f64 = 1e-9;
        let mut best: Option<(SurfaceHit, usize, bool)> = None;
        for (i, item) in self.items.iter().enumerate() {
            let Some(hit) = item.surface.intersect(o, d, f64::INFINITY) else { continue };
            let emitter = matches!(item.material, MaterialKind::Emitter { .. });
            let wins = match best {
                None => true,
                Some((best_hit, _, best_is_emitter)) => match (emitter, best_is_emitter) {
                    (true, false) => hit.t <= best_hit.t * (1.0 + TIE),
                    (false, true) => hit.t < best_hit.t * (1.0 - TIE),
                    _ => hit.t < best_hit.t,
                },
            };
            if wins {
                best = Some((hit, i, emitter));
            }
        }
        best.map(|(hit, i, _)| (hit, i))
    }

    /// Whether any non-emitting object lies on o + t d for 0 < t < t_max.
    fn blocked(&self, o: DVec3, d: DVec3, t_max: f64) -> bool {
        self.items.iter().any(|item| {
            !matches!(item.material, MaterialKind::Emitter { .. })
                && item.surface.intersect(o, d, t_max).is_some()
        })
    }

    /// For each light seen from p (normal n): (unit vector toward it, E_l, visibility).
    fn lights_at(&self, p: DVec3, n: DVec3) -> Vec<(DVec3, DVec3, f64)> {
        let origin = offset(p, n);
        self.lights
            .iter()
            .map(|light| match *light {
                Light::Directional { to_light, radiance } => {
                    let visible = !self.blocked(origin, to_light, f64::INFINITY);
                    (to_light, radiance, f64::from(u8::from(visible)))
                }
                Light::Point { position, normal, power } => {
                    let to = position - p;
                    let r2 = to.length_squared();
                    let l = to / r2.sqrt();
                    let cos_light = (-l).dot(normal).max(0.0);
                    let visible = cos_light > 0.0 && !self.blocked(origin, l, r2.sqrt() * (1.0 - 1e-9));
                    (l, power * cos_light / (PI * r2), f64::from(u8::from(visible)))
                }
            })
            .collect()
    }

    /// Radiance arriving at o along unit d, with `depth` reflections or refractions left.
    fn trace(&self, o: DVec3, d: DVec3, depth: u32) -> DVec3 {
        let Some((hit, index)) = self.closest(o, d) else { return self.background };
        let item = &self.items[index];
        let p = o + hit.t * d;
        let front = hit.normal.dot(d) < 0.0;
        // The normals against the ray: geometric and shading.
        let (n, ns) = if front { (hit.normal, hit.shading) } else { (-hit.normal, -hit.shading) };
        let v = -d;
        // Lights in front of the geometric surface (none leaks through it).
        let lights: Vec<(DVec3, DVec3, f64)> =
            self.lights_at(p, n).into_iter().filter(|(l, _, _)| n.dot(*l) > 0.0).collect();
        let lambert = |c: DVec3| {
            let direct: DVec3 = lights.iter().map(|&(l, e, vis)| e * ns.dot(l).max(0.0) * vis).sum();
            c * (self.ambient + direct)
        };
        let highlights = |shininess: f64| -> DVec3 {
            lights
                .iter()
                .filter(|(l, _, _)| ns.dot(*l) > 0.0)
                .map(|&(l, e, vis)| e * (ns.dot((l + v).normalize()).max(0.0)).powf(shininess) * vis)
                .sum()
        };
        let reflected = |depth: u32, about: DVec3| {
            if depth == 0 {
                return DVec3::ZERO;
            }
            self.trace(offset(p, n), reflect(d, about), depth - 1)
        };
        match item.material {
            MaterialKind::Emitter { radiance } => {
                if front {
                    dvec(radiance)
                } else {
                    DVec3::ZERO
                }
            }
            MaterialKind::Lambertian { albedo } => lambert(dvec(albedo)),
            MaterialKind::Checker(checker) => {
                let Surface::Parallelogram(quad) = item.surface else {
                    unreachable!("validation puts checkers on quads only")
                };
                lambert(checker_albedo(&quad, checker, p))
            }
            MaterialKind::Mirror { reflectance } => {
                let c = dvec(reflectance);
                let w = self.mirror_weight;
                (1.0 - w) * lambert(c)
                    + w * c * reflected(depth, mirror_normal(d, n, ns))
                    + self.mirror_specular * highlights(self.mirror_shininess)
            }
            MaterialKind::Dielectric { ior } => {
                // Entering through the front (outward normal against the ray) or leaving.
                let eta = if front { 1.0 / f64::from(ior) } else { f64::from(ior) };
                let optic = dielectric_normal(d, n, ns, eta);
                let cos_i = v.dot(optic);
                let spark = highlights(self.dielectric_shininess);
                match refract(d, optic, eta) {
                    None => reflected(depth, optic) + spark,
                    Some(refracted) => {
                        let f = fresnel(cos_i, -refracted.dot(optic), eta);
                        let transmitted = if depth == 0 {
                            DVec3::ZERO
                        } else {
                            self.trace(offset(p, -n), refracted, depth - 1)
                        };
                        f * reflected(depth, optic) + (1.0 - f) * transmitted + spark
                    }
                }
            }
        }
    }
}

/// p moved off its surface along n by a bound on its rounding error.
fn offset(p: DVec3, n: DVec3) -> DVec3 {
    p + n * SPAWN_EPSILON * (1.0 + p.abs().max_element())
}
