//! A `--reference` file: a converged image of a scene that another image is compared with (the
//! rasterizer's and the Whitted tracer's difference layers, the measuring tools' errors, the
//! viewer's Difference view). One rule for every reader:
//!
//! - the file must be an EXR of the render's size (the camera's width and height);
//! - a file that names its scene by content (`illum.scene_hash`, which covers the camera,
//!   materials, objects and lights, no settings) must name this scene's; another hash is refused,
//!   naming the file, the field and both values;
//! - a file without it (made by another renderer, such as Mitsuba, or without illum's metadata)
//!   is taken as given, with a note saying that its scene could not be checked.

use std::path::{Path, PathBuf};

use illum_image::{ExrMetadata, RgbImage32};
use illum_scene::Scene;

use crate::metadata::scene_hash;

/// The scene a converged reference of `scene` is rendered as, at `spp` samples per pixel:
/// cosine sampling (the estimator with no sample-count-dependent choice), and a seed of its own
/// (the scene's plus `0x5eed`), so that a reference's noise is independent of the renders it is
/// compared with. The measuring tools' cached references and Auto's pilot truth both use it.
pub fn reference_scene(scene: &Scene, spp: u32) -> Scene {
    let mut reference = scene.clone();
    reference.pathtrace.sampling = illum_scene::Sampling::Cosine;
    reference.pathtrace.spp = spp;
    reference.pathtrace.seed = scene.pathtrace.seed.wrapping_add(0x5eed);
    reference
}

/// The metadata key that names a file's scene by content.
pub const SCENE_HASH: &str = "scene_hash";

/// A reference image, read from its file.
#[derive(Clone, Debug)]
pub struct Reference {
    pub path: PathBuf,
    pub image: RgbImage32,
    /// illum's metadata (`illum.*` attributes); `None` for a file another program wrote.
    pub metadata: Option<ExrMetadata>,
}

/// What a reader tells a user whose reference has another size than the render.
#[derive(Clone, Copy, Debug)]
pub enum SizePolicy<'a> {
    /// The render's size comes from `--width` and `--height`: the refusal names the values that
    /// match the file.
    Flags,
    /// Another remedy, in the reader's words (the viewer's: resize the window).
    Advice(&'a str),
}

/// Why a file cannot be the reference of a render.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReferenceError {
    #[error("--reference {}: {reason}", path.display())]
    Unreadable { path: PathBuf, reason: String },
    #[error(
        "--reference {}: illum.scene_hash = {theirs} (scene {their_name:?}), but this render's scene {our_name:?} \
         has illum.scene_hash = {ours}: a reference must show the same camera, materials, objects and lights",
        path.display()
    )]
    OtherScene { path: PathBuf, theirs: String, their_name: String, ours: String, our_name: String },
    #[error("--reference {}: it is {} x {} pixels, but this render is {} x {}: {advice}", path.display(), theirs[0], theirs[1], ours[0], ours[1])]
    OtherSize { path: PathBuf, theirs: [u32; 2], ours: [u32; 2], advice: String },
}

impl Reference {
    /// Reads `path` (an EXR) without checking what it shows: for a reader that checks it
    /// against a scene that changes ([`Reference::check`]), such as the viewer's.
    pub fn read(path: &Path) -> Result<Reference, ReferenceError> {
        let unreadable = |reason: String| ReferenceError::Unreadable { path: path.to_path_buf(), reason };
        if !path.exists() {
            return Err(unreadable("no such file".to_owned()));
        }
        let (image, attributes) = illum_image::load_exr(path).map_err(|e| unreadable(e.to_string()))?;
        let metadata =
            ExrMetadata::from_attributes(path, &attributes).map_err(|e| unreadable(e.to_string()))?;
        Ok(Reference { path: path.to_path_buf(), image, metadata })
    }

    /// Reads `path` and checks it against `scene` at its camera's size ([`Reference::check`]).
    /// With the reference, the note to show when its scene could not be checked.
    pub fn load(
        path: &Path,
        scene: &Scene,
        policy: SizePolicy,
    ) -> Result<(Reference, Option<String>), ReferenceError> {
        let reference = Reference::read(path)?;
        let note = reference.check(scene, policy)?;
        Ok((reference, note))
    }

    /// Whether this file can be the truth of a render of `scene` at its camera's size (see the
    /// module's rule). `Ok(Some(note))`: it can, but its scene could not be checked, and the
    /// note, one line, says so.
    pub fn check(&self, scene: &Scene, policy: SizePolicy) -> Result<Option<String>, ReferenceError> {
        let note = match self.metadata.as_ref().and_then(|m| m.get(SCENE_HASH)) {
            None => Some(format!(
                "note: --reference {} has no illum.{SCENE_HASH} (not an illum render: another renderer's, such as \
                 Mitsuba's?), so whether it shows scene {:?} (camera, materials, objects, lights) could not be \
                 checked; using it as given",
                self.path.display(),
                scene.name
            )),
            Some(theirs) => {
                let ours = scene_hash(scene);
                if theirs != ours {
                    return Err(ReferenceError::OtherScene {
                        path: self.path.clone(),
                        theirs: theirs.to_owned(),
                        their_name: self.metadata.as_ref().map_or(String::new(), |m| m.scene.clone()),
                        ours,
                        our_name: scene.name.clone(),
                    });
                }
                None
            }
        };
        let theirs = [self.image.width, self.image.height];
        let ours = [scene.camera.width, scene.camera.height];
        if theirs != ours {
            let advice = match policy {
                SizePolicy::Flags => {
                    format!("give --width {} --height {}, or a reference of this size", theirs[0], theirs[1])
                }
                SizePolicy::Advice(advice) => advice.to_owned(),
            };
            return Err(ReferenceError::OtherSize { path: self.path.clone(), theirs, ours, advice });
        }
        Ok(note)
    }

