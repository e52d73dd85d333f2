//! Thomson's multitaper harmonic F-test: is there a sinusoid (a periodic line) at frequency `f`
//! in a record whose spectrum is otherwise smooth over `f +- W`?
//!
//! With `K` discrete prolate spheroidal (Slepian) tapers `v_k` of length `N` and half-bandwidth
//! `W = NW / N` cycles per sample, the eigencoefficients of the mean-removed record `x` are
//! `y_k(f) = sum_t v_k(t) x_t exp(-i 2 pi f t / fs)` and the tapers' sums `U_k = sum_t v_k(t)`.
//! A line `mu exp(i 2 pi f t)` gives `y_k(f) = mu U_k` plus noise. The least-squares line
//! amplitude is `mu(f) = sum_k U_k y_k(f) / sum_k U_k^2` and
//!
//! `F(f) = (K - 1) |mu(f)|^2 sum_k U_k^2 / sum_k |y_k(f) - mu(f) U_k|^2`,
//!
//! which under "no line, locally white Gaussian noise" follows Fisher's F distribution with
//! `(2, 2K - 2)` degrees of freedom (Thomson 1982, Percival & Walden 1993 section 10.11). Its
//! survival function has the closed form `P(F > f) = (1 + 2 f / nu)^(-nu / 2)` with `nu = 2K - 2`
//! ([`f_test_p_value`]).
//!
//! The null also holds for a randomly excited mode whose spectrum is smooth over `+- W`: a mode
//! with half-power half-width `zeta f_n` well above `W`. A lightly damped mode narrower than the
//! tapers' band raises `F` at its peak (docs/analysis.md states the rates measured).

use crate::error::SpectraError;
use crate::welch::{check_fs, check_samples};
use std::sync::Arc;
use vibmode_fft::RealToComplex;

/// Discrete prolate spheroidal sequences: the `k` tapers of length `n` with time-half-bandwidth
/// product `nw`, each of unit energy, in order of decreasing concentration in `[-nw/n, nw/n]`,
/// with scipy's signs (`scipy.signal.windows.dpss(n, nw, k, norm=2)`: symmetric tapers have a
/// positive sum, antisymmetric ones begin with a positive lobe).
///
/// Computed as the eigenvectors of the symmetric tridiagonal matrix that commutes with the
/// concentration operator (Percival & Walden 1993, eq. 378): eigenvalues by bisection on
/// Sturm counts, eigenvectors by inverse iteration with a pivoted tridiagonal solve.
/// Errors: `n < 2`, `k` zero or above `n`, `nw` not in `(0, n / 2)`.
pub fn dpss(n: usize, nw: f64, k: usize) -> Result<Vec<Vec<f64>>, SpectraError> {
    if n < 2 || k == 0 || k > n || !(nw > 0.0 && nw < n as f64 / 2.0) {
        return Err(SpectraError::InvalidTapers { n, nw, k });
    }
    let w = nw / n as f64;
    let c = (2.0 * std::f64::consts::PI * w).cos();
    let half = (n as f64 - 1.0) / 2.0;
    let diag: Vec<f64> = (0..n).map(|t| (half - t as f64).powi(2) * c).collect();
    // off[t] couples t and t + 1.
    let off: Vec<f64> = (1..n).map(|t| (t * (n - t)) as f64 / 2.0).collect();
    // Gershgorin bounds.
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for t in 0..n {
        let r = if t > 0 { off[t - 1].abs() } else { 0.0 } + off.get(t).map_or(0.0, |v| v.abs());
        lo = lo.min(diag[t] - r);
        hi = hi.max(diag[t] + r);
    }
    let scale = hi.abs().max(lo.abs()).max(1.0);
    let mut tapers = Vec::with_capacity(k);
    for j in 0..k {
        // The (j+1)-th largest eigenvalue: the one with n - 1 - j eigenvalues below it.
        let idx = n - 1 - j;
        let (mut a, mut b) = (lo, hi);
        for _ in 0..200 {
            let m = 0.5 * (a + b);
            if sturm_count(&diag, &off, m) <= idx {
                a = m;
            } else {
                b = m;
            }
            if b - a <= 1e-15 * scale {
                break;
            }
        }
        let lambda = 0.5 * (a + b);
        let mut v = inverse_iteration(&diag, &off, lambda, scale, j);
        fix_sign(&mut v, j);
        tapers.push(v);
    }
    Ok(tapers)
}

