//! Writing JSON to a file or standard output, and small output helpers.

use anyhow::{Context, Result};
use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// Writes `value` as pretty JSON to `dest`, where `-` means standard output.
pub fn write_json<T: Serialize>(dest: &str, value: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(value).context("serialising results to JSON")?;
    if dest == "-" {
        let mut out = std::io::stdout().lock();
        out.write_all(text.as_bytes())?;
        out.write_all(b"\n")?;
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
