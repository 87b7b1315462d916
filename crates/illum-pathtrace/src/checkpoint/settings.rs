//! The settings that change the image: as a checkpoint stores them, and the check that a file's
//! match a scene's before a render continues it.

use std::path::Path;

use illum_scene::Scene;

use super::{CheckpointError, CheckpointHeader};
use crate::TracerOptions;
use crate::estimators::{Estimators, KeyMismatch, compare_key};

impl CheckpointHeader {
    /// Checks that these samples were rendered from `scene` with `options`: an error naming
    /// every difference (content hash, resolution, bounces, seed, sampling, sequence, caustics
    /// and their estimators), with both values. The scene is known by its content
    /// (`illum.scene_hash`), not its name: a scene renamed, or a comment edited, goes on.
    pub fn check_matches(
        &self,
        path: &Path,
        scene: &Scene,
        options: TracerOptions,
    ) -> Result<(), CheckpointError> {
        let mut differences: Vec<String> =
            check_estimators(path, self, &Estimators::of(scene))?.into_iter().collect();
        for (key, now) in image_settings(scene, options) {
            let then = self.setting(key);
            if then.as_deref() != Some(now.as_str()) {
                differences.push(if key == "scene_hash" {
                    format!(
                        "scene content (camera, materials, objects, lights; illum.scene_hash): {} ({:?}) in the file, \
                         {now} ({:?}) now",
                        shown(then.as_deref()),
                        self.metadata.scene,
                        scene.name
                    )
                } else {
                    format!("{key}: {} in the file, {} now", shown(then.as_deref()), shown(Some(&now)))
                });
            }
        }
        if differences.is_empty() {
            Ok(())
        } else {
            Err(CheckpointError::OtherSettings { path: path.to_path_buf(), differences })
        }
    }

    /// The value of a setting in the file; width and height come from the image itself.
    pub(super) fn setting(&self, key: &str) -> Option<String> {
        match key {
            "width" => Some(self.width.to_string()),
            "height" => Some(self.height.to_string()),
            "scene" => Some(self.metadata.scene.clone()),
            // A file without the key was rendered without the caustic's light tracer.
            "caustics" => Some(self.metadata.get(key).unwrap_or("off").to_owned()),
            // A file without the key has no glint in its means (one with the older text form is
            // refused when loaded, `CheckpointError::OlderGlint`).
            "glint_hash" => Some(self.metadata.get(key).unwrap_or("none").to_owned()),
            _ => self.metadata.get(key).map(str::to_owned),
        }
    }
}

/// Longest value a refusal shows whole: every setting's (the longest, the caustic estimators'
/// token list, is under 100 characters); only an edited file's can be longer.
const SHOWN_CHARS: usize = 200;

/// A setting's value as a refusal shows it: whole when short, else its start and its length.
pub(super) fn shown(value: Option<&str>) -> String {
    match value {
        None => "(missing)".to_owned(),
        Some(v) if v.chars().count() <= SHOWN_CHARS => v.to_owned(),
        Some(v) => format!(
            "{}... ({} characters)",
            v.chars().take(SHOWN_CHARS).collect::<String>(),
            v.chars().count()
        ),
    }
}

/// The settings that change the image, as stored in a checkpoint and as `scene` and `options`
/// would store them: (key, value). Compared one by one so that a refusal names what differs.
pub fn image_settings(scene: &Scene, options: TracerOptions) -> Vec<(&'static str, String)> {
    vec![
        ("scene_hash", crate::metadata::scene_hash(scene)),
        ("width", scene.camera.width.to_string()),
        ("height", scene.camera.height.to_string()),
        ("bounces", scene.pathtrace.bounces.to_string()),
        ("seed", scene.pathtrace.seed.to_string()),
        ("sampling", scene.pathtrace.sampling.to_string()),
        ("sequence", options.sequence_label()),
        ("caustics", Estimators::of(scene).caustics_label().to_owned()),
    ]
}

/// Checks that the file at `path` (its `header`) was made by the estimators `now` names, by the
/// same rules (`estimators.rs`): samples of another set hold other light. A file that names its
/// estimators in an older form (the sentence of `illum.caustic_estimators`, or no key) is
/// refused with that reason; one whose tokens differ gives the difference to report beside the
/// other settings that differ.
fn check_estimators(
    path: &Path,
    header: &CheckpointHeader,
    now: &Estimators,
) -> Result<Option<String>, CheckpointError> {
    let stored = header.metadata.get(crate::metadata::ESTIMATORS);
    let legacy = header.metadata.get(crate::metadata::LEGACY_ESTIMATORS);
    match compare_key(stored, legacy, now) {
        Ok(()) => Ok(None),
        Err(mismatch @ KeyMismatch::OlderForm { .. }) => {
            Err(CheckpointError::OlderEstimators { path: path.to_path_buf(), reason: mismatch.to_string() })
        }
        Err(mismatch) => Ok(Some(format!("{}: {mismatch}", crate::metadata::ESTIMATORS))),
    }
}

#[cfg(test)]
mod tests {
    use illum_image::ExrMetadata;

    use super::*;

    /// A checkpoint is of a scene by content: renamed, it goes on; of edited content, it is
    /// refused naming both hashes and both names.
    #[test]
    fn a_renamed_scene_resumes_and_other_content_is_refused_by_hash_and_name() {
        let mut scene = Scene::load(&illum_scene::resolve_scene_path(Path::new("scenes/cornell.toml")))
            .expect("the Cornell box");
        let options = TracerOptions::default();
        let header = |scene: &Scene| CheckpointHeader {
            metadata: ExrMetadata {
                renderer: crate::metadata::RENDERER.to_owned(),
                scene: scene.name.clone(),
                render_seconds: 1.0,
                fields: image_settings(scene, options)
                    .into_iter()
                    .filter(|(k, _)| !matches!(*k, "width" | "height"))
                    .chain([(crate::metadata::ESTIMATORS, Estimators::of(scene).key())])
                    .map(|(k, v)| (k.to_owned(), v))
                    .collect(),
            },
            width: scene.camera.width,
            height: scene.camera.height,
            spp_done: 16,
            sample_start: 0,
            partial_pass: None,
        };
        let file = header(&scene);
        scene.name = "cornell-renamed".to_owned();
        assert!(file.check_matches(Path::new("long.exr"), &scene, options).is_ok());
        scene.camera.vfov_deg += 1.0;
        let error = file.check_matches(Path::new("long.exr"), &scene, options).unwrap_err().to_string();
        let (then, now) = (file.metadata.get("scene_hash").unwrap(), crate::metadata::scene_hash(&scene));
        for part in ["long.exr", "illum.scene_hash", then, &now, "\"cornell\"", "\"cornell-renamed\""] {
            assert!(error.contains(part), "the refusal lacks {part:?}: {error}");
        }
    }
}
