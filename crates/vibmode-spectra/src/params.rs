//! Parameter enums and structs, with scipy.signal's vocabulary and defaults.

use crate::SpectraError;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Taper fraction of the window named plain `tukey`: scipy.signal.windows.tukey's default 0.5.
const DEFAULT_TUKEY_ALPHA: f64 = 0.5;

/// Taper applied to each segment. All windows are *periodic* (scipy
/// `get_window(name, n)`, i.e. `fftbins=True`): the symmetric window of length n + 1
/// with its last sample dropped.
///
/// `FromStr` (case-insensitive) accepts `hann`, `hamming`, `blackman`, `boxcar` (or `rect`),
/// `flattop`, `tukey` (alpha 0.5), `tukey:ALPHA` (e.g. `tukey:0.25`, ALPHA in [0, 1]) and
/// `kaiser:BETA` (e.g. `kaiser:8.6`; scipy's `('kaiser', beta)`, which has no default beta).
/// `Display` writes the same names (`tukey:0.25`, `kaiser:8.6`), so the two round-trip.
/// Other windows: give their coefficients ([`crate::WindowSpec::Custom`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Window {
    /// Hann: 0.5 - 0.5 cos(2 pi k / n).
    Hann,
    /// Hamming: 0.54 - 0.46 cos(2 pi k / n).
    Hamming,
    /// Blackman: 0.42 - 0.5 cos(2 pi k / n) + 0.08 cos(4 pi k / n).
    Blackman,
    /// Rectangular (all ones).
    Boxcar,
    /// Flat top (scipy's 5-term coefficients); peak heights of off-bin tones are accurate.
    Flattop,
    /// Tukey (tapered cosine): `alpha` (dimensionless, in [0, 1]) is the tapered fraction;
    /// 0 is boxcar, 1 is Hann.
    Tukey {
        /// Fraction of the window inside the cosine tapers, in [0, 1].
        alpha: f64,
    },
    /// Kaiser: `I0(beta sqrt(1 - (2 j / n - 1)^2)) / I0(beta)` (periodic, as scipy's
    /// `('kaiser', beta)`); `beta` (dimensionless, |beta| <= 700) trades main-lobe width for
    /// side-lobe level: 0 is boxcar, about 5 Hamming-like, 8.6 Blackman-like.
    Kaiser {
        /// Shape parameter; the window depends on |beta| only.
        beta: f64,
    },
}

/// Largest Kaiser |beta|: I0(beta) overflows a double beyond about 713.
const MAX_KAISER_BETA: f64 = 700.0;

impl Window {
    /// Checks the window's parameters (Tukey alpha in [0, 1], Kaiser |beta| <= 700).
    pub fn validate(&self) -> Result<(), SpectraError> {
        match *self {
            Window::Tukey { alpha } if !(0.0..=1.0).contains(&alpha) => {
                Err(SpectraError::InvalidTukeyAlpha { alpha })
            }
            Window::Kaiser { beta } if !(-MAX_KAISER_BETA..=MAX_KAISER_BETA).contains(&beta) => {
                Err(SpectraError::InvalidKaiserBeta { beta })
            }
            _ => Ok(()),
        }
    }
}

impl fmt::Display for Window {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Window::Hann => f.write_str("hann"),
            Window::Hamming => f.write_str("hamming"),
            Window::Blackman => f.write_str("blackman"),
            Window::Boxcar => f.write_str("boxcar"),
            Window::Flattop => f.write_str("flattop"),
            Window::Tukey { alpha } => write!(f, "tukey:{alpha}"),
            Window::Kaiser { beta } => write!(f, "kaiser:{beta}"),
        }
    }
}

impl FromStr for Window {
    type Err = SpectraError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim().to_ascii_lowercase();
        let unknown = || SpectraError::UnknownWindow {
            name: s.to_string(),
        };
        let w = match t.as_str() {
            "hann" => Window::Hann,
            "hamming" => Window::Hamming,
            "blackman" => Window::Blackman,
            "boxcar" | "rect" => Window::Boxcar,
            "flattop" => Window::Flattop,
            "tukey" => Window::Tukey {
                alpha: DEFAULT_TUKEY_ALPHA,
            },
            _ => {
                if let Some(rest) = t.strip_prefix("kaiser:") {
                    let beta: f64 = rest.trim().parse().map_err(|_| unknown())?;
                    Window::Kaiser { beta }
                } else {
                    let rest = t.strip_prefix("tukey:").ok_or_else(unknown)?;
                    let alpha: f64 = rest.trim().parse().map_err(|_| unknown())?;
                    Window::Tukey { alpha }
                }
            }
        };
        w.validate()?;
        Ok(w)
    }
}

/// Trend removed from each segment before windowing (scipy `detrend=`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Detrend {
    /// Nothing removed (scipy `detrend=False`). `FromStr`: "none" (or "false").
    None,
    /// Segment mean removed (scipy `'constant'`).
    Constant,
    /// Least-squares straight line removed (scipy `'linear'`).
    Linear,
}

impl fmt::Display for Detrend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Detrend::None => "none",
            Detrend::Constant => "constant",
            Detrend::Linear => "linear",
        })
    }
}

