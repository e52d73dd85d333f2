//! `vibmode psd`: Welch and periodogram spectra with scipy.signal's parameters.

use crate::input::InputArgs;
use crate::output::write_json;
use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use vibmode_report::Scale;
use vibmode_run::psd::PsdMethod;
use vibmode_spectra::{
    Average, Detrend, PeriodogramParams, Scaling, ShortRecord, WelchParams, Window,
};

/// Which spectral estimator to compute.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Welch's averaged modified periodogram (scipy.signal.welch).
    Welch,
    /// Single-segment periodogram (scipy.signal.periodogram).
    Periodogram,
    /// Both, overlaid in plots (the paper's Fig. 5); Welch is the primary output.
    Both,
}

/// Axis scale for plots.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisScale {
    /// Linear axis.
    Linear,
    /// Logarithmic axis.
    Log,
}

impl From<Method> for PsdMethod {
    fn from(m: Method) -> PsdMethod {
        match m {
            Method::Welch => PsdMethod::Welch,
            Method::Periodogram => PsdMethod::Periodogram,
            Method::Both => PsdMethod::Both,
        }
    }
}

impl From<AxisScale> for Scale {
    fn from(a: AxisScale) -> Scale {
        match a {
            AxisScale::Linear => Scale::Linear,
            AxisScale::Log => Scale::Log,
        }
    }
}

/// Arguments of `vibmode psd`.
#[derive(Args, Debug)]
pub struct PsdArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Estimator: welch, periodogram, or both.
    #[arg(long, value_enum, default_value_t = Method::Welch)]
    pub method: Method,
    #[command(flatten)]
    pub spectral: SpectralArgs,
    /// Write JSON results to this path (`-` for standard output).
    #[arg(long)]
    pub json: Option<String>,
    /// Write a CSV table: frequency_hz then one PSD column per channel.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Write a plot (.svg or .png).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Frequency axis scale of the plot.
    #[arg(long, value_enum, default_value_t = AxisScale::Linear)]
    pub xscale: AxisScale,
    /// PSD axis scale of the plot.
    #[arg(long, value_enum, default_value_t = AxisScale::Log)]
    pub yscale: AxisScale,
    /// Highest frequency shown in the plot, Hz (default: Nyquist).
    #[arg(long = "fmax")]
    pub fmax_hz: Option<f64>,
}

/// scipy.signal's spectral parameters, shared by several commands.
#[derive(Args, Debug, Clone)]
pub struct SpectralArgs {
    /// Window: hann, hamming, blackman, boxcar, flattop, tukey, tukey:ALPHA or kaiser:BETA
    /// (default: hann for Welch, boxcar for the periodogram, as in scipy).
    #[arg(long)]
    pub window: Option<String>,
    /// Samples per Welch segment (default 256, as in scipy).
    #[arg(long)]
    pub nperseg: Option<usize>,
    /// Samples of overlap between segments (default nperseg/2).
    #[arg(long)]
    pub noverlap: Option<usize>,
    /// FFT length, >= nperseg, zero-padded (default nperseg; periodogram: record length).
    #[arg(long)]
    pub nfft: Option<usize>,
    /// Detrend each segment: constant, linear or none.
    #[arg(long, default_value = "constant")]
    pub detrend: String,
    /// density (units^2/Hz) or spectrum (units^2).
    #[arg(long, default_value = "density")]
    pub scaling: String,
    /// Welch averaging: mean, or median (with scipy's bias correction).
    #[arg(long, default_value = "mean")]
    pub average: String,
}

impl SpectralArgs {
    /// Welch parameters; an explicit `--nperseg` longer than the record is an error.
    pub fn welch_params(&self) -> Result<WelchParams> {
        let window = match &self.window {
            Some(w) => w.parse::<Window>()?,
            None => Window::Hann,
        };
        Ok(WelchParams {
            window,
            nperseg: self.nperseg,
            noverlap: self.noverlap,
            nfft: self.nfft,
            detrend: self.detrend.parse::<Detrend>()?,
            scaling: self.scaling.parse::<Scaling>()?,
            average: self.average.parse::<Average>()?,
            short_record: if self.nperseg.is_some() {
                ShortRecord::Error
            } else {
                ShortRecord::Clamp
            },
        })
    }

    /// Periodogram parameters.
    pub fn periodogram_params(&self) -> Result<PeriodogramParams> {
        let window = match &self.window {
            Some(w) => w.parse::<Window>()?,
            None => Window::Boxcar,
        };
        Ok(PeriodogramParams {
            window,
            nfft: self.nfft,
            detrend: self.detrend.parse::<Detrend>()?,
            scaling: self.scaling.parse::<Scaling>()?,
        })
    }
}

/// Runs `vibmode psd`.
pub fn run(a: &PsdArgs) -> Result<()> {
    crate::output::check_outputs(
        &a.input.input,
        &[a.csv.as_deref()],
        &[a.plot.as_deref()],
        a.json.as_deref(),
    )?;
    if let Some(f) = a.fmax_hz {
        if !(f.is_finite() && f > 0.0) {
            anyhow::bail!(
                "--fmax {f}: the plot's highest frequency must be a positive number of Hz"
            );
        }
    }
    let rec = a.input.load()?;
    let resampled = a
        .input
        .fs_out_hz
        .map(|to| (to, a.input.cutoff_hz.unwrap_or(to / 2.0)));
    let output = vibmode_run::psd::psd(
        &rec,
        &a.input.input.display().to_string(),
        a.method.into(),
        &a.spectral.welch_params()?,
        &a.spectral.periodogram_params()?,
        resampled,
    )?;
    if let Some(path) = &a.csv {
        let text = output.csv_text();
        vibmode_core::files::write_atomic(path, anyhow::Error::from, |tmp| {
            Ok(std::fs::write(tmp, &text)?)
        })
        .with_context(|| format!("cannot write CSV file {}", path.display()))?;
    }
    if let Some(path) = &a.plot {
        let fig = output.figure(a.xscale.into(), a.yscale.into(), a.fmax_hz);
        fig.save(path)
            .with_context(|| format!("writing plot {}", path.display()))?;
    }
    match &a.json {
        Some(dest) => write_json(dest, &output)?,
        None => {
            eprintln!("{}", output.header_line());
            crate::output::print_stdout(&output.table_text())?;
        }
    }
    Ok(())
}
