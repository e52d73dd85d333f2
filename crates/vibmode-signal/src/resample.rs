//! The paper's ideal (rectangular DFT) anti-alias filter and resampling.
//!
//! # Methods
//! Let `N` be the record length, `fs_in` its rate, `fs_out_hz` the requested rate and
//! `r = fs_in / fs_out_hz`.
//!
//! - **Integer ratio** (`r` = D, an integer within 1e-9): the paper's method. With `filter`, the
//!   whole record is transformed (real FFT, any length), every bin with `|f_k| > cutoff_hz` is
//!   zeroed (`f_k = k fs_in / N`; a bin exactly at the cutoff is kept), the inverse FFT is taken
//!   and every D-th sample is kept, starting with the first: `ceil(N / D)` samples at exactly
//!   `fs_in / D`. Without `filter`, it is plain decimation `x[0], x[D], x[2D], ...` (aliasing shows,
//!   as in the paper's Fig. 3-4). When D divides N the decimation is done in the frequency domain
//!   (folding the spectrum onto `N / D` bins), which is mathematically identical and faster.
//! - **Non-integer ratio**: Fourier resampling to `num = round(N fs_out_hz / fs_in)` samples (ties to
//!   even, like Python's `round`), like
//!   `scipy.signal.resample(x, num)`: the ideal cutoff is applied, the spectrum is truncated (or
//!   zero-padded when upsampling) to `num` samples with scipy's handling of the Nyquist bin for
//!   even lengths (doubled when downsampling, halved when upsampling), inverse FFT, scaled by
//!   `num / N`. The output rate is `fs_in num / N` (reported by [`Resampler::fs_out_hz`]), which
//!   differs from the requested `fs_out_hz` by less than `0.5 / N` relative when `N fs_out_hz / fs_in` is not an integer.
//!   Without `filter`, samples are linearly interpolated at `t = m / fs_out_hz` (no anti-aliasing;
//!   `floor((N - 1) fs_out_hz / fs_in) + 1` samples).
//!
//! # Relation to `scipy.signal.resample`
//! With the default cutoff (the output Nyquist frequency) the Fourier path equals
//! `scipy.signal.resample(x, num)` to rounding (tested to 1e-9 relative on even/odd lengths, up
//! and down, rational ratios). The integer-ratio path with the ideal filter also equals
//! `scipy.signal.resample(x, N / D)` **when D divides N**, including the Nyquist bin: for an
//! even output length `num`, decimation folds the kept bins `+num/2` and `-num/2` of the filtered
//! spectrum onto one output bin, giving `2 Re X[num/2] / D`, which is exactly scipy's doubling of
//! that bin followed by the real inverse FFT (which ignores its imaginary part). When D does not
//! divide N the two differ (e.g. by 30 % of the peak for white noise, N = 999, D = 5): decimation
//! keeps `ceil(N / D)` samples on the exact grid `t = m D / fs_in`, while scipy returns
//! `round(N / D)` samples spaced `N / num` input samples apart, a slightly different rate; that
//! case is tested against a numpy implementation of the paper's steps instead.
//!
//! The default cutoff is the actual output Nyquist frequency `min(fs_in, fs_out) / 2`; a cutoff
//! above it is refused (it would alias on decimation and has no effect on the Fourier path).

use crate::error::{Result, SignalError};
use num_complex::Complex;
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use vibmode_core::limits::{SAMPLES_OUT_MAX, UPSAMPLE_RATIO_MAX};
use vibmode_core::{check_fs, Channel, Num, Recording, RecordingError, TimeAxis};
use vibmode_fft::{ComplexToReal, RealToComplex};

/// Parameters of [`resample`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ResampleParams {
    /// The rate to resample to, Hz (the one name of a target rate: `--fs-out` on the command
    /// line, `fs_out` in Python; the older key `to_hz` is still read). Default 200.0 (the paper:
    /// 20 kHz -> 200 Hz).
    #[serde(alias = "to_hz")]
    pub fs_out_hz: f64,
    /// Cutoff of the ideal low-pass, Hz (bins with |f| > cutoff are zeroed). Default `None` =
    /// the output Nyquist frequency. The paper uses 25 Hz with `fs_out_hz` = 200.
    pub cutoff_hz: Option<f64>,
    /// Apply the ideal anti-alias filter. Default true; false gives plain decimation (integer
    /// ratios) or linear interpolation (other ratios), which alias.
    pub filter: bool,
}

impl Default for ResampleParams {
    fn default() -> Self {
        ResampleParams {
            fs_out_hz: 200.0,
            cutoff_hz: None,
            filter: true,
        }
    }
}

