//! Additive outliers (isolated spikes in the measured signal): a robust AR filter-cleaner in the
//! spirit of Martin & Thomson (1982), own implementation. See docs/identification.md, section
//! "Additive outliers".
//!
//! A spike added to `y_t` corrupts every prediction error that uses `y_t` as a regressor (p + 1 of
//! them through A, many more through 1/C), which the Huber criterion cannot bound. The cleaner runs
//! a long AR predictor through the data, replaces a sample by its prediction from the already
//! cleaned past when (i) its one-step residual exceeds `threshold` robust standard deviations and
//! (ii) the replacement makes the following residuals much smaller (an isolated spike: the data
//! after it follow the undisturbed trajectory) rather than larger (a genuine innovation, e.g. a
//! pothole's impulse response, which the data after it keep following). The AR model is refitted
//! on the cleaned data and the pass repeated.

use serde::{Deserialize, Serialize};

use nalgebra::DMatrix;

use crate::ar::burg;
use crate::linalg::{check_signal, cholesky_solve_ridged, median, predict_errors, robust_std};
use crate::IdentError;
use vibmode_core::ParamError;

/// Settings of the robust AR filter-cleaner ([`clean_additive_outliers`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CleanerParams {
    /// Order m of the AR predictor (samples). Default 20. The order actually used is
    /// `min(ar_order, N / 10)`; with fewer than 10 samples nothing is cleaned.
    pub ar_order: usize,
    /// Detection threshold k (dimensionless, > 0): a sample is a candidate when its one-step
    /// residual exceeds `k` robust standard deviations (MAD / 0.6745) of the predictor's residuals.
    /// Default 4.0 (a Gaussian innovation exceeds it with probability 6e-5, and is then kept by the
    /// look-ahead test).
    pub threshold: f64,
    /// Passes (AR fit + filter), at least 1; the cleaner stops early when a pass replaces the same
    /// samples as the previous one. Default 3.
    pub passes: usize,
}

impl Default for CleanerParams {
    fn default() -> Self {
        CleanerParams {
            ar_order: 20,
            threshold: 4.0,
            passes: 3,
        }
    }
}

impl CleanerParams {
    pub(crate) fn validate(&self) -> Result<(), IdentError> {
        if self.ar_order == 0 {
            return Err(ParamError::out_of_range(
                "ar_order",
                0,
                "must be an AR predictor order of at least 1 (or OutlierCleaning::Off)",
                CleanerParams::default().ar_order,
            )
            .into());
        }
        if !(self.threshold.is_finite() && self.threshold > 0.0) {
            return Err(ParamError::out_of_range(
                "threshold",
                self.threshold,
                "must be a positive number of robust standard deviations",
                CleanerParams::default().threshold,
            )
            .into());
        }
        if self.passes == 0 {
            return Err(ParamError::out_of_range(
                "passes",
                0,
                "must be at least 1 (or OutlierCleaning::Off)",
                CleanerParams::default().passes,
            )
            .into());
        }
        Ok(())
    }
}

/// Additive-outlier cleaning applied by [`crate::fit_arma`] before a robust
/// (`Robust::Huber`) fit; ignored by `Robust::Off` fits, which stay purely quadratic.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum OutlierCleaning {
    /// No cleaning: the Huber criterion alone (bounds innovation outliers only).
    Off,
    /// Robust AR filter-cleaner ([`clean_additive_outliers`]) with these settings.
    RobustFilter(CleanerParams),
}

impl Default for OutlierCleaning {
    /// `RobustFilter(CleanerParams::default())`.
    fn default() -> Self {
        OutlierCleaning::RobustFilter(CleanerParams::default())
    }
}

/// Result of [`clean_additive_outliers`].
#[derive(Debug, Clone, PartialEq)]
pub struct CleanedSignal {
    /// The cleaned signal (signal units): equal to the input bit for bit except at `replaced`.
    pub y: Vec<f64>,
    /// Indices of the replaced samples, ascending.
    pub replaced: Vec<usize>,
    /// A coefficients (leading 1, dimensionless) of the last pass's AR predictor, for the signal
    /// minus `centre`; empty when nothing could be cleaned (fewer than 10 samples).
    pub ar: Vec<f64>,
    /// Median of the input, subtracted before prediction (signal units).
    pub centre: f64,
    /// Robust standard deviation of the last pass's one-step residuals (signal units).
    pub residual_scale: f64,
    /// Passes run.
    pub passes: usize,
}

