//! Direct light in closed form, evaluated in f64 and sharing no code with the shader: the
//! expected values that the path tracer's and the oracle's tests compare against.
//!
//! With bounces = 0 the radiance leaving a Lambertian point x (unit normal n) is
//!     L(x) = albedo / pi * Le * F(x, n),
//! where F is Lambert's form factor integral for a uniformly emitting polygon P of unit radiance,
//!     F(x, n) = 1/2 | sum_i theta_i (n . g_i) |,
//! theta_i being the angle subtended at x by the edge (v_i, v_{i+1}) and g_i the unit normal of
//! the plane through x and that edge. The formula holds for a polygon entirely in front of x's
//! tangent plane; a light partly behind it is first clipped to the front half-space
//! (Sutherland-Hodgman), because the part behind sends nothing.
//!
//! [`Room`] is the assignment's box without its blocks (walls, floor, ceiling, back wall; open at
//! z = 0) with one rectangular light set into the ceiling. [`Room::ray_radiance`] traces a ray
//! from inside it by intersecting the five inner planes, and [`expected_pixel`] averages that over
//! a pixel's footprint, which is what the jittered estimator converges to.

use glam::DVec3;
use illum_scene::{Camera, Scene};

/// Lambert's form factor integral (Lambert, 1760) at `x` (unit normal `n`) from `polygon` (unit
/// radiance): the irradiance is `Le` times this. The polygon must lie in front of x's tangent
/// plane (see [`clip_to_front`]); edges of zero length are skipped.
pub fn lambert_irradiance_factor(x: DVec3, n: DVec3, polygon: &[DVec3]) -> f64 {
    let mut sum = 0.0;
    for i in 0..polygon.len() {
        let a = (polygon[i] - x).normalize();
        let b = (polygon[(i + 1) % polygon.len()] - x).normalize();
        let cross = a.cross(b);
        let length = cross.length();
        if length == 0.0 {
            continue; // a degenerate edge (two equal vertices after clipping) subtends nothing
        }
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * n.dot(cross / length);
    }
    0.5 * sum.abs()
}

/// The part of `polygon` on the side of the plane through `x` that `n` points to.
pub fn clip_to_front(x: DVec3, n: DVec3, polygon: &[DVec3]) -> Vec<DVec3> {
    let side = |p: DVec3| n.dot(p - x);
    let mut out = Vec::new();
    for i in 0..polygon.len() {
        let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
        let (sa, sb) = (side(a), side(b));
        if sa > 0.0 {
            out.push(a);
        }
        if (sa > 0.0) != (sb > 0.0) && sa != sb {
            out.push(a + (b - a) * (sa / (sa - sb)));
        }
    }
    out
}

/// What a ray from inside the room hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RoomHit {
    /// A diffuse inner face, by its inward normal.
    Face(DVec3),
    /// The light, seen from below.
    Light,
    /// Out through the open front (z < 0): black.
    Nothing,
}

/// The assignment's box without blocks: inner faces x = 1, x = 555, y = 1, y = 555, z = 555, open
/// at z = 0, every face white, one light (`corner + s u + t v`, facing down) in the ceiling.
#[derive(Clone, Copy, Debug)]
pub struct Room {
    pub light_corner: DVec3,
    pub light_u: DVec3,
    pub light_v: DVec3,
    /// Emitted radiance (all channels).
    pub radiance: f64,
    /// Albedo of every face (all channels).
    pub albedo: f64,
}

/// The assignment's light's power divided by pi: radiance x area = 30 x 130 x 105.
pub const ASSIGNMENT_RADIANCE_AREA: f64 = 30.0 * 130.0 * 105.0;

/// The room's five walls as boxes 2 units thick: (name, centre, half extent) in TOML.
const ROOM_WALLS: [(&str, &str, &str); 5] = [
    ("left wall", "[556.0, 278.0, 278.0]", "[1.0, 278.0, 278.0]"),
    ("right wall", "[0.0, 278.0, 278.0]", "[1.0, 278.0, 278.0]"),
    ("ceiling", "[278.0, 556.0, 278.0]", "[278.0, 1.0, 278.0]"),
    ("floor", "[278.0, 0.0, 278.0]", "[278.0, 1.0, 278.0]"),
    ("back wall", "[278.0, 278.0, 556.0]", "[278.0, 278.0, 1.0]"),
];

impl Room {
    /// The assignment's light: 130 x 105 at y = 555, radiance 30; white albedo 0.5.
    pub fn assignment() -> Self {
        Room {
            light_corner: DVec3::new(213.0, 555.0, 225.5),
            light_u: DVec3::new(130.0, 0.0, 0.0),
            light_v: DVec3::new(0.0, 0.0, 105.0),
            radiance: 30.0,
            albedo: 0.5,
        }
    }

    /// A square light of side `side` centred in the ceiling, with its radiance scaled so that it
    /// emits the assignment light's power (radiance x area is kept).
    pub fn square_light(side: f64) -> Self {
        Room {
            light_corner: DVec3::new(278.0 - 0.5 * side, 555.0, 278.0 - 0.5 * side),
            light_u: DVec3::new(side, 0.0, 0.0),
            light_v: DVec3::new(0.0, 0.0, side),
            radiance: ASSIGNMENT_RADIANCE_AREA / (side * side),
            ..Room::assignment()
        }
    }

    pub fn light_polygon(&self) -> [DVec3; 4] {
        let c = self.light_corner;
        [c, c + self.light_u, c + self.light_u + self.light_v, c + self.light_v]
    }

