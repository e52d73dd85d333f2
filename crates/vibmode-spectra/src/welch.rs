//! Welch's method: [`WelchPlan`] and the results it produces.

use crate::{Average, Detrend, Scaling, ShortRecord, SpectraError, WelchParams, WindowSpec};
use num_complex::Complex64;
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use vibmode_fft::RealToComplex;

/// One-sided auto-spectrum (power spectral density or power spectrum) of a real signal.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spectrum {
    /// Frequencies of the bins, Hz: `k * fs_hz / nfft` for `k = 0 ..= nfft / 2`
    /// (scipy `rfftfreq`).
    pub freq_hz: Vec<f64>,
    /// One value per bin: units^2/Hz with [`Scaling::Density`], units^2 with
    /// [`Scaling::Spectrum`]. Every bin but DC (and Nyquist for even nfft) is doubled,
    /// so the total power is kept.
    pub psd: Vec<f64>,
    /// Segment length actually used, samples (after clamping to the record length).
    pub nperseg: usize,
    /// Overlap actually used, samples.
    pub noverlap: usize,
    /// FFT length actually used, samples.
    pub nfft: usize,
    /// Number of segments averaged.
    pub n_segments: usize,
    /// Human-readable notes on deviations from the request (e.g. nperseg clamped).
    pub notes: Vec<String>,
}

/// One-sided cross-spectral density `Pxy = conj(X) Y` (scipy.signal.csd's convention).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CrossSpectrum {
    /// Frequencies of the bins, Hz (`k * fs_hz / nfft`, `k = 0 ..= nfft / 2`).
    pub freq_hz: Vec<f64>,
    /// Complex cross-spectrum per bin: units_x*units_y/Hz ([`Scaling::Density`]) or
    /// units_x*units_y ([`Scaling::Spectrum`]); one-sided doubling as for [`Spectrum`].
    pub csd: Vec<Complex64>,
    /// Segment length actually used, samples.
    pub nperseg: usize,
    /// Overlap actually used, samples.
    pub noverlap: usize,
    /// FFT length actually used, samples.
    pub nfft: usize,
    /// Number of segments averaged.
    pub n_segments: usize,
    /// Human-readable notes on deviations from the request.
    pub notes: Vec<String>,
}

/// Magnitude-squared coherence `|Pxy|^2 / (Pxx Pyy)` (scipy.signal.coherence).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Coherence {
    /// Frequencies of the bins, Hz (`k * fs_hz / nfft`, `k = 0 ..= nfft / 2`).
    pub freq_hz: Vec<f64>,
    /// Coherence per bin, dimensionless, in [0, 1] (up to rounding). Bins where
    /// `Pxx * Pyy == 0` (scipy gives NaN there) are set to 0 and reported in `notes`.
    pub coherence: Vec<f64>,
    /// Segment length actually used, samples.
    pub nperseg: usize,
    /// Overlap actually used, samples.
    pub noverlap: usize,
    /// FFT length actually used, samples.
    pub nfft: usize,
    /// Number of segments averaged.
    pub n_segments: usize,
    /// Human-readable notes on deviations from the request.
    pub notes: Vec<String>,
}

/// Short-time spectra of a real signal (scipy.signal.spectrogram with `mode="psd"`): the
/// periodogram of each segment of a [`WelchPlan`], not averaged.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spectrogram {
    /// Frequencies of the bins, Hz (`k * fs_hz / nfft`, `k = 0 ..= nfft / 2`).
    pub freq_hz: Vec<f64>,
    /// Centre of each segment, s from the first sample (`(start + nperseg / 2) / fs_hz`, as
    /// scipy).
    pub time_s: Vec<f64>,
    /// One one-sided spectrum per segment (`psd[segment][bin]`), scaled and doubled as
    /// [`Spectrum::psd`].
    pub psd: Vec<Vec<f64>>,
    /// Segment length, samples.
    pub nperseg: usize,
    /// Overlap, samples.
    pub noverlap: usize,
    /// FFT length, samples.
    pub nfft: usize,
    /// Human-readable notes on deviations from the request.
    pub notes: Vec<String>,
}

/// Resolved segment sizes of a plan, samples.
struct Sizes {
    nperseg: usize,
    noverlap: usize,
    nfft: usize,
}

