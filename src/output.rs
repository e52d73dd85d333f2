//! Writing JSON to a file or standard output, and small output helpers.

use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes `text` to standard output. A closed pipe (`vibmode ... | head`) is not an error: the
/// reader has what it wanted, so the rest is dropped quietly.
pub fn print_stdout(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}

/// Writes `value` as pretty JSON to `dest`, where `-` means standard output.
pub fn write_json<T: Serialize>(dest: &str, value: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(value).context("serialising results to JSON")?;
    if dest == "-" {
        print_stdout(&(text + "\n"))?;
    } else {
        let path = Path::new(dest);
        vibmode_core::files::write_atomic(path, anyhow::Error::from, |tmp| {
            std::fs::write(tmp, text + "\n").map_err(anyhow::Error::from)
        })
        .with_context(|| format!("cannot write JSON to {dest}"))?;
    }
    Ok(())
}

/// Checks before any work that an output file can be written: its folder exists (vibmode does
/// not create folders for single files) and it is not one of the inputs.
pub fn check_output(path: &Path, inputs: &[&Path]) -> Result<()> {
    vibmode_core::files::check_output_file(path)
        .with_context(|| format!("cannot write {}", path.display()))?;
    if let Ok(o) = path.canonicalize() {
        for i in inputs {
            if i.canonicalize().is_ok_and(|i| i == o) || same_file(path, i) {
                anyhow::bail!(
                    "the output {} is an input file; write to another file",
                    path.display()
                );
            }
        }
    }
    Ok(())
}

/// Whether two existing paths are one file (the same device and inode: hard links too).
#[cfg(unix)]
fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_: &Path, _: &Path) -> bool {
    false
}

/// [`check_output`] for an optional JSON destination (`-` is standard output).
pub fn check_json_dest(dest: Option<&str>, inputs: &[&Path]) -> Result<()> {
    match dest {
        Some(d) if d != "-" => check_output(Path::new(d), inputs),
        _ => Ok(()),
    }
}

/// Checks every output of a single-input command before any work: folders exist, no output is
/// the input, plots end in `.svg` or `.png`.
pub fn check_outputs(
    input: &Path,
    files: &[Option<&Path>],
    plots: &[Option<&Path>],
    json: Option<&str>,
) -> Result<()> {
    for f in files.iter().chain(plots).flatten() {
        check_output(f, &[input])?;
    }
    for p in plots.iter().flatten() {
        let ext = p
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        if ext != "svg" && ext != "png" {
            anyhow::bail!(
                "the plot {} must end in .svg or .png (got '{}')",
                p.display(),
                ext
            );
        }
    }
    check_json_dest(json, &[input])
}

/// An output folder (report, simulation) written as a whole. Files go into a fresh hidden
/// folder beside the target; [`StagedDir::commit`] swaps it in atomically (Linux
/// `RENAME_EXCHANGE`), so a crash or `kill -9` at any moment leaves the old complete folder or
/// the new complete one. While a run holds the target it is locked: a second run into the same
/// folder is refused instead of racing.
pub struct StagedDir {
    target: PathBuf,
    stage: Option<tempfile::TempDir>,
    _lock: std::fs::File,
    /// The target did not exist before: a failed run removes the empty folder it made.
    created: bool,
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if self.created && self.stage.is_some() {
            // Only an empty folder goes (remove_dir fails on anything else).
            let _ = std::fs::remove_dir(&self.target);
        }
    }
}

/// Files that mark a folder as vibmode's own output (which may be replaced as a whole).
const OUTPUT_MARKERS: &[&str] = &[
    "results.json",
    "index.html",
    "truth.json",
    "fleet.json",
    "segments.json",
];