/// Robust AR filter-cleaner for additive outliers (isolated spikes) in `y` (signal units).
///
/// Each pass: fit AR(m) (m = `min(ar_order, N/10)`) by forward-backward least squares to the
/// windows of the signal minus its median that contain no suspect sample (first pass: samples
/// beyond 5 robust standard deviations of `y`; later passes: the samples the previous pass
/// replaced); `s` = MAD/0.6745 of its one-step residuals. Then run a Kalman filter of that AR
/// process through the raw signal: prediction `yhat_t` from the cleaned past, variance `v_t`
/// (`s^2` when the m previous samples were observed, larger after a replaced one). When
/// `(y_t - yhat_t)^2 > threshold^2 v_t`, filter the next `L = min(m, N - 1 - t)` samples once with
/// `y_t` kept and once with it skipped, each costing `min(z^2, threshold^2)` per standardised
/// residual z (samples beyond the threshold skipped); replace `y_t` by `yhat_t` when skipping costs
/// less than half of keeping. The first m samples are checked by the same filter run backwards in
/// time (a stationary AR process has the same coefficients in reversed time). Passes stop early
/// when the replaced set repeats. Details and measured figures: docs/identification.md.
///
/// When the m samples before t were kept, a replaced sample becomes exactly
/// `centre - sum_k ar[k] (y_{t-k} - centre)`; after a replaced sample the filter uses its estimate
/// of the past (corrected by the samples observed since).
///
/// Errors: empty, non-finite or constant input; invalid params.
pub fn clean_additive_outliers(
    y: &[f64],
    params: &CleanerParams,
) -> Result<CleanedSignal, IdentError> {
    params.validate()?;
    check_signal(y, 3)?;
    let n = y.len();
    let centre = median(y);
    let m = params.ar_order.min(n / SAMPLES_PER_AR_ORDER);
    let mut out = CleanedSignal {
        y: y.to_vec(),
        replaced: Vec::new(),
        ar: Vec::new(),
        centre,
        residual_scale: f64::NAN,
        passes: 0,
    };
    if m == 0 {
        return Ok(out);
    }
    let raw: Vec<f64> = y.iter().map(|v| v - centre).collect();
    let rms = (raw.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
    // First pass: fit on the windows free of gross marginal outliers.
    let (mut x, mut bad) = prescreen(&raw);
    let prescreened = bad.iter().any(|&b| b);
    let mut flags = vec![false; n];
    let mut resid = vec![0.0; n];
    for pass in 0..params.passes {
        let (a, s) = fit_predictor(&x, &bad, m, &mut resid);
        out.ar = a;
        out.residual_scale = s;
        out.passes = pass + 1;
        // No usable scale (e.g. a perfectly predictable signal): nothing can be called an outlier.
        if !(s.is_finite() && s > MIN_RELATIVE_SCALE * rms) {
            x.copy_from_slice(&raw);
            flags.iter_mut().for_each(|f| *f = false);
            break;
        }
        let (nx, nflags) = clean_pass(&raw, &x[..m], &out.ar, s, params.threshold);
        let same = nflags == flags;
        x = nx;
        flags = nflags;
        bad.copy_from_slice(&flags);
        // Same replaced set as before (or, in the first pass, nothing replaced and nothing
        // pre-screened): the next fit and pass would repeat this one.
        if same && (pass > 0 || !prescreened) {
            break;
        }
    }
    for (t, &f) in flags.iter().enumerate() {
        if f {
            out.y[t] = x[t] + centre;
            out.replaced.push(t);
        }
    }
    Ok(out)
}

/// AR(m) predictor of one pass (m = `a.len() - 1`): the masked forward-backward least-squares fit
/// of `x` on the windows free of `bad` samples, or, when too few windows are usable, Burg's fit
/// of the whole of `x` with the robust scale of its residuals (computed in `resid`). Returns the
/// A coefficients and the innovation scale.
fn fit_predictor(x: &[f64], bad: &[bool], m: usize, resid: &mut [f64]) -> (Vec<f64>, f64) {
    match masked_fb_ls(x, bad, m) {
        Some(fit) => fit,
        None => {
            let (a, _, _) = burg(x, m);
            predict_errors(x, &a, &[1.0], resid);
            let s = robust_std(&resid[m..]);
            (a, s)
        }
    }
}

/// One filter-cleaner pass over the centred raw signal `raw` with the AR predictor `a` (order m)
/// and innovation scale `s`: forward from t = m, the first m samples keeping their previous
/// cleaned values `head` as the initial state; then backward (time reversed, the rest already
/// cleaned) over the first m samples. Returns the cleaned signal and the replaced samples' flags.
fn clean_pass(
    raw: &[f64],
    head: &[f64],
    a: &[f64],
    s: f64,
    threshold: f64,
) -> (Vec<f64>, Vec<bool>) {
    let n = raw.len();
    let m = head.len();
    let mut nx = raw.to_vec();
    nx[..m].copy_from_slice(head);
    let mut nflags = vec![false; n];
    filter_forward(raw, &mut nx, &mut nflags, a, s, threshold, m..n);
    let rraw: Vec<f64> = raw.iter().rev().copied().collect();
    let mut rx: Vec<f64> = nx.iter().rev().copied().collect();
    let mut rflags = vec![false; n];
    for (t, v) in rx.iter_mut().enumerate().skip(n - m) {
        *v = rraw[t];
    }
    filter_forward(&rraw, &mut rx, &mut rflags, a, s, threshold, n - m..n);
    for t in 0..m {
        nx[t] = rx[n - 1 - t];
        nflags[t] = rflags[n - 1 - t];
    }
    (nx, nflags)
}

/// The cleaner's AR order is at most N / 10 (and nothing is cleaned below 10 samples): an AR
/// predictor needs several samples per coefficient to be estimated at all. The same ratio sets the
/// least number of usable windows of the masked fit.
const SAMPLES_PER_AR_ORDER: usize = 10;

/// The masked least-squares fit needs at least 5 usable windows per coefficient (else Burg on the
/// whole signal is used).
const MIN_WINDOWS_PER_ORDER: usize = 5;

/// Refinement steps of the masked least-squares fit with the exact residual gradient (undo the
/// precision lost to the normal equations).
const MASKED_LS_REFINEMENTS: usize = 2;

/// A residual scale below 1e-12 of the signal's RMS is rounding error (a perfectly predictable
/// signal): nothing is then called an outlier.
const MIN_RELATIVE_SCALE: f64 = 1e-12;

/// Marginal threshold (robust standard deviations of the signal) of the pre-screen that protects the
/// first pass's AR fit.
const PRESCREEN: f64 = 5.0;

/// Copy of `x` (centred on its median) with the samples beyond `PRESCREEN` robust standard
/// deviations replaced by linear interpolation between their nearest kept neighbours (constant
/// extrapolation at the ends), and the flags of those samples. Only used for the first pass's AR
/// predictor.
fn prescreen(x: &[f64]) -> (Vec<f64>, Vec<bool>) {
    let s = robust_std(x);
    let mut out = x.to_vec();
    let mut bad = vec![false; x.len()];
    if !(s.is_finite() && s > 0.0) {
        return (out, bad);
    }
    let cut = PRESCREEN * s;
    let keep: Vec<usize> = (0..x.len()).filter(|&t| x[t].abs() <= cut).collect();
    if keep.is_empty() || keep.len() == x.len() {
        return (out, bad);
    }
    let mut next = 0; // index into keep of the first kept sample at or after t
    for t in 0..x.len() {
        while next < keep.len() && keep[next] < t {
            next += 1;
        }
        if next < keep.len() && keep[next] == t {
            continue;
        }
        bad[t] = true;
        out[t] = match (next.checked_sub(1).map(|i| keep[i]), keep.get(next)) {
            (Some(l), Some(&r)) => {
                let w = (t - l) as f64 / (r - l) as f64;
                (1.0 - w) * x[l] + w * x[r]
            }
            (Some(l), None) => x[l],
            (None, Some(&r)) => x[r],
            (None, None) => 0.0,
        };
    }
    (out, bad)
}

/// Forward-backward least-squares AR(m) fit over the windows `[t - m, t]` that contain no `bad`
/// sample (normal equations, Cholesky, two steps of refinement with the exact residual gradient),
/// and the robust std (MAD/0.6745) of its forward residuals on those windows. None when fewer than
/// `max(5 m, N / 10)` windows are usable or the system is singular.
fn masked_fb_ls(x: &[f64], bad: &[bool], m: usize) -> Option<(Vec<f64>, f64)> {
    let n = x.len();
    let mut windows = Vec::with_capacity(n);
    let mut run = 0usize; // good samples in a row ending at t
    for (t, &b) in bad.iter().enumerate() {
        run = if b { 0 } else { run + 1 };
        if t >= m && run > m {
            windows.push(t);
        }
    }
    if windows.len() < (MIN_WINDOWS_PER_ORDER * m).max(n / SAMPLES_PER_AR_ORDER) {
        return None;
    }
    let mut g = DMatrix::<f64>::zeros(m, m);
    let mut rhs = vec![0.0; m];
    for &t in &windows {
        for i in 1..=m {
            let (fi, bi) = (x[t - i], x[t - m + i]);
            rhs[i - 1] -= fi * x[t] + bi * x[t - m];
            for j in i..=m {
                g[(i - 1, j - 1)] += fi * x[t - j] + bi * x[t - m + j];
            }
        }
    }
    g.fill_lower_triangle_with_upper_triangle();
    let solve = |b: &[f64]| cholesky_solve_ridged(&g, b);
    let mut coef = solve(&rhs)?;
    let residuals = |coef: &[f64], t: usize| -> (f64, f64) {
        let mut f = x[t];
        let mut b = x[t - m];
        for k in 1..=m {
            f += coef[k - 1] * x[t - k];
            b += coef[k - 1] * x[t - m + k];
        }
        (f, b)
    };
    for _ in 0..MASKED_LS_REFINEMENTS {
        let mut grad = vec![0.0; m];
        for &t in &windows {
            let (f, b) = residuals(&coef, t);
            for k in 1..=m {
                grad[k - 1] -= f * x[t - k] + b * x[t - m + k];
            }
        }
        let d = solve(&grad)?;
        for (c, dk) in coef.iter_mut().zip(&d) {
            *c += dk;
        }
    }
    let fwd: Vec<f64> = windows.iter().map(|&t| residuals(&coef, t).0).collect();
    let mut a = Vec::with_capacity(m + 1);
    a.push(1.0);
    a.extend_from_slice(&coef);
    if a.iter().all(|v| v.is_finite()) {
        Some((a, robust_std(&fwd)))
    } else {
        None
    }
}

/// A candidate is replaced only when the look-ahead loss of replacing it is below this fraction of
/// the loss of keeping it (dimensionless). An isolated spike gives ratios of 0.1 or less; after a
/// genuine transient far larger than the innovations, the estimated predictor's own error makes
/// both hypotheses costly (ratio near 1), and the sample is kept.
const REPLACE_MARGIN: f64 = 0.5;

/// Kalman filter of the AR(m) process `x_t = -sum_k a_k x_{t-k} + e_t`, `var(e) = s2`, observed
/// without noise (`y_t = x_t`) except where a sample is skipped as an outlier. State: the estimates
/// of `x_{t-1}, ..., x_{t-m}` (newest first) and their error covariance P. After m consecutive
/// observed samples the state is known exactly (P = 0) and a step costs O(m); otherwise O(m^2).
#[derive(Clone)]
struct ArKalman<'a> {
    a: &'a [f64],
    s2: f64,
    state: Vec<f64>,
    p: Vec<f64>,
    /// Prediction covariance of the current step (valid when `exact < m`).
    mm: Vec<f64>,
    /// Consecutive observed samples since the last skipped one (>= m: P = 0).
    exact: usize,
}

