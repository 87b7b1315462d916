//! Traversal code generated for one scene ("model only what a scene requires").
//!
//! The generic traversal loops over a storage buffer of objects and switches on each one's kind.
//! On a CPU Vulkan driver such as lavapipe every one of those reads is a per-lane memory access
//! and the loop cannot be unrolled. For a scene of a handful of analytic shapes it is cheaper to
//! emit one straight-line test per object with its numbers as literals: the compiler then folds
//! the constants (an axis-aligned box needs no frame change) and no object data is read while
//! tracing. The generated module also contains only what the scene uses:
//! - surface reconstruction only for the kinds of shape present (for the path tracer, only
//!   those of non-emitters), one function for axis-aligned and rotated boxes;
//! - no light-selection code when there is one light;
//! - shadow rays test only the objects that can block a light (see [`can_block_light`]);
//! - the object and material at a hit come from literals (`object_at`, and `material_at` in
//!   the separate module [`materials_module`]), not from storage buffers: a specialised
//!   pipeline binds neither buffer. On lavapipe a read at a per-lane index costs a scalar load
//!   per lane and component, which made the Cornell box 29% slower at 2 bounces.
//!
//! The module (`illum::rtcore::traversal`) is shared: the Whitted ray tracer imports the same
//! `closest_hit`, `occluded` and `surface_at` (`choose_light` and `scattering_surface_at` are the
//! path tracer's alone).
//!
//! About 400 lines, one concept: the generator of one WGSL module, each function writing one of
//! its functions.

use std::collections::BTreeSet;

use illum_gpu::shader::ShaderFile;
use illum_scene::Scene;

use glam::Vec3;

use crate::gpu_scene::{GpuObject, GpuScene, GpuShape, ObjectRecord, ShapeKind};

/// What a specialised pipeline was built for. Two scenes with equal keys share a pipeline.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Specialisation {
    /// Kinds of shape with code in the pipeline.
    pub kinds: BTreeSet<ShapeKind>,
    /// Number of lights (1 means no light-selection code).
    pub lights: usize,
    /// Indices (into the uploaded objects) of the objects shadow rays test.
    pub occluders: Vec<usize>,
    /// The generated WGSL (the scene's numbers are literals in it).
    pub source: String,
}

impl Specialisation {
    /// The names of [`Self::kinds`] ("aabb", "box", "quad", "sphere"), in order.
    pub fn kind_names(&self) -> Vec<&'static str> {
        self.kinds.iter().map(|k| k.name()).collect()
    }
}

/// WGSL for an f32 literal that reads back as exactly the same f32 (Rust's `{:?}` prints the
/// shortest string that round-trips, always with a `.` or an exponent).
fn lit(x: f32) -> String {
    format!("{x:?}")
}

fn vec3(v: Vec3) -> String {
    format!("vec3<f32>({}, {}, {})", lit(v.x), lit(v.y), lit(v.z))
}

/// The WGSL expression for the object's hit distance along (o, d); `inv_d` = 1 / d.
fn hit_expression(object: &GpuObject) -> String {
    match object.shape {
        GpuShape::Aabb { min, max } => format!("hit_slabs(o, inv_d, {}, {})", vec3(min), vec3(max)),
        GpuShape::Box { local_min, local_max, cos, sin, offset } => format!(
            "hit_box(o, d, {}, {}, {}, {}, {})",
            vec3(local_min),
            vec3(local_max),
            lit(cos),
            lit(sin),
            vec3(offset)
        ),
        GpuShape::Quad { corner, edge_u, edge_v } => format!(
            "hit_quad(o, d, {}, {}, {}, {})",
            vec3(corner),
            vec3(edge_u),
            vec3(edge_v),
            vec3(edge_u.cross(edge_v))
        ),
        GpuShape::Sphere { center, radius } => format!("hit_sphere(o, d, {}, {})", vec3(center), lit(radius)),
    }
}

