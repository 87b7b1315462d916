//! Where a scene file named on a command line is found.

use std::path::{Path, PathBuf};

/// `path` as given when it exists; a relative path that does not exist from the working
/// directory is tried from the workspace root too (the checkout this crate was built in), so
/// `scenes/cornell.toml` works from `cargo run` anywhere in the workspace and from any crate's
/// tests.
pub fn resolve_scene_path(path: &Path) -> PathBuf {
    if path.is_relative() && !path.exists() {
        // crates/illum-scene -> the workspace root, without `..` in what errors then show.
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).ancestors().nth(2).unwrap_or(Path::new("."));
        let from_root = root.join(path.strip_prefix(".").unwrap_or(path));
        if from_root.exists() {
            return from_root;
        }
    }
    path.to_path_buf()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_workspace_relative_path_is_found_from_anywhere() {
        let found = resolve_scene_path(Path::new("scenes/cornell.toml"));
        assert!(found.exists(), "{}", found.display());
        // What an error message shows from outside the checkout: a clean path.
        assert!(!found.components().any(|c| c == std::path::Component::ParentDir), "{}", found.display());
        let missing = Path::new("no/such/scene.toml");
        assert_eq!(resolve_scene_path(missing), missing);
    }
}
