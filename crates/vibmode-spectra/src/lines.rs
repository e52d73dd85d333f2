//! Periodic lines (engine and gear orders) told from randomly excited modes by the statistics of
//! their narrow-band signal, not by a fitted damping.
//!
//! A sine `A sin(w t + p)` has kurtosis `E[x^4] / E[x^2]^2 = 1.5`; a Gaussian process (a mode
//! driven by a random road) has 3; a sine plus Gaussian power in the same band lies between:
//! with sine power `S` and Gaussian power `G`, `(1.5 S^2 + 6 S G + 3 G^2) / (S + G)^2`. Amplitude
//! modulation of a few percent and a slowly wandering frequency keep a line near 1.5 as long as
//! it stays inside the band.

use crate::error::SpectraError;
use crate::harmonic::{f_test_peaks, HarmonicF};
use crate::welch::{check_fs, check_samples, median_in_place};
use crate::{Spectrogram, WelchParams, WelchPlan};
use serde::{Deserialize, Serialize};
use vibmode_core::LineParams;

/// A prominent spectral peak and the kurtosis of the signal in a narrow band around it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LineCandidate {
    /// Peak frequency (parabolic interpolation of the log periodogram), Hz.
    pub frequency_hz: f64,
    /// Kurtosis of the signal band-passed to `frequency_hz +- half_width_hz` (1.5 sine,
    /// 3 Gaussian).
    pub kurtosis: f64,
    /// Height of the peak above the median periodogram within +-1 Hz, dB.
    pub prominence_db: f64,
    /// True when `kurtosis < max_kurtosis` ([`line_candidates`]) or the F-test's p-value is
    /// below `f_test_alpha` ([`f_test_line_candidates`]): a periodic line.
    pub periodic: bool,
    /// `P(F > F_obs)` of Thomson's harmonic F-test at `frequency_hz` without a line (F(2, 2K -
    /// 2)); NaN for a candidate found by the periodogram and kurtosis alone.
    #[serde(default = "nan")]
    pub p_value: f64,
}

fn nan() -> f64 {
    f64::NAN
}

/// Kurtosis `E[y^4] / E[y^2]^2` of `x` (sampled at `fs_hz`, Hz) ideally band-passed to
/// `center_hz +- half_width_hz` (DFT bins outside the band zeroed; the mean is removed first).
///
/// Returns `Ok(f64::NAN)` when the band holds no power (less than 1e-20 of the variance of
/// `x`, for example no bin inside it).
/// Errors: fs_hz not positive/finite, empty `x`, NaN/Inf sample.
pub fn narrowband_kurtosis(
    x: &[f64],
    fs_hz: f64,
    center_hz: f64,
    half_width_hz: f64,
) -> Result<f64, SpectraError> {
    let (m2, m4) = narrowband_moments(x, fs_hz, center_hz, half_width_hz)?;
    Ok(if m2 > 0.0 { m4 / (m2 * m2) } else { f64::NAN })
}

/// The second and fourth moments `(E[y^2], E[y^4])` of `x` ideally band-passed to
/// `center_hz +- half_width_hz` (as [`narrowband_kurtosis`]; `(0, 0)` when the band holds less
/// than 1e-20 of the variance). Moments of several records can be pooled (averaged, weighted by
/// their lengths) before forming the kurtosis: a randomly excited mode whose amplitude differs
/// from record to record then shows a Gaussian-like kurtosis even when each record is too short
/// for it.
/// Errors: fs_hz not positive/finite, empty `x`, NaN/Inf sample.
pub fn narrowband_moments(
    x: &[f64],
    fs_hz: f64,
    center_hz: f64,
    half_width_hz: f64,
) -> Result<(f64, f64), SpectraError> {
    check_fs(fs_hz)?;
    check_samples(x, "x")?;
    let mut planner = vibmode_fft::Planner::new();
    Ok(band_moments(
        &mut planner,
        x,
        fs_hz,
        center_hz,
        half_width_hz,
    ))
}

