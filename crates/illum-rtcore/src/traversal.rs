//! The traversal generated for one scene: `illum::rtcore::traversal`, whose `closest_hit`,
//! `occluded`, `object_at`, `surface_at` and `scattering_surface_at` both compute ray tracers
//! import ("model only what a scene requires").
//!
//! A generic traversal loops over a storage buffer of objects and switches on each one's kind.
//! On a CPU Vulkan driver such as lavapipe every one of those reads is a per-lane memory access
//! and the loop cannot be unrolled. For a scene of a handful of analytic shapes it is cheaper to
//! emit one straight-line test per object with its numbers as literals: the compiler then folds
//! the constants (an axis-aligned box needs no frame change) and no object data is read while
//! tracing. The generated module also contains only what the scene uses:
//! - surface reconstruction only for the kinds of shape present (for `scattering_surface_at`,
//!   only those of non-emitters), one function for axis-aligned and rotated boxes;
//! - shadow rays test only the objects that can block a light (see [`can_block_light`]);
//! - the object at a hit comes from literals (`object_at`), not from a storage buffer.
//!
//! A literal list's compile time grows with its length, so past a measured crossover the many
//! are read from buffers under a BVH instead: small non-emitting analytic objects past
//! [`analytic_bvh::LITERAL_OBJECTS`] (analytic_bvh.rs, which states which), mesh triangles past
//! [`crate::mesh_traversal::LITERAL_TRIANGLES`] (mesh_traversal.rs); the other objects stay
//! literals.
//!
//! The measured effect of each is in docs/performance-levers.md.

use std::collections::BTreeSet;

use illum_gpu::shader::ShaderFile;

use crate::analytic_bvh;
use crate::bvh_traversal::{self, Tree};
use crate::literal::{lit, switch_cases, vec3, vec4};
use crate::mesh_traversal::mesh_code;
use crate::object::{GpuObject, GpuShape, ObjectRecord, ShapeKind};
pub use crate::scene_geometry::Geometry;

/// A traversal generated for one scene. Two scenes with equal traversals share a pipeline.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Traversal {
    /// Kinds of shape with code in the pipeline.
    pub kinds: BTreeSet<ShapeKind>,
    /// Indices (into the uploaded objects) of the objects shadow rays test.
    pub occluders: Vec<usize>,
    /// The generated WGSL (the scene's numbers are literals in it).
    pub source: String,
}

impl Traversal {
    /// The names of [`Self::kinds`] ("aabb", "box", "quad", "sphere"), in order.
    pub fn kind_names(&self) -> Vec<&'static str> {
        self.kinds.iter().map(|k| k.name()).collect()
    }

    /// The generated module.
    pub fn module(&self, scene: &str) -> ShaderFile {
        ShaderFile::generated(format!("generated traversal for scene {scene:?}"), self.source.clone())
    }
}

/// The WGSL expression for the hit distance along (o, d) of the object at `index`; `inv_d` =
/// 1 / d, `own` the index of the object the ray leaves (geometry.wgsl's hit_sphere).
fn hit_expression(object: &GpuObject, index: usize) -> String {
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
        GpuShape::Sphere { center, radius } => {
            format!("hit_sphere(o, d, {}, {}, own == {index}u)", vec3(center), lit(radius))
        }
    }
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

/// An axis-aligned box [lo, hi] (lo <= hi; a flat box for a quad).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bounds {
    lo: [f32; 3],
    hi: [f32; 3],
}

impl Bounds {
    fn of(object: &GpuObject) -> Self {
        let [lo, hi] = object.shape.bounds();
        Bounds { lo: lo.to_array(), hi: hi.to_array() }
    }