/// Segment length when [`WelchParams::nperseg`] is `None`: scipy.signal.welch's default.
const DEFAULT_NPERSEG: usize = 256;

/// Checks that the sampling rate is positive and finite.
pub(crate) fn check_fs(fs_hz: f64) -> Result<(), SpectraError> {
    if fs_hz.is_finite() && fs_hz > 0.0 {
        Ok(())
    } else {
        Err(SpectraError::InvalidSampleRate { fs_hz })
    }
}

/// Checks that `x` is non-empty and finite.
pub(crate) fn check_samples(x: &[f64], name: &'static str) -> Result<(), SpectraError> {
    if x.is_empty() {
        return Err(SpectraError::EmptyInput { name });
    }
    match x.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(SpectraError::NonFiniteSample {
            name,
            index,
            value: x[index],
        }),
        None => Ok(()),
    }
}

/// Checks a pair of inputs: each non-empty and finite, and of one length.
pub(crate) fn check_pair_samples(x: &[f64], y: &[f64]) -> Result<(), SpectraError> {
    check_samples(x, "x")?;
    check_samples(y, "y")?;
    if x.len() != y.len() {
        return Err(SpectraError::LengthMismatch {
            len_x: x.len(),
            len_y: y.len(),
        });
    }
    Ok(())
}

/// scipy's bias of the median of `k` periodograms relative to their mean.
fn median_bias(k: usize) -> f64 {
    let m = (k.saturating_sub(1)) / 2;
    1.0 + (1..=m)
        .map(|i| {
            let ii2 = 2.0 * i as f64;
            1.0 / (ii2 + 1.0) - 1.0 / ii2
        })
        .sum::<f64>()
}

pub(crate) use vibmode_core::stats::median_in_place;

/// A reusable Welch computation for records of one length: resolves the parameters
/// once (clamping, defaults), and keeps the FFT plan, the window and all scratch buffers,
/// so that computing many channels or records allocates only the outputs.
///
/// ```
/// use vibmode_spectra::{WelchPlan, WelchParams};
/// let fs_hz = 100.0;
/// let x: Vec<f64> = (0..4096).map(|i| (i as f64 * 0.37).sin()).collect();
/// let mut plan = WelchPlan::new(x.len(), fs_hz, &WelchParams::default())?;
/// let s = plan.welch(&x)?;
/// assert_eq!(s.psd.len(), 129);
/// assert_eq!(s.n_segments, 31); // (4096 - 256) / 128 + 1
/// # Ok::<(), vibmode_spectra::SpectraError>(())
/// ```
pub struct WelchPlan {
    n_samples: usize,
    fs_hz: f64,
    nperseg: usize,
    noverlap: usize,
    nfft: usize,
    n_segments: usize,
    detrend: Detrend,
    average: Average,
    /// Density or spectrum scale factor, applied after averaging.
    scale: f64,
    window: Vec<f64>,
    freq_hz: Vec<f64>,
    notes: Vec<String>,
    fft: Arc<dyn RealToComplex<f64>>,
    seg: Vec<f64>,
    spec_x: Vec<Complex64>,
    spec_y: Vec<Complex64>,
    scratch: Vec<Complex64>,
    /// Per-bin accumulators (mean) for Pxx, Pyy and Pxy.
    acc_xx: Vec<f64>,
    acc_yy: Vec<f64>,
    acc_xy: Vec<Complex64>,
    /// Per-segment values for the median, bin-major (`bin * n_segments + segment`);
    /// allocated on first use.
    store_re: Vec<f64>,
    store_im: Vec<f64>,
}

impl std::fmt::Debug for WelchPlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WelchPlan")
            .field("n_samples", &self.n_samples)
            .field("nperseg", &self.nperseg)
            .field("noverlap", &self.noverlap)
            .field("nfft", &self.nfft)
            .field("n_segments", &self.n_segments)
            .finish_non_exhaustive()
    }
}

impl WelchPlan {
    /// Prepares Welch spectra of records of `n_samples` samples at `fs_hz` (Hz).
    ///
    /// Resolves `p` as scipy.signal.welch does: nperseg defaults to 256 and is clamped
    /// to `n_samples` (or rejected, with [`ShortRecord::Error`]); noverlap defaults to
    /// nperseg / 2; nfft defaults to nperseg. Errors: invalid fs_hz, `n_samples == 0`,
    /// nperseg = 0, noverlap >= nperseg, nfft < nperseg, Tukey alpha outside [0, 1].
    pub fn new(n_samples: usize, fs_hz: f64, p: &WelchParams) -> Result<Self, SpectraError> {
        Self::with_window(n_samples, fs_hz, p, &WindowSpec::Named(p.window))
    }