/// Number of eigenvalues of the tridiagonal matrix below `x`.
fn sturm_count(diag: &[f64], off: &[f64], x: f64) -> usize {
    let mut count = 0;
    let mut q = 1.0;
    for t in 0..diag.len() {
        let b2 = if t > 0 { off[t - 1] * off[t - 1] } else { 0.0 };
        q = diag[t] - x - if t > 0 { b2 / q } else { 0.0 };
        if q == 0.0 {
            q = -1e-300;
        }
        if q < 0.0 {
            count += 1;
        }
    }
    count
}

/// Eigenvector for the eigenvalue `lambda` by inverse iteration (unit norm).
fn inverse_iteration(diag: &[f64], off: &[f64], lambda: f64, scale: f64, seed: usize) -> Vec<f64> {
    let n = diag.len();
    let shift = lambda + 1e-13 * scale;
    // A start vector with a component along every eigenvector (deterministic).
    let mut v: Vec<f64> = (0..n)
        .map(|t| 1.0 + 0.1 * ((t * 7 + seed * 13 + 1) % 17) as f64 / 17.0)
        .collect();
    for _ in 0..4 {
        v = solve_tridiagonal(diag, off, shift, &v);
        let norm = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            break;
        }
        v.iter_mut().for_each(|a| *a /= norm);
    }
    v
}

/// Solves `(T - shift I) x = rhs` for the symmetric tridiagonal `T` by Gaussian elimination
/// with partial pivoting (LAPACK's `gtsv`); a zero pivot is replaced by a tiny number, as
/// inverse iteration wants.
fn solve_tridiagonal(diag: &[f64], off: &[f64], shift: f64, rhs: &[f64]) -> Vec<f64> {
    let n = diag.len();
    // Row i holds d[i] at column i, du[i] at i + 1, du2[i] at i + 2 (after pivoting).
    let mut d: Vec<f64> = diag.iter().map(|a| a - shift).collect();
    let mut dl: Vec<f64> = off.to_vec();
    let mut du: Vec<f64> = off.to_vec();
    let mut du2 = vec![0.0; n.saturating_sub(2)];
    let mut b = rhs.to_vec();
    let tiny = 1e-300;
    for i in 0..n - 1 {
        if d[i].abs() >= dl[i].abs() {
            if d[i] == 0.0 {
                d[i] = tiny;
            }
            let f = dl[i] / d[i];
            d[i + 1] -= f * du[i];
            b[i + 1] -= f * b[i];
            dl[i] = 0.0;
        } else {
            // Swap rows i and i + 1.
            let f = d[i] / dl[i];
            d[i] = dl[i];
            let tmp = d[i + 1];
            d[i + 1] = du[i] - f * tmp;
            if i + 2 < n {
                du2[i] = du[i + 1];
                du[i + 1] *= -f;
            }
            du[i] = tmp;
            b.swap(i, i + 1);
            b[i + 1] -= f * b[i];
        }
    }
    if d[n - 1] == 0.0 {
        d[n - 1] = tiny;
    }
    let mut x = vec![0.0; n];
    x[n - 1] = b[n - 1] / d[n - 1];
    if n >= 2 {
        x[n - 2] = (b[n - 2] - du[n - 2] * x[n - 1]) / d[n - 2];
    }
    for i in (0..n.saturating_sub(2)).rev() {
        x[i] = (b[i] - du[i] * x[i + 1] - du2[i] * x[i + 2]) / d[i];
    }
    x
}

/// scipy's sign convention: symmetric tapers (even index) have a positive sum; antisymmetric
/// ones have their first value with `v^2 > max(1e-7, 1/n)` positive.
fn fix_sign(v: &mut [f64], index: usize) {
    let flip = if index % 2 == 0 {
        v.iter().sum::<f64>() < 0.0
    } else {
        let thresh = (1e-7f64).max(1.0 / v.len() as f64);
        v.iter()
            .find(|a| *a * *a > thresh)
            .is_some_and(|a| *a < 0.0)
    };
    if flip {
        v.iter_mut().for_each(|a| *a = -*a);
    }
}

/// `P(F > f)` for Fisher's F with `(2, nu)` degrees of freedom: `(1 + 2 f / nu)^(-nu / 2)`
/// (1 for `f <= 0`, NaN for NaN).
pub fn f_test_p_value(f: f64, nu: f64) -> f64 {
    if f.is_nan() || nu.is_nan() {
        return f64::NAN;
    }
    if f <= 0.0 {
        return 1.0;
    }
    (1.0 + 2.0 * f / nu).powf(-nu / 2.0)
}