    /// The scene file for this room with the given camera (bounces 0, cosine sampling).
    pub fn scene(&self, camera: &Camera, spp: u32, seed: u32) -> Scene {
        let v = |d: DVec3| format!("[{:?}, {:?}, {:?}]", d.x as f32, d.y as f32, d.z as f32);
        let text = format!(
            r#"
name = "room"
[camera]
eye = {eye}
target = {target}
up = {up}
vfov = {vfov:?}
width = {width}
height = {height}
[pathtrace]
spp = {spp}
bounces = 0
seed = {seed}
[materials.white]
albedo = [{albedo:?}, {albedo:?}, {albedo:?}]
[materials.light]
emission = [{radiance:?}, {radiance:?}, {radiance:?}]
{walls}[[objects]]
name = "light"
material = "light"
quad = {{ corner = {corner}, edge_u = {u}, edge_v = {v} }}
"#,
            eye = v(camera.eye.as_dvec3()),
            target = v(camera.target.as_dvec3()),
            up = v(camera.up.as_dvec3()),
            vfov = camera.vfov_deg,
            width = camera.width,
            height = camera.height,
            albedo = self.albedo as f32,
            radiance = self.radiance as f32,
            corner = v(self.light_corner),
            u = v(self.light_u),
            v = v(self.light_v),
            walls = ROOM_WALLS
                .iter()
                .map(|(name, center, half_extent)| format!(
                    "[[objects]]\nname = \"{name}\"\nmaterial = \"white\"\n\
                     box = {{ center = {center}, half_extent = {half_extent} }}\n"
                ))
                .collect::<String>(),
        );
        Scene::from_toml_str(&text, "room.toml").expect("the generated room parses")
    }

    /// Radiance leaving x (unit normal n) with bounces = 0: albedo / pi x Le x F over the part of
    /// the light in front of x.
    pub fn direct_radiance(&self, x: DVec3, n: DVec3) -> f64 {
        let front = clip_to_front(x, n, &self.light_polygon());
        if front.len() < 3 {
            return 0.0;
        }
        self.albedo / std::f64::consts::PI * self.radiance * lambert_irradiance_factor(x, n, &front)
    }

    /// What the ray (o, d) from inside the room hits, and where.
    pub fn trace(&self, o: DVec3, d: DVec3) -> (RoomHit, DVec3) {
        // (plane coordinate, axis, inward normal) of the five inner faces.
        let faces = [
            (1.0, 0, DVec3::X),
            (555.0, 0, DVec3::NEG_X),
            (1.0, 1, DVec3::Y),
            (555.0, 1, DVec3::NEG_Y),
            (555.0, 2, DVec3::NEG_Z),
        ];
        let mut best: Option<(f64, DVec3)> = None;
        for (plane, axis, normal) in faces {
            // Only faces the ray travels toward (against their inward normal).
            if normal.dot(d) >= 0.0 {
                continue;
            }
            let t = (plane - o[axis]) / d[axis];
            if t > 0.0 && best.is_none_or(|(bt, _)| t < bt) {
                best = Some((t, normal));
            }
        }
        // The open front: a ray whose nearest face lies beyond z = 0 leaves the room first.
        let Some((t, normal)) = best else { return (RoomHit::Nothing, o) };
        let x = o + t * d;
        if x.z < 0.0 {
            return (RoomHit::Nothing, x);
        }
        if normal == DVec3::NEG_Y {
            let h = x - self.light_corner;
            let s = h.dot(self.light_u) / self.light_u.length_squared();
            let r = h.dot(self.light_v) / self.light_v.length_squared();
            if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&r) {
                return (RoomHit::Light, x);
            }
        }
        (RoomHit::Face(normal), x)
    }

    /// Radiance along the ray (o, d), bounces = 0.
    pub fn ray_radiance(&self, o: DVec3, d: DVec3) -> (f64, RoomHit) {
        match self.trace(o, d) {
            (RoomHit::Face(n), x) => (self.direct_radiance(x, n), RoomHit::Face(n)),
            (RoomHit::Light, _) => (self.radiance, RoomHit::Light),
            (RoomHit::Nothing, _) => (0.0, RoomHit::Nothing),
        }
    }
}

/// The ray through image point (px, py) (pixels from the top-left corner, y down), computed in
/// f64 from the camera's (f32) frame the way the shader does.
pub fn pixel_ray(camera: &Camera, px: f64, py: f64) -> (DVec3, DVec3) {
    let b = camera.basis();
    let (w, h) = (camera.width as f64, camera.height as f64);
    let tan = b.tan_half_fov as f64;
    let sx = (2.0 * px / w - 1.0) * b.aspect as f64 * tan;
    let sy = (1.0 - 2.0 * py / h) * tan;
    let d = b.forward.as_dvec3() + sx * b.right.as_dvec3() + sy * b.up.as_dvec3();
    (camera.eye.as_dvec3(), d.normalize())
}

/// The expectation of pixel (x, y) of a bounces-0 render of `room`: the radiance averaged over
/// `sub` x `sub` points of the pixel (midpoint rule; the estimator jitters uniformly inside the
/// pixel). `smooth` is false when the points see different surfaces, i.e. an edge crosses the
/// pixel and the midpoint rule is not accurate there.
pub fn expected_pixel(room: &Room, camera: &Camera, x: u32, y: u32, sub: u32) -> (f64, bool) {
    let mut sum = 0.0;
    let mut first: Option<RoomHit> = None;
    let mut smooth = true;
    for j in 0..sub {
        for i in 0..sub {
            let px = x as f64 + (i as f64 + 0.5) / sub as f64;
            let py = y as f64 + (j as f64 + 0.5) / sub as f64;
            let (o, d) = pixel_ray(camera, px, py);
            let (radiance, hit) = room.ray_radiance(o, d);
            sum += radiance;
            match first {
                None => first = Some(hit),
                Some(f) if f != hit => smooth = false,
                _ => {}
            }
        }
    }
    (sum / (sub * sub) as f64, smooth)
}
