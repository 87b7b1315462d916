//! The scene's geometry and specular materials in f64, for the glint's solve: nearest hits of a
//! ray, with the surface normal, and how a mirror or a dielectric scatters it.

use glam::DVec3;
use illum_scene::{MaterialKind, Scene, Shape};

use super::tree::{Node, build_tree, slab_hit};

/// How a surface scatters light, as far as the glint is concerned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Surface {
    /// Lambertian, checker or emitter: a chain that reaches it carries no glint.
    Other,
    Mirror {
        reflectance: [f64; 3],
    },
    Dielectric {
        ior: f64,
    },
}

#[derive(Clone, Copy, Debug)]
pub(super) enum Body {
    Sphere {
        center: DVec3,
        radius: f64,
    },
    Quad {
        corner: DVec3,
        edge_u: DVec3,
        edge_v: DVec3,
        normal: DVec3,
    },
    /// `world = rotation * local + offset`, local box [min, max].
    Box {
        min: DVec3,
        max: DVec3,
        rotation: glam::DMat3,
        offset: DVec3,
    },
}

/// A ray's nearest hit: the object, the distance along the (unit) direction and the outward
/// geometric normal there.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub object: usize,
    pub t: f64,
    pub normal: DVec3,
}

/// Every object of a scene, in f64, with its surface.
#[derive(Clone, Debug)]
pub struct Bodies {
    bodies: Vec<Body>,
    surfaces: Vec<Surface>,
    /// Scene size, for the distance below which a ray leaving a flat face ignores hits.
    scale: f64,
    /// A bounding-volume hierarchy over the bodies: the solve follows each chain many thousands
    /// of times, and without it a scene of n objects costs n ray tests per segment.
    tree: Vec<Node>,
    /// Scene indices of the bodies in the hierarchy's order: a leaf holds `order[first..][..count]`.
    order: Vec<usize>,
    /// The bodies kept out of the hierarchy and tested by every ray: those whose box spans more
    /// than a quarter of the scene's on some axis (a floor). In a leaf, such a body's box would
    /// swell the leaf's and its ancestors' to the whole scene, and every ray near it would test
    /// the leaf's other bodies too.
    large: Vec<usize>,
}

fn d3(v: glam::Vec3) -> DVec3 {
    v.as_dvec3()
}