/// The F statistic over a frequency grid, with the line amplitude it implies.
#[derive(Clone, Debug, PartialEq)]
pub struct HarmonicF {
    /// Frequencies of the grid, Hz (`0, fs / nfft, ...` up to Nyquist).
    pub freq_hz: Vec<f64>,
    /// Thomson's F at each frequency (F(2, 2K - 2) without a line).
    pub f_stat: Vec<f64>,
    /// Estimated amplitude of a real sinusoid `A cos(2 pi f t + p)` at each frequency, `2 |mu|`,
    /// in the unit of the samples.
    pub amplitude: Vec<f64>,
    /// Degrees of freedom of the denominator, `2K - 2`.
    pub dof: f64,
    /// Half-bandwidth of the tapers, `NW fs / N`, Hz.
    pub half_bandwidth_hz: f64,
}

impl HarmonicF {
    /// `P(F > F(f))` at grid point `j` without a line.
    pub fn p_value(&self, j: usize) -> f64 {
        self.f_stat
            .get(j)
            .map_or(f64::NAN, |&f| f_test_p_value(f, self.dof))
    }
}

/// Tapers and FFT plan for the F-test of records of one length: reuse it over records.
pub struct HarmonicPlan {
    n: usize,
    nfft: usize,
    nw: f64,
    tapers: Arc<Vec<Vec<f64>>>,
    sums: Vec<f64>,
    fft: Arc<dyn RealToComplex<f64>>,
}

/// The tapers made by [`HarmonicPlan::new`] in this process, by `(n, nw's bits, k)`, newest
/// last: a fleet makes one plan per record of the same length, and the tapers (a bisection for
/// each eigenvalue) cost more than the F-test of a short record.
static TAPERS: std::sync::LazyLock<std::sync::Mutex<Vec<TapersKey>>> =
    std::sync::LazyLock::new(|| std::sync::Mutex::new(Vec::new()));

type TapersKey = ((usize, u64, usize), Arc<Vec<Vec<f64>>>);

/// The most taper sets [`TAPERS`] keeps (the oldest is dropped first).
const TAPERS_KEPT: usize = 8;

/// [`dpss`] of `(n, nw, k)`, made once per process for the last [`TAPERS_KEPT`] settings.
fn shared_dpss(n: usize, nw: f64, k: usize) -> Result<Arc<Vec<Vec<f64>>>, SpectraError> {
    let key = (n, nw.to_bits(), k);
    // A poisoned lock only means another thread panicked while holding it: the list is whole.
    let find = || {
        let kept = TAPERS.lock().unwrap_or_else(|e| e.into_inner());
        kept.iter().find(|(k, _)| *k == key).map(|(_, t)| t.clone())
    };
    if let Some(t) = find() {
        return Ok(t);
    }
    let tapers = Arc::new(dpss(n, nw, k)?);
    let mut kept = TAPERS.lock().unwrap_or_else(|e| e.into_inner());
    if !kept.iter().any(|(k, _)| *k == key) {
        if kept.len() >= TAPERS_KEPT {
            kept.remove(0);
        }
        kept.push((key, tapers.clone()));
    }
    Ok(tapers)
}

impl std::fmt::Debug for HarmonicPlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HarmonicPlan")
            .field("n", &self.n)
            .field("nfft", &self.nfft)
            .field("nw", &self.nw)
            .field("k", &self.tapers.len())
            .finish()
    }
}

impl HarmonicPlan {
    /// A plan for records of `n` samples: `k` tapers of time-half-bandwidth `nw`, FFTs zero-padded
    /// to `pad * n` (pad >= 1; 4 gives a grid of a quarter of the Rayleigh resolution). `k` must be
    /// at least 2 (the F-test needs a residual). Errors as [`dpss`].
    pub fn new(n: usize, nw: f64, k: usize, pad: usize) -> Result<Self, SpectraError> {
        if k < 2 {
            return Err(SpectraError::InvalidTapers { n, nw, k });
        }
        let tapers = shared_dpss(n, nw, k)?;
        let sums = tapers.iter().map(|v| v.iter().sum()).collect();
        let nfft = n * pad.max(1);
        let fft = vibmode_fft::Planner::new().forward(nfft);
        Ok(HarmonicPlan {
            n,
            nfft,
            nw,
            tapers,
            sums,
            fft,
        })
    }