fn band_kurtosis(
    planner: &mut vibmode_fft::Planner,
    x: &[f64],
    fs_hz: f64,
    center_hz: f64,
    half_width_hz: f64,
) -> f64 {
    let (m2, m4) = band_moments(planner, x, fs_hz, center_hz, half_width_hz);
    if m2 > 0.0 {
        m4 / (m2 * m2)
    } else {
        f64::NAN
    }
}

fn band_moments(
    planner: &mut vibmode_fft::Planner,
    x: &[f64],
    fs_hz: f64,
    center_hz: f64,
    half_width_hz: f64,
) -> (f64, f64) {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let mut buf: Vec<f64> = x.iter().map(|v| v - mean).collect();
    let var = buf.iter().map(|v| v * v).sum::<f64>() / n as f64;
    let fwd = planner.forward(n);
    let inv = planner.inverse(n);
    let mut spec = fwd.make_output_vec();
    if fwd.process(&mut buf, &mut spec).is_err() {
        return (0.0, 0.0);
    }
    let df = fs_hz / n as f64;
    let last = spec.len() - 1;
    for (k, c) in spec.iter_mut().enumerate() {
        let f = k as f64 * df;
        if (f - center_hz).abs() > half_width_hz || k == 0 {
            *c = num_complex::Complex64::new(0.0, 0.0);
        }
        // The inverse real FFT needs a real Nyquist bin (even n).
        if k == last && n % 2 == 0 {
            c.im = 0.0;
        }
    }
    let mut y = inv.make_output_vec();
    if inv.process(&mut spec, &mut y).is_err() {
        return (0.0, 0.0);
    }
    // realfft's inverse is unnormalised: divide by n.
    let k = 1.0 / n as f64;
    let m2 = y.iter().map(|v| (v * k).powi(2)).sum::<f64>() / n as f64;
    let m4 = y.iter().map(|v| (v * k).powi(4)).sum::<f64>() / n as f64;
    // Below ~1e-20 of the signal's variance the band holds only rounding residue.
    if m2 > 1e-20 * var && m2 > 0.0 {
        (m2, m4)
    } else {
        (0.0, 0.0)
    }
}

/// Local maxima of `pw` (above their two neighbours on each side) in bins `k_lo..=k_hi`
/// standing at least `min_db` above the median of the bins within `reach`: `(bin, dB above the
/// median)`, by increasing bin.
fn prominent_peaks(
    pw: &[f64],
    k_lo: usize,
    k_hi: usize,
    reach: usize,
    min_db: f64,
) -> Vec<(usize, f64)> {
    let mut peaks = Vec::new();
    for k in k_lo.max(2)..=k_hi.min(pw.len().saturating_sub(3)) {
        if !(pw[k - 2..=k + 2].iter().all(|&v| v <= pw[k])) {
            continue;
        }
        let lo = k.saturating_sub(reach);
        let hi = (k + reach).min(pw.len() - 1);
        let mut near: Vec<f64> = pw[lo..=hi].to_vec();
        let level = vibmode_core::stats::median_high_in_place(&mut near);
        let prominence_db = 10.0 * (pw[k] / level).log10();
        if prominence_db >= min_db {
            peaks.push((k, prominence_db));
        }
    }
    peaks
}

/// The fractional bin of the peak at bin `k` (`0 < k < len - 1`): the vertex of the parabola
/// through the log powers of bins `k - 1, k, k + 1`, within half a bin of `k`.
fn peak_bin(pw: &[f64], k: usize) -> f64 {
    let (a, b, c) = (pw[k - 1].ln(), pw[k].ln(), pw[k + 1].ln());
    let den = a - 2.0 * b + c;
    let delta = if den.abs() > 0.0 {
        0.5 * (a - c) / den
    } else {
        0.0
    };
    k as f64 + delta.clamp(-0.5, 0.5)
}