/// Which algorithm a [`Resampler`] uses (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ResampleMethod {
    /// Integer ratio, no filter: keep every D-th sample.
    Decimate {
        /// The decimation factor D.
        factor: usize,
    },
    /// Integer ratio with the ideal DFT filter, then keep every D-th sample.
    FilterDecimate {
        /// The decimation factor D.
        factor: usize,
    },
    /// Non-integer ratio: ideal filter and Fourier resampling (as `scipy.signal.resample`).
    Fourier,
    /// Non-integer ratio, no filter: linear interpolation.
    Linear,
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Pick,
    Fold,
    Full,
    Fourier,
    Linear,
}

/// A planned resampler for records of a fixed length, reusing FFT plans and buffers across
/// calls (one per thread; e.g. for 7 channels x many records).
pub struct Resampler {
    n_in: usize,
    n_out: usize,
    fs_in: f64,
    fs_out: f64,
    cutoff_hz: Option<f64>,
    /// Highest kept bin index (filter) in the input spectrum.
    kc: usize,
    kind: Kind,
    factor: usize,
    fwd: Option<Arc<dyn RealToComplex<f64>>>,
    inv: Option<Arc<dyn ComplexToReal<f64>>>,
    buf_in: Vec<f64>,
    spec_in: Vec<Complex<f64>>,
    spec_out: Vec<Complex<f64>>,
    buf_out: Vec<f64>,
    scratch: Vec<Complex<f64>>,
}

impl std::fmt::Debug for Resampler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Resampler")
            .field("n_in", &self.n_in)
            .field("n_out", &self.n_out)
            .field("fs_in", &self.fs_in)
            .field("fs_out", &self.fs_out)
            .field("cutoff_hz", &self.cutoff_hz)
            .field("method", &self.method())
            .finish()
    }
}

fn invalid(name: &'static str, value: f64, fix: String) -> SignalError {
    SignalError::InvalidParam {
        name,
        value: vibmode_core::Num(value).to_string(),
        fix,
    }
}

fn fft_err(e: vibmode_fft::FftError) -> SignalError {
    SignalError::InvalidParam {
        name: "fft",
        value: e.to_string(),
        fix: "internal FFT error; please report this as a bug".into(),
    }
}

/// The output rate, Hz, of a [`Resampler`] planned for `n_in` samples at `fs_hz` with `p` (its
/// [`Resampler::fs_out_hz`]), without planning it: with a non-integer rate ratio it is
/// `n_out / duration`, which can fall a hair below `p.fs_out_hz`. It does not depend on
/// `p.cutoff_hz`. Meaningful only for inputs [`Resampler::new`] accepts.
pub fn planned_fs_out_hz(n_in: usize, fs_hz: f64, p: &ResampleParams) -> f64 {
    plan_kind(n_in, fs_hz, p).3
}

/// How a record of `n_in` samples at `fs_hz` is resampled to `p.fs_out_hz`: the method, the
/// decimation factor (integer ratios), the number of output samples and the output rate.
fn plan_kind(n_in: usize, fs_hz: f64, p: &ResampleParams) -> (Kind, usize, usize, f64) {
    let ratio = fs_hz / p.fs_out_hz;
    let d = ratio.round();
    let integer = d >= 1.0 && (ratio - d).abs() <= 1e-9 * ratio;
    if integer {
        let dd = d as usize;
        let n_out = n_in.div_ceil(dd);
        let kind = match (p.filter, n_in % dd == 0) {
            (false, _) => Kind::Pick,
            (true, true) => Kind::Fold,
            (true, false) => Kind::Full,
        };
        (kind, dd, n_out, fs_hz / d)
    } else if p.filter {
        let num = (n_in as f64 * p.fs_out_hz / fs_hz).round_ties_even();
        let fs_out = fs_hz * num / n_in as f64;
        let fs_out = if (fs_out - p.fs_out_hz).abs() <= 1e-9 * p.fs_out_hz {
            p.fs_out_hz
        } else {
            fs_out
        };
        (Kind::Fourier, 0, num as usize, fs_out)
    } else {
        let n_out = if n_in == 0 {
            0
        } else {
            ((n_in - 1) as f64 * p.fs_out_hz / fs_hz * (1.0 + 1e-12)).floor() as usize + 1
        };
        (Kind::Linear, 0, n_out, p.fs_out_hz)
    }
}

/// The cutoff (Hz) and the highest kept DFT bin of the ideal low-pass (every bin up to Nyquist
/// without a filter).
fn cutoff_bin(
    n_in: usize,
    fs_hz: f64,
    fs_out: f64,
    p: &ResampleParams,
) -> Result<(Option<f64>, usize)> {
    let nyq_out = 0.5 * fs_hz.min(fs_out);
    let mut cutoff = None;
    let mut kc = n_in / 2;
    if p.filter {
        let c = match p.cutoff_hz {
            Some(c) => {
                if !(c.is_finite() && c > 0.0) || c > nyq_out * (1.0 + 1e-9) {
                    return Err(invalid(
                        "cutoff_hz",
                        c,
                        format!(
                            "the cutoff must be > 0 and <= the output Nyquist frequency {nyq_out} Hz; use e.g. a cutoff of {} Hz",
                            nyq_out / 2.0
                        ),
                    ));
                }
                c
            }
            None => nyq_out,
        };
        let r = c * n_in as f64 / fs_hz;
        kc = ((r + 1e-9 * r.max(1.0)).floor() as usize).min(n_in / 2);
        cutoff = Some(c);
    }
    Ok((cutoff, kc))
}

