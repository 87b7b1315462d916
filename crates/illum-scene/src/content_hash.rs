//! The scene's identity: a hash of its physical content over explicit, versioned bytes, so that
//! a file written today (a checkpoint's `illum.scene_hash`, a cached reference's key) is
//! recognised by any later build. It never depends on how a type prints (`{:?}` of glam or of
//! an f32 may change with a dependency) or on Rust's `Hash`, which is not stable across builds.
//!
//! What is hashed: every number that changes the path-traced image apart from the settings
//! (resolution, spp, bounces, seed, sampling, caustics), which files store and compare one by
//! one so that a refusal can name the one that differs. Names (the scene's, materials', objects')
//! do not change the image and are left out; so are the comments and key order of the file and
//! the sections only other renderers read (`[raster]`, `[whitted]`, `[shading]`, clip planes).
//!
//! # Canonical bytes, version 1
//!
//! Every number is written as its little-endian bytes: an f32 as its IEEE 754 bits (so -0.0 and
//! 0.0 differ, and every value parsed from the same text gives the same bits), a count, index
//! or code as a u32. A vector is its x, y, z. In this order:
//!
//! 1. the tag: the 16 ASCII bytes [`CONTENT_TAG`], then the u32 [`CONTENT_VERSION`];
//! 2. the camera: `eye`, `target`, `up`, `vfov_deg`;
//! 3. the number of materials, then each material in file order: its kind code and fields:
//!    0 Lambertian `albedo`; 1 checker `even`, `odd`, `tile`; 2 dielectric `ior`; 3 mirror
//!    `reflectance`; 4 emitter `radiance`;
//! 4. the number of objects, then each object in file order: its material's index, its shape
//!    code and fields: 0 box `min`, `max`, `rotate_y_deg`, `pivot`, `translate`; 1 quad
//!    `corner`, `edge_u`, `edge_v`; 2 sphere `center`, `radius`; 3 mesh: the u64 FNV-1a of
//!    its file's bytes, then `translate`, `scale`, `rotate_deg`, and 1 for smooth shading or 0
//!    for flat (so a changed mesh file makes another scene);
//! 5. the directional light: 0, or 1 then `direction`, `irradiance`, `angular_radius_deg`;
//! 6. the environment: 0, or 1 then `radiance`.
//!
//! The hash is 64-bit FNV-1a ([`fnv1a_64`]) of those bytes. A change to this list (a new field,
//! another order) must raise [`CONTENT_VERSION`]; the pinned hash of `scenes/cornell.toml` in
//! the tests below fails until it does. A new shape code (mesh, 3) extends the list without
//! changing the bytes of any scene that could be written before it, so it keeps the version.

use glam::Vec3;

use crate::{MaterialKind, Scene, Shape};

/// The first bytes of the canonical form: what the bytes are.
pub const CONTENT_TAG: &[u8; 16] = b"illum.scene.v001";

/// The version of the canonical form (see the module's documentation), written after the tag.
pub const CONTENT_VERSION: u32 = 1;

/// 64-bit FNV-1a (Fowler, Noll, Vo): a stable, dependency-free hash. Not cryptographic: it
/// tells scenes apart, it does not defend against a forged file.
pub fn fnv1a_64(bytes: &[u8]) -> u64 {
    const OFFSET_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0100_0000_01b3;
    bytes.iter().fold(OFFSET_BASIS, |h, &b| (h ^ u64::from(b)).wrapping_mul(PRIME))
}

/// The canonical bytes as they are written.
struct Canonical(Vec<u8>);

impl Canonical {
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    fn count(&mut self, n: usize) {
        self.u32(u32::try_from(n).expect("a scene's counts fit in u32"));
    }

    fn f32(&mut self, v: f32) {
        self.0.extend_from_slice(&v.to_bits().to_le_bytes());
    }

    fn vec3(&mut self, v: Vec3) {
        for c in v.to_array() {
            self.f32(c);
        }
    }
}

