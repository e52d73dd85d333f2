//! `vibmode psd` as a library: the Welch and/or periodogram spectra of every channel of a
//! recording with scipy.signal's parameters, the parameters used, and how they are printed,
//! tabulated and drawn.

use serde::Serialize;
use vibmode_signal::Recording;
use vibmode_spectra::{PeriodogramParams, Scaling, Spectrum, WelchParams};

use crate::RunError;

/// Which spectral estimator to compute.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PsdMethod {
    /// Welch's averaged modified periodogram (scipy.signal.welch).
    Welch,
    /// Single-segment periodogram (scipy.signal.periodogram).
    Periodogram,
    /// Both, overlaid in plots (the paper's Fig. 5); Welch is the primary output.
    Both,
}

/// The spectra of one channel.
#[derive(Clone, Debug, Serialize)]
pub struct ChannelPsd {
    /// Channel name.
    pub name: String,
    /// Unit of the samples.
    pub unit: String,
    /// Unit of the PSD (`(unit)^2/Hz` or `(unit)^2`).
    pub psd_unit: String,
    /// The estimator of `psd`.
    pub method: PsdMethod,
    /// Frequencies, Hz.
    pub frequency_hz: Vec<f64>,
    /// The primary spectrum (Welch, or the periodogram alone).
    pub psd: Vec<f64>,
    /// With [`PsdMethod::Both`], the periodogram beside Welch.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub periodogram: Option<PlainSpectrum>,
    /// The estimator's notes (e.g. a segment clamped to the record).
    pub notes: Vec<String>,
}

/// A spectrum without its parameters.
#[derive(Clone, Debug, Serialize)]
pub struct PlainSpectrum {
    /// Frequencies, Hz.
    pub frequency_hz: Vec<f64>,
    /// PSD.
    pub psd: Vec<f64>,
}

/// The parameters the spectra were computed with (after defaults and clamping).
#[derive(Clone, Debug, Serialize)]
pub struct UsedParams {
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Samples per channel.
    pub n_samples: usize,
    /// Window.
    pub window: String,
    /// Samples per Welch segment.
    pub nperseg: Option<usize>,
    /// Overlap of Welch segments.
    pub noverlap: Option<usize>,
    /// FFT length.
    pub nfft: usize,
    /// Welch segments averaged.
    pub n_segments: Option<usize>,
    /// Detrending.
    pub detrend: String,
    /// density or spectrum.
    pub scaling: String,
    /// Welch averaging.
    pub average: Option<String>,
    /// The rate the recording was resampled to before, Hz.
    pub resampled_to_hz: Option<f64>,
    /// The ideal low-pass's cutoff of that resampling, Hz.
    pub cutoff_hz: Option<f64>,
}

/// The spectra of a recording (`vibmode psd --json`).
#[derive(Clone, Debug, Serialize)]
pub struct PsdOutput {
    /// The file.
    pub source: String,
    /// The estimator.
    pub method: PsdMethod,
    /// The parameters used.
    pub parameters: UsedParams,
    /// One entry per channel.
    pub channels: Vec<ChannelPsd>,
}

fn psd_unit(unit: &str, scaling: Scaling) -> String {
    let u = if unit.is_empty() { "input units" } else { unit };
    match scaling {
        Scaling::Density => format!("({u})^2/Hz"),
        Scaling::Spectrum => format!("({u})^2"),
    }
}

/// The spectra of every channel of `rec` (read from `source`; `resampled`: the rate it was
/// resampled to and the cutoff, Hz). A non-finite ordinate is an error, never written.
pub fn psd(
    rec: &Recording,
    source: &str,
    method: PsdMethod,
    welch: &WelchParams,
    periodogram: &PeriodogramParams,
    resampled: Option<(f64, f64)>,
) -> Result<PsdOutput, RunError> {
    let channel_err = |name: &str| {
        let name = name.to_string();
        move |source| RunError::Spectrum {
            channel: name,
            source,
        }
    };
    let mut channels = Vec::new();
    let mut first: Option<Spectrum> = None;
    for ch in &rec.channels {
        let welch_of =
            || vibmode_spectra::welch(&ch.samples, rec.fs_hz, welch).map_err(channel_err(&ch.name));
        let periodogram_of = || {
            vibmode_spectra::periodogram(&ch.samples, rec.fs_hz, periodogram)
                .map_err(channel_err(&ch.name))
        };
        let (main, per) = match method {
            PsdMethod::Welch => (welch_of()?, None),
            PsdMethod::Periodogram => (periodogram_of()?, None),
            PsdMethod::Both => {
                let p = periodogram_of()?;
                (
                    welch_of()?,
                    Some(PlainSpectrum {
                        frequency_hz: p.freq_hz,
                        psd: p.psd,
                    }),
                )
            }
        };
        if main.psd.iter().any(|v| !v.is_finite()) {
            return Err(RunError::NonFiniteSpectrum {
                channel: ch.name.clone(),
            });
        }
        if first.is_none() {
            first = Some(main.clone());
        }
        channels.push(ChannelPsd {
            name: ch.name.clone(),
            unit: ch.unit.clone(),
            psd_unit: psd_unit(&ch.unit, welch.scaling),
            method,
            frequency_hz: main.freq_hz,
            psd: main.psd,
            periodogram: per,
            notes: main.notes,
        });
    }
    let is_welch = method != PsdMethod::Periodogram;
    let f = first.ok_or(RunError::NoChannels)?;
    let parameters = UsedParams {
        fs_hz: rec.fs_hz,
        n_samples: rec.len(),
        window: if is_welch {
            welch.window.to_string()
        } else {
            periodogram.window.to_string()
        },
        nperseg: is_welch.then_some(f.nperseg),
        noverlap: is_welch.then_some(f.noverlap),
        nfft: f.nfft,
        n_segments: is_welch.then_some(f.n_segments),
        detrend: welch.detrend.to_string(),
        scaling: welch.scaling.to_string(),
        average: is_welch.then(|| welch.average.to_string()),
        resampled_to_hz: resampled.map(|r| r.0),
        cutoff_hz: resampled.map(|r| r.1),
    };
    Ok(PsdOutput {
        source: source.to_string(),
        method,
        parameters,
        channels,
    })
}