/// The FFT plans and buffers of one resampler.
struct Ffts {
    fwd: Option<Arc<dyn RealToComplex<f64>>>,
    inv: Option<Arc<dyn ComplexToReal<f64>>>,
    buf_in: Vec<f64>,
    spec_in: Vec<Complex<f64>>,
    spec_out: Vec<Complex<f64>>,
    buf_out: Vec<f64>,
    scratch_len: usize,
}

impl Ffts {
    fn plan(kind: Kind, n_in: usize, n_out: usize) -> Ffts {
        // The plans are shared by every resampler of the process (vibmode_fft caches them).
        use vibmode_fft::{forward, inverse};
        let (fwd, inv) = match kind {
            Kind::Pick | Kind::Linear => (None, None),
            Kind::Fold => (Some(forward(n_in)), Some(inverse(n_out))),
            Kind::Full => (Some(forward(n_in)), Some(inverse(n_in))),
            Kind::Fourier => (Some(forward(n_in)), Some(inverse(n_out))),
        };
        let scratch_len = fwd
            .as_ref()
            .map_or(0, |f| f.get_scratch_len())
            .max(inv.as_ref().map_or(0, |f| f.get_scratch_len()));
        let (buf_in, spec_in) = match &fwd {
            Some(f) => (f.make_input_vec(), f.make_output_vec()),
            None => (Vec::new(), Vec::new()),
        };
        let (spec_out, buf_out) = match &inv {
            Some(f) => (f.make_input_vec(), f.make_output_vec()),
            None => (Vec::new(), Vec::new()),
        };
        Ffts {
            fwd,
            inv,
            buf_in,
            spec_in,
            spec_out,
            buf_out,
            scratch_len,
        }
    }
}

impl Resampler {
    /// Plans a resampler for records of `n_in` samples at `fs_hz`.
    ///
    /// Errors: `fs_hz` or `fs_out_hz` not positive and finite; `cutoff_hz` not positive or above the
    /// output Nyquist frequency `min(fs_in, fs_out) / 2`; fewer than 2 output samples.
    pub fn new(n_in: usize, fs_hz: f64, p: &ResampleParams) -> Result<Resampler> {
        check_fs(fs_hz, "input fs_hz")?;
        if !(p.fs_out_hz.is_finite() && p.fs_out_hz > 0.0) {
            return Err(invalid(
                "fs_out_hz",
                p.fs_out_hz,
                "the target rate must be a positive finite number of Hz, e.g. 200".into(),
            ));
        }
        check_fs(p.fs_out_hz, "target rate fs_out_hz")?;
        let ratio = p.fs_out_hz / fs_hz;
        if ratio > UPSAMPLE_RATIO_MAX {
            return Err(invalid(
                "fs_out_hz",
                p.fs_out_hz,
                format!(
                    "it is {} times the input rate {} Hz; vibmode upsamples at most {UPSAMPLE_RATIO_MAX} times: check the rates' units",
                    Num(ratio),
                    Num(fs_hz)
                ),
            ));
        }
        if (n_in as f64 * ratio) > SAMPLES_OUT_MAX as f64 {
            return Err(invalid(
                "fs_out_hz",
                p.fs_out_hz,
                format!(
                    "{n_in} samples would become {} samples, more than the {SAMPLES_OUT_MAX} vibmode makes at once; cut the recording into parts",
                    Num((n_in as f64 * ratio).round())
                ),
            ));
        }
        let (kind, factor, n_out, fs_out) = plan_kind(n_in, fs_hz, p);
        if n_out < 2 {
            return Err(SignalError::TooShort {
                what: format!("resampling from {fs_hz} Hz to {} Hz", p.fs_out_hz),
                n: n_in,
                fix: format!(
                    "that gives {n_out} output samples; need at least 2 (a record of at least {:.0} samples)",
                    (2.0 * fs_hz / p.fs_out_hz).ceil()
                ),
            });
        }
        let (cutoff, kc) = cutoff_bin(n_in, fs_hz, fs_out, p)?;
        let ffts = Ffts::plan(kind, n_in, n_out);
        Ok(Resampler {
            n_in,
            n_out,
            fs_in: fs_hz,
            fs_out,
            cutoff_hz: cutoff,
            kc,
            kind,
            factor,
            fwd: ffts.fwd,
            inv: ffts.inv,
            buf_in: ffts.buf_in,
            spec_in: ffts.spec_in,
            spec_out: ffts.spec_out,
            buf_out: ffts.buf_out,
            scratch: vec![Complex::new(0.0, 0.0); ffts.scratch_len],
        })
    }