    /// As [`WelchPlan::new`], with the taper `window` in place of `p.window` (which is not
    /// used). Custom coefficients follow scipy's rules for a window array: they set the segment
    /// length, so `p.nperseg` must be `None` or their length, and the record must be at least
    /// that long (never clamped, whatever [`WelchParams::short_record`] says).
    ///
    /// Errors: those of [`WelchPlan::new`]; custom coefficients that are empty, non-finite or
    /// all zero, differ in length from `p.nperseg`, or are longer than the record; a window
    /// whose `sum(w)` (spectrum scaling) or `sum(w^2)` (density) is 0.
    pub fn with_window(
        n_samples: usize,
        fs_hz: f64,
        p: &WelchParams,
        window: &WindowSpec,
    ) -> Result<Self, SpectraError> {
        check_fs(fs_hz)?;
        window.validate()?;
        if n_samples == 0 {
            return Err(SpectraError::EmptyInput { name: "x" });
        }
        if p.nperseg == Some(0) {
            return Err(SpectraError::ZeroNperseg);
        }
        let mut notes = Vec::new();
        let nperseg = match window.fixed_len() {
            Some(window_len) => {
                if let Some(nperseg) = p.nperseg.filter(|&m| m != window_len) {
                    return Err(SpectraError::WindowLengthMismatch {
                        window_len,
                        nperseg,
                    });
                }
                if window_len > n_samples {
                    return Err(SpectraError::WindowLongerThanRecord {
                        window_len,
                        n_samples,
                    });
                }
                window_len
            }
            None => {
                let requested = p.nperseg.unwrap_or(DEFAULT_NPERSEG);
                if requested > n_samples {
                    match p.short_record {
                        ShortRecord::Error => {
                            return Err(SpectraError::ShortRecord {
                                n_samples,
                                nperseg: requested,
                            })
                        }
                        ShortRecord::Clamp => {
                            notes.push(format!(
                                "nperseg = {requested} is greater than the record length {n_samples}; \
                                 using nperseg = {n_samples} (one segment, as scipy.signal)"
                            ));
                            n_samples
                        }
                    }
                } else {
                    requested
                }
            }
        };
        let nfft = match p.nfft {
            None => nperseg,
            Some(0) => return Err(SpectraError::ZeroNfft),
            Some(n) if n < nperseg => return Err(SpectraError::NfftTooSmall { nfft: n, nperseg }),
            Some(n) => n,
        };
        let noverlap = p.noverlap.unwrap_or(nperseg / 2);
        if noverlap >= nperseg {
            return Err(SpectraError::NoverlapTooLarge {
                noverlap,
                nperseg,
                suggested: nperseg / 2,
            });
        }
        let coefficients = window.values(nperseg);
        let (scale, what, scaling) = match p.scaling {
            Scaling::Density => (
                1.0 / (fs_hz * coefficients.iter().map(|w| w * w).sum::<f64>()),
                "sum(w^2)",
                "density",
            ),
            Scaling::Spectrum => {
                let s: f64 = coefficients.iter().sum();
                (1.0 / (s * s), "sum(w)", "spectrum")
            }
        };
        if !scale.is_finite() {
            return Err(SpectraError::WindowScaleZero { what, scaling });
        }
        Ok(Self::build(
            n_samples,
            fs_hz,
            Sizes {
                nperseg,
                noverlap,
                nfft,
            },
            p,
            coefficients,
            scale,
            notes,
        ))
    }

