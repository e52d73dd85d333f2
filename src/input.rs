//! Shared input options: which file, which channels, which rate, optional resampling.

use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use vibmode_signal::{ChannelSelector, ReadOptions, Recording, ResampleParams, ResampleRecording};

/// How files are read: the options every command that reads recordings flattens (`psd`, `fit`,
/// `sweep`, `ssi`, `resample`, `segment`, `analyze`, `fleet ingest`, `fleet check`). Each
/// option has one name, one default and one help text, here; [`ReadArgs::options`] is the one
/// mapping to the reader's [`ReadOptions`].
#[derive(Args, Debug, Clone)]
pub struct ReadArgs {
    /// Sampling rate in Hz, required when a file has no time column and no header rate.
    #[arg(long = "fs")]
    pub fs_hz: Option<f64>,
    /// Multiplier applied to WAV integer samples after scaling to [-1, 1) full scale.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Unit of the samples when the file does not say (e.g. m/s^2).
    #[arg(long)]
    pub unit: Option<String>,
    /// Unit of a text file's time column (s, ms, us, ns, min, h), overriding what its name and
    /// header say, e.g. ms for a `Timestamp` column in milliseconds.
    #[arg(long = "time-unit", value_name = "UNIT")]
    pub time_unit: Option<String>,
    /// Accept a non-uniform time column by interpolating onto a uniform grid at the mean rate.
    #[arg(long)]
    pub resample_nonuniform: bool,
}

impl ReadArgs {
    /// The reader's options (the one place the flags map to [`ReadOptions`]).
    pub fn options(&self) -> Result<ReadOptions> {
        let time_scale_s = match &self.time_unit {
            Some(u) => Some(vibmode_signal::time_unit_scale(u)?),
            None => None,
        };
        Ok(ReadOptions {
            fs_hz: self.fs_hz,
            scale: self.scale,
            unit: self.unit.clone(),
            allow_nonuniform: self.resample_nonuniform,
            time_scale_s,
            ..ReadOptions::default()
        })
    }
}

/// `--channel`, for the commands that select channels.
#[derive(Args, Debug, Clone, Default)]
pub struct ChannelArgs {
    /// Channel to use, by name or 0-based index; repeat for several (default: every channel but
    /// the time column).
    #[arg(long = "channel", short = 'c')]
    pub channels: Vec<String>,
}

impl ChannelArgs {
    /// The parsed selectors (empty: every channel).
    pub fn selectors(&self) -> Result<Vec<ChannelSelector>> {
        selectors(&self.channels)
    }
}

/// Parses `--channel` values (names or 0-based indices).
pub fn selectors(channels: &[String]) -> Result<Vec<ChannelSelector>> {
    Ok(channels
        .iter()
        .map(|s| s.parse::<ChannelSelector>())
        .collect::<Result<Vec<_>, _>>()?)
}

/// Options every analysis command shares for reading its input.
#[derive(Args, Debug, Clone)]
pub struct InputArgs {
    /// Input file: delimited text (.csv, .txt, .tsv), WAV (.wav), raw f32/f64 with a JSON sidecar,
    /// or a NumPy array (.npy, samples x channels).
    pub input: PathBuf,
    #[command(flatten)]
    pub channel: ChannelArgs,
    #[command(flatten)]
    pub read: ReadArgs,
    /// Resample to this rate in Hz (ideal DFT anti-alias filter first) before the analysis; for
    /// `vibmode resample`, the output's rate. (`--resample-to` is still accepted.)
    #[arg(long = "fs-out", value_name = "HZ", alias = "resample-to")]
    pub fs_out_hz: Option<f64>,
    /// Cutoff of the ideal anti-alias filter in Hz (default: the new Nyquist frequency).
    #[arg(long = "cutoff")]
    pub cutoff_hz: Option<f64>,
}

impl InputArgs {
    /// Reads the file, selects channels and optionally resamples.
    pub fn load(&self) -> Result<Recording> {
        let rec = self.load_raw()?;
        match self.fs_out_hz {
            Some(fs_out_hz) => {
                let p = ResampleParams {
                    fs_out_hz,
                    cutoff_hz: self.cutoff_hz,
                    filter: true,
                };
                rec.resample(&p).context("resampling")
            }
            None => {
                if let Some(c) = self.cutoff_hz {
                    anyhow::bail!("--cutoff {c} needs --fs-out HZ (the rate to resample to)");
                }
                Ok(rec)
            }
        }
    }

    /// Reads, selects and optionally resamples, with the band the signal then carries: `Some`
    /// after resampling (the ideal low-pass's cutoff and whether an empty band lies above it),
    /// `None` for a file used as it is (the identification then judges the band itself).
    pub fn load_with_band(&self) -> Result<(Recording, Option<vibmode_core::BandLimit>)> {
        let rec = self.load()?;
        let band = self.fs_out_hz.map(|_| {
            let nyquist = rec.fs_hz / 2.0;
            vibmode_core::BandLimit::ideal_lowpass(rec.fs_hz, self.cutoff_hz.unwrap_or(nyquist))
        });
        Ok((rec, band))
    }

    /// Opens the file as a stream of blocks with the channels selected (for any length).
    pub fn open_stream(&self) -> Result<vibmode_signal::FrameStream> {
        let mut s = vibmode_signal::open_stream(&self.input, &self.read.options()?)?;
        s.select(&self.channel.selectors()?)?;
        Ok(s)
    }

    /// Reads the file and selects channels, without resampling.
    pub fn load_raw(&self) -> Result<Recording> {
        let rec = vibmode_signal::read_path(&self.input, &self.read.options()?)?;
        if self.channel.channels.is_empty() {
            return Ok(rec);
        }
        Ok(rec.select(&self.channel.selectors()?)?)
    }
}