    /// Input length this resampler was planned for, samples.
    pub fn n_in(&self) -> usize {
        self.n_in
    }

    /// Output length, samples.
    pub fn n_out(&self) -> usize {
        self.n_out
    }

    /// Input sampling rate, Hz.
    pub fn fs_in_hz(&self) -> f64 {
        self.fs_in
    }

    /// Actual output sampling rate, Hz (see the module documentation for non-integer ratios).
    pub fn fs_out_hz(&self) -> f64 {
        self.fs_out
    }

    /// The cutoff actually used, Hz (`None` without filter).
    pub fn cutoff_hz(&self) -> Option<f64> {
        self.cutoff_hz
    }

    /// The algorithm used.
    pub fn method(&self) -> ResampleMethod {
        match self.kind {
            Kind::Pick => ResampleMethod::Decimate {
                factor: self.factor,
            },
            Kind::Fold | Kind::Full => ResampleMethod::FilterDecimate {
                factor: self.factor,
            },
            Kind::Fourier => ResampleMethod::Fourier,
            Kind::Linear => ResampleMethod::Linear,
        }
    }

    /// Resamples `x` (length [`Resampler::n_in`]) into `out` (length [`Resampler::n_out`]).
    ///
    /// Errors: wrong slice lengths, non-finite input.
    pub fn process(&mut self, x: &[f64], out: &mut [f64]) -> Result<()> {
        self.check_lengths(x, out)?;
        finite_input(x)?;
        match self.kind {
            Kind::Pick => {
                for (o, v) in out.iter_mut().zip(x.iter().step_by(self.factor)) {
                    *o = *v;
                }
                Ok(())
            }
            Kind::Linear => {
                let step = self.fs_in / self.fs_out;
                for (m, o) in out.iter_mut().enumerate() {
                    let pos = m as f64 * step;
                    let k = (pos.floor() as usize).min(self.n_in - 2);
                    let w = pos - k as f64;
                    *o = x[k] + w * (x[k + 1] - x[k]);
                }
                Ok(())
            }
            Kind::Fold | Kind::Full | Kind::Fourier => self.process_fft(x, out),
        }
    }

    /// The buffers' lengths against the plan.
    fn check_lengths(&self, x: &[f64], out: &[f64]) -> Result<()> {
        if x.len() != self.n_in || out.len() != self.n_out {
            return Err(SignalError::InvalidParam {
                name: "buffer lengths",
                value: format!("{} in, {} out", x.len(), out.len()),
                fix: format!(
                    "this Resampler was planned for {} in, {} out; plan a new one with Resampler::new",
                    self.n_in, self.n_out
                ),
            });
        }
        Ok(())
    }

    fn process_fft(&mut self, x: &[f64], out: &mut [f64]) -> Result<()> {
        let Some(fwd) = self.fwd.clone() else {
            return Err(fft_err(vibmode_fft::FftError::InputBuffer(0, 0)));
        };
        self.buf_in.copy_from_slice(x);
        fwd.process_with_scratch(&mut self.buf_in, &mut self.spec_in, &mut self.scratch)
            .map_err(fft_err)?;
        self.resample_spectrum(None, out)
    }

    /// As [`Resampler::process`], with `x`'s spectrum taken before by [`ChannelSpectrum::of`]
    /// (for one channel resampled to several rates: the forward transform is the costly part).
    /// The output is [`Resampler::process`]'s bit for bit. A spectrum of another length than
    /// the resampler's input, or a resampler that takes no transform (plain decimation or
    /// interpolation), resamples `x` itself.
    ///
    /// Errors: as [`Resampler::process`].
    pub fn process_spectrum(
        &mut self,
        x: &[f64],
        spectrum: &ChannelSpectrum,
        out: &mut [f64],
    ) -> Result<()> {
        // The decimation reads the bins up to the cutoff's, the other transforms all of them.
        let enough = match self.kind {
            Kind::Fold => spectrum.bins.len() > self.kc,
            Kind::Full | Kind::Fourier => spectrum.bins.len() == self.spec_in.len(),
            Kind::Pick | Kind::Linear => false,
        };
        if !enough || spectrum.n != self.n_in {
            return self.process(x, out);
        }
        // `x` itself is not read (its spectrum is), and was checked finite by
        // `ChannelSpectrum::of`: only the lengths are checked here.
        self.check_lengths(x, out)?;
        self.resample_spectrum(Some(&spectrum.bins), out)
    }

