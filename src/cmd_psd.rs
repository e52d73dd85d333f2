//! `vibmode psd`: Welch and periodogram spectra with scipy.signal's parameters.

use crate::input::InputArgs;
use crate::output::write_json;
use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use serde::Serialize;
use std::path::PathBuf;
use vibmode_report::{Curve, Figure, Scale};
use vibmode_signal::Recording;
use vibmode_spectra::{
    Average, Detrend, PeriodogramParams, Scaling, ShortRecord, Spectrum, WelchParams, Window,
};

/// Which spectral estimator to compute.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
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

#[derive(Serialize)]
struct ChannelPsd {
    name: String,
    unit: String,
    psd_unit: String,
    method: Method,
    frequency_hz: Vec<f64>,
    psd: Vec<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    periodogram: Option<PlainSpectrum>,
    notes: Vec<String>,
}

#[derive(Serialize)]
struct PlainSpectrum {
    frequency_hz: Vec<f64>,
    psd: Vec<f64>,
}

#[derive(Serialize)]
struct UsedParams {
    fs_hz: f64,
    n_samples: usize,
    window: String,
    nperseg: Option<usize>,
    noverlap: Option<usize>,
    nfft: usize,
    n_segments: Option<usize>,
    detrend: String,
    scaling: String,
    average: Option<String>,
    resampled_to_hz: Option<f64>,
    cutoff_hz: Option<f64>,
}

#[derive(Serialize)]
struct PsdOutput {
    source: String,
    method: Method,
    parameters: UsedParams,
    channels: Vec<ChannelPsd>,
}

fn psd_unit(unit: &str, scaling: Scaling) -> String {
    let u = if unit.is_empty() { "input units" } else { unit };
    match scaling {
        Scaling::Density => format!("({u})^2/Hz"),
        Scaling::Spectrum => format!("({u})^2"),
    }
}

/// Computes the requested spectra of every channel of `rec`.
fn compute(
    rec: &Recording,
    method: Method,
    sp: &SpectralArgs,
) -> Result<(Vec<ChannelPsd>, UsedParams)> {
    let wp = sp.welch_params()?;
    let pp = sp.periodogram_params()?;
    let mut out = Vec::new();
    let mut first: Option<Spectrum> = None;
    for ch in &rec.channels {
        let (main, per) = match method {
            Method::Welch => (
                vibmode_spectra::welch(&ch.samples, rec.fs_hz, &wp)
                    .with_context(|| format!("channel '{}'", ch.name))?,
                None,
            ),
            Method::Periodogram => (
                vibmode_spectra::periodogram(&ch.samples, rec.fs_hz, &pp)
                    .with_context(|| format!("channel '{}'", ch.name))?,
                None,
            ),
            Method::Both => {
                let w = vibmode_spectra::welch(&ch.samples, rec.fs_hz, &wp)
                    .with_context(|| format!("channel '{}'", ch.name))?;
                let p = vibmode_spectra::periodogram(&ch.samples, rec.fs_hz, &pp)
                    .with_context(|| format!("channel '{}'", ch.name))?;
                (
                    w,
                    Some(PlainSpectrum {
                        frequency_hz: p.freq_hz,
                        psd: p.psd,
                    }),
                )
            }
        };
        if first.is_none() {
            first = Some(main.clone());
        }
        out.push(ChannelPsd {
            name: ch.name.clone(),
            unit: ch.unit.clone(),
            psd_unit: psd_unit(&ch.unit, wp.scaling),
            method,
            frequency_hz: main.freq_hz.clone(),
            psd: main.psd.clone(),
            periodogram: per,
            notes: main.notes.clone(),
        });
    }
    let is_welch = method != Method::Periodogram;
    let f = first.context("the input has no channels; check --channel")?;
    let used = UsedParams {
        fs_hz: rec.fs_hz,
        n_samples: rec.len(),
        window: if is_welch {
            wp.window.to_string()
        } else {
            pp.window.to_string()
        },
        nperseg: is_welch.then_some(f.nperseg),
        noverlap: is_welch.then_some(f.noverlap),
        nfft: f.nfft,
        n_segments: is_welch.then_some(f.n_segments),
        detrend: wp.detrend.to_string(),
        scaling: wp.scaling.to_string(),
        average: is_welch.then(|| wp.average.to_string()),
        resampled_to_hz: None,
        cutoff_hz: None,
    };
    Ok((out, used))
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
    let (channels, mut used) = compute(&rec, a.method, &a.spectral)?;
    // A non-finite value is never printed or written (the input limits should make this
    // impossible; this is the last guard).
    for c in &channels {
        if c.psd.iter().any(|v| !v.is_finite()) {
            anyhow::bail!(
                "the spectrum of channel '{}' has a non-finite value; rescale the signal (another unit)",
                c.name
            );
        }
    }
    used.resampled_to_hz = a.input.resample_to_hz;
    used.cutoff_hz = a
        .input
        .resample_to_hz
        .map(|to| a.input.cutoff_hz.unwrap_or(to / 2.0));
    let output = PsdOutput {
        source: a.input.input.display().to_string(),
        method: a.method,
        parameters: used,
        channels,
    };
    if let Some(path) = &a.csv {
        write_csv(path, &output)?;
    }
    if let Some(path) = &a.plot {
        let fig = psd_figure(&output, a.xscale.into(), a.yscale.into(), a.fmax_hz);
        fig.save(path)
            .with_context(|| format!("writing plot {}", path.display()))?;
    }
    match &a.json {
        Some(dest) => write_json(dest, &output)?,
        None => print_summary(&output)?,
    }
    Ok(())
}