    /// A number from the file's metadata (`spp`, `estimated_relative_error`, ...), if it has it.
    pub fn number(&self, key: &str) -> Option<f64> {
        self.metadata.as_ref()?.get(key)?.parse().ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> Scene {
        Scene::load(&illum_scene::resolve_scene_path(Path::new("scenes/cornell.toml")))
            .expect("the Cornell box")
    }

    /// A reference of `scene`'s size, with `hash` as its `illum.scene_hash` (`None`: no illum
    /// metadata at all, as a Mitsuba render).
    fn reference(scene: &Scene, hash: Option<&str>) -> Reference {
        let metadata = hash.map(|h| ExrMetadata {
            renderer: "pathtrace".into(),
            scene: "other box".into(),
            render_seconds: 1.0,
            fields: vec![(SCENE_HASH.into(), h.into()), ("spp".into(), "4096".into())],
        });
        Reference {
            path: PathBuf::from("truth.exr"),
            image: RgbImage32::new(scene.camera.width, scene.camera.height),
            metadata,
        }
    }

    #[test]
    fn a_file_of_the_same_scene_is_taken_without_a_note() {
        let scene = scene();
        let file = reference(&scene, Some(&scene_hash(&scene)));
        assert_eq!(file.check(&scene, SizePolicy::Flags), Ok(None));
        assert_eq!(file.number("spp"), Some(4096.0));
    }

    #[test]
    fn a_file_without_a_scene_hash_is_taken_with_one_line_naming_what_was_not_checked() {
        let scene = scene();
        let note = reference(&scene, None).check(&scene, SizePolicy::Flags).unwrap().expect("a note");
        assert!(!note.contains('\n'), "{note}");
        for part in ["truth.exr", "illum.scene_hash", "\"cornell\"", "could not be checked"] {
            assert!(note.contains(part), "the note lacks {part:?}: {note}");
        }
    }

    #[test]
    fn a_file_of_another_scene_is_refused_naming_file_field_and_both_hashes() {
        let scene = scene();
        let ours = scene_hash(&scene);
        let error = reference(&scene, Some("0123456789abcdef")).check(&scene, SizePolicy::Flags).unwrap_err();
        let text = error.to_string();
        for part in
            ["truth.exr", "illum.scene_hash", "0123456789abcdef", &ours, "\"other box\"", "\"cornell\""]
        {
            assert!(text.contains(part), "the refusal lacks {part:?}: {text}");
        }
        assert!(!text.contains("  "), "stray spaces: {text:?}");
    }

    #[test]
    fn a_file_of_another_size_is_refused_with_the_flags_or_the_readers_advice() {
        let scene = scene();
        let mut file = reference(&scene, None);
        file.image = RgbImage32::new(64, 32);
        let text = file.check(&scene, SizePolicy::Flags).unwrap_err().to_string();
        let size = format!("{} x {}", scene.camera.width, scene.camera.height);
        for part in ["truth.exr", "64 x 32", &size, "--width 64 --height 32"] {
            assert!(text.contains(part), "the refusal lacks {part:?}: {text}");
        }
        let text = file.check(&scene, SizePolicy::Advice("resize the window")).unwrap_err().to_string();
        assert!(text.ends_with(": resize the window"), "{text}");
        assert!(!text.contains("  "), "stray spaces: {text:?}");
    }

    #[test]
    fn a_missing_or_unreadable_file_is_refused_by_name() {
        let scene = scene();
        let missing = Reference::load(Path::new("no/such/truth.exr"), &scene, SizePolicy::Flags).unwrap_err();
        assert_eq!(missing.to_string(), "--reference no/such/truth.exr: no such file");
        let folder = tempfile::tempdir().expect("a temporary folder");
        let text_file = folder.path().join("notes.exr");
        std::fs::write(&text_file, "not an image").expect("written");
        let error = Reference::load(&text_file, &scene, SizePolicy::Flags).unwrap_err().to_string();
        assert!(error.starts_with(&format!("--reference {}: ", text_file.display())), "{error}");
    }

    #[test]
    fn a_written_reference_reads_back_and_is_checked_as_given() {
        let scene = scene();
        let folder = tempfile::tempdir().expect("a temporary folder");
        let path = folder.path().join("truth.exr");
        let file = reference(&scene, Some(&scene_hash(&scene)));
        illum_image::save_exr(&path, &file.image, file.metadata.as_ref().unwrap()).expect("written");
        let (read, note) = Reference::load(&path, &scene, SizePolicy::Flags).expect("accepted");
        assert_eq!(note, None);
        assert_eq!(read.number("spp"), Some(4096.0));
    }
}