/// Every prominent peak of the periodogram of `x` (sampled at `fs_hz`, Hz) between
/// `2 half_width_hz` and `fs_hz / 2 - half_width_hz`, with its narrow-band kurtosis.
///
/// The periodogram is Hann-windowed and zero-padded 4x; a peak is a local maximum over +-2
/// padded bins rising `min_prominence_db` above the median within +-1 Hz; peaks closer than
/// `half_width_hz` to a higher one are dropped. Sorted by frequency.
/// Errors: fs_hz not positive/finite, empty `x`, NaN/Inf sample.
pub fn line_candidates(
    x: &[f64],
    fs_hz: f64,
    p: &LineParams,
) -> Result<Vec<LineCandidate>, SpectraError> {
    check_fs(fs_hz)?;
    check_samples(x, "x")?;
    let n = x.len();
    if n < 8 {
        return Ok(Vec::new());
    }
    let mut planner = vibmode_fft::Planner::new();
    let nfft = 4 * n;
    let mean = x.iter().sum::<f64>() / n as f64;
    let mut buf = vec![0.0; nfft];
    for (i, v) in x.iter().enumerate() {
        let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos();
        buf[i] = (v - mean) * w;
    }
    let fwd = planner.forward(nfft);
    let mut spec = fwd.make_output_vec();
    if fwd.process(&mut buf, &mut spec).is_err() {
        return Ok(Vec::new());
    }
    let pw: Vec<f64> = spec.iter().map(|c| c.norm_sqr().max(1e-300)).collect();
    let df = fs_hz / nfft as f64;
    let k_lo = ((2.0 * p.half_width_hz / df).ceil() as usize).max(2);
    let k_hi = ((fs_hz / 2.0 - p.half_width_hz) / df).floor() as usize;
    let k_hi = k_hi.min(pw.len().saturating_sub(3));
    let reach = ((1.0 / df).round() as usize).max(3);
    let mut peaks = prominent_peaks(&pw, k_lo, k_hi, reach, p.min_prominence_db);
    // Strongest first; drop peaks within half_width_hz of a stronger one.
    peaks.sort_by(|a, b| pw[b.0].total_cmp(&pw[a.0]));
    let mut kept: Vec<(usize, f64)> = Vec::new();
    for (k, prom) in peaks {
        if kept
            .iter()
            .all(|&(j, _)| (j as f64 - k as f64).abs() * df > p.half_width_hz)
        {
            kept.push((k, prom));
        }
    }
    let mut out: Vec<LineCandidate> = kept
        .into_iter()
        .map(|(k, prominence_db)| {
            let frequency_hz = peak_bin(&pw, k) * df;
            let kurtosis = band_kurtosis(&mut planner, x, fs_hz, frequency_hz, p.half_width_hz);
            LineCandidate {
                frequency_hz,
                kurtosis,
                prominence_db,
                periodic: kurtosis < p.max_kurtosis,
                p_value: f64::NAN,
            }
        })
        .collect();
    out.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    Ok(out)
}

/// The lines of `x` (sampled at `fs_hz`, Hz) from its harmonic F-test `h`
/// ([`HarmonicPlan::f_test`](crate::HarmonicPlan::f_test) with `p.f_test_nw`,
/// `p.f_test_tapers`): every local maximum of F over `+- W` with
/// `P(F > F_obs) < p.f_test_alpha`, between `max(2 W, p.min_frequency_hz)` and `hi_hz - W`,
/// each with the narrow-band kurtosis of its band (`p.half_width_hz`, for information) and as
/// prominence the line's power over the residual of the tapers' fit, `10 log10(F / (K - 1))`
/// dB. All are `periodic`. Sorted by frequency.
pub fn f_test_line_candidates(
    h: &HarmonicF,
    x: &[f64],
    fs_hz: f64,
    hi_hz: f64,
    p: &LineParams,
) -> Vec<LineCandidate> {
    let w = h.half_bandwidth_hz;
    let mut planner = vibmode_fft::Planner::new();
    let dof_num = h.dof / 2.0; // K - 1
    let df = h.freq_hz.get(1).copied().unwrap_or(f64::NAN);
    f_test_peaks(
        h,
        p.f_test_alpha,
        (2.0 * w).max(p.min_frequency_hz),
        hi_hz - w,
    )
    .into_iter()
    .map(|(f, pv, _)| {
        let j = (f / df).round() as usize;
        let fstat = h.f_stat.get(j).copied().unwrap_or(f64::NAN);
        LineCandidate {
            frequency_hz: f,
            kurtosis: band_kurtosis(&mut planner, x, fs_hz, f, p.half_width_hz),
            prominence_db: 10.0 * (fstat / dof_num).log10(),
            periodic: true,
            p_value: pv,
        }
    })
    .collect()
}