/// A rate for the terminal: ten significant digits, trailing zeros dropped (a time column of
/// `i / 100` gives 100.00000000000001 Hz, shown as 100; 425.0796211146227 as 425.0796211). The
/// JSON keeps every digit.
fn rate_text(fs_hz: f64) -> String {
    if !(fs_hz.is_finite() && fs_hz > 0.0) {
        return format!("{fs_hz}");
    }
    let decimals = (9 - fs_hz.log10().floor() as i32).max(0) as usize;
    let s = format!("{fs_hz:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

impl PsdOutput {
    /// One line: the file, its rate and length, and the estimator's parameters.
    pub fn header_line(&self) -> String {
        let p = &self.parameters;
        format!(
            "{}: fs = {} Hz, {} samples, window {}, nfft {}{}",
            self.source,
            rate_text(p.fs_hz),
            p.n_samples,
            p.window,
            p.nfft,
            match (p.nperseg, p.noverlap, p.n_segments) {
                (Some(n), Some(ov), Some(k)) =>
                    format!(", nperseg {n}, noverlap {ov}, {k} segments"),
                _ => String::new(),
            }
        )
    }

    /// The table printed on the terminal: per channel the peak's frequency and level and the
    /// RMS, with units.
    pub fn table_text(&self) -> String {
        use std::fmt::Write as _;
        let mut text = String::new();
        let _ = writeln!(
            text,
            "{:<24} {:>14} {:>16} {:>12}  unit of peak / unit of rms",
            "channel", "peak_hz", "peak", "rms"
        );
        let scaling = if self.parameters.scaling == "density" {
            Scaling::Density
        } else {
            Scaling::Spectrum
        };
        for c in &self.channels {
            let (fpk, vp) =
                vibmode_spectra::peak(&c.frequency_hz, &c.psd).unwrap_or((f64::NAN, f64::NAN));
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
        text
    }

    /// The CSV table: `frequency_hz`, then one PSD column per channel.
    pub fn csv_text(&self) -> String {
        use std::fmt::Write as _;
        let mut t = String::new();
        let mut header = vec!["frequency_hz".to_string()];
        header.extend(self.channels.iter().map(|c| c.name.replace(',', "_")));
        let _ = writeln!(t, "{}", header.join(","));
        if let Some(c0) = self.channels.first() {
            for (i, f) in c0.frequency_hz.iter().enumerate() {
                let _ = write!(t, "{f}");
                for c in &self.channels {
                    let _ = write!(t, ",{:e}", c.psd.get(i).copied().unwrap_or(f64::NAN));
                }
                t.push('\n');
            }
        }
        t
    }

    /// The figure: every channel's spectrum (the periodograms behind Welch with
    /// [`PsdMethod::Both`]), up to `fmax_hz` (default: the Nyquist frequency).
    #[cfg(feature = "report")]
    pub fn figure(
        &self,
        xs: vibmode_report::Scale,
        ys: vibmode_report::Scale,
        fmax_hz: Option<f64>,
    ) -> vibmode_report::Figure {
        use vibmode_report::{Curve, Scale};
        let several = self.channels.len() > 1;
        let background: Vec<Curve> = self
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
        let curves: Vec<Curve> = self
            .channels
            .iter()
            .map(|c| {
                let label = match (c.method, several) {
                    (PsdMethod::Periodogram, false) => "periodogram".to_string(),
                    (_, false) => "Welch".to_string(),
                    (PsdMethod::Periodogram, true) => c.name.clone(),
                    (_, true) => format!("{} Welch", c.name),
                };
                Curve::new(label, c.frequency_hz.clone(), c.psd.clone())
            })
            .collect();
        let unit = self
            .channels
            .first()
            .map(|c| c.psd_unit.clone())
            .unwrap_or_default();
        let nyq = self.parameters.fs_hz / 2.0;
        let xmin = if xs == Scale::Log {
            self.parameters.fs_hz / self.parameters.nfft as f64
        } else {
            0.0
        };
        let name = std::path::Path::new(&self.source)
            .file_name()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_else(|| self.source.clone());
        vibmode_report::psd_figure(
            &format!("Power spectral density: {name}"),
            &background,
            &curves,
            &unit,
            (xs, ys),
            (xmin, fmax_hz.unwrap_or(nyq).min(nyq)),
        )
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn rates_are_shown_to_ten_digits() {
        assert_eq!(super::rate_text(100.00000000000001), "100");
        assert_eq!(super::rate_text(425.0796211146227), "425.0796211");
        assert_eq!(super::rate_text(20000.0), "20000");
        assert_eq!(super::rate_text(0.001), "0.001");
        assert_eq!(super::rate_text(1e7), "10000000");
    }
}
