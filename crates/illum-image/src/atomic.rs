//! Atomic file output: a reader of the target path sees either the old file or the complete
//! new one, never a half-written image, even if the program is interrupted or the encoder
//! fails midway.
//!
//! The data go to a temporary file in the *same directory* as the target (a rename is only
//! atomic within one file system), which is flushed and fsynced before it is renamed over
//! the target. On any error the temporary file is deleted and the target is left untouched.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::ImageError;

/// The target's folder ("." for a bare file name) and its file name, after the checks every
/// output needs: the path names a file, is not an existing directory, and is not a read-only
/// file (the rename would silently replace it).
fn target_parts(path: &Path) -> Result<(PathBuf, &std::ffi::OsStr), ImageError> {
    let file_name = path
        .file_name()
        .ok_or_else(|| ImageError::invalid(path, "the path names no file (it is empty or ends in '..')"))?;
    if let Ok(metadata) = std::fs::metadata(path) {
        if metadata.is_dir() {
            return Err(ImageError::invalid(
                path,
                "it is a directory; give a file name ending in .png or .exr",
            ));
        }
        if metadata.permissions().readonly() {
            return Err(ImageError::invalid(
                path,
                "the file exists and is read-only; illum does not replace read-only files \
                 (make it writable, or choose another name)",
            ));
        }
    }
    let dir: PathBuf = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok((dir, file_name))
}

/// The file a write to `path` should replace: `path` itself, or where it points if it is a
/// symbolic link (renaming onto the link would replace the link by a regular file and leave
/// the file it points to as it was). A dangling link gives the file it names.
fn resolve_link(path: &Path) -> PathBuf {
    let is_link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if !is_link {
        return path.to_path_buf();
    }
    if let Ok(target) = std::fs::canonicalize(path) {
        return target;
    }
    match std::fs::read_link(path) {
        Ok(target) if target.is_relative() => path.parent().map_or(target.clone(), |dir| dir.join(&target)),
        Ok(target) => target,
        Err(_) => path.to_path_buf(),
    }
}

/// Creates the temporary file next to `path` that [`write_atomically`] writes into (creating
/// the folder if it is missing).
fn temporary_next_to(path: &Path) -> Result<tempfile::NamedTempFile, ImageError> {
    let (dir, file_name) = target_parts(path)?;
    std::fs::create_dir_all(&dir).map_err(|e| ImageError::io(path, "creating the folder", e))?;
    // A dot-prefixed name that shows what it will become, e.g. ".render.png.a1B2c3.tmp".
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(file_name);
    prefix.push(".");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    // tempfile creates files readable by the owner only; output images should get the usual
    // permissions (0o666 less the umask), as a plain `File::create` would give them, or those
    // of the file they replace.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        match std::fs::metadata(path) {
            Ok(existing) => builder.permissions(existing.permissions()),
            Err(_) => builder.permissions(std::fs::Permissions::from_mode(0o666)),
        };
    }
    builder
        .tempfile_in(&dir)
        .map_err(|e| ImageError::io(path, "creating a temporary file next to the output", e))
}

/// Checks, before a long render, that [`write_atomically`] will be able to write `path`: it
/// names a file that is not a directory and not read-only, and a file can be created in its
/// folder (which is created if it is missing). Nothing is left behind but the folder.
pub fn check_output(path: impl AsRef<Path>) -> Result<(), ImageError> {
    temporary_next_to(&resolve_link(path.as_ref())).map(drop)
}