/// A ridge of the short-time spectra: a prominent peak followed from slice to slice.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ridge {
    /// Centre of each slice the ridge spans, s from the first sample (gaps filled).
    pub time_s: Vec<f64>,
    /// Ridge frequency in each of those slices, Hz (peaks interpolated parabolically in the log
    /// spectrum, gaps filled linearly, then a running median of three).
    pub freq_hz: Vec<f64>,
    /// Slices in which a peak was found (the rest of the span are filled gaps).
    pub n_found: usize,
}

impl Ridge {
    /// Highest minus lowest frequency of the ridge, Hz.
    pub fn range_hz(&self) -> f64 {
        let (lo, hi) = self.span_hz();
        if hi >= lo {
            hi - lo
        } else {
            0.0
        }
    }

    /// Lowest and highest frequency of the ridge, Hz.
    pub fn span_hz(&self) -> (f64, f64) {
        let lo = self.freq_hz.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = self
            .freq_hz
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    }

    /// Median absolute second difference of the ridge frequency from slice to slice, Hz: near
    /// 0 for a line whose frequency changes smoothly (a chirp has exactly 0), about the peak's
    /// jitter for a ridge that follows the random peak of a mode.
    pub fn roughness_hz(&self) -> f64 {
        let mut d2: Vec<f64> = self
            .freq_hz
            .windows(3)
            .map(|w| (w[0] - 2.0 * w[1] + w[2]).abs())
            .collect();
        if d2.is_empty() {
            return 0.0;
        }
        median_in_place(&mut d2)
    }

    /// Ridge frequency at time `t_s` (linear between slice centres, held before the first and
    /// after the last), Hz; `None` for an empty ridge.
    pub fn freq_at(&self, t_s: f64) -> Option<f64> {
        let (first, last) = (self.time_s.first()?, self.time_s.last()?);
        if t_s <= *first {
            return self.freq_hz.first().copied();
        }
        if t_s >= *last {
            return self.freq_hz.last().copied();
        }
        let k = self.time_s.partition_point(|&t| t <= t_s).max(1);
        let (t0, t1) = (self.time_s[k - 1], self.time_s[k]);
        let (f0, f1) = (self.freq_hz[k - 1], self.freq_hz[k]);
        let a = if t1 > t0 { (t_s - t0) / (t1 - t0) } else { 0.0 };
        Some(f0 + a * (f1 - f0))
    }
}

/// A ridge that may be a swept line, with the kurtosis of the signal demodulated along it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweptCandidate {
    /// The ridge.
    pub ridge: Ridge,
    /// Kurtosis of the signal demodulated along the ridge and band-limited to
    /// `+- half_width_hz` (see [`tracked_kurtosis`]; 1.5 sine, 3 Gaussian).
    pub kurtosis: f64,
    /// The same kurtosis with the demodulation held at the ridge's median frequency: a line
    /// that really sweeps leaves a fixed band most of the time (high), a ridge that follows
    /// the random peak of a mode gains little by being followed.
    pub fixed_kurtosis: f64,
    /// True when `kurtosis < max_kurtosis`, `fixed_kurtosis - kurtosis` is at least
    /// [`SWEEP_KURTOSIS_GAIN_MIN`] and the ridge is smooth (its [`Ridge::roughness_hz`] at most
    /// [`SWEEP_ROUGHNESS_MAX_SHARE`] of its range).
    pub periodic: bool,
}

