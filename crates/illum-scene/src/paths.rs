//! Where a scene file named on a command line is found.

use std::path::{Path, PathBuf};

/// `path` as given when it exists; a relative path that does not exist from the working
/// directory is tried from the workspace root too (the checkout this crate was built in), so
/// `scenes/cornell.toml` works from `cargo run` anywhere in the workspace and from any crate's
/// tests.
pub fn resolve_scene_path(path: &Path) -> PathBuf {
    if path.is_relative() && !path.exists() {
        let from_root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path);
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
        let missing = Path::new("no/such/scene.toml");
        assert_eq!(resolve_scene_path(missing), missing);
    }
}
