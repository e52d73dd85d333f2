//! Writing JSON to a file or standard output, and small output helpers.

use anyhow::{Context, Result};
use serde::Serialize;
use std::io::Write;
use std::path::Path;

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
        std::fs::write(dest, text + "\n")
            .with_context(|| format!("cannot write JSON to {dest}"))?;
    }
    Ok(())
}

/// Creates the parent folder of `path` if it does not exist.
pub fn ensure_parent(path: &Path) -> Result<()> {
    if let Some(parent) = path.parent() {
        if !parent.as_os_str().is_empty() {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("cannot create folder {}", parent.display()))?;
        }
    }
    Ok(())
}