/// A swept line's kurtosis along its ridge must be this much below the kurtosis at the ridge's
/// median frequency. Measured on the realistic demo (5 seeds): the braking and acceleration
/// sweeps gained 1 or more; ridges on the 9 Hz bending and the 1.3 Hz body modes, whose peaks
/// jitter within their bandwidth, gained less than 0.3 (docs/analysis.md).
pub const SWEEP_KURTOSIS_GAIN_MIN: f64 = 0.5;

/// A swept line's ridge changes smoothly: its roughness (median absolute second difference from
/// slice to slice) is at most this share of its range. A chirp has 0; the demo's braking and
/// acceleration sweeps had 0.008-0.02; ridges on the 1.3 Hz body modes and the 9-10 Hz bending
/// and wheel-hop modes, whose peaks jitter within their bandwidth, 0.035-0.16.
pub const SWEEP_ROUGHNESS_MAX_SHARE: f64 = 0.03;

/// A ridge may skip this many slices (a line crossing another peak, a fade of the modulation).
pub const RIDGE_MAX_GAP: usize = 2;
/// A ridge must be found in at least this share of a record's slices.
pub const RIDGE_MIN_SLICE_SHARE: f64 = 0.5;

/// Ridges of the short-time spectra `spec`: in every slice the peaks rising `stft_min_prominence_db`
/// above the slice's median within +-max(1 Hz, 4 fs/nperseg), linked from slice to slice when the
/// frequency changes by at most `sweep_rate_max_hz_per_s` times the time step plus a quarter of
/// the slice resolution `fs/nperseg` (the nearest pairs first; gaps of up to [`RIDGE_MAX_GAP`]
/// slices). Ridges found in fewer than [`RIDGE_MIN_SLICE_SHARE`] of the slices are dropped.
/// Only peaks between `2 half_width_hz` and `fs/2 - half_width_hz` are followed. Sorted by mean
/// frequency.
pub fn ridges(spec: &Spectrogram, p: &LineParams) -> Vec<Ridge> {
    let n_slices = spec.psd.len();
    if n_slices == 0 || spec.freq_hz.len() < 8 || spec.nfft == 0 {
        return Vec::new();
    }
    let df = spec.freq_hz[1] - spec.freq_hz[0];
    let fs_hz = df * spec.nfft as f64;
    let resolution_hz = fs_hz / spec.nperseg.max(1) as f64;
    let reach = ((1.0f64.max(4.0 * resolution_hz) / df).round() as usize).max(3);
    let k_lo = ((2.0 * p.half_width_hz / df).ceil() as usize).max(2);
    let k_hi = (((fs_hz / 2.0 - p.half_width_hz) / df).floor() as usize)
        .min(spec.freq_hz.len().saturating_sub(3));
    let dt = if n_slices > 1 {
        spec.time_s[1] - spec.time_s[0]
    } else {
        1.0
    };
    // Peaks of each slice: (frequency, power).
    let peaks: Vec<Vec<f64>> = spec
        .psd
        .iter()
        .map(|row| {
            let pw: Vec<f64> = row.iter().map(|v| v.max(1e-300)).collect();
            prominent_peaks(&pw, k_lo, k_hi, reach, p.stft_min_prominence_db)
                .into_iter()
                .map(|(k, _)| peak_bin(&pw, k) * df)
                .collect()
        })
        .collect();
    // Link: (slice, frequency) lists.
    let mut building: Vec<Vec<(usize, f64)>> = Vec::new();
    for (s, fs) in peaks.iter().enumerate() {
        let mut pairs: Vec<(usize, usize, f64)> = Vec::new();
        for (i, &f) in fs.iter().enumerate() {
            for (j, r) in building.iter().enumerate() {
                let Some(&(ls, lf)) = r.last() else { continue };
                let gap = s - ls;
                if gap == 0 || gap > RIDGE_MAX_GAP + 1 {
                    continue;
                }
                let d = (f - lf).abs();
                if d <= p.sweep_rate_max_hz_per_s * dt * gap as f64 + 0.25 * resolution_hz {
                    pairs.push((i, j, d));
                }
            }
        }
        pairs.sort_by(|a, b| a.2.total_cmp(&b.2));
        let (mut used_p, mut used_r) = (vec![false; fs.len()], vec![false; building.len()]);
        for (i, j, _) in pairs {
            if !used_p[i] && !used_r[j] {
                used_p[i] = true;
                used_r[j] = true;
                building[j].push((s, fs[i]));
            }
        }
        for (i, &f) in fs.iter().enumerate() {
            if !used_p[i] {
                building.push(vec![(s, f)]);
            }
        }
    }
    let mut out: Vec<Ridge> = building
        .into_iter()
        .filter(|r| r.len() as f64 >= RIDGE_MIN_SLICE_SHARE * n_slices as f64 && r.len() >= 3)
        .map(|r| {
            let (s0, s1) = (r[0].0, r[r.len() - 1].0);
            // Fill the gaps linearly.
            let mut f: Vec<f64> = Vec::with_capacity(s1 - s0 + 1);
            for w in r.windows(2) {
                let ((sa, fa), (sb, fb)) = (w[0], w[1]);
                for s in sa..sb {
                    f.push(fa + (fb - fa) * (s - sa) as f64 / (sb - sa) as f64);
                }
            }
            f.push(r[r.len() - 1].1);
            let smooth: Vec<f64> = (0..f.len())
                .map(|i| {
                    if i == 0 || i + 1 == f.len() {
                        f[i]
                    } else {
                        vibmode_core::stats::median(&[f[i - 1], f[i], f[i + 1]])
                    }
                })
                .collect();
            Ridge {
                time_s: spec.time_s[s0..=s1].to_vec(),
                freq_hz: smooth,
                n_found: r.len(),
            }
        })
        .collect();
    let mean = |r: &Ridge| r.freq_hz.iter().sum::<f64>() / r.freq_hz.len().max(1) as f64;
    out.sort_by(|a, b| mean(a).total_cmp(&mean(b)));
    out
}