    /// Record length the plan is for, samples.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Always false (a plan has at least 2 samples).
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The F-test of `x` (exactly `len()` samples, sampled at `fs_hz`) at every grid frequency.
    /// Errors: fs_hz not positive/finite, a NaN/Inf sample, a length other than the plan's.
    pub fn f_test(&self, x: &[f64], fs_hz: f64) -> Result<HarmonicF, SpectraError> {
        check_fs(fs_hz)?;
        check_samples(x, "x")?;
        if x.len() != self.n {
            return Err(SpectraError::LengthMismatch {
                len_x: x.len(),
                len_y: self.n,
            });
        }
        let k = self.tapers.len();
        let mean = x.iter().sum::<f64>() / self.n as f64;
        let n_out = self.nfft / 2 + 1;
        let mut buf = vec![0.0; self.nfft];
        let mut spec = self.fft.make_output_vec();
        // y[k][j]
        let mut y = Vec::with_capacity(k);
        for v in self.tapers.iter() {
            buf.iter_mut().for_each(|b| *b = 0.0);
            for ((b, xv), vv) in buf.iter_mut().zip(x).zip(v) {
                *b = (xv - mean) * vv;
            }
            self.fft
                .process(&mut buf, &mut spec)
                .map_err(|_| SpectraError::EmptyInput { name: "x" })?;
            y.push(spec.clone());
        }
        let su2: f64 = self.sums.iter().map(|u| u * u).sum();
        let dof = 2.0 * k as f64 - 2.0;
        let mut f_stat = Vec::with_capacity(n_out);
        let mut amplitude = Vec::with_capacity(n_out);
        for j in 0..n_out {
            let mut mu = num_complex::Complex64::new(0.0, 0.0);
            for (yk, u) in y.iter().zip(&self.sums) {
                mu += yk[j] * *u;
            }
            mu /= su2;
            let resid: f64 = y
                .iter()
                .zip(&self.sums)
                .map(|(yk, u)| (yk[j] - mu * *u).norm_sqr())
                .sum();
            let num = (k as f64 - 1.0) * mu.norm_sqr() * su2;
            f_stat.push(if resid > 0.0 {
                num / resid
            } else {
                f64::INFINITY
            });
            amplitude.push(2.0 * mu.norm());
        }
        Ok(HarmonicF {
            freq_hz: (0..n_out)
                .map(|j| j as f64 * fs_hz / self.nfft as f64)
                .collect(),
            f_stat,
            amplitude,
            dof,
            half_bandwidth_hz: self.nw * fs_hz / self.n as f64,
        })
    }
}

/// Thomson's harmonic F-test of `x` (sampled at `fs_hz`) with `k` tapers of time-half-bandwidth
/// `nw`, on a grid zero-padded `pad` times. See the module's documentation; a plan
/// ([`HarmonicPlan`]) reuses the tapers over records.
/// Errors: as [`HarmonicPlan::new`] and [`HarmonicPlan::f_test`].
pub fn harmonic_f_test(
    x: &[f64],
    fs_hz: f64,
    nw: f64,
    k: usize,
    pad: usize,
) -> Result<HarmonicF, SpectraError> {
    check_fs(fs_hz)?;
    check_samples(x, "x")?;
    HarmonicPlan::new(x.len(), nw, k, pad)?.f_test(x, fs_hz)
}