impl<'a> ArKalman<'a> {
    /// Starts from exactly known past samples `past` (oldest first, length m).
    fn new(a: &'a [f64], s2: f64, past: &[f64]) -> Self {
        let m = a.len() - 1;
        ArKalman {
            a,
            s2,
            state: past.iter().rev().copied().collect(),
            p: vec![0.0; m * m],
            mm: vec![0.0; m * m],
            exact: m,
        }
    }

    fn m(&self) -> usize {
        self.state.len()
    }

    /// One-step prediction of the next sample and its error variance.
    fn predict(&mut self) -> (f64, f64) {
        let m = self.m();
        let pred = -(1..=m).map(|k| self.a[k] * self.state[k - 1]).sum::<f64>();
        if self.exact >= m {
            return (pred, self.s2);
        }
        // G = Phi P (companion Phi: first row -a_1..-a_m, then the shift), M = G Phi^T + s2 e1 e1^T.
        let mut g = vec![0.0; m * m];
        for (j, gj) in g.iter_mut().enumerate().take(m) {
            *gj = -(1..=m)
                .map(|k| self.a[k] * self.p[(k - 1) * m + j])
                .sum::<f64>();
        }
        g[m..].copy_from_slice(&self.p[..(m - 1) * m]);
        for i in 0..m {
            let row = &g[i * m..(i + 1) * m];
            self.mm[i * m] = -(1..=m).map(|k| self.a[k] * row[k - 1]).sum::<f64>();
            for j in 1..m {
                self.mm[i * m + j] = row[j - 1];
            }
        }
        self.mm[0] += self.s2;
        (pred, self.mm[0])
    }