/// Kurtosis of `x` (sampled at `fs_hz`, Hz) demodulated along `ridge` and band-limited to
/// `+- half_width_hz`: the complex envelope `z = lowpass(x exp(-i phi))`, `phi` the integral of
/// the ridge frequency, gives `1.5 E|z|^4 / E|z|^2^2` over the ridge's span (its first slice
/// centre minus half a segment `half_segment_s` to its last plus half a segment). On the scale of
/// [`narrowband_kurtosis`]: a sine followed by the ridge has 1.5, Gaussian noise 3. `NaN` when
/// the span holds no power.
/// Errors: fs_hz not positive/finite, empty `x`, NaN/Inf sample.
pub fn tracked_kurtosis(
    x: &[f64],
    fs_hz: f64,
    ridge: &Ridge,
    half_width_hz: f64,
    half_segment_s: f64,
) -> Result<f64, SpectraError> {
    check_fs(fs_hz)?;
    check_samples(x, "x")?;
    let n = x.len();
    let (Some(&t0), Some(&t1)) = (ridge.time_s.first(), ridge.time_s.last()) else {
        return Ok(f64::NAN);
    };
    let mean = x.iter().sum::<f64>() / n as f64;
    let dt = 1.0 / fs_hz;
    let mut phase = 0.0f64;
    let mut re = Vec::with_capacity(n);
    let mut im = Vec::with_capacity(n);
    for (i, v) in x.iter().enumerate() {
        let f = ridge.freq_at(i as f64 * dt).unwrap_or(0.0);
        re.push((v - mean) * phase.cos());
        im.push(-(v - mean) * phase.sin());
        phase = (phase + 2.0 * std::f64::consts::PI * f * dt) % (2.0 * std::f64::consts::PI);
    }
    let mut planner = vibmode_fft::Planner::new();
    lowpass(&mut planner, &mut re, fs_hz, half_width_hz);
    lowpass(&mut planner, &mut im, fs_hz, half_width_hz);
    let lo = (((t0 - half_segment_s) * fs_hz).floor().max(0.0)) as usize;
    let hi = ((((t1 + half_segment_s) * fs_hz).ceil()) as usize).min(n);
    let (mut m2, mut m4, mut k) = (0.0, 0.0, 0usize);
    for i in lo..hi {
        let a = re[i] * re[i] + im[i] * im[i];
        m2 += a;
        m4 += a * a;
        k += 1;
    }
    if k == 0 || m2 <= 0.0 {
        return Ok(f64::NAN);
    }
    let (m2, m4) = (m2 / k as f64, m4 / k as f64);
    Ok(1.5 * m4 / (m2 * m2))
}