/// Writes `path` atomically. `write` receives the temporary file (seekable, as some encoders
/// need); it should write the whole content and may return any [`ImageError`], which is
/// passed on after the temporary file has been removed. The parent directory is created if
/// it is missing. An existing file is replaced and keeps its permissions; a read-only one is
/// refused, and so is a directory. A symbolic link is followed: the file it points to is
/// replaced and the link stays.
pub fn write_atomically<F>(path: impl AsRef<Path>, write: F) -> Result<(), ImageError>
where
    F: FnOnce(&mut File) -> Result<(), ImageError>,
{
    let resolved = resolve_link(path.as_ref());
    let path = resolved.as_path();
    // From here on, dropping `tmp` (on any early return) deletes the temporary file.
    let mut tmp = temporary_next_to(path)?;
    #[cfg(unix)]
    let (dir, _) = target_parts(path)?;

    write(tmp.as_file_mut())?;

    let file = tmp.as_file_mut();
    file.flush().map_err(|e| ImageError::io(path, "flushing the temporary file", e))?;
    // fsync before the rename: otherwise a crash shortly after could leave the *renamed*
    // file with missing data on some file systems.
    file.sync_all().map_err(|e| ImageError::io(path, "syncing the temporary file to disk", e))?;

    // Keep the mode of the file being replaced exactly (creating the temporary file applied
    // the umask to it).
    if let Ok(existing) = std::fs::metadata(path) {
        tmp.as_file()
            .set_permissions(existing.permissions())
            .map_err(|e| ImageError::io(path, "giving the new file the old one's permissions", e))?;
    }
    tmp.persist(path).map_err(|e| {
        // `e.file` is the temporary file; dropping it with `e` deletes it.
        ImageError::io(path, "renaming the temporary file onto the output", e.error)
    })?;

    // Make the rename itself durable. Best effort: some file systems refuse to fsync a
    // directory, and the image is already complete and in place.
    #[cfg(unix)]
    if let Ok(d) = File::open(&dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Writing through a symbolic link replaces the file it points to and keeps the link; a
    /// dangling link gets the file it names.
    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_is_followed_not_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let at = |name: &str| dir.path().join(name);
        std::fs::write(at("target.png"), b"old").unwrap();
        for (link, points_to, content) in
            [("link.png", "target.png", b"new"), ("dangling.png", "made.png", b"xyz")]
        {
            std::os::unix::fs::symlink(points_to, at(link)).unwrap();
            check_output(at(link)).unwrap();
            write_atomically(at(link), |f| {
                f.write_all(content).map_err(|e| ImageError::io(at(link), "writing", e))
            })
            .unwrap();
            assert!(
                std::fs::symlink_metadata(at(link)).unwrap().file_type().is_symlink(),
                "{link} was replaced"
            );
            assert_eq!(std::fs::read(at(points_to)).unwrap(), content);
        }
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn writes_new_file_and_creates_parent() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("a/b/out.bin");
        write_atomically(&target, |f| f.write_all(b"hello").map_err(|e| ImageError::io("x", "writing", e)))
            .unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"hello");
        assert_eq!(entries(&dir.path().join("a/b")), vec!["out.bin".to_string()]);
    }

    #[test]
    fn replaces_existing_file() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.bin");
        std::fs::write(&target, b"old content").unwrap();
        write_atomically(&target, |f| f.write_all(b"new").map_err(|e| ImageError::io("x", "writing", e)))
            .unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
    }

    #[test]
    fn failing_writer_leaves_old_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.bin");
        std::fs::write(&target, b"old content").unwrap();
        let err = write_atomically(&target, |f| {
            // Write part of the content, then fail, as an encoder might.
            f.write_all(b"half").unwrap();
            Err(ImageError::invalid(&target, "simulated encoder failure"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("simulated encoder failure"), "{err}");
        assert_eq!(std::fs::read(&target).unwrap(), b"old content");
        assert_eq!(entries(dir.path()), vec!["out.bin".to_string()], "temporary file left");
    }

    #[test]
    fn failing_writer_creates_no_target() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("never.bin");
        write_atomically(&target, |_| Err(ImageError::invalid("never.bin", "no"))).unwrap_err();
        assert!(!target.exists());
        assert!(entries(dir.path()).is_empty());
    }

    #[cfg(unix)]
    #[test]
    fn output_is_not_owner_only() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("perm.bin");
        write_atomically(&target, |_| Ok(())).unwrap();
        let mode = std::fs::metadata(&target).unwrap().permissions().mode() & 0o777;
        // A plain File::create gets 0o666 less the umask; the atomic writer must match it
        // rather than keep tempfile's owner-only 0o600.
        let plain = dir.path().join("plain.bin");
        std::fs::File::create(&plain).unwrap();
        let plain_mode = std::fs::metadata(&plain).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, plain_mode, "atomic {mode:o} vs plain {plain_mode:o}");
    }

    #[cfg(unix)]
    #[test]
    fn a_replaced_file_keeps_its_mode_and_a_read_only_one_is_refused() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("kept.bin");
        std::fs::write(&target, b"old").unwrap();
        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_atomically(&target, |f| f.write_all(b"new").map_err(|e| ImageError::io("x", "writing", e)))
            .unwrap();
        assert_eq!(std::fs::metadata(&target).unwrap().permissions().mode() & 0o777, 0o640);

        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o444)).unwrap();
        for err in [check_output(&target).unwrap_err(), write_atomically(&target, |_| Ok(())).unwrap_err()] {
            assert!(
                err.to_string().contains("kept.bin") && format!("{err:?}").contains("read-only"),
                "{err:?}"
            );
        }
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert_eq!(std::fs::metadata(&target).unwrap().permissions().mode() & 0o777, 0o444);
    }

    #[test]
    fn check_output_refuses_directories_and_unwritable_folders_and_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let err = check_output(dir.path()).unwrap_err();
        assert!(format!("{err:?}").contains("is a directory"), "{err:?}");
        // A folder that cannot exist: its parent is a file.
        let file = dir.path().join("plain");
        std::fs::write(&file, b"x").unwrap();
        let err = check_output(file.join("out.png")).unwrap_err();
        assert!(matches!(err, ImageError::Io { .. }), "{err:?}");
        let fine = dir.path().join("new/out.png");
        check_output(&fine).unwrap();
        assert!(!fine.exists());
        assert!(entries(&dir.path().join("new")).is_empty(), "the probe left a file");
    }

    #[test]
    fn path_without_file_name_is_an_error() {
        let err = write_atomically("..", |_| Ok(())).unwrap_err();
        assert!(matches!(err, ImageError::Invalid { .. }), "{err}");
    }
}