fn print_summary(o: &PsdOutput) -> Result<()> {
    use std::fmt::Write as _;
    let mut text = String::new();
    let p = &o.parameters;
    eprintln!(
        "{}: fs = {} Hz, {} samples, window {}, nfft {}{}",
        o.source,
        p.fs_hz,
        p.n_samples,
        p.window,
        p.nfft,
        match (p.nperseg, p.noverlap, p.n_segments) {
            (Some(n), Some(ov), Some(k)) => format!(", nperseg {n}, noverlap {ov}, {k} segments"),
            _ => String::new(),
        }
    );
    let _ = writeln!(
        text,
        "{:<24} {:>14} {:>16} {:>12}  unit of peak / unit of rms",
        "channel", "peak_hz", "peak", "rms"
    );
    for c in &o.channels {
        let (fpk, vp) =
            vibmode_spectra::peak(&c.frequency_hz, &c.psd).unwrap_or((f64::NAN, f64::NAN));
        let scaling = if p.scaling == "density" {
            Scaling::Density
        } else {
            Scaling::Spectrum
        };
        let rms = vibmode_spectra::rms(&c.frequency_hz, &c.psd, scaling);
        let unit = if c.unit.is_empty() {
            "input units"
        } else {
            c.unit.as_str()
        };
        let _ = writeln!(
            text,
            "{:<24} {:>14.4} {:>16.6e} {:>12.5e}  {} / {}",
            c.name, fpk, vp, rms, c.psd_unit, unit
        );
    }
    crate::output::print_stdout(&text)
}

fn write_csv(path: &std::path::Path, o: &PsdOutput) -> Result<()> {
    use std::io::Write;
    vibmode_core::files::write_atomic(path, anyhow::Error::from, |tmp| {
        let f = std::fs::File::create(tmp)?;
        let mut w = std::io::BufWriter::new(f);
        let mut header = vec!["frequency_hz".to_string()];
        header.extend(o.channels.iter().map(|c| c.name.replace(',', "_")));
        writeln!(w, "{}", header.join(","))?;
        if let Some(c0) = o.channels.first() {
            for (i, f) in c0.frequency_hz.iter().enumerate() {
                write!(w, "{f}")?;
                for c in &o.channels {
                    write!(w, ",{:e}", c.psd.get(i).copied().unwrap_or(f64::NAN))?;
                }
                writeln!(w)?;
            }
        }
        w.flush()?;
        Ok(())
    })
    .with_context(|| format!("cannot write CSV file {}", path.display()))
}

fn psd_figure(o: &PsdOutput, xs: Scale, ys: Scale, fmax: Option<f64>) -> Figure {
    let several = o.channels.len() > 1;
    let background: Vec<Curve> = o
        .channels
        .iter()
        .filter_map(|c| {
            let p = c.periodogram.as_ref()?;
            let label = if several {
                format!("{} periodogram", c.name)
            } else {
                "periodogram".into()
            };
            Some(Curve::new(label, p.frequency_hz.clone(), p.psd.clone()))
        })
        .collect();
    let curves: Vec<Curve> = o
        .channels
        .iter()
        .map(|c| {
            let label = match (c.method, several) {
                (Method::Periodogram, false) => "periodogram".to_string(),
                (_, false) => "Welch".to_string(),
                (Method::Periodogram, true) => c.name.clone(),
                (_, true) => format!("{} Welch", c.name),
            };
            Curve::new(label, c.frequency_hz.clone(), c.psd.clone())
        })
        .collect();
    let unit = o
        .channels
        .first()
        .map(|c| c.psd_unit.clone())
        .unwrap_or_default();
    let nyq = o.parameters.fs_hz / 2.0;
    let xmin = if xs == Scale::Log {
        o.parameters.fs_hz / o.parameters.nfft as f64
    } else {
        0.0
    };
    let name = std::path::Path::new(&o.source)
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| o.source.clone());
    vibmode_report::psd_figure(
        &format!("Power spectral density: {name}"),
        &background,
        &curves,
        &unit,
        (xs, ys),
        (xmin, fmax.unwrap_or(nyq).min(nyq)),
    )
}