/// Ideal DFT low-pass of `y` to `cut_hz` (DC kept), in place.
fn lowpass(planner: &mut vibmode_fft::Planner, y: &mut [f64], fs_hz: f64, cut_hz: f64) {
    let n = y.len();
    let fwd = planner.forward(n);
    let inv = planner.inverse(n);
    let mut spec = fwd.make_output_vec();
    if fwd.process(y, &mut spec).is_err() {
        return;
    }
    let df = fs_hz / n as f64;
    let last = spec.len() - 1;
    for (k, c) in spec.iter_mut().enumerate() {
        if k as f64 * df > cut_hz {
            *c = num_complex::Complex64::new(0.0, 0.0);
        }
        if k == last && n % 2 == 0 {
            c.im = 0.0;
        }
        if k == 0 {
            c.im = 0.0;
        }
    }
    if inv.process(&mut spec, y).is_err() {
        return;
    }
    let s = 1.0 / n as f64;
    y.iter_mut().for_each(|v| *v *= s);
}

/// Ridges of `x` (sampled at `fs_hz`, Hz) that span at least `sweep_min_range_hz`, each with
/// its [`tracked_kurtosis`]: the candidates for lines whose frequency moves within the record.
/// The short-time spectra are Hann-windowed periodograms of `stft_nperseg` samples overlapping
/// by `stft_noverlap`, zero-padded 4x ([`WelchPlan::spectrogram`]); ridges as [`ridges`].
/// A record shorter than `stft_nperseg`, or `sweep_min_range_hz = 0`, gives none.
/// Errors: fs_hz not positive/finite, empty `x`, NaN/Inf sample.
pub fn swept_line_candidates(
    x: &[f64],
    fs_hz: f64,
    p: &LineParams,
) -> Result<Vec<SweptCandidate>, SpectraError> {
    check_fs(fs_hz)?;
    check_samples(x, "x")?;
    if p.sweep_min_range_hz <= 0.0 || x.len() < p.stft_nperseg || p.stft_nperseg < 4 {
        return Ok(Vec::new());
    }
    let wp = WelchParams {
        nperseg: Some(p.stft_nperseg),
        noverlap: Some(p.stft_noverlap.min(p.stft_nperseg - 1)),
        nfft: Some(4 * p.stft_nperseg),
        ..WelchParams::default()
    };
    let mut plan = WelchPlan::new(x.len(), fs_hz, &wp)?;
    let spec = plan.spectrogram(x)?;
    let half_segment_s = p.stft_nperseg as f64 / fs_hz / 2.0;
    let mut out = Vec::new();
    for ridge in ridges(&spec, p) {
        if ridge.range_hz() < p.sweep_min_range_hz {
            continue;
        }
        let kurtosis = tracked_kurtosis(x, fs_hz, &ridge, p.half_width_hz, half_segment_s)?;
        let mut f = ridge.freq_hz.clone();
        let fixed = Ridge {
            time_s: ridge.time_s.clone(),
            freq_hz: vec![median_in_place(&mut f); ridge.time_s.len()],
            n_found: ridge.n_found,
        };
        let fixed_kurtosis = tracked_kurtosis(x, fs_hz, &fixed, p.half_width_hz, half_segment_s)?;
        out.push(SweptCandidate {
            periodic: kurtosis < p.max_kurtosis
                && fixed_kurtosis - kurtosis >= SWEEP_KURTOSIS_GAIN_MIN
                && ridge.roughness_hz() <= SWEEP_ROUGHNESS_MAX_SHARE * ridge.range_hz(),
            ridge,
            kurtosis,
            fixed_kurtosis,
        });
    }
    Ok(out)
}