    /// Observes the predicted sample as `y` (`pred`, `var` from [`Self::predict`]).
    fn observe(&mut self, y: f64, pred: f64, var: f64) {
        let m = self.m();
        self.state.rotate_right(1);
        self.state[0] = pred;
        if self.exact >= m {
            self.state[0] = y;
        } else {
            let r = y - pred;
            for i in 0..m {
                self.state[i] += self.mm[i * m] / var * r;
            }
            self.state[0] = y;
            for i in 0..m {
                for j in 0..m {
                    self.p[i * m + j] = self.mm[i * m + j] - self.mm[i * m] * self.mm[j] / var;
                }
            }
        }
        self.exact += 1;
        if self.exact >= m {
            self.p.iter_mut().for_each(|v| *v = 0.0);
        }
    }

    /// Skips the predicted sample (treated as missing): the state advances by the prediction.
    fn skip(&mut self, pred: f64) {
        let m = self.m();
        self.state.rotate_right(1);
        self.state[0] = pred;
        if self.exact >= m {
            self.p.iter_mut().for_each(|v| *v = 0.0);
            self.p[0] = self.s2;
        } else {
            self.p.copy_from_slice(&self.mm);
        }
        self.exact = 0;
    }
}

/// One filter-cleaner sweep over `range` (every t in it has t >= m = a.len() - 1): `x` holds the
/// cleaned signal before `range.start` and receives the cleaned values in `range`; `raw` is the
/// raw signal, `s` the innovation scale, `k` the threshold (robust standard deviations).
fn filter_forward(
    raw: &[f64],
    x: &mut [f64],
    flags: &mut [bool],
    a: &[f64],
    s: f64,
    k: f64,
    range: std::ops::Range<usize>,
) {
    let n = raw.len();
    let m = a.len() - 1;
    let start = range.start;
    let mut kf = ArKalman::new(a, s * s, &x[start - m..start]);
    for t in range {
        let (pred, var) = kf.predict();
        let r = raw[t] - pred;
        x[t] = raw[t];
        if r * r <= k * k * var {
            kf.observe(raw[t], pred, var);
            continue;
        }
        let look = m.min(n - 1 - t);
        let mut keep = kf.clone();
        keep.observe(raw[t], pred, var);
        let mut replace = kf.clone();
        replace.skip(pred);
        let loss_keep = lookahead_loss(&raw[t + 1..=t + look], keep, k);
        let loss_replace = lookahead_loss(&raw[t + 1..=t + look], replace, k);
        // The last sample (the first, in the backward run) has nothing after it to tell a spike
        // from the start of a step: it is replaced when it lies beyond END_FACTOR x threshold.
        let at_end = look == 0 && r * r > (END_FACTOR * k) * (END_FACTOR * k) * var;
        if at_end || loss_replace < REPLACE_MARGIN * loss_keep {
            kf.skip(pred);
            x[t] = pred;
            flags[t] = true;
        } else {
            kf.observe(raw[t], pred, var);
        }
    }
}