    fn contains(&self, other: &Bounds) -> bool {
        (0..3).all(|a| self.lo[a] <= other.lo[a] && other.hi[a] <= self.hi[a])
    }
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
pub fn can_block_light(scene: &Geometry, index: usize) -> bool {
    let object = &scene.objects[index];
    // A directional light shines from everywhere on a hemisphere's worth of directions: the
    // half-space argument below covers only lights of bounded extent.
    // Mesh triangles are surfaces the argument would have to clear too: with any, every object is
    // kept.
    if object.shape.kind() != ShapeKind::Aabb
        || object.emitter
        || scene.unbounded_lights
        || scene.meshes.is_some()
    {
        return true;
    }
    let o = Bounds::of(object);
    let lights = &scene.light_corners;
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

/// Generates the `illum::rtcore::traversal` module for `scene`.
pub fn generate(scene: &Geometry) -> Traversal {
    let mut kinds: BTreeSet<ShapeKind> = scene.objects.iter().map(|o| o.shape.kind()).collect();
    let mut closest = String::new();
    let mut occluded = String::new();
    let mut occluders = Vec::new();
    // Triangles are numbered after the analytic objects.
    let base = scene.objects.len();
    let mesh = scene.meshes.as_ref().map(|form| mesh_code(form, base));
    // Objects 0 to under_bvh - 1 are under a hierarchy (analytic_bvh.rs), the rest literals.
    let under_bvh = scene.analytic.as_ref().map_or(0, |bvh| bvh.objects.len());
    // The walks closest_hit runs after the literal non-emitters (whose nearest hit, often the
    // floor's, bounds them) and before the emitters.
    let mut walks = String::new();
    let mut bvh_imports: Vec<&'static str> = Vec::new();
    let mut definitions = String::new();
    if let Some(bvh) = &scene.analytic {
        let kinds = bvh.kinds();
        let names = kinds.iter().map(|k| k.name()).collect::<Vec<_>>().join(", ");
        let tree = Tree::Analytic { kinds };
        let prefix = tree.prefix();
        walks.push_str(&format!(
            "    // Objects 0 to {} ({names}) under one BVH (analytic_bvh.rs).\n    best = {prefix}_closest(o, d, inv_d, own, best);\n",
            under_bvh - 1
        ));
        occluded.push_str(&format!(
            "    // Objects 0 to {}\n    if ({prefix}_occluded(o, d, inv_d, t_max, own)) {{\n        return true;\n    }}\n",
            under_bvh - 1
        ));
        occluders.extend(0..under_bvh);
        bvh_imports.extend(tree.imports());
        definitions.push_str(&analytic_bvh::declarations(bvh));
        definitions.push_str(&bvh_traversal::functions(&tree));
    }
    if let Some(mesh) = &mesh {
        walks.push_str(&mesh.closest);
    }
    for (i, object) in scene.objects.iter().enumerate() {
        if i == scene.first_emitter as usize {
            closest.push_str(&walks);
        }
        if i < under_bvh {
            continue;
        }
        let name = scene.names[i].replace(['\n', '\r'], " ");
        let hit = hit_expression(object, i);
        closest.push_str(&format!("    // {i}: {name}\n    t = {hit};\n"));
        if object.emitter {
            // The emitter wins a tie with the surface it is set into (EMITTER_TIE in geometry.wgsl); the cap at
            // FAR keeps a missed emitter (which reports FAR) from counting as a hit.
            closest.push_str(&format!(
                "    if (t < min(best.t * (1.0 + EMITTER_TIE), FAR)) {{\n        best = Hit(t, {i}u);\n    }}\n"
            ));
        } else {
            closest.push_str(&format!("    if (t < best.t) {{\n        best = Hit(t, {i}u);\n    }}\n"));
            if can_block_light(scene, i) {
                occluders.push(i);
                occluded.push_str(&format!(
                    "    // {name}\n    if ({hit} < t_max) {{\n        return true;\n    }}\n"
                ));
            } else {
                occluded.push_str(&format!(
                    "    // {name}: cannot block a light (traversal.rs, can_block_light)\n"
                ));
            }
        }
    }
    if scene.first_emitter as usize == scene.objects.len() {
        closest.push_str(&walks);
    }
    // object_at: the ranges read from buffers, each (condition, record), then the literals.
    let mut ranges: Vec<(String, String)> = Vec::new();
    if under_bvh > 0 {
        ranges.push((format!("index < {under_bvh}u"), "analytic_object(index)".to_owned()));
    }
    let mut objects: Vec<String> = scene.object_records()[under_bvh..].iter().map(object_literal).collect();
    if let Some(mesh) = mesh {
        kinds.insert(ShapeKind::Triangle);
        occluded.push_str(&mesh.occluded);
        objects.extend(mesh.object_literals);
        if let Some(record) = mesh.object_range {
            ranges.push((format!("index >= {base}u"), record));
        }
        for name in mesh.bvh_imports {
            if !bvh_imports.contains(&name) {
                bvh_imports.push(name);
            }
        }
        definitions.insert_str(0, &mesh.definitions);
    }
    let mesh_imports = if bvh_imports.is_empty() {
        String::new()
    } else {
        format!("#import illum::rtcore::bvh::{{{}}}\n\n{definitions}", bvh_imports.join(", "))
    };
    let mut object_body = String::new();
    for (k, (condition, record)) in ranges.iter().enumerate() {
        // Without literals the last range answers every index left.
        if objects.is_empty() && k + 1 == ranges.len() {
            object_body.push_str(&format!("    return {record};\n"));
        } else {
            object_body.push_str(&format!("    if ({condition}) {{\n        return {record};\n    }}\n"));
        }
    }
    if !objects.is_empty() {
        object_body.push_str(&format!(
            "    switch index {{\n{}    }}\n",
            switch_cases(under_bvh, objects.into_iter())
        ));
    }
    let normal_cases = surface_cases(&kinds);
    // Shading never needs an emitter's surface (a hit on a light only needs the side, from the
    // light's normal), so this reconstruction covers the non-emitters' kinds alone.
    // Mesh triangles never emit (validation refuses emitting meshes).
    let triangles = scene.meshes.is_some().then_some(ShapeKind::Triangle);
    let scattering: BTreeSet<ShapeKind> =
        scene.objects.iter().filter(|o| !o.emitter).map(|o| o.shape.kind()).chain(triangles).collect();
    let scattering_cases = surface_cases(if scattering.is_empty() { &kinds } else { &scattering });
    let source = format!(
        "#define_import_path illum::rtcore::traversal

// Generated by illum-rtcore (traversal.rs) for scene {scene_name:?}: {count} objects, each
// test unrolled with its numbers as constants. Emitters come last.

#import illum::rtcore::codes::{{KIND_AABB, KIND_BOX, KIND_QUAD, KIND_SPHERE}}
#import illum::rtcore::geometry::{{Hit, Object, FAR, NO_HIT, EMITTER_TIE, safe_inverse, hit_slabs, hit_box, hit_quad, hit_sphere, Surface, surface_aabb, surface_box, surface_quad, surface_sphere}}
{mesh_imports}
// The nearest object along the ray from o in the unit direction d. `own`: the index of the object
// whose surface the ray leaves (NO_HIT for a camera or light ray); its root at o is never taken.
fn closest_hit(o: vec3<f32>, d: vec3<f32>, own: u32) -> Hit {{
    let inv_d = safe_inverse(d);
    var best = Hit(FAR, NO_HIT);
    var t: f32;
{closest}    return best;
}}

// True when an object that can block a light lies on the ray strictly between 0 and t_max
// (`own` as for closest_hit).
fn occluded(o: vec3<f32>, d: vec3<f32>, t_max: f32, own: u32) -> bool {{
    let inv_d = safe_inverse(d);
{occluded}    return false;
}}

// The object at `index` (< the number of objects), as the storage buffer holds it, from
// literals (a specialised pipeline binds no object buffer).
fn object_at(index: u32) -> Object {{
{object_body}}}

// Surfaces for the kinds of shape in this scene ({kind_list}).
fn surface_at(obj: Object, p: vec3<f32>) -> Surface {{
    switch obj.kind {{
{normal_cases}    }}
}}

// The surface of a non-emitter (`obj.emitter == 0`): only the kinds that scatter light in this
// scene.
fn scattering_surface_at(obj: Object, p: vec3<f32>) -> Surface {{
    switch obj.kind {{
{scattering_cases}    }}
}}
",
        scene_name = scene.scene,
        count = scene.objects.len(),
        kind_list = kinds.iter().map(|k| k.name()).collect::<Vec<_>>().join(", "),
    );
    Traversal { kinds, occluders, source }
}
