//! Shared input options: which file, which channels, which rate, optional resampling.

use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use vibmode_signal::{ChannelSelector, ReadOptions, Recording, ResampleParams, ResampleRecording};

/// How files are read: rate, WAV scale and unit where the file does not say (every command that
/// reads recordings flattens this).
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
}

impl ReadArgs {
    /// The reader's options.
    pub fn options(&self) -> ReadOptions {
        ReadOptions {
            fs_hz: self.fs_hz,
            scale: self.scale,
            unit: self.unit.clone(),
            ..ReadOptions::default()
        }
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
    /// Input file: delimited text (.csv, .txt, .tsv), WAV (.wav), or raw f32/f64 with a JSON sidecar.
    pub input: PathBuf,
    /// Channel to analyse, by name or 0-based index; repeat for several (default: all but time).
    #[arg(long = "channel", short = 'c')]
    pub channels: Vec<String>,
    #[command(flatten)]
    pub read: ReadArgs,
    /// Accept a non-uniform time column by interpolating onto a uniform grid at the mean rate.
    #[arg(long)]
    pub resample_nonuniform: bool,
    /// Resample to this rate in Hz (ideal DFT anti-alias filter first) before analysis.
    #[arg(long = "resample-to")]
    pub resample_to_hz: Option<f64>,
    /// Cutoff of the ideal anti-alias filter in Hz (default: the new Nyquist frequency).
    #[arg(long = "cutoff")]
    pub cutoff_hz: Option<f64>,
}

impl InputArgs {
    /// Reads the file, selects channels and optionally resamples.
    pub fn load(&self) -> Result<Recording> {
        let rec = self.load_raw()?;
        match self.resample_to_hz {
            Some(to_hz) => {
                let p = ResampleParams {
                    to_hz,
                    cutoff_hz: self.cutoff_hz,
                    filter: true,
                };
                rec.resample(&p).context("resampling")
            }
            None => {
                if let Some(c) = self.cutoff_hz {
                    anyhow::bail!("--cutoff {c} needs --resample-to HZ (the rate to resample to)");
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
        let band = self.resample_to_hz.map(|_| {
            let nyquist = rec.fs_hz / 2.0;
            vibmode_core::BandLimit::ideal_lowpass(rec.fs_hz, self.cutoff_hz.unwrap_or(nyquist))
        });
        Ok((rec, band))
    }

    /// Opens the file as a stream of blocks with the channels selected (for any length).
    pub fn open_stream(&self) -> Result<vibmode_signal::FrameStream> {
        let mut s = vibmode_signal::open_stream(&self.input, &self.read_options())?;
        s.select(&selectors(&self.channels)?)?;
        Ok(s)
    }

    fn read_options(&self) -> ReadOptions {
        ReadOptions {
            allow_nonuniform: self.resample_nonuniform,
            ..self.read.options()
        }
    }

    /// Reads the file and selects channels, without resampling.
    pub fn load_raw(&self) -> Result<Recording> {
        let rec = vibmode_signal::read_path(&self.input, &self.read_options())?;
        if self.channels.is_empty() {
            return Ok(rec);
        }
        Ok(rec.select(&selectors(&self.channels)?)?)
    }
}
