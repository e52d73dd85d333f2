//! Periodic lines (engine and gear orders) told from randomly excited modes by the statistics of
//! their narrow-band signal, not by a fitted damping.
//!
//! A sine `A sin(w t + p)` has kurtosis `E[x^4] / E[x^2]^2 = 1.5`; a Gaussian process (a mode
//! driven by a random road) has 3; a sine plus Gaussian power in the same band lies between:
//! with sine power `S` and Gaussian power `G`, `(1.5 S^2 + 6 S G + 3 G^2) / (S + G)^2`. Amplitude
//! modulation of a few percent and a slowly wandering frequency keep a line near 1.5 as long as
//! it stays inside the band.

use crate::error::SpectraError;
use crate::welch::{check_fs, check_samples};
use realfft::RealFftPlanner;
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
    /// True when `kurtosis < max_kurtosis`: a periodic line.
    pub periodic: bool,
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
    let mut planner = RealFftPlanner::<f64>::new();
    Ok(band_moments(
        &mut planner,
        x,
        fs_hz,
        center_hz,
        half_width_hz,
    ))
}

fn band_kurtosis(
    planner: &mut RealFftPlanner<f64>,
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
    planner: &mut RealFftPlanner<f64>,
    x: &[f64],
    fs_hz: f64,
    center_hz: f64,
    half_width_hz: f64,
) -> (f64, f64) {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let mut buf: Vec<f64> = x.iter().map(|v| v - mean).collect();
    let var = buf.iter().map(|v| v * v).sum::<f64>() / n as f64;
    let fwd = planner.plan_fft_forward(n);
    let inv = planner.plan_fft_inverse(n);
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
    let mut planner = RealFftPlanner::<f64>::new();
    let nfft = 4 * n;
    let mean = x.iter().sum::<f64>() / n as f64;
    let mut buf = vec![0.0; nfft];
    for (i, v) in x.iter().enumerate() {
        let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos();
        buf[i] = (v - mean) * w;
    }
    let fwd = planner.plan_fft_forward(nfft);
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
    let mut peaks: Vec<(usize, f64)> = Vec::new();
    for k in k_lo..=k_hi {
        if k < 2 || !(pw[k - 2..=k + 2].iter().all(|&v| v <= pw[k])) {
            continue;
        }
        let lo = k.saturating_sub(reach);
        let hi = (k + reach).min(pw.len() - 1);
        let mut near: Vec<f64> = pw[lo..=hi].to_vec();
        near.sort_by(f64::total_cmp);
        let median = near[near.len() / 2];
        let prominence_db = 10.0 * (pw[k] / median).log10();
        if prominence_db >= p.min_prominence_db {
            peaks.push((k, prominence_db));
        }
    }
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
            let (a, b, c) = (pw[k - 1].ln(), pw[k].ln(), pw[k + 1].ln());
            let den = a - 2.0 * b + c;
            let delta = if den.abs() > 0.0 {
                0.5 * (a - c) / den
            } else {
                0.0
            };
            let frequency_hz = (k as f64 + delta.clamp(-0.5, 0.5)) * df;
            let kurtosis = band_kurtosis(&mut planner, x, fs_hz, frequency_hz, p.half_width_hz);
            LineCandidate {
                frequency_hz,
                kurtosis,
                prominence_db,
                periodic: kurtosis < p.max_kurtosis,
            }
        })
        .collect();
    out.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    Ok(out)
}