impl FromStr for Detrend {
    type Err = SpectraError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "none" | "false" => Ok(Detrend::None),
            "constant" => Ok(Detrend::Constant),
            "linear" => Ok(Detrend::Linear),
            _ => Err(SpectraError::UnknownDetrend {
                name: s.to_string(),
            }),
        }
    }
}

/// Output scaling (scipy `scaling=`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scaling {
    /// Power spectral density, units^2/Hz: scaled by 1 / (fs_hz * sum w^2).
    Density,
    /// Power spectrum, units^2: scaled by 1 / (sum w)^2; a sine of amplitude A at a bin
    /// frequency peaks at A^2 / 2.
    Spectrum,
}

impl fmt::Display for Scaling {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Scaling::Density => "density",
            Scaling::Spectrum => "spectrum",
        })
    }
}

impl FromStr for Scaling {
    type Err = SpectraError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "density" => Ok(Scaling::Density),
            "spectrum" => Ok(Scaling::Spectrum),
            _ => Err(SpectraError::UnknownScaling {
                name: s.to_string(),
            }),
        }
    }
}

/// How Welch combines the segment periodograms (scipy `average=`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Average {
    /// Arithmetic mean.
    Mean,
    /// Median, divided by scipy's bias factor `1 + sum_{i=1}^{(K-1)/2} (1/(2i+1) - 1/(2i))`
    /// for K segments. For cross-spectra the real and imaginary parts are medians taken
    /// separately, as in scipy. Keeps every segment's periodogram: memory
    /// `n_segments * (nfft / 2 + 1) * 8` bytes (16 for cross-spectra).
    Median,
}

impl fmt::Display for Average {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Average::Mean => "mean",
            Average::Median => "median",
        })
    }
}

impl FromStr for Average {
    type Err = SpectraError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "mean" => Ok(Average::Mean),
            "median" => Ok(Average::Median),
            _ => Err(SpectraError::UnknownAverage {
                name: s.to_string(),
            }),
        }
    }
}

/// What to do when the record is shorter than `nperseg`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShortRecord {
    /// Like scipy: use `nperseg = len(x)` (a single segment); a note is added to the result.
    Clamp,
    /// Return [`SpectraError::ShortRecord`].
    Error,
}

impl fmt::Display for ShortRecord {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ShortRecord::Clamp => "clamp",
            ShortRecord::Error => "error",
        })
    }
}

impl FromStr for ShortRecord {
    type Err = SpectraError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "clamp" => Ok(ShortRecord::Clamp),
            "error" => Ok(ShortRecord::Error),
            _ => Err(SpectraError::UnknownShortRecord {
                name: s.to_string(),
            }),
        }
    }
}

/// Parameters of [`crate::welch()`], [`crate::csd`], [`crate::coherence`] and
/// [`crate::WelchPlan`], with scipy.signal.welch's meaning and defaults.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WelchParams {
    /// Segment taper. Default [`Window::Hann`].
    pub window: Window,
    /// Segment length, samples. Default `None` = 256 (as scipy).
    pub nperseg: Option<usize>,
    /// Overlap between consecutive segments, samples. Default `None` = nperseg / 2
    /// (of the nperseg in force after clamping).
    pub noverlap: Option<usize>,
    /// FFT length, samples, >= nperseg (segments are zero-padded). Default `None` = nperseg.
    pub nfft: Option<usize>,
    /// Trend removed from each segment. Default [`Detrend::Constant`].
    pub detrend: Detrend,
    /// Density (units^2/Hz) or spectrum (units^2). Default [`Scaling::Density`].
    pub scaling: Scaling,
    /// Mean or median of the segment periodograms. Default [`Average::Mean`].
    pub average: Average,
    /// Record shorter than nperseg: clamp (scipy) or error. Default [`ShortRecord::Clamp`].
    pub short_record: ShortRecord,
}

impl Default for WelchParams {
    fn default() -> Self {
        WelchParams {
            window: Window::Hann,
            nperseg: None,
            noverlap: None,
            nfft: None,
            detrend: Detrend::Constant,
            scaling: Scaling::Density,
            average: Average::Mean,
            short_record: ShortRecord::Clamp,
        }
    }
}

/// Parameters of [`crate::periodogram`], with scipy.signal.periodogram's meaning and defaults.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PeriodogramParams {
    /// Taper over the whole record. Default [`Window::Boxcar`] (no taper).
    pub window: Window,
    /// FFT length, samples. Default `None` = record length. Larger zero-pads; smaller
    /// uses only the first `nfft` samples (as scipy; a note is added to the result).
    pub nfft: Option<usize>,
    /// Trend removed before the FFT. Default [`Detrend::Constant`].
    pub detrend: Detrend,
    /// Density (units^2/Hz) or spectrum (units^2). Default [`Scaling::Density`].
    pub scaling: Scaling,
}

impl Default for PeriodogramParams {
    fn default() -> Self {
        PeriodogramParams {
            window: Window::Boxcar,
            nfft: None,
            detrend: Detrend::Constant,
            scaling: Scaling::Density,
        }
    }
}