impl Bodies {
    pub fn new(scene: &Scene) -> Self {
        let mut scale: f64 = 1.0;
        let bodies: Vec<Body> = scene
            .objects
            .iter()
            .map(|o| match &o.shape {
                Shape::Sphere(s) => {
                    scale = scale.max(d3(s.center).abs().max_element() + f64::from(s.radius));
                    Body::Sphere { center: d3(s.center), radius: f64::from(s.radius) }
                }
                Shape::Quad(q) => {
                    let (u, v) = (d3(q.edge_u), d3(q.edge_v));
                    scale = scale.max(d3(q.corner).abs().max_element() + u.length() + v.length());
                    Body::Quad { corner: d3(q.corner), edge_u: u, edge_v: v, normal: u.cross(v).normalize() }
                }
                Shape::Box(b) => {
                    let rotation = glam::DMat3::from_rotation_y(f64::from(b.rotate_y_deg).to_radians());
                    let offset = d3(b.pivot) + d3(b.translate) - rotation * d3(b.pivot);
                    scale = scale.max(offset.abs().max_element() + d3(b.max - b.min).length());
                    Body::Box { min: d3(b.min), max: d3(b.max), rotation, offset }
                }
                Shape::Mesh(_) => {
                    unreachable!("the path tracer refuses meshes by name (gpu_scene.rs, implements)")
                }
            })
            .collect();
        let surfaces = scene
            .objects
            .iter()
            .map(|o| match scene.material_of(o).kind {
                MaterialKind::Mirror { reflectance } => {
                    Surface::Mirror { reflectance: d3(reflectance).to_array() }
                }
                MaterialKind::Dielectric { ior } => Surface::Dielectric { ior: f64::from(ior) },
                _ => Surface::Other,
            })
            .collect();
        let boxes: Vec<(DVec3, DVec3)> = bodies.iter().map(|b| bounds(b, scale)).collect();
        let (lo, hi) = boxes
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), b| (lo.min(b.0), hi.max(b.1)));
        let (large, members): (Vec<usize>, Vec<usize>) =
            (0..boxes.len()).partition(|&i| (boxes[i].1 - boxes[i].0).cmpgt(0.25 * (hi - lo)).any());
        let (tree, order) = build_tree(&boxes, members);
        Self { bodies, surfaces, scale, tree, order, large }
    }

    pub fn surface(&self, object: usize) -> Surface {
        self.surfaces[object]
    }

    /// The derivative of the outward normal per unit move of the hit point along the surface:
    /// 1 / r on a sphere (n = (p - c) / r), 0 on a flat face.
    pub fn curvature(&self, object: usize) -> f64 {
        match self.bodies[object] {
            Body::Sphere { radius, .. } => 1.0 / radius,
            Body::Quad { .. } | Body::Box { .. } => 0.0,
        }
    }

    /// The spheres with a specular surface: (object, centre, radius).
    pub fn specular_spheres(&self) -> impl Iterator<Item = (usize, DVec3, f64)> + '_ {
        self.bodies.iter().enumerate().filter_map(|(i, b)| match (b, self.surfaces[i]) {
            (_, Surface::Other) => None,
            (Body::Sphere { center, radius }, _) => Some((i, *center, *radius)),
            _ => None,
        })
    }

    /// Whether any object other than a sphere is specular (a flat mirror or a glass box).
    pub fn has_flat_specular(&self) -> bool {
        self.bodies
            .iter()
            .zip(&self.surfaces)
            .any(|(b, s)| *s != Surface::Other && !matches!(b, Body::Sphere { .. }))
    }

    /// The nearest hit of the ray `o + t d` (d a unit vector), `t > 0`, leaving the surface of
    /// object `own` (None for the camera ray). Leaving a sphere, its root at the origin is
    /// skipped exactly: the other root is `-2 (o - c).d`. Leaving a flat face, hits nearer than
    /// 1e-9 of the scene's size are ignored. The same hit as testing every body in turn (ties to
    /// the lower index), found through the hierarchy.
    pub fn nearest(&self, o: DVec3, d: DVec3, own: Option<usize>) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        self.visit(o, d, f64::INFINITY, |i, far| {
            if let Some((t, normal)) = self.hit_body(i, o, d, own)
                && best.is_none_or(|b| t < b.t || (t == b.t && i < b.object))
            {
                best = Some(Hit { object: i, t, normal });
                *far = t;
            }
            false
        });
        best
    }

    /// Object `object`'s own hit of the ray, as [`Self::nearest`] defines hits, whatever else
    /// is in the way.
    pub fn hit(&self, object: usize, o: DVec3, d: DVec3, own: Option<usize>) -> Option<Hit> {
        self.hit_body(object, o, d, own).map(|(t, normal)| Hit { object, t, normal })
    }

    /// Whether any object but `except` has a hit of the ray (as [`Self::nearest`] defines
    /// hits) nearer than `far`: the ray from o does not reach `far` unobstructed. It stops at
    /// the first such hit, so it costs less than [`Self::nearest`].
    pub fn blocked(&self, o: DVec3, d: DVec3, own: Option<usize>, far: f64, except: Option<usize>) -> bool {
        let mut found = false;
        self.visit(o, d, far, |i, _| {
            found = Some(i) != except && self.hit_body(i, o, d, own).is_some_and(|(t, _)| t < far);
            found
        });
        found
    }

    /// Walks the large bodies, then the hierarchy along the ray o + t d through the nodes it
    /// meets before `far`: `body(i, far)` is called with each large body and each body of an
    /// entered leaf, may lower `far`, and ends the walk by returning true.
    fn visit(&self, o: DVec3, d: DVec3, mut far: f64, mut body: impl FnMut(usize, &mut f64) -> bool) {
        for &i in &self.large {
            if body(i, &mut far) {
                return;
            }
        }
        let inv = d.recip();
        let mut stack = [0usize; 64];
        let mut depth = usize::from(!self.tree.is_empty());
        while depth > 0 {
            depth -= 1;
            let node = self.tree[stack[depth]];
            if !slab_hit(o, inv, node.lo, node.hi, far) {
                continue;
            }
            if node.count == 0 {
                stack[depth] = node.first;
                stack[depth + 1] = node.first + 1;
                depth += 2;
                continue;
            }
            for &i in &self.order[node.first..node.first + node.count] {
                if body(i, &mut far) {
                    return;
                }
            }
        }
    }

    /// Body `i`'s hit of the ray, as [`Self::nearest`] defines it.
    fn hit_body(&self, i: usize, o: DVec3, d: DVec3, own: Option<usize>) -> Option<(f64, DVec3)> {
        match self.bodies[i] {
            Body::Sphere { center, radius } => sphere_hit(o, d, center, radius, own == Some(i)),
            Body::Quad { corner, edge_u, edge_v, normal } => {
                let t_min = if own == Some(i) { f64::INFINITY } else { 0.0 };
                quad_hit(o, d, corner, edge_u, edge_v, normal).filter(|h| h.0 > t_min)
            }
            Body::Box { min, max, rotation, offset } => {
                let t_min = if own == Some(i) { 1e-9 * self.scale } else { 0.0 };
                box_hit(o, d, min, max, rotation, offset, t_min)
            }
        }
    }
}

