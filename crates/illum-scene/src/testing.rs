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

/// A refusal an error test expects: `(from, to, field, value, allowed)`, the base scene with
/// `from` replaced by `to` must fail on `field`, showing `value`, allowing `allowed` (see
/// [`check_invalid`]).
pub type InvalidEdit<'a> = (&'a str, &'a str, &'a str, &'a str, &'a str);

/// A refusal of one value: `(value, shown, allowed)`, written in place of a line's value (see
/// [`Edits::expect_invalid_values`]).
pub type InvalidValue<'a> = (&'a str, &'a str, &'a str);

/// What an error test edits and how it loads the result: a valid scene text, the file label
/// its errors name, and the loader (`Scene::from_toml_str`, or a renderer's view of a scene).
/// The error tests of every crate share it, so that each checks a rule the same way.
pub struct Edits<T> {
    /// The valid scene every edit starts from.
    pub base: &'static str,
    /// The file label given to the loader, which every error must name.
    pub file: &'static str,
    /// Loads a scene text under a file label.
    pub load: fn(&str, &str) -> Result<T, SceneError>,
}

impl<T: std::fmt::Debug> Edits<T> {
    /// The base with `from` replaced by `to`; `from` must occur exactly once (see [`edit_once`]).
    pub fn edit(&self, from: &str, to: &str) -> String {
        edit_once(self.base, from, to)
    }

    /// `text` loaded under the file label.
    pub fn parse(&self, text: &str) -> Result<T, SceneError> {
        (self.load)(text, self.file)
    }

    /// Asserts `text` fails validation on `field` with the shown `value`, and that the allowed
    /// text contains `allowed`; the displayed message must contain all four parts.
    pub fn expect_invalid(&self, text: &str, field: &str, value: &str, allowed: &str) {
        match self.parse(text) {
            Ok(_) => panic!("expected an error on {field} = {value}, but the scene loaded"),
            Err(e) => check_invalid(&e, self.file, field, value, allowed),
        }
    }

    /// [`Edits::expect_invalid`] for each edit of the base in `cases`.
    pub fn expect_invalid_edits(&self, cases: &[InvalidEdit]) {
        for &(from, to, field, value, allowed) in cases {
            self.expect_invalid(&self.edit(from, to), field, value, allowed);
        }
    }

    /// `line` is a `KEY = VALUE` line of the base; for each `(value, shown, allowed)` in `cases`,
    /// the base with `KEY = value` in its place must fail on `field`.
    pub fn expect_invalid_values(&self, line: &str, field: &str, cases: &[InvalidValue]) {
        let (key, _) = line.split_once(" = ").unwrap_or_else(|| panic!("{line:?} is not KEY = VALUE"));
        for &(value, shown, allowed) in cases {
            self.expect_invalid(&self.edit(line, &format!("{key} = {value}")), field, shown, allowed);
        }
    }
}