    /// The low-pass, decimation or truncation and inverse transform of the input's spectrum:
    /// `given`, or the one held in `spec_in`.
    fn resample_spectrum(&mut self, given: Option<&[Complex<f64>]>, out: &mut [f64]) -> Result<()> {
        let Some(inv) = self.inv.clone() else {
            return Err(fft_err(vibmode_fft::FftError::InputBuffer(0, 0)));
        };
        let n = self.n_in;
        let zero = Complex::new(0.0, 0.0);
        let scale = 1.0 / n as f64;
        if !matches!(self.kind, Kind::Fold) {
            if let Some(g) = given {
                self.spec_in.copy_from_slice(g);
            }
            // Ideal low-pass: zero every bin above the cutoff bin.
            for v in self.spec_in.iter_mut().skip(self.kc + 1) {
                *v = zero;
            }
        }
        // The decimation reads the spectrum without changing it.
        let spec_in: &[Complex<f64>] = match given {
            Some(g) if matches!(self.kind, Kind::Fold) => g,
            _ => &self.spec_in,
        };
        match self.kind {
            Kind::Fold => {
                // y[m] = x_f[m D] = (1/N) sum_j (sum_l X[j + l num]) e^{2 pi i j m / num}, X the
                // spectrum with every bin above the cutoff bin `kc` zero: of the terms
                // `m = j, j + num, ...` only `m <= kc` (X[m]) and `m >= n - kc` (conj X[n - m])
                // are summed, in that order. Leaving the zero bins out of a sum started at +0
                // gives the same bits (x + 0 = x; a sum of them never is -0).
                let num = self.n_out;
                let half = num / 2;
                let low_last = self.kc.min(n / 2);
                let high_first = (n - low_last).max(n / 2 + 1);
                for (j, o) in self.spec_out.iter_mut().enumerate() {
                    let mut s = zero;
                    let mut m = j;
                    while m <= low_last {
                        s += spec_in[m];
                        m += num;
                    }
                    if m < high_first {
                        m += (high_first - m).div_ceil(num) * num;
                    }
                    while m < n {
                        s += spec_in[n - m].conj();
                        m += num;
                    }
                    *o = s;
                }
                self.spec_out[0].im = 0.0;
                if num % 2 == 0 {
                    self.spec_out[half].im = 0.0;
                }
                inv.process_with_scratch(&mut self.spec_out, &mut self.buf_out, &mut self.scratch)
                    .map_err(fft_err)?;
                for (o, v) in out.iter_mut().zip(&self.buf_out) {
                    *o = v * scale;
                }
            }
            Kind::Full => {
                self.spec_in[0].im = 0.0;
                if n % 2 == 0 {
                    self.spec_in[n / 2].im = 0.0;
                }
                inv.process_with_scratch(&mut self.spec_in, &mut self.buf_out, &mut self.scratch)
                    .map_err(fft_err)?;
                for (o, v) in out.iter_mut().zip(self.buf_out.iter().step_by(self.factor)) {
                    *o = v * scale;
                }
            }
            Kind::Fourier => {
                let num = self.n_out;
                let m = num.min(n);
                for v in self.spec_out.iter_mut() {
                    *v = zero;
                }
                let nyq = m / 2 + 1;
                self.spec_out[..nyq].copy_from_slice(&self.spec_in[..nyq]);
                if m % 2 == 0 {
                    if num < n {
                        self.spec_out[m / 2] *= 2.0;
                    } else if n < num {
                        self.spec_out[m / 2] *= 0.5;
                    }
                }
                self.spec_out[0].im = 0.0;
                if num % 2 == 0 {
                    self.spec_out[num / 2].im = 0.0;
                }
                inv.process_with_scratch(&mut self.spec_out, &mut self.buf_out, &mut self.scratch)
                    .map_err(fft_err)?;
                for (o, v) in out.iter_mut().zip(&self.buf_out) {
                    *o = v * scale;
                }
            }
            Kind::Pick | Kind::Linear => {}
        }
        Ok(())
    }
}

/// Every sample of `x` finite, else the first that is not (as a channel named "input": callers
/// with a name put it in).
fn finite_input(x: &[f64]) -> Result<()> {
    match x.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(RecordingError::NonFinite {
            channel: "input".into(),
            index: i,
            value: x[i],
        }
        .into()),
        None => Ok(()),
    }
}

/// The real DFT of one channel (its `n / 2 + 1` bins, unscaled, or the first of them), taken
/// once so that the channel can be resampled to several rates without transforming it again
/// ([`Resampler::process_spectrum`], [`resample_recording`]); the transform a [`Resampler`]
/// takes, bit for bit. Whole, it holds as many values as the channel (complex, half as many).
#[derive(Clone, Debug)]
pub struct ChannelSpectrum {
    n: usize,
    bins: Vec<Complex<f64>>,
}