impl Scene {
    /// The canonical bytes of the scene's physical content (see the module's documentation for
    /// what they hold and in which order).
    pub fn content_bytes(&self) -> Vec<u8> {
        let mut out = Canonical(Vec::new());
        out.0.extend_from_slice(CONTENT_TAG);
        out.u32(CONTENT_VERSION);
        let c = &self.camera;
        out.vec3(c.eye);
        out.vec3(c.target);
        out.vec3(c.up);
        out.f32(c.vfov_deg);
        out.count(self.materials.len());
        for material in &self.materials {
            match material.kind {
                MaterialKind::Lambertian { albedo } => {
                    out.u32(0);
                    out.vec3(albedo);
                }
                MaterialKind::Checker(checker) => {
                    out.u32(1);
                    out.vec3(checker.even);
                    out.vec3(checker.odd);
                    out.f32(checker.tile);
                }
                MaterialKind::Dielectric { ior } => {
                    out.u32(2);
                    out.f32(ior);
                }
                MaterialKind::Mirror { reflectance } => {
                    out.u32(3);
                    out.vec3(reflectance);
                }
                MaterialKind::Emitter { radiance } => {
                    out.u32(4);
                    out.vec3(radiance);
                }
            }
        }
        out.count(self.objects.len());
        for object in &self.objects {
            out.count(object.material);
            match &object.shape {
                Shape::Box(b) => {
                    out.u32(0);
                    out.vec3(b.min);
                    out.vec3(b.max);
                    out.f32(b.rotate_y_deg);
                    out.vec3(b.pivot);
                    out.vec3(b.translate);
                }
                Shape::Quad(q) => {
                    out.u32(1);
                    out.vec3(q.corner);
                    out.vec3(q.edge_u);
                    out.vec3(q.edge_v);
                }
                Shape::Sphere(s) => {
                    out.u32(2);
                    out.vec3(s.center);
                    out.f32(s.radius);
                }
                Shape::Mesh(m) => {
                    out.u32(3);
                    out.0.extend_from_slice(&m.file_hash.to_le_bytes());
                    out.vec3(m.placement.translate);
                    out.f32(m.placement.scale);
                    out.vec3(m.placement.rotate_deg);
                    out.u32(u32::from(m.smooth()));
                }
            }
        }
        match &self.directional_light {
            None => out.u32(0),
            Some(light) => {
                out.u32(1);
                out.vec3(light.direction);
                out.vec3(light.irradiance);
                out.f32(light.angular_radius_deg);
            }
        }
        match &self.environment {
            None => out.u32(0),
            Some(environment) => {
                out.u32(1);
                out.vec3(environment.radiance);
            }
        }
        out.0
    }