fn vec4(v: [f32; 4]) -> String {
    format!("vec4<f32>({}, {}, {}, {})", lit(v[0]), lit(v[1]), lit(v[2]), lit(v[3]))
}

/// An object's storage record as a WGSL `Object` literal.
fn object_literal(record: &ObjectRecord) -> String {
    format!(
        "Object({}u, {}u, {}u, {}u, {}, {}, {}, {})",
        record.kind,
        record.material,
        record.emitter,
        record.padding,
        vec4(record.a),
        vec4(record.b),
        vec4(record.c),
        vec4(record.d)
    )
}

/// The cases of `switch index` returning value i for index i (the last as the default, which
/// WGSL requires; callers pass only valid indices).
///
/// Why a switch over literals rather than a storage-buffer read: on lavapipe a read at a
/// per-lane index is one scalar load per lane and component (an `Object` is 20 of them), while
/// each case of the switch costs a few vector selects. At 256 x 256, bounces 2, the Cornell box
/// rendered 29% faster (docs/performance.md).
fn switch_cases(values: impl ExactSizeIterator<Item = String>) -> String {
    let count = values.len();
    let mut cases = String::new();
    for (i, value) in values.enumerate() {
        if i + 1 == count {
            cases.push_str(&format!("        default: {{ return {value}; }}\n"));
        } else {
            cases.push_str(&format!("        case {i}u: {{ return {value}; }}\n"));
        }
    }
    cases
}

/// An axis-aligned box [lo, hi] (lo <= hi; a flat box for a quad).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bounds {
    lo: [f32; 3],
    hi: [f32; 3],
}

impl Bounds {
    fn of(object: &GpuObject) -> Self {
        let points: Vec<[f32; 3]> = match object.shape {
            GpuShape::Aabb { min, max } => vec![min.to_array(), max.to_array()],
            GpuShape::Box { local_min, local_max, cos: c, sin: s, offset } => {
                // The eight corners of the rotated box.
                let mut corners = Vec::new();
                for i in 0..8 {
                    let l = [
                        if i & 1 == 0 { local_min.x } else { local_max.x },
                        if i & 2 == 0 { local_min.y } else { local_max.y },
                        if i & 4 == 0 { local_min.z } else { local_max.z },
                    ];
                    corners.push([
                        c * l[0] + s * l[2] + offset.x,
                        l[1] + offset.y,
                        -s * l[0] + c * l[2] + offset.z,
                    ]);
                }
                corners
            }
            GpuShape::Quad { corner, edge_u, edge_v } => {
                let (p, u, v) = (corner.to_array(), edge_u.to_array(), edge_v.to_array());
                vec![p, add(p, u), add(p, v), add(add(p, u), v)]
            }
            GpuShape::Sphere { center, radius: r } => {
                vec![[center.x - r, center.y - r, center.z - r], [center.x + r, center.y + r, center.z + r]]
            }
        };
        let mut bounds = Bounds { lo: [f32::MAX; 3], hi: [f32::MIN; 3] };
        for p in points {
            for (a, value) in p.into_iter().enumerate() {
                bounds.lo[a] = bounds.lo[a].min(value);
                bounds.hi[a] = bounds.hi[a].max(value);
            }
        }
        bounds
    }

    fn contains(&self, other: &Bounds) -> bool {
        (0..3).all(|a| self.lo[a] <= other.lo[a] && other.hi[a] <= self.hi[a])
    }
}

fn xyz(v: [f32; 4]) -> [f32; 3] {
    [v[0], v[1], v[2]]
}

fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Corners of every light.
fn light_corners(scene: &GpuScene) -> Vec<[f32; 3]> {
    scene
        .lights
        .iter()
        .flat_map(|l| {
            let (p, u, v) = (xyz(l.corner), xyz(l.edge_u), xyz(l.edge_v));
            [p, add(p, u), add(p, v), add(add(p, u), v)]
        })
        .collect()
}