impl ChannelSpectrum {
    /// The spectrum of `x` (at least 2 samples).
    ///
    /// Errors: fewer than 2 samples, a non-finite sample.
    pub fn of(x: &[f64]) -> Result<ChannelSpectrum> {
        // One channel in, one spectrum out (an empty list only from a bug).
        Self::of_each([x], usize::MAX)?
            .pop()
            .ok_or_else(|| fft_err(vibmode_fft::FftError::InputBuffer(0, 0)))
    }

    /// [`ChannelSpectrum::of`] of each channel, keeping its first `bins` bins (all of them
    /// with `usize::MAX`; a decimation to `fs_out` with the cutoff at most `fs_out / 2` reads
    /// the bins up to `n fs_out / (2 fs)`, [`Resampler::process_spectrum`] resamples a channel
    /// itself where its spectrum holds too few); the transform's buffers shared. The bins kept
    /// are [`ChannelSpectrum::of`]'s bit for bit.
    ///
    /// Errors: as [`ChannelSpectrum::of`], for the first channel that has one.
    pub fn of_each<'a>(
        channels: impl IntoIterator<Item = &'a [f64]>,
        bins: usize,
    ) -> Result<Vec<ChannelSpectrum>> {
        type Planned = (
            usize,
            Arc<dyn RealToComplex<f64>>,
            Vec<f64>,
            Vec<Complex<f64>>,
            Vec<Complex<f64>>,
        );
        let mut out = Vec::new();
        let mut planned: Option<Planned> = None;
        for x in channels {
            if x.len() < 2 {
                return Err(SignalError::TooShort {
                    what: "a channel's spectrum".into(),
                    n: x.len(),
                    fix: "give at least 2 samples".into(),
                });
            }
            finite_input(x)?;
            let (_, fwd, buf, spec, scratch) = match &mut planned {
                Some(p) if p.0 == x.len() => p,
                _ => {
                    let fwd = vibmode_fft::forward(x.len());
                    let buffers = (
                        fwd.make_input_vec(),
                        fwd.make_output_vec(),
                        fwd.make_scratch_vec(),
                    );
                    planned.insert((x.len(), fwd, buffers.0, buffers.1, buffers.2))
                }
            };
            buf.copy_from_slice(x);
            fwd.process_with_scratch(buf, spec, scratch)
                .map_err(fft_err)?;
            out.push(ChannelSpectrum {
                n: x.len(),
                bins: spec[..bins.min(spec.len())].to_vec(),
            });
        }
        Ok(out)
    }

    /// Number of samples of the channel it is the spectrum of.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Always false (a spectrum is of 2 samples or more).
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }
}

/// [`ResampleRecording::resample`] of `rec`, each channel's forward transform taken from
/// `spectra[i]` (of `rec.channels[i]`, [`ChannelSpectrum::of`]) where given: the same
/// recording bit for bit. `spectra` of another number of channels than `rec` is not used.
///
/// Errors: as [`ResampleRecording::resample`].
pub fn resample_recording(
    rec: &Recording,
    p: &ResampleParams,
    spectra: Option<&[ChannelSpectrum]>,
) -> Result<Recording> {
    let spectra = spectra.filter(|s| s.len() == rec.channels.len());
    let mut r = Resampler::new(rec.len(), rec.fs_hz, p)?;
    let total = r.n_out() as u64 * rec.channels.len() as u64;
    if total > SAMPLES_OUT_MAX {
        return Err(invalid(
            "fs_out_hz",
            p.fs_out_hz,
            format!(
                "{} channels of {} samples each are more than the {SAMPLES_OUT_MAX} samples vibmode makes at once; cut the recording into parts",
                rec.channels.len(),
                r.n_out()
            ),
        ));
    }
    let mut channels = Vec::with_capacity(rec.channels.len());
    for (i, c) in rec.channels.iter().enumerate() {
        let mut out = vec![0.0; r.n_out()];
        match spectra {
            Some(s) => r.process_spectrum(&c.samples, &s[i], &mut out),
            None => r.process(&c.samples, &mut out),
        }
        .map_err(|e| match e {
            SignalError::Recording(RecordingError::NonFinite { index, value, .. }) => {
                RecordingError::NonFinite {
                    channel: c.name.clone(),
                    index,
                    value,
                }
                .into()
            }
            other => other,
        })?;
        channels.push(Channel {
            samples: out,
            ..Channel::new(c.name.clone(), c.unit.clone(), Vec::new()).with_placement(c.placement)
        });
    }
    Ok(Recording {
        fs_hz: r.fs_out_hz(),
        channels,
        time_axis: rec.time_axis.as_ref().map(|t| TimeAxis {
            column: t.column.clone(),
            fs_hz: r.fs_out_hz(),
            jitter_rel: 0.0,
            start_s: t.start_s,
            origin_unix_s: t.origin_unix_s,
        }),
    })
}