fn sphere_hit(o: DVec3, d: DVec3, c: DVec3, r: f64, own: bool) -> Option<(f64, DVec3)> {
    let oc = o - c;
    let b = oc.dot(d);
    if own {
        let t = -2.0 * b;
        return (t > 0.0).then(|| (t, (o + t * d - c) / r));
    }
    // The discriminant as r^2 - |oc - b d|^2: no cancellation between |oc|^2 and r^2 far away.
    let perp = oc - b * d;
    let disc = r * r - perp.length_squared();
    if disc < 0.0 {
        return None;
    }
    let h = disc.sqrt();
    // Roots -b -+ h; the nearer one from the stable product form.
    let q = if b > 0.0 { -b - h } else { -b + h };
    if q == 0.0 {
        return None;
    }
    let dist = oc.length();
    let other = (dist - r) * (dist + r) / q;
    let (t1, t2) = (q.min(other), q.max(other));
    let t = if t1 > 0.0 {
        t1
    } else if t2 > 0.0 {
        t2
    } else {
        return None;
    };
    Some((t, (o + t * d - c) / r))
}

fn quad_hit(o: DVec3, d: DVec3, corner: DVec3, u: DVec3, v: DVec3, n: DVec3) -> Option<(f64, DVec3)> {
    let denom = n.dot(d);
    if denom == 0.0 {
        return None;
    }
    let t = n.dot(corner - o) / denom;
    let p = o + t * d - corner;
    // Coordinates of p in the (u, v) frame through the dual basis.
    let uv = u.cross(v);
    let s = p.cross(v).dot(uv) / uv.length_squared();
    let w = u.cross(p).dot(uv) / uv.length_squared();
    ((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&w) && t > 0.0).then_some((t, n))
}

fn box_hit(
    o: DVec3,
    d: DVec3,
    min: DVec3,
    max: DVec3,
    rotation: glam::DMat3,
    offset: DVec3,
    t_min: f64,
) -> Option<(f64, DVec3)> {
    let inv = rotation.transpose();
    let lo = inv * (o - offset);
    let ld = inv * d;
    // Slabs: every face plane crossing, the nearest beyond t_min inside the box.
    let mut best: Option<(f64, DVec3)> = None;
    for axis in 0..3 {
        if ld[axis] == 0.0 {
            continue;
        }
        for (plane, sign) in [(min[axis], -1.0), (max[axis], 1.0)] {
            let t = (plane - lo[axis]) / ld[axis];
            if t <= t_min || best.is_some_and(|b| t >= b.0) {
                continue;
            }
            let p = lo + t * ld;
            let inside = (0..3).all(|k| k == axis || (min[k]..=max[k]).contains(&p[k]));
            if inside {
                let mut n = DVec3::ZERO;
                n[axis] = sign;
                best = Some((t, rotation * n));
            }
        }
    }
    best
}

/// Unpolarised Fresnel reflectance for a ray meeting an interface at cos_i > 0 with
/// eta = n_from / n_to, and the transmitted cosine (None: total internal reflection).
pub fn fresnel(cos_i: f64, eta: f64) -> (f64, Option<f64>) {
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return (1.0, None);
    }
    let cos_t = k.sqrt();
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (0.5 * (rs * rs + rp * rp), Some(cos_t))
}