/// Whether the object at `index` can lie on a shadow ray between a lit surface point and a light.
///
/// Only axis-aligned boxes are ever excluded (every other shape is kept, conservatively). A box
/// O is excluded when one of its faces lies in a plane P with:
/// 1. every light point on the far side of P from O (or on P), and
/// 2. every surface point that can receive light and is not inside O, also on that far side:
///    for each other object B, the part of B beyond P is inside O, except on faces of B that
///    face away from every light point (they never send shadow rays: cos theta <= 0).
///
/// Then a shadow ray runs from a point on the far side to a light point on the far side: the
/// segment stays in that closed half-space, which meets O at most in its face on P, so O
/// cannot block it. Points on O itself need no test either: O is convex, and next-event
/// estimation only traces rays leaving a surface on its outer side.
pub fn can_block_light(scene: &GpuScene, index: usize) -> bool {
    let object = &scene.objects[index];
    // A directional light shines from everywhere on a hemisphere's worth of directions: the
    // half-space argument below covers only area lights.
    if object.shape.kind() != ShapeKind::Aabb || object.emitter || scene.defs.contains(&"SUN") {
        return true;
    }
    let o = Bounds::of(object);
    let lights = light_corners(scene);
    for axis in 0..3 {
        // side = +1: the plane x_axis = o.hi with O below it; -1: x_axis = o.lo with O above.
        for side in [1.0f32, -1.0] {
            let plane = if side > 0.0 { o.hi[axis] } else { o.lo[axis] };
            // Signed distance beyond the plane (positive on the far side from O).
            let beyond = |value: f32| side * (value - plane);
            if lights.iter().any(|c| beyond(c[axis]) < 0.0) {
                continue;
            }
            let others_clear = scene.objects.iter().enumerate().all(|(j, b)| {
                if j == index || b.emitter {
                    return true; // paths end at emitters: no shading points there
                }
                let bounds = Bounds::of(b);
                // The part of B on O's side of the plane (strictly): B clipped to that half-space.
                let mut clipped = bounds;
                if side > 0.0 {
                    clipped.hi[axis] = clipped.hi[axis].min(plane);
                } else {
                    clipped.lo[axis] = clipped.lo[axis].max(plane);
                }
                let reaches_past = if side > 0.0 { bounds.lo[axis] < plane } else { bounds.hi[axis] > plane };
                if !reaches_past || o.contains(&clipped) {
                    return true;
                }
                if b.shape.kind() != ShapeKind::Aabb {
                    return false;
                }
                // An axis-aligned B: each of its faces that some light point is in front of
                // must, within the clipped part, lie inside O.
                (0..3).all(|face_axis| {
                    [1.0f32, -1.0].iter().all(|&face_side| {
                        let face_plane =
                            if face_side > 0.0 { bounds.hi[face_axis] } else { bounds.lo[face_axis] };
                        let lit = lights.iter().any(|c| face_side * (c[face_axis] - face_plane) > 0.0);
                        if !lit {
                            return true;
                        }
                        let mut face = clipped;
                        face.lo[face_axis] = face_plane;
                        face.hi[face_axis] = face_plane;
                        let empty = (0..3).any(|a| face.lo[a] > face.hi[a])
                            || face_plane < clipped.lo[face_axis]
                            || face_plane > clipped.hi[face_axis];
                        empty || o.contains(&face)
                    })
                })
            });
            if others_clear {
                return false;
            }
        }
    }
    true
}