    /// Builds a plan from already-validated, resolved sizes, window and scale factor.
    fn build(
        n_samples: usize,
        fs_hz: f64,
        sizes: Sizes,
        p: &WelchParams,
        window: Vec<f64>,
        scale: f64,
        notes: Vec<String>,
    ) -> Self {
        let Sizes {
            nperseg,
            noverlap,
            nfft,
        } = sizes;
        let step = nperseg - noverlap;
        let n_segments = (n_samples - nperseg) / step + 1;
        let nfreq = nfft / 2 + 1;
        let df = 1.0 / (nfft as f64 * (1.0 / fs_hz));
        let freq_hz = (0..nfreq).map(|k| k as f64 * df).collect();
        let fft = vibmode_fft::Planner::new().forward(nfft);
        let seg = fft.make_input_vec();
        let spec_x = fft.make_output_vec();
        let spec_y = fft.make_output_vec();
        let scratch = fft.make_scratch_vec();
        WelchPlan {
            n_samples,
            fs_hz,
            nperseg,
            noverlap,
            nfft,
            n_segments,
            detrend: p.detrend,
            average: p.average,
            scale,
            window,
            freq_hz,
            notes,
            fft,
            seg,
            spec_x,
            spec_y,
            scratch,
            acc_xx: vec![0.0; nfreq],
            acc_yy: vec![0.0; nfreq],
            acc_xy: vec![Complex64::new(0.0, 0.0); nfreq],
            store_re: Vec::new(),
            store_im: Vec::new(),
        }
    }

