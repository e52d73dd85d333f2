//! `vibmode resample`: the paper's ideal DFT anti-alias filter and resampling.

use crate::input::InputArgs;
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::PathBuf;
use vibmode_signal::ResampleParams;
use vibmode_signal::ResampleRecording;

/// Arguments of `vibmode resample`.
#[derive(Args, Debug)]
pub struct ResampleArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Target sampling rate in Hz.
    #[arg(long = "to")]
    pub to_hz: f64,
    /// Skip the anti-alias filter (plain decimation; shows aliasing).
    #[arg(long)]
    pub no_filter: bool,
    /// Output file: .csv (with a time_s column), .wav (32-bit float), or .f32/.f64 (+ .json sidecar).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Plot raw, resampled without and with the filter, in time and frequency (.svg or .png),
    /// as in the paper's Fig. 3-4 (first selected channel).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Seconds of signal shown in the time panel of the plot (default: 0.5 s).
    #[arg(long = "plot-seconds", default_value_t = 0.5)]
    pub plot_seconds: f64,
}

/// Runs `vibmode resample`.
pub fn run(a: &ResampleArgs) -> Result<()> {
    if a.input.resample_to_hz.is_some() {
        bail!("use --to HZ with `vibmode resample` (--resample-to is for the analysis commands)");
    }
    // Every output checked before any work (an output that is the input would be truncated
    // while still being read).
    crate::output::check_outputs(
        &a.input.input,
        &[Some(a.output.as_path())],
        &[a.plot.as_deref()],
        None,
    )?;
    if !(a.plot_seconds.is_finite() && a.plot_seconds > 0.0) {
        bail!(
            "--plot-seconds {}: the time panel needs a positive number of seconds, e.g. 0.5",
            a.plot_seconds
        );
    }
    let raw = a.input.load_raw()?;
    let p = ResampleParams {
        to_hz: a.to_hz,
        cutoff_hz: a.input.cutoff_hz,
        filter: !a.no_filter,
    };
    let out = raw.resample(&p)?;
    vibmode_signal::write_path(&a.output, &out)
        .with_context(|| format!("writing {}", a.output.display()))?;
    eprintln!(
        "{}: {} channel(s), {} samples at {} Hz -> {} samples at {} Hz ({}) written to {}",
        a.input.input.display(),
        raw.channels.len(),
        raw.len(),
        raw.fs_hz,
        out.len(),
        out.fs_hz,
        if a.no_filter {
            "no anti-alias filter".to_string()
        } else {
            format!(
                "ideal DFT low-pass at {} Hz",
                a.input.cutoff_hz.unwrap_or(a.to_hz / 2.0)
            )
        },
        a.output.display()
    );
    if let Some(path) = &a.plot {
        let fig =
            vibmode_report::antialias_figure(&raw, a.to_hz, a.input.cutoff_hz, a.plot_seconds)?;
        fig.save(path)
            .with_context(|| format!("writing plot {}", path.display()))?;
    }
    Ok(())
}