/// The cases of a `switch obj.kind` that reconstructs the surface of each kind in `kinds`; the
/// last one is the default (WGSL requires one). On lavapipe each case costs time by being in
/// the shader, and at a bounce the 8 lanes of a group hit different kinds, so kinds share a case
/// where one function serves them: an axis-aligned box is stored as
/// a box rotated by zero with an error bound of zero ([`GpuObject::record`]), which
/// `surface_box` reconstructs exactly as `surface_aabb` does (same point, normal and bound), so
/// where both kinds occur `surface_box` serves both.
fn surface_cases(kinds: &BTreeSet<ShapeKind>) -> String {
    let mut groups: Vec<(Vec<ShapeKind>, &str)> = Vec::new();
    for &kind in kinds {
        if kind == ShapeKind::Aabb && kinds.contains(&ShapeKind::Box) {
            continue;
        }
        let mut members = vec![kind];
        if kind == ShapeKind::Box && kinds.contains(&ShapeKind::Aabb) {
            members.insert(0, ShapeKind::Aabb);
        }
        groups.push((members, kind.surface_function()));
    }
    let mut cases = String::new();
    for (i, (members, function)) in groups.iter().enumerate() {
        let call = format!("{function}(obj, p)");
        if i + 1 == groups.len() {
            cases.push_str(&format!("        default: {{ return {call}; }}\n"));
        } else {
            let selectors = members.iter().map(|k| k.wgsl_constant()).collect::<Vec<_>>().join(", ");
            cases.push_str(&format!("        case {selectors}: {{ return {call}; }}\n"));
        }
    }
    cases
}

