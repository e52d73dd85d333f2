//! `vibmode info`: what each recording file holds (format, rate, channels, length, start time,
//! each channel's range, mean, std and RMS, and the analysis's sensor checks), read block by
//! block.

use crate::input::ReadArgs;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `vibmode info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Recording files or folders (delimited text, WAV, raw with a .json sidecar, NumPy .npy).
    #[arg(required = true, num_args = 1..)]
    pub inputs: Vec<PathBuf>,
    #[command(flatten)]
    pub read: ReadArgs,
    /// Print JSON (one array of the files' summaries) instead of the tables.
    #[arg(long)]
    pub json: bool,
}

/// Summarises every file (folders expanded) and prints the tables or the JSON; the first file
/// that cannot be read ends the command with its error.
pub fn run(a: &InfoArgs) -> Result<()> {
    let opts = a.read.options()?;
    let files = vibmode_signal::expand_folders(&a.inputs)?;
    let mut all = Vec::with_capacity(files.len());
    for f in &files {
        let s = vibmode_signal::summarize(f, &opts)?;
        if !a.json {
            print!("{s}");
        }
        all.push(s);
    }
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&all).context("writing the summaries as JSON")?
        );
    }
    Ok(())
}