    /// Segment length in force, samples.
    pub fn nperseg(&self) -> usize {
        self.nperseg
    }
    /// Overlap in force, samples.
    pub fn noverlap(&self) -> usize {
        self.noverlap
    }
    /// FFT length, samples.
    pub fn nfft(&self) -> usize {
        self.nfft
    }
    /// Number of segments per record.
    pub fn n_segments(&self) -> usize {
        self.n_segments
    }
    /// Record length the plan accepts, samples.
    pub fn n_samples(&self) -> usize {
        self.n_samples
    }
    /// Bin frequencies, Hz.
    pub fn freq_hz(&self) -> &[f64] {
        &self.freq_hz
    }
    /// The (periodic) window applied to each segment, dimensionless.
    pub fn window(&self) -> &[f64] {
        &self.window
    }
    /// Notes on how the request was resolved (e.g. nperseg clamped).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    fn check_input(&self, x: &[f64], name: &'static str) -> Result<(), SpectraError> {
        check_samples(x, name)?;
        if x.len() != self.n_samples {
            return Err(SpectraError::PlanLengthMismatch {
                name,
                expected: self.n_samples,
                got: x.len(),
            });
        }
        Ok(())
    }

    /// Welch PSD of `x` (scipy.signal.welch with this plan's parameters).
    /// Errors: empty or non-finite `x`, or `x.len()` differing from the plan's record length.
    pub fn welch(&mut self, x: &[f64]) -> Result<Spectrum, SpectraError> {
        self.check_input(x, "x")?;
        let k = self.n_segments;
        let median = self.begin_average(false);
        for s in 0..k {
            self.transform_segment(x, s, false);
            if median {
                for (b, c) in self.spec_x.iter().enumerate() {
                    self.store_re[b * k + s] = c.norm_sqr();
                }
            } else {
                for (a, c) in self.acc_xx.iter_mut().zip(&self.spec_x) {
                    *a += c.norm_sqr();
                }
            }
        }
        let mut psd = if median {
            let bias = median_bias(k);
            self.store_re
                .chunks_exact_mut(k)
                .map(|ch| median_in_place(ch) * self.scale / bias)
                .collect::<Vec<_>>()
        } else {
            let f = self.scale / k as f64;
            self.acc_xx.iter().map(|a| a * f).collect()
        };
        self.double_one_sided(&mut psd);
        Ok(Spectrum {
            freq_hz: self.freq_hz.clone(),
            psd,
            nperseg: self.nperseg,
            noverlap: self.noverlap,
            nfft: self.nfft,
            n_segments: k,
            notes: self.notes.clone(),
        })
    }

    /// Short-time spectra of `x`: the scaled one-sided periodogram of every segment of the plan
    /// (scipy.signal.spectrogram with `mode="psd"` and this plan's window, nperseg, noverlap,
    /// nfft, detrend and scaling; the mean over the segments is [`WelchPlan::welch`] with the
    /// mean average).
    /// Errors: empty or non-finite `x`, or `x.len()` differing from the plan's record length.
    pub fn spectrogram(&mut self, x: &[f64]) -> Result<Spectrogram, SpectraError> {
        self.check_input(x, "x")?;
        let step = self.nperseg - self.noverlap;
        let mut psd = Vec::with_capacity(self.n_segments);
        let mut time_s = Vec::with_capacity(self.n_segments);
        for s in 0..self.n_segments {
            self.transform_segment(x, s, false);
            let mut p: Vec<f64> = self
                .spec_x
                .iter()
                .map(|c| c.norm_sqr() * self.scale)
                .collect();
            self.double_one_sided(&mut p);
            psd.push(p);
            time_s.push((s * step) as f64 / self.fs_hz + self.nperseg as f64 / 2.0 / self.fs_hz);
        }
        Ok(Spectrogram {
            freq_hz: self.freq_hz.clone(),
            time_s,
            psd,
            nperseg: self.nperseg,
            noverlap: self.noverlap,
            nfft: self.nfft,
            notes: self.notes.clone(),
        })
    }

    /// Cross-spectral density of `x` and `y` (scipy.signal.csd: `conj(X) * Y`).
    /// Errors: empty or non-finite inputs, lengths differing from each other or the plan.
    pub fn csd(&mut self, x: &[f64], y: &[f64]) -> Result<CrossSpectrum, SpectraError> {
        self.check_pair(x, y)?;
        let k = self.n_segments;
        let median = self.begin_average(true);
        for s in 0..k {
            self.transform_segment(x, s, false);
            self.transform_segment(y, s, true);
            for (b, (cx, cy)) in self.spec_x.iter().zip(&self.spec_y).enumerate() {
                let v = cx.conj() * cy;
                if median {
                    self.store_re[b * k + s] = v.re;
                    self.store_im[b * k + s] = v.im;
                } else {
                    self.acc_xy[b] += v;
                }
            }
        }
        let mut csd: Vec<Complex64> = if median {
            let f = self.scale / median_bias(k);
            self.store_re
                .chunks_exact_mut(k)
                .zip(self.store_im.chunks_exact_mut(k))
                .map(|(re, im)| Complex64::new(median_in_place(re), median_in_place(im)) * f)
                .collect()
        } else {
            let f = self.scale / k as f64;
            self.acc_xy.iter().map(|a| a * f).collect()
        };
        self.double_one_sided(&mut csd);
        Ok(CrossSpectrum {
            freq_hz: self.freq_hz.clone(),
            csd,
            nperseg: self.nperseg,
            noverlap: self.noverlap,
            nfft: self.nfft,
            n_segments: k,
            notes: self.notes.clone(),
        })
    }

    /// Magnitude-squared coherence of `x` and `y` (scipy.signal.coherence).
    ///
    /// Like scipy.signal.coherence, always averages with the mean; if the plan was built
    /// with [`Average::Median`] a note says so. Errors as [`WelchPlan::csd`].
    pub fn coherence(&mut self, x: &[f64], y: &[f64]) -> Result<Coherence, SpectraError> {
        self.check_pair(x, y)?;
        let k = self.n_segments;
        self.acc_xx.fill(0.0);
        self.acc_yy.fill(0.0);
        self.acc_xy.fill(Complex64::new(0.0, 0.0));
        for s in 0..k {
            self.transform_segment(x, s, false);
            self.transform_segment(y, s, true);
            for b in 0..self.freq_hz.len() {
                let (cx, cy) = (self.spec_x[b], self.spec_y[b]);
                self.acc_xx[b] += cx.norm_sqr();
                self.acc_yy[b] += cy.norm_sqr();
                self.acc_xy[b] += cx.conj() * cy;
            }
        }
        let mut notes = self.notes.clone();
        if self.average == Average::Median {
            notes.push(
                "average = median ignored: coherence always uses the mean, as scipy.signal.coherence"
                    .to_string(),
            );
        }
        // Scale and one-sided doubling cancel in the ratio; they are applied anyway so the
        // rounding follows scipy's (which divides scaled, doubled spectra).
        let f = self.scale / k as f64;
        let mut pxx: Vec<f64> = self.acc_xx.iter().map(|a| a * f).collect();
        let mut pyy: Vec<f64> = self.acc_yy.iter().map(|a| a * f).collect();
        let mut pxy: Vec<Complex64> = self.acc_xy.iter().map(|a| a * f).collect();
        self.double_one_sided(&mut pxx);
        self.double_one_sided(&mut pyy);
        self.double_one_sided(&mut pxy);
        let mut n_zero = 0usize;
        let coherence = pxy
            .iter()
            .zip(pxx.iter().zip(&pyy))
            .map(|(xy, (&xx, &yy))| {
                if xx == 0.0 || yy == 0.0 {
                    n_zero += 1;
                    0.0
                } else {
                    xy.norm_sqr() / xx / yy
                }
            })
            .collect();
        if n_zero > 0 {
            notes.push(format!(
                "{n_zero} bin(s) with zero auto-spectrum (e.g. DC after detrending with a boxcar window) set to coherence 0"
            ));
        }
        Ok(Coherence {
            freq_hz: self.freq_hz.clone(),
            coherence,
            nperseg: self.nperseg,
            noverlap: self.noverlap,
            nfft: self.nfft,
            n_segments: k,
            notes,
        })
    }

    fn check_pair(&self, x: &[f64], y: &[f64]) -> Result<(), SpectraError> {
        check_pair_samples(x, y)?;
        self.check_input(x, "x")?;
        self.check_input(y, "y")
    }

    /// Prepares the buffers of a [`WelchPlan::welch`] (`cross` false: `acc_xx`, `store_re`) or
    /// [`WelchPlan::csd`] (`cross` true: `acc_xy`, `store_re`, `store_im`) average. Returns whether
    /// the median is taken (per-segment values stored) rather than the mean (accumulated).
    fn begin_average(&mut self, cross: bool) -> bool {
        let k = self.n_segments;
        let nfreq = self.freq_hz.len();
        let median = self.average == Average::Median && k > 1;
        if median {
            self.store_re.resize(nfreq * k, 0.0);
            if cross {
                self.store_im.resize(nfreq * k, 0.0);
            }
        } else if cross {
            self.acc_xy.fill(Complex64::new(0.0, 0.0));
        } else {
            self.acc_xx.fill(0.0);
        }
        median
    }

    /// Detrends, windows, zero-pads and transforms segment `s` of `x` into `spec_x`
    /// (or `spec_y` when `into_y`). Allocates nothing.
    fn transform_segment(&mut self, x: &[f64], s: usize, into_y: bool) {
        let n = self.nperseg;
        let start = s * (self.nperseg - self.noverlap);
        let (head, tail) = self.seg.split_at_mut(n);
        head.copy_from_slice(&x[start..start + n]);
        tail.fill(0.0);
        detrend_in_place(head, self.detrend);
        for (v, w) in head.iter_mut().zip(&self.window) {
            *v *= w;
        }
        let out = if into_y {
            &mut self.spec_y
        } else {
            &mut self.spec_x
        };
        // Lengths all come from the plan itself, so this cannot fail; ignore defensively
        // rather than panic (the output would then be stale, which cannot happen).
        let _ = self
            .fft
            .process_with_scratch(&mut self.seg, out, &mut self.scratch);
    }

    /// Doubles every bin except DC and (for even nfft) Nyquist, as scipy does.
    fn double_one_sided<T: std::ops::MulAssign<f64>>(&self, v: &mut [T]) {
        let end = if self.nfft % 2 == 0 {
            v.len().saturating_sub(1)
        } else {
            v.len()
        };
        for a in v.iter_mut().take(end).skip(1) {
            *a *= 2.0;
        }
    }
}

/// Removes the trend from `seg` in place (scipy.signal.detrend semantics).
pub(crate) fn detrend_in_place(seg: &mut [f64], d: Detrend) {
    let n = seg.len();
    if n == 0 {
        return;
    }
    match d {
        Detrend::None => {}
        Detrend::Constant => {
            let m = seg.iter().sum::<f64>() / n as f64;
            seg.iter_mut().for_each(|v| *v -= m);
        }
        Detrend::Linear => {
            let m = seg.iter().sum::<f64>() / n as f64;
            if n < 2 {
                seg.iter_mut().for_each(|v| *v -= m);
                return;
            }
            // Least-squares line in centred time t_i = i - (n-1)/2: slope = sum t x / sum t^2.
            let c = (n as f64 - 1.0) / 2.0;
            let mut stx = 0.0;
            let mut stt = 0.0;
            for (i, v) in seg.iter().enumerate() {
                let t = i as f64 - c;
                stx += t * v;
                stt += t * t;
            }
            let slope = stx / stt;
            for (i, v) in seg.iter_mut().enumerate() {
                *v -= m + slope * (i as f64 - c);
            }
        }
    }
}