/// Frequencies where `F` is a local maximum over `+- half_bandwidth_hz` with `P(F > F(f))` below
/// `alpha`, between `lo_hz` and `hi_hz`: `(frequency Hz, p-value, amplitude)`, by frequency.
/// Within `+- W` of a detected line the F-test sees the line's own leakage, so only the
/// strongest peak of each band of that width is kept.
pub fn f_test_peaks(h: &HarmonicF, alpha: f64, lo_hz: f64, hi_hz: f64) -> Vec<(f64, f64, f64)> {
    let n = h.f_stat.len();
    if n < 3 {
        return Vec::new();
    }
    let df = h.freq_hz[1] - h.freq_hz[0];
    let reach = ((h.half_bandwidth_hz / df).round() as usize).max(1);
    let mut out = Vec::new();
    for j in 1..n - 1 {
        let f = h.freq_hz[j];
        if f < lo_hz || f > hi_hz {
            continue;
        }
        let p = h.p_value(j);
        if p.is_nan() || p >= alpha {
            continue;
        }
        let a = j.saturating_sub(reach);
        let b = (j + reach).min(n - 1);
        // Ties keep the lowest index.
        let is_max = (a..=b)
            .all(|i| i == j || h.f_stat[i] < h.f_stat[j] || (h.f_stat[i] == h.f_stat[j] && i > j));
        if is_max {
            out.push((f, p, h.amplitude[j]));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plan's tapers are `dpss` of its settings bit for bit, whether made now, kept from an
    /// earlier plan, or made again after more settings than the process keeps pushed them out.
    #[test]
    fn plans_share_their_tapers_and_they_are_dpss_of_their_settings() {
        let settings: Vec<(usize, f64, usize)> = (0..TAPERS_KEPT + 3)
            .map(|i| (64 + 7 * i, 2.5 + 0.25 * (i % 3) as f64, 3 + i % 4))
            .collect();
        for round in 0..2 {
            for &(n, nw, k) in &settings {
                let plan = HarmonicPlan::new(n, nw, k, 2).unwrap();
                assert_eq!(
                    *plan.tapers,
                    dpss(n, nw, k).unwrap(),
                    "round {round}: {n} {nw} {k}"
                );
                let again = HarmonicPlan::new(n, nw, k, 4).unwrap();
                assert!(Arc::ptr_eq(&plan.tapers, &again.tapers), "{n} {nw} {k}");
            }
        }
        assert!(TAPERS.lock().unwrap_or_else(|e| e.into_inner()).len() <= TAPERS_KEPT);
        // Bad settings are refused as dpss refuses them, and nothing is kept for them.
        assert!(HarmonicPlan::new(10, 6.0, 3, 1).is_err());
    }

    #[test]
    fn the_p_value_of_f_2_nu_by_hand() {
        // nu = 4: (1 + f / 2)^-2; f = 2 -> 1/4.
        assert!((f_test_p_value(2.0, 4.0) - 0.25).abs() < 1e-15);
        // nu = 2: (1 + f)^-1; f = 9 -> 0.1.
        assert!((f_test_p_value(9.0, 2.0) - 0.1).abs() < 1e-15);
        assert_eq!(f_test_p_value(0.0, 12.0), 1.0);
        assert!(f_test_p_value(f64::NAN, 12.0).is_nan());
    }

    #[test]
    fn one_taper_of_two_samples_is_flat_and_two_are_the_sum_and_difference() {
        // n = 2: T = [[c/4, 1/2], [1/2, c/4]], eigenvectors (1, 1) (larger) and (1, -1).
        let v = dpss(2, 0.5, 2).unwrap();
        let s = std::f64::consts::FRAC_1_SQRT_2;
        assert!(
            (v[0][0] - s).abs() < 1e-12 && (v[0][1] - s).abs() < 1e-12,
            "{v:?}"
        );
        assert!(
            (v[1][0] - s).abs() < 1e-12 && (v[1][1] + s).abs() < 1e-12,
            "{v:?}"
        );
    }

    #[test]
    fn tapers_are_orthonormal_and_symmetric_or_antisymmetric() {
        let v = dpss(100, 3.0, 5).unwrap();
        for i in 0..5 {
            for j in 0..5 {
                let d: f64 = v[i].iter().zip(&v[j]).map(|(a, b)| a * b).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((d - want).abs() < 1e-9, "<v{i}, v{j}> = {d}");
            }
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            for t in 0..50 {
                assert!((v[i][t] - sign * v[i][99 - t]).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn bad_taper_settings_are_refused_naming_them() {
        for (n, nw, k) in [
            (1, 1.0, 1),
            (10, 0.0, 1),
            (10, 5.0, 1),
            (10, 2.0, 0),
            (10, 2.0, 11),
        ] {
            let e = dpss(n, nw, k).unwrap_err().to_string();
            assert!(e.contains("nw") && !e.contains('\n'), "{e}");
        }
        assert!(HarmonicPlan::new(64, 2.0, 1, 1).is_err());
    }

    #[test]
    fn a_pure_sinusoid_gives_its_amplitude_and_a_huge_f() {
        let fs = 50.0;
        let n = 512;
        let x: Vec<f64> = (0..n)
            .map(|t| 0.7 * (2.0 * std::f64::consts::PI * 10.0 * t as f64 / fs + 0.3).cos())
            .collect();
        let h = harmonic_f_test(&x, fs, 4.0, 7, 1).unwrap();
        // Bin of 10 Hz: 10 / (50 / 512) = 102.4; pad 1 -> nearest bin 102 (9.96 Hz); use pad 5.
        let h5 = harmonic_f_test(&x, fs, 4.0, 7, 5).unwrap();
        let j = h5
            .freq_hz
            .iter()
            .position(|f| (f - 10.0).abs() < 1e-9)
            .unwrap();
        assert!((h5.amplitude[j] - 0.7).abs() < 1e-3, "{}", h5.amplitude[j]);
        assert!(h5.f_stat[j] > 1e6, "{}", h5.f_stat[j]);
        assert_eq!(h.dof, 12.0);
        let peaks = f_test_peaks(&h5, 1e-3, 1.0, 24.0);
        assert_eq!(peaks.len(), 1, "{peaks:?}");
        assert!((peaks[0].0 - 10.0).abs() < 1e-9);
    }
}