impl StagedDir {
    /// Prepares writing `target`: its parent must exist; `target` must be new, empty, or an
    /// earlier vibmode output (`results.json`, `index.html` or `truth.json` inside), and must not
    /// hold any of `inputs`. Leftovers of interrupted runs beside it are removed.
    pub fn begin(target: &Path, inputs: &[PathBuf]) -> Result<StagedDir> {
        let parent = vibmode_core::files::parent_dir(target);
        if !parent.is_dir() {
            bail!(
                "the folder {} (where {} would go) does not exist; create it first or write elsewhere",
                parent.display(),
                target.display()
            );
        }
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .filter(|n| n != "." && n != "..")
            .with_context(|| {
                format!(
                    "{} names no folder; give a new folder name such as -o report",
                    target.display()
                )
            })?;
        let created = !target.exists();
        if !created {
            if !target.is_dir() {
                bail!(
                    "{} is a file, not a folder; give a folder name",
                    target.display()
                );
            }
            let mut entries = std::fs::read_dir(target)
                .with_context(|| format!("cannot read folder {}", target.display()))?;
            let empty = entries.next().is_none();
            if !empty && !OUTPUT_MARKERS.iter().any(|m| target.join(m).exists()) {
                bail!(
                    "{} is not empty and holds no earlier vibmode output; it would be replaced as a whole: give a new folder",
                    target.display()
                );
            }
        } else {
            std::fs::create_dir(target)
                .with_context(|| format!("cannot create folder {}", target.display()))?;
        }
        let canon = target.canonicalize()?;
        for i in inputs {
            if i.canonicalize().is_ok_and(|i| i.starts_with(&canon)) {
                bail!(
                    "the input {} is inside the output folder {}, which is replaced as a whole; write the output elsewhere",
                    i.display(),
                    target.display()
                );
            }
        }
        let lock = std::fs::File::open(target)
            .with_context(|| format!("cannot open folder {}", target.display()))?;
        #[cfg(unix)]
        {
            use rustix::fs::{flock, FlockOperation};
            if flock(&lock, FlockOperation::NonBlockingLockExclusive).is_err() {
                bail!(
                    "another vibmode run is writing {}; wait for it to finish or write elsewhere",
                    target.display()
                );
            }
        }
        // Leftovers of interrupted runs into this target (safe: we hold its lock).
        let prefix = format!(".{name}.vibmode-");
        if let Ok(rd) = std::fs::read_dir(&parent) {
            for e in rd.flatten() {
                if e.file_name().to_string_lossy().starts_with(&prefix) {
                    let _ = std::fs::remove_dir_all(e.path());
                }
            }
        }
        let stage = tempfile::Builder::new()
            .prefix(&format!("{prefix}new-"))
            .tempdir_in(&parent)
            .with_context(|| format!("cannot create a folder in {}", parent.display()))?;
        Ok(StagedDir {
            target: target.to_path_buf(),
            stage: Some(stage),
            _lock: lock,
            created,
        })
    }

    /// Where to write the files now.
    pub fn path(&self) -> &Path {
        self.stage
            .as_ref()
            .map_or(self.target.as_path(), |s| s.path())
    }

    /// Puts the written folder in place of the target (the old one is removed).
    pub fn commit(mut self) -> Result<()> {
        let Some(stage) = self.stage.take() else {
            return Ok(());
        };
        let staged = stage.keep();
        #[cfg(unix)]
        let swapped = rustix::fs::renameat_with(
            rustix::fs::CWD,
            &staged,
            rustix::fs::CWD,
            &self.target,
            rustix::fs::RenameFlags::EXCHANGE,
        )
        .is_ok();
        #[cfg(not(unix))]
        let swapped = false;
        if swapped {
            // `staged` now holds the old folder.
            let _ = std::fs::remove_dir_all(&staged);
            return Ok(());
        }
        // No atomic exchange on this file system: move the old folder aside, then rename.
        let mut old = staged.as_os_str().to_owned();
        old.push("-old");
        let old = PathBuf::from(old);
        std::fs::rename(&self.target, &old)
            .with_context(|| format!("cannot replace {}", self.target.display()))?;
        std::fs::rename(&staged, &self.target)
            .with_context(|| format!("cannot move the new output to {}", self.target.display()))?;
        let _ = std::fs::remove_dir_all(&old);
        Ok(())
    }
}