/// Resamples one signal `x` sampled at `fs_hz` (see the module documentation).
///
/// ```
/// use vibmode_signal::{resample, ResampleParams};
/// // 1 Hz sine at 1000 Hz, to 100 Hz: the tone is far below the cutoff and passes unchanged.
/// let x: Vec<f64> = (0..1000).map(|i| (2.0 * std::f64::consts::PI * i as f64 / 1000.0).sin()).collect();
/// let y = resample(&x, 1000.0, &ResampleParams { fs_out_hz: 100.0, ..Default::default() }).unwrap();
/// assert_eq!(y.len(), 100);
/// assert!((y[25] - 1.0).abs() < 1e-12);
/// ```
pub fn resample(x: &[f64], fs_hz: f64, p: &ResampleParams) -> Result<Vec<f64>> {
    let mut r = Resampler::new(x.len(), fs_hz, p)?;
    let mut out = vec![0.0; r.n_out()];
    r.process(x, &mut out)?;
    Ok(out)
}

/// Resampling of a whole [`Recording`] (an extension trait: the recording type lives in
/// `vibmode-core`, which does no numerics).
pub trait ResampleRecording {
    /// Resamples every channel (one planned [`Resampler`] shared by all channels). The new
    /// `fs_hz` is [`Resampler::fs_out_hz`]; a time axis keeps its start time and column name,
    /// with `fs_hz` the new rate and `jitter_rel` 0.
    fn resample(&self, p: &ResampleParams) -> Result<Recording>;
}

impl ResampleRecording for Recording {
    /// Resamples every channel (one planned [`Resampler`] shared by all channels). The new
    /// `fs_hz` is [`Resampler::fs_out_hz`]; a time axis keeps its start time and column name,
    /// with `fs_hz` the new rate and `jitter_rel` 0.
    fn resample(&self, p: &ResampleParams) -> Result<Recording> {
        resample_recording(self, p, None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The decimation's fold as it was first written (every bin zeroed above the cutoff, then
    /// every term `j + l num` summed, in order), on the resampler's own plans and buffers.
    fn fold_every_term(r: &mut Resampler, x: &[f64]) -> Vec<f64> {
        let (fwd, inv) = (r.fwd.clone().unwrap(), r.inv.clone().unwrap());
        let n = r.n_in;
        r.buf_in.copy_from_slice(x);
        fwd.process_with_scratch(&mut r.buf_in, &mut r.spec_in, &mut r.scratch)
            .unwrap();
        let zero = Complex::new(0.0, 0.0);
        for v in r.spec_in.iter_mut().skip(r.kc + 1) {
            *v = zero;
        }
        let num = r.n_out;
        for (j, o) in r.spec_out.iter_mut().enumerate() {
            let mut s = zero;
            let mut m = j;
            while m < n {
                s += if m <= n / 2 {
                    r.spec_in[m]
                } else {
                    r.spec_in[n - m].conj()
                };
                m += num;
            }
            *o = s;
        }
        r.spec_out[0].im = 0.0;
        if num % 2 == 0 {
            r.spec_out[num / 2].im = 0.0;
        }
        inv.process_with_scratch(&mut r.spec_out, &mut r.buf_out, &mut r.scratch)
            .unwrap();
        r.buf_out.iter().map(|v| v * (1.0 / n as f64)).collect()
    }

    /// The fold that sums only the bins the cutoff keeps gives every output sample bit for bit
    /// as summing every term does: seeded signals of even and odd lengths, factors 2-400,
    /// cutoffs from the lowest bins to the output's Nyquist frequency.
    #[test]
    fn the_fold_over_the_kept_bins_is_the_fold_over_every_bin() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut next = move || rng.gen::<f64>();
        let mut folds = 0;
        for &(n_out, factor) in &[
            (2, 2),
            (3, 2),
            (5, 3),
            (8, 4),
            (51, 7),
            (64, 400),
            (512, 400),
        ] {
            for &share in &[0.02, 0.3, 0.7, 1.0] {
                let n = n_out * factor;
                let fs_hz = 1000.0;
                let fs_out_hz = fs_hz / factor as f64;
                let p = ResampleParams {
                    fs_out_hz,
                    cutoff_hz: Some(share * fs_out_hz / 2.0),
                    filter: true,
                };
                let mut r = Resampler::new(n, fs_hz, &p).unwrap();
                if !matches!(r.kind, Kind::Fold) {
                    continue;
                }
                folds += 1;
                let x: Vec<f64> = (0..n).map(|_| next() - 0.5).collect();
                let mut got = vec![0.0; r.n_out()];
                r.process(&x, &mut got).unwrap();
                let want = fold_every_term(&mut r, &x);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    bits(&got),
                    bits(&want),
                    "{n} samples by {factor}, cutoff share {share}"
                );
            }
        }
        assert!(folds >= 20, "{folds}");
    }

