//! The file helpers every layer shares, so that none reads without bound or leaves a
//! half-written output: the only I/O in this crate.
//!
//! - [`read_text_capped`]: a small text file (configuration, vehicle, sidecar) of at most
//!   [`CONFIG_BYTES_MAX`] bytes.
//! - [`write_atomic`]: an output file written under a temporary name in its folder and renamed
//!   over the final name only when complete; a crash or `kill -9` leaves the old file or the new
//!   one, never part of one. The folder must exist: nothing is created silently.

use crate::limits::CONFIG_BYTES_MAX;
use std::io;
use std::path::{Path, PathBuf};

/// Reads a small text file (a configuration, vehicle parameters, a sidecar) of at most
/// [`CONFIG_BYTES_MAX`] bytes: `/dev/zero` or a recording passed by mistake is not read without
/// bound.
///
/// Errors: the file cannot be read, is larger than the limit (`InvalidData`), or is not UTF-8.
pub fn read_text_capped(path: &std::path::Path) -> io::Result<String> {
    use io::Read;
    let mut text = String::new();
    std::fs::File::open(path)?
        .take(CONFIG_BYTES_MAX + 1)
        .read_to_string(&mut text)?;
    if text.len() as u64 > CONFIG_BYTES_MAX {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "larger than {} KiB; a configuration file is a few KiB (is this the right file?)",
                CONFIG_BYTES_MAX / 1024
            ),
        ));
    }
    Ok(text)
}

/// The folder `path` will be written in (`.` for a bare file name).
pub fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Checks, before any work, that `path` can be written: its folder exists (it is never created
/// silently) and `path` is not a folder.
///
/// Errors (`NotFound`, `InvalidInput`) name the folder or file.
pub fn check_output_file(path: &Path) -> io::Result<()> {
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Err(io::Error::new(
            io::ErrorKind::NotFound,
            format!(
                "the folder {} does not exist; create it first or write elsewhere",
                dir.display()
            ),
        ));
    }
    if path.is_dir() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} is a folder; give a file name", path.display()),
        ));
    }
    Ok(())
}

/// Writes `path` atomically: `write` gets a temporary path in the same folder with the same
/// extension, and the file is renamed over `path` only when `write` succeeds (else removed).
/// The file gets the usual permissions (0644 before the umask), not a temporary file's 0600.
///
/// Errors: the folder does not exist or the rename fails (through `on_io`), `write`'s error.
pub fn write_atomic<E>(
    path: &Path,
    on_io: impl Fn(io::Error) -> E,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), E> {
    check_output_file(path).map_err(&on_io)?;
    let dir = parent_dir(path);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let suffix = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    let prefix = format!(".{name}.");
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(&suffix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o644));
    }
    let tmp = b.tempfile_in(&dir).map_err(&on_io)?.into_temp_path();
    write(&tmp)?;
    tmp.persist(path).map_err(|e| on_io(e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces_only_on_success() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("out.csv");
        std::fs::write(&p, "old").unwrap();
        let r: io::Result<()> = write_atomic(
            &p,
            |e| e,
            |t| {
                std::fs::write(t, "partial")?;
                Err(io::Error::other("failed half way"))
            },
        );
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "old");
        assert_eq!(
            std::fs::read_dir(d.path()).unwrap().count(),
            1,
            "temporary file left"
        );
        write_atomic(&p, |e| e, |t| std::fs::write(t, "new")).unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "new");
        let missing = d.path().join("no/such/dir/out.csv");
        let e = write_atomic(&missing, |e| e, |t| std::fs::write(t, "x")).unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
        assert!(!d.path().join("no").exists(), "a folder was created");
    }

    #[test]
    fn capped_read_refuses_endless_files() {
        let e = read_text_capped(Path::new("/dev/zero")).unwrap_err();
        assert!(e.to_string().contains("larger than"), "{e}");
    }
}