/// A last (or first) sample is replaced beyond this many times the threshold (no look-ahead
/// there): a 1e12 spike in the last of 2048 samples was kept and made the noise variance 5e20.
const END_FACTOR: f64 = 5.0;

/// Loss of the standardised residuals `r / sqrt(var)` of the samples `next` when filtered by `kf`
/// with the simple rule: a residual beyond `k` costs `k^2` and its sample is skipped, otherwise it
/// costs its square. A second spike inside the look-ahead window thus costs both hypotheses alike
/// instead of masking the comparison.
fn lookahead_loss(next: &[f64], mut kf: ArKalman<'_>, k: f64) -> f64 {
    let mut loss = 0.0;
    for &y in next {
        let (pred, var) = kf.predict();
        let z2 = (y - pred) * (y - pred) / var;
        if z2 > k * k {
            loss += k * k;
            kf.skip(pred);
        } else {
            loss += z2;
            kf.observe(y, pred, var);
        }
    }
    loss
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A spike in the first or last sample is replaced like one inside the signal (it was kept:
    /// no look-ahead there), over many seeds; a sample at the end within the noise is kept.
    #[test]
    fn spikes_at_the_ends_are_replaced() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        for seed in 0..20u64 {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let noise = Normal::new(0.0, 1.0).unwrap();
            let y0: Vec<f64> = (0..2048).map(|_| noise.sample(&mut rng)).collect();
            for (pos, size) in [(0usize, 1e12), (2047, 1e12), (2047, -50.0), (0, 40.0)] {
                let mut y = y0.clone();
                y[pos] += size;
                let c = clean_additive_outliers(&y, &CleanerParams::default()).unwrap();
                assert!(
                    c.replaced.contains(&pos),
                    "seed {seed}: spike {size} at {pos} kept"
                );
                assert!(
                    c.y[pos].abs() < 10.0,
                    "seed {seed}: replaced by {}",
                    c.y[pos]
                );
            }
            let c = clean_additive_outliers(&y0, &CleanerParams::default()).unwrap();
            assert!(
                !c.replaced.contains(&0) && !c.replaced.contains(&2047),
                "seed {seed}: a noise sample at an end replaced"
            );
        }
    }

    /// AR(2) x_t = 1.5 x_{t-1} - 0.7 x_{t-2} + e_t with a deterministic small innovation.
    fn ar2(n: usize) -> Vec<f64> {
        let mut x = vec![0.0; n];
        x[0] = 1.0;
        x[1] = 0.5;
        for t in 2..n {
            let e = 0.1 * ((t as f64) * 1.3).sin();
            x[t] = 1.5 * x[t - 1] - 0.7 * x[t - 2] + e;
        }
        x
    }

    #[test]
    fn spike_replaced_by_exactly_its_prediction_known_model() {
        let a = [1.0, -1.5, 0.7];
        let clean = ar2(60);
        let mut y = clean.clone();
        y[30] += 50.0;
        let mut x = y.clone();
        let mut flags = vec![false; y.len()];
        filter_forward(&y, &mut x, &mut flags, &a, 0.25, 4.0, 2..60);
        // Prediction by hand: 1.5 x_29 - 0.7 x_28 (both clean samples).
        let pred = 1.5 * clean[29] - 0.7 * clean[28];
        assert_eq!(x[30], pred);
        // Only the spike is flagged: the other residuals are |e_t| <= 0.1 < 1 (or, just after the
        // spike, computed from the cleaned past).
        let flagged: Vec<usize> = (0..60).filter(|&t| flags[t]).collect();
        assert_eq!(flagged, vec![30]);
        for t in (0..60).filter(|&t| t != 30) {
            assert_eq!(x[t], y[t], "sample {t} changed");
        }
    }

    #[test]
    fn innovation_outlier_kept_known_model() {
        // A large innovation at t = 30 (the process keeps following it): residual 50 > cut, but
        // replacing it would make the next residuals -a_j * 50 -> kept.
        let a = [1.0, -1.5, 0.7];
        let n = 60;
        let mut x = vec![0.0; n];
        x[0] = 1.0;
        x[1] = 0.5;
        for t in 2..n {
            let e = 0.1 * ((t as f64) * 1.3).sin() + if t == 30 { 50.0 } else { 0.0 };
            x[t] = 1.5 * x[t - 1] - 0.7 * x[t - 2] + e;
        }
        let mut out = x.clone();
        let mut flags = vec![false; n];
        filter_forward(&x, &mut out, &mut flags, &a, 0.25, 4.0, 2..n);
        assert!(flags.iter().all(|f| !f));
        assert_eq!(out, x);
    }

    #[test]
    fn kalman_ar1_after_a_skipped_sample_by_hand() {
        // AR(1) x_t = 0.8 x_{t-1} + e_t, var(e) = 1, x_0 = 2 known. Skip x_1 (missing): x_2 is
        // predicted as 0.8^2 * 2 = 1.28 with variance 1 + 0.8^2 = 1.64. Observing x_2 = 3 gives the
        // interpolated x_1 = 0.8 (x_0 + x_2) / (1 + 0.8^2) = 4 / 1.64 in the state.
        let a = [1.0, -0.8];
        let mut kf = ArKalman::new(&a, 1.0, &[2.0]);
        let (p1, v1) = kf.predict();
        assert_eq!((p1, v1), (1.6, 1.0));
        kf.skip(p1);
        let (p2, v2) = kf.predict();
        assert!(
            (p2 - 1.28).abs() < 1e-15 && (v2 - 1.64).abs() < 1e-15,
            "{p2} {v2}"
        );
        kf.observe(3.0, p2, v2);
        // State holds x_2 only (m = 1); check the interpolation with m = 2 instead.
        assert_eq!(kf.state, vec![3.0]);
        let a2 = [1.0, -0.8, 0.0];
        let mut kf = ArKalman::new(&a2, 1.0, &[0.0, 2.0]);
        let (p1, _) = kf.predict();
        kf.skip(p1);
        let (p2, v2) = kf.predict();
        assert!(
            (p2 - 1.28).abs() < 1e-15 && (v2 - 1.64).abs() < 1e-15,
            "{p2} {v2}"
        );
        kf.observe(3.0, p2, v2);
        assert_eq!(kf.state[0], 3.0);
        assert!((kf.state[1] - 4.0 / 1.64).abs() < 1e-14, "{:?}", kf.state);
        // Two more observed samples: the state is exact again (P = 0, variance back to s2).
        for y in [2.0, 1.0] {
            let (p, v) = kf.predict();
            kf.observe(y, p, v);
        }
        assert!(kf.p.iter().all(|&v| v == 0.0));
        assert_eq!(kf.predict(), (0.8, 1.0));
    }

    #[test]
    fn masked_fb_ls_without_mask_is_forward_backward_least_squares() {
        let x: Vec<f64> = ar2(400).iter().map(|v| v - 0.1).collect();
        let (a, s) = masked_fb_ls(&x, &vec![false; 400], 3).unwrap();
        let (a_ref, _) = crate::ar::fb_least_squares(&x, 3);
        for (u, v) in a.iter().zip(&a_ref) {
            assert!((u - v).abs() < 1e-10, "{a:?} vs {a_ref:?}");
        }
        assert!(s.is_finite() && s > 0.0);
        // A masked sample removes exactly the windows that contain it: corrupting it changes
        // nothing.
        let mut bad = vec![false; 400];
        bad[200] = true;
        let mut y = x.clone();
        let (a1, _) = masked_fb_ls(&y, &bad, 3).unwrap();
        y[200] = 1e6;
        let (a2, _) = masked_fb_ls(&y, &bad, 3).unwrap();
        assert_eq!(a1, a2);
    }
}