    /// A resampler given the channel's spectrum (whole, or its first bins where it decimates)
    /// gives `process`'s samples bit for bit, for every method, and resamples the channel itself
    /// where the spectrum holds too few bins or is of another length; `resample_recording` with
    /// the spectra is `resample`'s recording.
    #[test]
    fn resampling_from_a_spectrum_is_resampling_the_channel() {
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        let mut next = move || rng.gen::<f64>() - 0.5;
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let mut kinds = Vec::new();
        for &(n, fs_out_hz, cutoff) in &[
            (2000, 250.0, None),       // fold by 4
            (2001, 250.0, Some(60.0)), // full (4 does not divide 2001)
            (2000, 300.0, None),       // Fourier
            (1500, 2500.0, None),      // Fourier, upsampling
        ] {
            let p = ResampleParams {
                fs_out_hz,
                cutoff_hz: cutoff,
                filter: true,
            };
            let chans: Vec<Vec<f64>> = (0..3).map(|_| (0..n).map(|_| next()).collect()).collect();
            let mut r = Resampler::new(n, 1000.0, &p).unwrap();
            kinds.push(format!("{:?}", r.kind));
            let whole = ChannelSpectrum::of_each(chans.iter().map(|c| &c[..]), usize::MAX).unwrap();
            for (x, s) in chans.iter().zip(&whole) {
                let one = ChannelSpectrum::of(x).unwrap();
                assert_eq!(one.bins, s.bins);
                let mut want = vec![0.0; r.n_out()];
                r.process(x, &mut want).unwrap();
                let mut got = vec![0.0; r.n_out()];
                r.process_spectrum(x, s, &mut got).unwrap();
                assert_eq!(bits(&got), bits(&want), "{n} to {fs_out_hz} Hz");
                // The first bins only: enough for a decimation, else the channel is used.
                for keep in [r.kc + 1, r.kc, 3] {
                    let part = ChannelSpectrum::of_each([&x[..]], keep).unwrap().remove(0);
                    assert_eq!(part.bins[..], s.bins[..keep]);
                    let mut got = vec![0.0; r.n_out()];
                    r.process_spectrum(x, &part, &mut got).unwrap();
                    assert_eq!(
                        bits(&got),
                        bits(&want),
                        "{n} to {fs_out_hz} Hz, {keep} bins"
                    );
                }
                // A spectrum of another length is not used.
                let other = ChannelSpectrum::of(&x[..n - 1]).unwrap();
                let mut got = vec![0.0; r.n_out()];
                r.process_spectrum(x, &other, &mut got).unwrap();
                assert_eq!(bits(&got), bits(&want));
            }
            let rec = Recording::new(
                1000.0,
                chans
                    .iter()
                    .enumerate()
                    .map(|(i, c)| Channel::new(format!("c{i}"), "m/s^2", c.clone()))
                    .collect(),
            )
            .unwrap();
            let want = rec.resample(&p).unwrap();
            let got = resample_recording(&rec, &p, Some(&whole)).unwrap();
            for (a, b) in want.channels.iter().zip(&got.channels) {
                assert_eq!(bits(&a.samples), bits(&b.samples));
            }
            assert_eq!(want.fs_hz.to_bits(), got.fs_hz.to_bits());
        }
        assert_eq!(kinds, ["Fold", "Full", "Fourier", "Fourier"]);
        // A bad channel is refused as by `of`.
        let e = ChannelSpectrum::of_each([&[1.0, f64::NAN, 2.0][..]], 4).unwrap_err();
        assert!(e.to_string().contains("NaN"), "{e}");
    }

    /// The rate without planning is the planned resampler's, bit for bit, for integer and
    /// non-integer ratios, with and without the filter and a cutoff.
    #[test]
    fn planned_fs_out_hz_is_the_resamplers_rate() {
        for &(n_in, fs_hz, fs_out_hz) in &[
            (204_800, 20_000.0, 50.0),
            (204_800, 20_000.0, 500.0),
            (4_251, 425.08, 50.0),
            (1_000, 100.0, 33.3),
            (999, 200.0, 200.0),
            (5_000, 50.0, 120.0),
        ] {
            for filter in [true, false] {
                for cutoff_hz in [None, Some(0.3 * f64::min(fs_out_hz, fs_hz))] {
                    let p = ResampleParams {
                        fs_out_hz,
                        cutoff_hz: if filter { cutoff_hz } else { None },
                        filter,
                    };
                    let planned = Resampler::new(n_in, fs_hz, &p).unwrap().fs_out_hz();
                    assert_eq!(
                        planned_fs_out_hz(n_in, fs_hz, &p).to_bits(),
                        planned.to_bits(),
                        "{n_in} samples at {fs_hz} Hz to {fs_out_hz} Hz, filter {filter}"
                    );
                }
            }
        }
    }
}