/// Builds the `illum::rtcore::traversal` module for `scene`: `closest_hit`, `occluded`,
/// `surface_at` and `choose_light`.
pub fn specialise(scene: &Scene, gpu_scene: &GpuScene) -> Specialisation {
    // gpu_scene orders non-emitters before emitters; recover each object's name for comments.
    let mut names: Vec<&str> = Vec::new();
    for emitters in [false, true] {
        for object in &scene.objects {
            if scene.materials[object.material].is_emitter() == emitters {
                names.push(&object.name);
            }
        }
    }
    let kinds: BTreeSet<ShapeKind> = gpu_scene.objects.iter().map(|o| o.shape.kind()).collect();
    let mut closest = String::new();
    let mut occluded = String::new();
    let mut occluders = Vec::new();
    for (i, object) in gpu_scene.objects.iter().enumerate() {
        let name = names.get(i).copied().unwrap_or("?").replace(['\n', '\r'], " ");
        let hit = hit_expression(object);
        closest.push_str(&format!("    // {i}: {name}\n    t = {hit};\n"));
        if object.emitter {
            // The emitter wins a tie with the surface it is set into (see scene.wgsl); the cap at
            // FAR keeps a missed emitter (which reports FAR) from counting as a hit.
            closest.push_str(&format!(
                "    if (t < min(best.t * (1.0 + EMITTER_TIE), FAR)) {{\n        best = Hit(t, {i}u);\n    }}\n"
            ));
        } else {
            closest.push_str(&format!("    if (t < best.t) {{\n        best = Hit(t, {i}u);\n    }}\n"));
            if can_block_light(gpu_scene, i) {
                occluders.push(i);
                occluded.push_str(&format!(
                    "    // {name}\n    if ({hit} < t_max) {{\n        return true;\n    }}\n"
                ));
            } else {
                occluded.push_str(&format!(
                    "    // {name}: cannot block a light (specialise.rs, can_block_light)\n"
                ));
            }
        }
    }
    let normal_cases = surface_cases(&kinds);
    // The path tracer never asks for an emitter's surface (a hit on a light only needs the side,
    // from the light's normal), so its reconstruction covers the non-emitters' kinds alone.
    let scattering: BTreeSet<ShapeKind> =
        gpu_scene.objects.iter().filter(|o| !o.emitter).map(|o| o.shape.kind()).collect();
    let scattering_cases = surface_cases(if scattering.is_empty() { &kinds } else { &scattering });
    let object_cases = switch_cases(gpu_scene.object_records().iter().map(object_literal));
    let choose_light = if gpu_scene.lights.len() <= 1 {
        "    // One light (or none: then nothing calls this): nothing to choose.\n    return 0u;\n".to_owned()
    } else {
        let mut code = String::new();
        for (i, light) in gpu_scene.lights.iter().enumerate().take(gpu_scene.lights.len() - 1) {
            code.push_str(&format!(
                "    if (pick < {}) {{\n        return {i}u;\n    }}\n",
                lit(light.corner[3])
            ));
        }
        code.push_str(&format!("    return {}u;\n", gpu_scene.lights.len() - 1));
        code
    };
    let source = format!(
        "#define_import_path illum::rtcore::traversal

// Generated by illum-pathtrace (specialise.rs) for scene {scene_name:?}: {count} objects, each
// test unrolled with its numbers as constants. Emitters come last.

#import illum::rtcore::geometry::{{Hit, Object, FAR, NO_HIT, EMITTER_TIE, KIND_AABB, KIND_BOX, KIND_QUAD, KIND_SPHERE, safe_inverse, hit_slabs, hit_box, hit_quad, hit_sphere, Surface, surface_aabb, surface_box, surface_quad, surface_sphere}}

fn closest_hit(o: vec3<f32>, d: vec3<f32>) -> Hit {{
    let inv_d = safe_inverse(d);
    var best = Hit(FAR, NO_HIT);
    var t: f32;
{closest}    return best;
}}

// True when an object that can block a light lies on the ray strictly between 0 and t_max.
fn occluded(o: vec3<f32>, d: vec3<f32>, t_max: f32) -> bool {{
    let inv_d = safe_inverse(d);
{occluded}    return false;
}}

// The object at `index` (< the number of objects), as the storage buffer holds it, from
// literals (the path tracer binds no object buffer to a specialised pipeline).
fn object_at(index: u32) -> Object {{
    switch index {{
{object_cases}    }}
}}

// Surfaces for the kinds of shape in this scene ({kind_list}).
fn surface_at(obj: Object, p: vec3<f32>) -> Surface {{
    switch obj.kind {{
{normal_cases}    }}
}}

// The surface of a non-emitter (`obj.emitter == 0`), for the path tracer: only the kinds that
// scatter light in this scene.
fn scattering_surface_at(obj: Object, p: vec3<f32>) -> Surface {{
    switch obj.kind {{
{scattering_cases}    }}
}}

fn choose_light(pick: f32) -> u32 {{
{choose_light}}}
",
        scene_name = scene.name,
        count = gpu_scene.objects.len(),
        kind_list = kinds.iter().map(|k| k.name()).collect::<Vec<_>>().join(", "),
    );
    Specialisation { kinds, lights: gpu_scene.lights.len(), occluders, source }
}

/// The `illum::pathtrace::materials` module for `gpu_scene`: `material_at` returns its
/// materials as literals (the generic module, `shaders/pathtrace/materials.wgsl`, reads the
/// material buffer instead).
pub fn materials_module(scene: &Scene, gpu_scene: &GpuScene) -> ShaderFile {
    let cases = switch_cases(
        gpu_scene.materials.iter().map(|m| format!("Material({}, {})", vec4(m.albedo), vec4(m.emission))),
    );
    let source = format!(
        "#define_import_path illum::pathtrace::materials

// Generated by illum-pathtrace (specialise.rs) for scene {name:?}: its {count} materials.

#import illum::pathtrace::scene::Material

// The material at `index` (< the number of materials).
fn material_at(index: u32) -> Material {{
    switch index {{
{cases}    }}
}}
",
        name = scene.name,
        count = gpu_scene.materials.len(),
    );
    ShaderFile::generated(format!("generated materials for scene {:?}", scene.name), source)
}

/// The generated traversal as a shader module.
pub fn traversal_module(scene: &Scene, gpu_scene: &GpuScene) -> ShaderFile {
    ShaderFile::generated(
        format!("generated traversal for scene {:?}", scene.name),
        specialise(scene, gpu_scene).source,
    )
}
