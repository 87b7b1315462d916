//! Helpers for tests of scene validation, shared by every crate's error tests (the scene
//! crate's own, and the renderers' checks of what they refuse), so that each rule is checked
//! the same way: a panic with the error when it does not match.

use crate::error::SceneError;

/// `text` with its one occurrence of `from` replaced by `to`; panics unless `from` occurs
/// exactly once (an edit that silently missed would test the unedited scene).
pub fn edit_once(text: &str, from: &str, to: &str) -> String {
    assert_eq!(text.matches(from).count(), 1, "{from:?} must occur once");
    text.replacen(from, to, 1)
}

/// `text` without each of `cuts`, each of which must occur exactly once (see [`edit_once`]).
pub fn without(text: &str, cuts: &[&str]) -> String {
    cuts.iter().fold(text.to_owned(), |text, cut| edit_once(&text, cut, ""))
}

/// Asserts that `err` is [`SceneError::Invalid`] for `file` and `field` with the shown `value`,
/// that what it allows contains `allowed`, and that the displayed message starts with
/// `FILE: FIELD = VALUE: ` and contains all four parts.
pub fn check_invalid(err: &SceneError, file: &str, field: &str, value: &str, allowed: &str) {
    let SceneError::Invalid { file: f, field: fd, value: v, allowed: a } = err else {
        panic!("expected Invalid on {field}, got {err:?}");
    };
    assert_eq!((f.as_str(), fd.as_str(), v.as_str()), (file, field, value), "{err}");
    assert!(a.contains(allowed), "allowed {a:?} lacks {allowed:?}");
    let shown = err.to_string();
    for part in [file, field, value, allowed] {
        assert!(shown.contains(part), "{shown:?} lacks {part:?}");
    }
    assert!(shown.starts_with(&format!("{file}: {field} = {value}: ")), "{shown}");
}

/// A shipped scene file (`scenes/NAME`, found from any crate's tests) at a test's resolution;
/// panics with the loader's message if it does not load.
pub fn shipped_scene(name: &str, width: u32, height: u32) -> crate::Scene {
    let path = crate::resolve_scene_path(&std::path::Path::new("scenes").join(name));
    let mut scene = crate::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    scene.camera.width = width;
    scene.camera.height = height;
    scene
}