/// The box around a body, padded by 1e-9 of the scene's size so that rounding never puts a hit
/// outside it.
fn bounds(body: &Body, scale: f64) -> (DVec3, DVec3) {
    let (lo, hi) = match *body {
        Body::Sphere { center, radius } => (center - DVec3::splat(radius), center + DVec3::splat(radius)),
        Body::Quad { corner, edge_u, edge_v, .. } => {
            let corners = [corner, corner + edge_u, corner + edge_v, corner + edge_u + edge_v];
            (corners.iter().fold(corner, |a, &c| a.min(c)), corners.iter().fold(corner, |a, &c| a.max(c)))
        }
        Body::Box { min, max, rotation, offset } => {
            let corners = (0..8).map(|k| {
                let local = DVec3::new(
                    if k & 1 == 0 { min.x } else { max.x },
                    if k & 2 == 0 { min.y } else { max.y },
                    if k & 4 == 0 { min.z } else { max.z },
                );
                rotation * local + offset
            });
            corners.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), c| (lo.min(c), hi.max(c)))
        }
    };
    let pad = DVec3::splat(1e-9 * scale);
    (lo - pad, hi + pad)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `nearest` by testing every body in turn, ties to the lower index: what the hierarchy
    /// must reproduce.
    fn brute_nearest(bodies: &Bodies, o: DVec3, d: DVec3, own: Option<usize>) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        for i in 0..bodies.bodies.len() {
            if let Some((t, _)) = bodies.hit_body(i, o, d, own)
                && best.is_none_or(|b| t < b.1)
            {
                best = Some((i, t));
            }
        }
        best
    }

    /// A scene of 60 spheres of many sizes, a floor quad and a rotated box: enough bodies for a
    /// hierarchy several levels deep.
    fn crowded() -> Scene {
        let mut text = String::from(
            "[camera]\neye = [0.0, 2.0, 20.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nvfov = 40.0\n\
             width = 64\nheight = 64\n[materials.glass]\ndielectric = { ior = 1.5 }\n\
             [materials.white]\nalbedo = [0.5, 0.5, 0.5]\n\
             [[objects]]\nmaterial = \"white\"\n\
             quad = { corner = [-10.0, 0.0, -10.0], edge_u = [0.0, 0.0, 20.0], edge_v = [20.0, 0.0, 0.0] }\n\
             [[objects]]\nmaterial = \"white\"\n\
             box = { min = [0.0, 0.0, 0.0], max = [1.0, 2.0, 1.5], rotate_y = 30.0, pivot = [0.5, 0.0, 0.5], translate = [3.0, 0.0, -2.0] }\n",
        );
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..60 {
            let (x, y, z, r) = (next() * 16.0 - 8.0, next() * 4.0, next() * 16.0 - 8.0, 0.05 + next() * 0.8);
            text += &format!(
                "[[objects]]\nmaterial = \"glass\"\nsphere = {{ center = [{x:?}, {y:?}, {z:?}], radius = {r:?} }}\n"
            );
        }
        Scene::from_toml_str(&text, "crowded.toml").unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn the_hierarchy_finds_the_hit_that_testing_every_body_finds() {
        let scene = crowded();
        let bodies = Bodies::new(&scene);
        assert!(bodies.tree.len() > 15, "a hierarchy of {} nodes", bodies.tree.len());
        let mut state = 99u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut hits, mut checked) = (0, 0);
        for k in 0..20000 {
            // Rays from outside and from the surface of a body (as the chains' continuation rays
            // leave one), including directions along the axes, where 1 / d is infinite.
            let own = (k % 3 == 0).then(|| 2 + (k / 3) % 60);
            let o = match own {
                Some(i) => match bodies.bodies[i] {
                    Body::Sphere { center, radius } => {
                        let v = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
                        center + radius * v
                    }
                    _ => unreachable!("objects from 2 on are spheres"),
                },
                None => DVec3::new(next() * 24.0 - 12.0, next() * 6.0 - 1.0, next() * 24.0 - 12.0),
            };
            let d = if k % 7 == 0 {
                let mut a = DVec3::ZERO;
                a[k % 3] = if k % 2 == 0 { 1.0 } else { -1.0 };
                a
            } else {
                DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize()
            };
            let want = brute_nearest(&bodies, o, d, own);
            let got = bodies.nearest(o, d, own).map(|h| (h.object, h.t));
            assert_eq!(got, want, "ray {k} from {o} along {d}, leaving {own:?}");
            // blocked(far) is whether the nearest hit is nearer than far.
            for far in [0.5, 3.0, f64::INFINITY] {
                assert_eq!(
                    bodies.blocked(o, d, own, far, None),
                    want.is_some_and(|w| w.1 < far),
                    "ray {k}, far {far}"
                );
            }
            hits += usize::from(want.is_some());
            checked += 1;
        }
        assert!(hits > checked / 4 && hits < checked, "{hits} of {checked} rays hit something");
    }
}