    /// The scene's identity: [`fnv1a_64`] of [`Scene::content_bytes`]. Equal for scenes that
    /// differ only in names, settings or other renderers' sections; different when any number
    /// of the camera's placement, a material, an object or a light differs.
    pub fn content_hash(&self) -> u64 {
        fnv1a_64(&self.content_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::shipped_scene;

    /// Every f32 of the scene's content, in the canonical order: what the hash must follow.
    fn numbers(scene: &mut Scene) -> Vec<&mut f32> {
        fn vec3(v: &mut Vec3) -> [&mut f32; 3] {
            [&mut v.x, &mut v.y, &mut v.z]
        }
        let mut out = Vec::new();
        let c = &mut scene.camera;
        out.extend(vec3(&mut c.eye));
        out.extend(vec3(&mut c.target));
        out.extend(vec3(&mut c.up));
        out.push(&mut c.vfov_deg);
        for material in &mut scene.materials {
            match &mut material.kind {
                MaterialKind::Lambertian { albedo } => out.extend(vec3(albedo)),
                MaterialKind::Checker(checker) => {
                    out.extend(vec3(&mut checker.even));
                    out.extend(vec3(&mut checker.odd));
                    out.push(&mut checker.tile);
                }
                MaterialKind::Dielectric { ior } => out.push(ior),
                MaterialKind::Mirror { reflectance } => out.extend(vec3(reflectance)),
                MaterialKind::Emitter { radiance } => out.extend(vec3(radiance)),
            }
        }
        for object in &mut scene.objects {
            match &mut object.shape {
                Shape::Box(b) => {
                    out.extend(vec3(&mut b.min));
                    out.extend(vec3(&mut b.max));
                    out.push(&mut b.rotate_y_deg);
                    out.extend(vec3(&mut b.pivot));
                    out.extend(vec3(&mut b.translate));
                }
                Shape::Quad(q) => {
                    out.extend(vec3(&mut q.corner));
                    out.extend(vec3(&mut q.edge_u));
                    out.extend(vec3(&mut q.edge_v));
                }
                Shape::Sphere(s) => {
                    out.extend(vec3(&mut s.center));
                    out.push(&mut s.radius);
                }
                Shape::Mesh(m) => {
                    let p = &mut std::sync::Arc::make_mut(m).placement;
                    out.extend(vec3(&mut p.translate));
                    out.push(&mut p.scale);
                    out.extend(vec3(&mut p.rotate_deg));
                }
            }
        }
        if let Some(light) = &mut scene.directional_light {
            out.extend(vec3(&mut light.direction));
            out.extend(vec3(&mut light.irradiance));
            out.push(&mut light.angular_radius_deg);
        }
        if let Some(environment) = &mut scene.environment {
            out.extend(vec3(&mut environment.radiance));
        }
        out
    }

    /// Between them the shipped scenes have every material kind, every shape, both lights.
    fn scenes() -> [Scene; 2] {
        [shipped_scene("cornell.toml", 64, 64), shipped_scene("whitted.toml", 64, 36)]
    }

    #[test]
    fn equal_content_hashes_equal_whatever_the_names_and_settings() {
        for scene in scenes() {
            let hash = scene.content_hash();
            assert_eq!(shipped_scene(&format!("{}.toml", scene.name), 64, 64).content_hash(), hash);
            let mut other = scene.clone();
            other.name = "renamed".into();
            other.source = "elsewhere.toml".into();
            other.camera.width = 1920;
            other.camera.height = 7;
            other.pathtrace.spp = 4096;
            other.pathtrace.seed = 99;
            other.pathtrace.caustics = !other.pathtrace.caustics;
            other.raster.pcf_radius += 1.0;
            other.whitted.depth += 1;
            other.shading.ambient += Vec3::splat(0.25);
            for material in &mut other.materials {
                material.name.push('2');
            }
            for object in &mut other.objects {
                object.name.push('2');
            }
            assert_eq!(other.content_hash(), hash, "{}: only names and settings changed", scene.name);
        }
    }

    #[test]
    fn a_change_to_any_number_of_the_content_changes_the_hash() {
        for scene in scenes() {
            let hash = scene.content_hash();
            let count = numbers(&mut scene.clone()).len();
            assert!(count > 40, "{}: only {count} numbers found", scene.name);
            for i in 0..count {
                let mut other = scene.clone();
                let number = numbers(&mut other).swap_remove(i);
                // The smallest change an f32 can have: its last bit.
                *number = f32::from_bits(number.to_bits() ^ 1);
                assert_ne!(other.content_hash(), hash, "{}: number {i} of {count} changed", scene.name);
            }
        }
    }

    #[test]
    fn structure_changes_the_hash_with_the_same_numbers() {
        let [cornell, whitted] = scenes();
        let mut swapped = cornell.clone();
        swapped.objects.swap(0, 1);
        let mut rebound = cornell.clone();
        rebound.objects[0].material = (rebound.objects[0].material + 1) % rebound.materials.len();
        let mut kind = cornell.clone();
        let MaterialKind::Lambertian { albedo } = kind.materials[0].kind else { panic!("red is Lambertian") };
        kind.materials[0].kind = MaterialKind::Mirror { reflectance: albedo };
        let mut no_sky = whitted.clone();
        no_sky.environment = None;
        let mut no_sun = whitted.clone();
        no_sun.directional_light = None;
        for (what, changed, original) in [
            ("objects in another order", &swapped, &cornell),
            ("another material on an object", &rebound, &cornell),
            ("another material kind, the same numbers", &kind, &cornell),
            ("no environment", &no_sky, &whitted),
            ("no directional light", &no_sun, &whitted),
        ] {
            assert_ne!(changed.content_hash(), original.content_hash(), "{what}");
        }
    }

    /// The canonical form of a shipped scene, pinned: if this fails, the bytes changed, and every
    /// hash stored in a file (checkpoints, cached references) with them. Raise
    /// [`CONTENT_VERSION`] and update the value, or undo the change.
    #[test]
    fn the_hash_of_the_cornell_box_is_pinned() {
        let cornell = shipped_scene("cornell.toml", 512, 512);
        assert_eq!(&cornell.content_bytes()[..20], b"illum.scene.v001\x01\0\0\0");
        assert_eq!(format!("{:016x}", cornell.content_hash()), "5f888b18b8e54dd4");
    }

    #[test]
    fn fnv1a_64_matches_its_published_test_vectors() {
        assert_eq!(fnv1a_64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a_64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a_64(b"foobar"), 0x8594_4171_f739_67e8);
    }
}
