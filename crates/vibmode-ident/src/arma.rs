//! ARMA(p, q) by (robust) prediction-error minimisation. See docs/identification.md.

use num_complex::Complex64;

use crate::ar::{burg, burg_ladder};
use nalgebra::DMatrix;

use crate::linalg::{
    check_signal, cholesky_solve, dot, filter_inv_c, filter_inv_c_adjoint, filter_inv_c_each,
    is_min_phase, lagged_dot, lagged_gram, mirror_upper_block, predict_errors, robust_std,
    spd_inverse_diag, Lags,
};
use crate::model::{information_criteria, ArmaModel, Estimator, StopReason};
use crate::outliers::OutlierCleaning;
use crate::params::{ArmaParams, Robust, SearchStarts};
use crate::prepare::{self, Prepared};
use crate::roots::{aberth_roots_from, polynomial_roots, polynomial_roots_unpolished};
use crate::IdentError;

/// Largest N p (p + q) for which the AR columns of the Jacobian are filtered exactly
/// (O(N p (p + q)) per iteration); beyond it delayed copies of y/C are used.
const EXACT_JACOBIAN_BUDGET: f64 = 1.0e8;

/// Largest p + q searched from every starting candidate (multi-start).
const MULTISTART_MAX_ORDER: usize = 16;

/// Trial steps per iteration whose C leaves the unit circle and is reflected back (root finding);
/// further such trials are halved instead.
const MAX_REFLECTIONS: usize = 3;

/// Iterations over which the stall rule measures progress.
const STALL_WINDOW: usize = 5;

/// Initial Levenberg-Marquardt ridge of the Gauss-Newton search (relative to the unit diagonal of
/// the Jacobi-scaled normal matrix): small, so that a well-conditioned first step is almost a
/// pure Gauss-Newton step.
const MU_INITIAL: f64 = 1e-6;

/// Smallest ridge: at or below it the plain Gauss-Newton direction is used (the ridge would only
/// change the last digits of the step).
const MU_MIN: f64 = 1e-12;

/// Largest ridge: the step is then a short Jacobi-scaled gradient step; a larger ridge would only
/// shorten it further, which the step halvings do anyway.
const MU_MAX: f64 = 1e6;

/// Factor applied to the ridge after a full (unhalved) step.
const MU_DECREASE: f64 = 0.1;

/// Factor applied to the ridge after a step that needed halving.
const MU_INCREASE: f64 = 10.0;

/// Ridge of the solve for the Newton decrement (the predicted decrease that decides
/// convergence): just enough to factor a numerically singular normal matrix, without changing the
/// prediction.
const NEWTON_DECREMENT_RIDGE: f64 = 1e-12;

/// Ridge of the Hannan-Rissanen regression: its regressors (y and long-AR residuals) can be
/// nearly collinear for overfitted orders; 1e-10 keeps the solve stable without visibly biasing
/// a starting point that the search refines anyway.
const HANNAN_RISSANEN_RIDGE: f64 = 1e-10;

/// Attempts of [`solve_scaled`], each with the ridge multiplied by [`RIDGE_GROWTH`]: from
/// [`MIN_RIDGE`], 8 attempts reach 1e2 (a matrix dominated by its ridge, which always factors).
const RIDGE_ESCALATIONS: usize = 8;

/// Growth of the ridge between attempts of [`solve_scaled`].
const RIDGE_GROWTH: f64 = 100.0;

/// First non-zero ridge of [`solve_scaled`] when the requested one is zero (rounding level).
const MIN_RIDGE: f64 = 1e-12;

/// A search without a lower point has converged when the Newton decrement is within this
/// multiple of `tol x V`: a predicted gain that small is at the criterion's numerical floor, where
/// rounding in the loss hides any real decrease.
const NO_STEP_TOL_FACTOR: f64 = 100.0;

/// C has a zero "on" the unit circle when its modulus exceeds 1 - 1e-6: the radial shrink of
/// [`stabilise`] moves roots by at most this much, so such a zero is at the boundary of the
/// minimum-phase set.
const BOUNDARY_MARGIN: f64 = 1e-6;

/// Radial shrink factors tried in turn by [`stabilise`] for roots on or just outside the unit
/// circle (1 - 1e-9 .. 1 - 1e-6): the smallest move that makes C minimum phase, so that a
/// converged C whose zeros sit within rounding of the circle is changed as little as possible.
const SHRINK_FACTORS: [f64; 4] = [1.0 - 1e-9, 1.0 - 1e-8, 1.0 - 1e-7, 1.0 - 1e-6];

/// Shrink factor of the last-resort loop of [`stabilise`] (roots on the unit circle or failed root
/// finding), and the most times it is applied (0.999^200 ~ 0.82: far inside the circle).
const FALLBACK_SHRINK: f64 = 0.999;
/// See [`FALLBACK_SHRINK`].
const FALLBACK_SHRINK_STEPS: usize = 200;

/// Largest `p + q` allowed for `n` samples: `n / 3`.
pub fn max_arma_order(n: usize) -> usize {
    n / 3
}

/// Fits ARMA(p, q) `A(q) y_t = C(q) e_t` by minimising `V = (1/N) sum l(eps_t)`,
/// `eps = (A/C) y` with zero initial conditions (see docs/identification.md for every detail).
///
/// Starts from the best (by the residuals' robust scale, or mean square when `Robust::Off`) of a
/// Hannan-Rissanen estimate and a Burg AR(p) model, then runs damped Gauss-Newton. A fit that hits
/// `max_iterations` is returned with `converged: false`. `q = 0` is allowed (robust AR by prediction
/// error); `p = 0` is an error (no poles, no modes). With `Robust::Huber` and the default
/// `outlier_cleaning`, additive spikes are first replaced by [`crate::clean_additive_outliers`]
/// (count in `ArmaModel::outliers_replaced`).
///
/// Errors: empty, non-finite or constant input; `p = 0`; `q > p`; `p + q > N/3`; invalid params.
pub fn fit_arma(
    y: &[f64],
    p: usize,
    q: usize,
    params: &ArmaParams,
) -> Result<ArmaModel, IdentError> {
    fit_impl(y, p, q, None, params)
}

/// As [`fit_arma`], with `init` (a model of orders `init.p <= p`, `init.q <= q`, e.g. the
/// previous order of a sweep, zero-padded) as an extra starting candidate.
pub fn fit_arma_warm(
    y: &[f64],
    p: usize,
    q: usize,
    init: &ArmaModel,
    params: &ArmaParams,
) -> Result<ArmaModel, IdentError> {
    fit_impl(y, p, q, Some(init), params)
}

/// Order sweep: fits ARMA(o, o) for every `o` in `orders`, in the given order, each warm-started
/// from the previous successful fit of lower or equal order (ascending `orders` is best).
///
/// Each fit is what [`fit_arma_warm`] returns from the previous one, except that its
/// `std_errors` are NaN (the sweep's product is its poles; the standard errors would cost one more
/// Gauss-Newton matrix per order).
pub fn sweep_arma(
    y: &[f64],
    orders: &[usize],
    params: &ArmaParams,
) -> Vec<Result<ArmaModel, IdentError>> {
    let mut out: Vec<Result<ArmaModel, IdentError>> = Vec::with_capacity(orders.len());
    // Additive outliers are cleaned once for the whole sweep (the same result at every order).
    let cleaned = check_signal(y, 3)
        .and_then(|mean| prepare::cleaned(y, mean, params))
        .map(|(yc, _, k)| (yc.into_owned(), k));
    let (yc, replaced) = match cleaned {
        Ok(v) => v,
        Err(e) => {
            out.extend(orders.iter().map(|_| Err(e.clone())));
            return out;
        }
    };
    let inner = ArmaParams {
        outlier_cleaning: OutlierCleaning::Off,
        ..*params
    };
    // What every order shares, prepared once (as `fit_impl` would at each order): the checks that
    // do not depend on the order, the scaled signal, and the Burg polynomials of every order the
    // starting candidates use (one recursion instead of two per order, the same bits).
    let shared = inner
        .validate()
        .and_then(|()| check_signal(&yc, 3))
        .map(|mean| prepare::for_search(&yc, mean, &inner));
    let ladder_order = orders
        .iter()
        .filter(|&&o| o >= 1 && 2 * o <= max_arma_order(yc.len()))
        .map(|&o| burg_orders_needed(yc.len(), o, o))
        .max()
        .unwrap_or(0);
    let ladder = match &shared {
        Ok(Ok(prepared)) if ladder_order > 0 => burg_ladder(&prepared.ys, ladder_order),
        _ => Vec::new(),
    };
    let mut prev: Option<ArmaModel> = None;
    for &o in orders {
        let init = prev.as_ref().filter(|m| m.p <= o && m.q <= o);
        let r = match &shared {
            Err(e) => Err(e.clone()),
            Ok(prepared) => check_orders(yc.len(), o, o, init).and_then(|()| {
                let prepared = prepared.as_ref().map_err(Clone::clone)?;
                let out = search(
                    &prepared.ys,
                    o,
                    o,
                    init.map(|m| (&m.a[..], &m.c[..])),
                    &inner,
                    &ladder,
                );
                Ok(finish_model(prepared, o, o, out, &inner, false))
            }),
        }
        .map(|mut m| {
            m.outliers_replaced = replaced;
            m
        });
        if let Ok(m) = &r {
            prev = Some(m.clone());
        }
        out.push(r);
    }
    out
}

/// The highest Burg order the starting candidates of ARMA(p, q) on `n` samples use: the long AR
/// model of [`hannan_rissanen`] and the AR(p) candidate.
fn burg_orders_needed(n: usize, p: usize, q: usize) -> usize {
    hr_long_order(n, p, q).max(p)
}

/// The order of the long AR model of [`hannan_rissanen`] (0 when q = 0: none is fitted).
fn hr_long_order(n: usize, p: usize, q: usize) -> usize {
    if q == 0 {
        0
    } else {
        (p + HR_LONG_AR_PER_MA * q).min(n / 3).max(p + q)
    }
}

/// Burg's AR(m) polynomial of `ys`: from `ladder` (the polynomials of every order up to its
/// length, [`burg_ladder`] of the same `ys`) when it reaches `m`, else by [`burg`].
fn burg_poly(ys: &[f64], m: usize, ladder: &[Vec<f64>]) -> Vec<f64> {
    match ladder.get(m) {
        Some(a) => a.clone(),
        None => burg(ys, m).0,
    }
}

/// Huber loss (or quadratic when `rho` is None).
#[inline]
fn loss_of(e: f64, rho: Option<f64>) -> f64 {
    match rho {
        Some(r) if e.abs() > r => 2.0 * r * e.abs() - r * r,
        _ => e * e,
    }
}

fn mean_loss(eps: &[f64], rho: Option<f64>) -> f64 {
    eps.iter().map(|&e| loss_of(e, rho)).sum::<f64>() / eps.len() as f64
}

/// Monic polynomial (z^-1 form, leading 1) from its roots: the real parts of the coefficients
/// of `prod (z - r)`, highest power first (real where `roots` is closed under conjugation).
pub(crate) fn poly_from_roots(roots: &[Complex64]) -> Vec<f64> {
    let mut c = vec![Complex64::new(1.0, 0.0)];
    for &r in roots {
        let mut next = vec![Complex64::new(0.0, 0.0); c.len() + 1];
        for (i, &ci) in c.iter().enumerate() {
            next[i] += ci;
            next[i + 1] -= ci * r;
        }
        c = next;
    }
    c.iter().map(|z| z.re).collect()
}

/// Makes C minimum phase. Roots on or just outside the unit circle (a converged fit's C may have
/// zeros within rounding of it) are first moved radially inwards by a factor 1 - 1e-9 .. 1 - 1e-6
/// (c_k -> c_k r^k, exact up to one rounding per coefficient); otherwise roots outside the circle
/// are reflected (z -> 1/conj z). Rebuilding C from its roots loses many digits when they crowd
/// near the circle, so it is avoided where the radial shrink suffices.
fn stabilise(c: &mut [f64]) {
    stabilise_from(c, &mut Vec::new());
}

/// As [`stabilise`], the roots' iteration started from `roots_cache` (the roots of the C last
/// reflected in the same search, when of the same degree: the trial steps of one search move C
/// little), which then receives the roots of this C.
fn stabilise_from(c: &mut [f64], roots_cache: &mut Vec<Complex64>) {
    if c.len() <= 1 || is_min_phase(c) {
        return;
    }
    for r in SHRINK_FACTORS {
        let mut shrunk = c.to_vec();
        shrink_roots(&mut shrunk, r);
        if is_min_phase(&shrunk) {
            c.copy_from_slice(&shrunk);
            return;
        }
    }
    // Unpolished roots: the reflected C is a trial point of the search, not a result. Aberth's
    // iteration (O(q^2) per sweep) first, the companion matrix if it does not settle.
    let roots = aberth_roots_from(c, roots_cache)
        .map(Ok)
        .unwrap_or_else(|| polynomial_roots_unpolished(c));
    if let Ok(roots) = roots {
        roots_cache.clear();
        roots_cache.extend_from_slice(&roots);
        let refl: Vec<Complex64> = roots
            .iter()
            .map(|&z| {
                let m = z.norm();
                if m > 1.0 {
                    z / (m * m)
                } else {
                    z
                }
            })
            .collect();
        let new = poly_from_roots(&refl);
        if new.len() == c.len() && new.iter().all(|v| v.is_finite()) {
            c.copy_from_slice(&new);
        }
    }
    // Fallback (roots on the unit circle or failed root finding): shrink all roots.
    let mut guard = 0;
    while !is_min_phase(c) && guard < FALLBACK_SHRINK_STEPS {
        shrink_roots(c, FALLBACK_SHRINK);
        guard += 1;
    }
}

/// Moves every root of C radially by the factor `r` (`c_k -> c_k r^k`).
fn shrink_roots(c: &mut [f64], r: f64) {
    let mut rk = 1.0;
    for ck in c.iter_mut().skip(1) {
        rk *= r;
        *ck *= rk;
    }
}

struct Candidate {
    a: Vec<f64>,
    c: Vec<f64>,
    eps: Vec<f64>,
    score: f64,
    /// The caller's warm start (the previous order's solution in a sweep).
    warm: bool,
}

fn make_candidate(ys: &[f64], a: Vec<f64>, mut c: Vec<f64>, robust: bool) -> Option<Candidate> {
    if !(a.iter().all(|v| v.is_finite()) && c.iter().all(|v| v.is_finite())) {
        return None;
    }
    stabilise(&mut c);
    let mut eps = vec![0.0; ys.len()];
    predict_errors(ys, &a, &c, &mut eps);
    let t0 = a.len() - 1;
    let score = if robust {
        robust_std(&eps[t0..])
    } else {
        mean_loss(&eps[t0..], None)
    };
    if !score.is_finite() {
        return None;
    }
    Some(Candidate {
        a,
        c,
        eps,
        score,
        warm: false,
    })
}

/// The long AR model of the Hannan-Rissanen estimate has order p + 4 q (at most N / 3, at least
/// p + q): long enough for its residuals to approximate the innovations of an ARMA(p, q) whose
/// MA zeros are not close to the unit circle.
const HR_LONG_AR_PER_MA: usize = 4;

/// Hannan-Rissanen initial estimate on the scaled signal.
fn hannan_rissanen(ys: &[f64], p: usize, q: usize, ladder: &[Vec<f64>]) -> (Vec<f64>, Vec<f64>) {
    let n = ys.len();
    let k = p + q;
    let (ehat, t0) = if q > 0 {
        let m = hr_long_order(n, p, q);
        let a_long = burg_poly(ys, m, ladder);
        let mut e = vec![0.0; n];
        predict_errors(ys, &a_long, &[1.0], &mut e);
        (e, m + q)
    } else {
        (Vec::new(), p)
    };
    let mut g = DMatrix::<f64>::zeros(k, k);
    let (y_lags, e_lags) = (Lags::new(ys, p), Lags::new(&ehat, q));
    lagged_gram(y_lags, y_lags, t0, g.view_mut((0, 0), (p, p)), 1.0);
    if q > 0 {
        lagged_gram(y_lags, e_lags, t0, g.view_mut((0, p), (p, q)), -1.0);
        lagged_gram(e_lags, e_lags, t0, g.view_mut((p, p), (q, q)), 1.0);
        mirror_upper_block(&mut g, p);
    }
    let mut rhs = vec![0.0; k];
    for i in 1..=p {
        rhs[i - 1] = -lagged_dot(ys, i, ys, 0, t0);
    }
    for j in 1..=q {
        rhs[p + j - 1] = lagged_dot(&ehat, j, ys, 0, t0);
    }
    let theta = solve_scaled(&g, &rhs, HANNAN_RISSANEN_RIDGE).unwrap_or_else(|| vec![0.0; k]);
    let mut a = vec![1.0];
    a.extend_from_slice(&theta[..p]);
    let mut c = vec![1.0];
    c.extend_from_slice(&theta[p..]);
    (a, c)
}

/// Solves `h x = b` after Jacobi scaling, with relative ridge `mu` (added to the unit diagonal),
/// escalating the ridge if the factorisation fails.
fn solve_scaled(h: &DMatrix<f64>, b: &[f64], mu: f64) -> Option<Vec<f64>> {
    Scaled::new(h, b).solve(mu)
}

/// The Jacobi-scaled system `D^-1 h D^-1 (D x) = D^-1 b` (D = sqrt(diag h), 1 where that is not
/// positive), formed once for solves with several ridges.
struct Scaled {
    d: Vec<f64>,
    hs: DMatrix<f64>,
    bs: Vec<f64>,
}

impl Scaled {
    fn new(h: &DMatrix<f64>, b: &[f64]) -> Self {
        let k = h.nrows();
        let d: Vec<f64> = (0..k)
            .map(|i| {
                let v = h[(i, i)];
                if v > 0.0 && v.is_finite() {
                    v.sqrt()
                } else {
                    1.0
                }
            })
            .collect();
        let hs = DMatrix::from_fn(k, k, |i, j| h[(i, j)] / (d[i] * d[j]));
        let bs: Vec<f64> = (0..k).map(|i| b[i] / d[i]).collect();
        Scaled { d, hs, bs }
    }

    /// The solution with relative ridge `mu`, escalated while the factorisation fails.
    fn solve(&self, mu: f64) -> Option<Vec<f64>> {
        let mut ridge = mu;
        for _ in 0..RIDGE_ESCALATIONS {
            if let Some(x) = cholesky_solve(&self.hs, &self.bs, ridge) {
                return Some(x.iter().zip(&self.d).map(|(v, di)| v / di).collect());
            }
            ridge = if ridge > 0.0 {
                ridge * RIDGE_GROWTH
            } else {
                MIN_RIDGE
            };
        }
        None
    }
}

/// Scratch buffers and fixed data of one search.
struct Search<'a> {
    ys: &'a [f64],
    p: usize,
    q: usize,
    rho: Option<f64>,
    yf: Vec<f64>,
    ef: Vec<f64>,
    u: Vec<f64>,
    /// The exact AR columns of the Jacobian (when `exact_cols`), their buffers kept across
    /// iterations.
    cols: Vec<Vec<f64>>,
    exact_cols: bool,
    /// Scratch of [`Search::exact_ar_block`]: the delayed signal and the impulse response of 1/C.
    z: Vec<f64>,
    g: Vec<f64>,
}

impl<'a> Search<'a> {
    fn new(ys: &'a [f64], p: usize, q: usize, rho: Option<f64>) -> Self {
        let n = ys.len();
        Search {
            ys,
            p,
            q,
            rho,
            yf: vec![0.0; n],
            ef: vec![0.0; n],
            u: vec![0.0; n],
            cols: Vec::new(),
            exact_cols: false,
            z: Vec::new(),
            g: Vec::new(),
        }
    }

    /// Gradient `sum w eps psi` and matrix `sum w psi psi^T` (raw sums; Huber weights applied
    /// exactly through a sparse correction of the unweighted Toeplitz-structured Gram), plus the
    /// unweighted Gram. The Jacobian of `eps = (A/C) y` does not depend on A, so only `c` is
    /// needed besides the current residuals `eps`.
    fn normal_equations(
        &mut self,
        c: &[f64],
        eps: &[f64],
    ) -> (Vec<f64>, DMatrix<f64>, DMatrix<f64>) {
        let h_unweighted = self.gram(c, eps);
        let mut h = h_unweighted.clone();
        let g = self.gradient(c, eps);
        if let Some(r) = self.rho {
            self.add_huber_correction(eps, r, &mut h);
        }
        (g, h, h_unweighted)
    }

    /// Unweighted Gram `sum psi psi^T` of the Jacobian rows `psi_t` (t >= p), after filtering
    /// `y / C` and `eps / C` into the scratch buffers.
    fn gram(&mut self, c: &[f64], eps: &[f64]) -> DMatrix<f64> {
        let (p, q) = (self.p, self.q);
        let k = p + q;
        let n = self.ys.len();
        let mut h = DMatrix::<f64>::zeros(k, k);
        // Exact a-columns (1/C)[y_{t-k} 1{t >= p}] when affordable; otherwise delayed copies of y/C
        // (ignores that A(q) y is only formed from t = p on: a transient-only approximation).
        let exact = (n as f64) * (p as f64) * (k as f64) <= EXACT_JACOBIAN_BUDGET;
        self.exact_cols = false;
        // The filters by 1/C this step needs, run side by side ([`filter_inv_c_each`]): eps / C,
        // and y / C or the exact columns' first column and impulse response.
        if exact && self.exact_buffers() {
            let mut delta = vec![0.0; n - p];
            delta[0] = 1.0;
            filter_inv_c_each(
                &[eps, &self.z, &delta],
                c,
                &mut [&mut self.ef, &mut self.cols[0], &mut self.g],
            );
            self.exact_ar_block(&mut h);
        } else if exact {
            filter_inv_c(eps, c, &mut self.ef);
        } else {
            filter_inv_c_each(&[eps, self.ys], c, &mut [&mut self.ef, &mut self.yf]);
        }
        let (yf, ef) = (Lags::new(&self.yf, p), Lags::new(&self.ef, q));
        if !exact {
            lagged_gram(yf, yf, p, h.view_mut((0, 0), (p, p)), 1.0);
            if q > 0 {
                lagged_gram(yf, ef, p, h.view_mut((0, p), (p, q)), -1.0);
            }
        }
        if q > 0 {
            lagged_gram(ef, ef, p, h.view_mut((p, p), (q, q)), 1.0);
            mirror_upper_block(&mut h, p);
        }
        h
    }

    /// Whether the exact AR columns apply (`p > 0` and more samples than `p`), with their
    /// buffers made: `z`, the delayed signal; `g`, the impulse response's; `cols`.
    ///
    /// Column i is (1/C) z_i with z_i[t] = y[t-i] for t >= p, else 0. Since
    /// z_{i+1} = (z_i delayed by one) + y[p-1-i] delta_p and 1/C is linear and time-invariant,
    /// col_{i+1}[t] = col_i[t-1] + y[p-1-i] g[t-p], g the impulse response of 1/C: one filter
    /// pass for the first column and the impulse response instead of one pass per column.
    fn exact_buffers(&mut self) -> bool {
        let p = self.p;
        let n = self.ys.len();
        if p == 0 || n <= p {
            return false;
        }
        if self.z.len() != n {
            self.z = vec![0.0; n];
            for (t, zt) in self.z.iter_mut().enumerate().skip(p) {
                *zt = self.ys[t - 1];
            }
            self.g = vec![0.0; n - p];
            self.cols = vec![vec![0.0; n]; p];
        }
        true
    }

    /// The exact AR columns of the Jacobian into `self.cols` from the first (`(1/C) z`) and the
    /// impulse response of 1/C in `self.g` ([`Search::exact_buffers`]), and the rows `0..p`
    /// of the Gram (the AR block and the upper AR-MA block).
    fn exact_ar_block(&mut self, h: &mut DMatrix<f64>) {
        let p = self.p;
        let n = self.ys.len();
        // b[i]: the impulse's weight from column i to column i + 1.
        let b: Vec<f64> = (0..p - 1).map(|i| self.ys[p - 2 - i]).collect();
        for (i, &bi) in b.iter().enumerate() {
            let (done, rest) = self.cols.split_at_mut(i + 1);
            let (prev, next) = (&done[i], &mut rest[0]);
            // One pass: the previous column delayed by one, plus the impulse's share from p on
            // (the same sums as a copy followed by the addition).
            next[0] = 0.0;
            next[1..p].copy_from_slice(&prev[..p - 1]);
            for ((nt, &pt), &gt) in next[p..].iter_mut().zip(&prev[p - 1..n - 1]).zip(&self.g) {
                *nt = pt + bi * gt;
            }
        }
        self.exact_cols = true;
        let g = std::mem::take(&mut self.g);
        self.ar_gram_blocks(&g, &b, h);
        self.g = g;
    }

    /// The AR block `G[i][j] = sum_{t>=p} col_i[t] col_j[t]` and the AR-MA block
    /// `M[i][j] = sum_{t>=p} col_i[t] ef[t-j]` (stored negated) of the Gram, from their first
    /// row and column by the shift recursion of the columns (columns vanish before `p`):
    /// `G[i+1][j+1] = G[i][j] - col_i[n-1] col_j[n-1] + b_j D_i + b_i D_j + b_i b_j (g.g)` with
    /// `D_i = sum_{t>=p} col_i[t-1] g[t-p]`, and
    /// `M[i+1][j+1] = M[i][j] - col_i[n-1] ef[n-1-j] + b_i E_j` with
    /// `E_j = sum_{t>=p} g[t-p] ef[t-1-j]`: O(N (p + q) + p (p + q)) instead of O(N p (p + q)).
    fn ar_gram_blocks(&self, g: &[f64], b: &[f64], h: &mut DMatrix<f64>) {
        let (p, q) = (self.p, self.q);
        let n = self.ys.len();
        let cols = &self.cols;
        let last: Vec<f64> = cols.iter().map(|c| c[n - 1]).collect();
        let d: Vec<f64> = cols[..p - 1]
            .iter()
            .map(|c| dot(&c[p - 1..n - 1], g))
            .collect();
        let gg = dot(g, g);
        for j in 0..p {
            h[(0, j)] = dot(&cols[0][p..], &cols[j][p..]);
        }
        for i in 0..p - 1 {
            for j in i..p - 1 {
                let v =
                    h[(i, j)] - last[i] * last[j] + b[j] * d[i] + b[i] * d[j] + b[i] * b[j] * gg;
                h[(i + 1, j + 1)] = v;
            }
        }
        for i in 0..p {
            for j in 0..i {
                h[(i, j)] = h[(j, i)];
            }
        }
        if q == 0 {
            return;
        }
        let ef = &self.ef;
        // m[i][j - 1] = M[i][j] (MA lag j = 1..q).
        let mut m = DMatrix::<f64>::zeros(p, q);
        for j in 1..=q {
            m[(0, j - 1)] = dot(&cols[0][p..n], &ef[p - j..n - j]);
        }
        for i in 1..p {
            m[(i, 0)] = dot(&cols[i][p..n], &ef[p - 1..n - 1]);
        }
        let e: Vec<f64> = (1..q).map(|j| dot(g, &ef[p - 1 - j..n - 1 - j])).collect();
        for i in 0..p - 1 {
            for j in 1..q {
                m[(i + 1, j)] = m[(i, j - 1)] - last[i] * ef[n - 1 - j] + b[i] * e[j - 1];
            }
        }
        for i in 0..p {
            for j in 0..q {
                h[(i, p + j)] = -m[(i, j)];
            }
        }
    }

    /// Exact gradient by the adjoint filter: with v_t = w_t eps_t (= clip(eps_t, rho)),
    /// sum_t v_t d(eps_t)/d(theta) = sum_t u_t d(w_t)/d(theta), u = adjoint(1/C) v.
    fn gradient(&mut self, c: &[f64], eps: &[f64]) -> Vec<f64> {
        let (p, q) = (self.p, self.q);
        let we: Vec<f64> = match self.rho {
            Some(r) => eps.iter().map(|&e| e.clamp(-r, r)).collect(),
            None => eps.to_vec(),
        };
        filter_inv_c_adjoint(&we, c, &mut self.u);
        let mut g = vec![0.0; p + q];
        for i in 1..=p {
            g[i - 1] = lagged_dot(self.ys, i, &self.u, 0, p);
        }
        for j in 1..=q {
            g[p + j - 1] = -lagged_dot(eps, j, &self.u, 0, p);
        }
        g
    }

    /// Huber weights `w_t = r / |eps_t|` beyond the threshold `r`: adds `(w_t - 1) psi_t psi_t^T`
    /// to the unweighted Gram `h` for those samples only.
    fn add_huber_correction(&self, eps: &[f64], r: f64, h: &mut DMatrix<f64>) {
        let (p, q) = (self.p, self.q);
        let k = p + q;
        let flagged: Vec<(usize, f64)> = eps
            .iter()
            .enumerate()
            .skip(p)
            .filter(|(_, e)| e.abs() > r)
            .map(|(t, e)| (t, r / e.abs() - 1.0))
            .collect();
        if flagged.is_empty() || k == 0 {
            return;
        }
        // h += sum_t f_t psi_t psi_t^T as one matrix product (k x m) (m x k) over the m flagged
        // instants: columns psi_t of `psi`, rows f_t psi_t^T of `fpsi`.
        let m = flagged.len();
        let mut psi = DMatrix::<f64>::zeros(k, m);
        let mut fpsi = DMatrix::<f64>::zeros(m, k);
        for (col, &(t, f)) in flagged.iter().enumerate() {
            let mut column = psi.column_mut(col);
            let v = column.as_mut_slice();
            for i in 1..=p {
                v[i - 1] = if self.exact_cols {
                    self.cols[i - 1][t]
                } else if t >= i {
                    self.yf[t - i]
                } else {
                    0.0
                };
            }
            for j in 1..=q {
                v[p + j - 1] = if t >= j { -self.ef[t - j] } else { 0.0 };
            }
            for (i, &vi) in v.iter().enumerate() {
                fpsi[(col, i)] = f * vi;
            }
        }
        h.gemm(1.0, &psi, &fpsi, 1.0);
    }
}

/// Result of one prediction-error search on the scaled signal.
struct SearchOut {
    a: Vec<f64>,
    c: Vec<f64>,
    eps: Vec<f64>,
    v: f64,
    rho: Option<f64>,
    iterations: usize,
    stop: StopReason,
    converged: bool,
}

/// Candidates, rho, then damped Gauss-Newton on the scaled signal `ys`.
fn search(
    ys: &[f64],
    p: usize,
    q: usize,
    init: Option<(&[f64], &[f64])>,
    params: &ArmaParams,
    ladder: &[Vec<f64>],
) -> SearchOut {
    let robust = matches!(params.robust, Robust::Huber { .. });
    let mut cands = starting_candidates(ys, p, q, init, robust, ladder);
    let rho = match (params.robust, cands.first()) {
        (Robust::Huber { factor }, Some(best)) => huber_threshold(factor, &best.eps[p..]),
        _ => None,
    };
    // Start from the candidate with the lowest value of the criterion itself (the robust scale
    // above only fixes rho; with a warm start in a sweep this is usually the previous order).
    if rho.is_some() {
        for cand in cands.iter_mut() {
            cand.score = mean_loss(&cand.eps[p..], rho);
        }
        cands.sort_by(|x, y| x.score.total_cmp(&y.score));
    }
    if cands.is_empty() {
        // Unreachable in practice (Burg on finite data is finite); start from white noise.
        cands.push(white_noise_candidate(ys, p, q));
    }
    multistart(ys, p, q, cands, rho, params)
}

/// The starting candidates, best (lowest score) first: Hannan-Rissanen, Burg AR(p) with C = 1,
/// and the caller's warm start `init` zero-padded to the orders (marked `warm`). Candidates with
/// non-finite coefficients or score are left out.
fn starting_candidates(
    ys: &[f64],
    p: usize,
    q: usize,
    init: Option<(&[f64], &[f64])>,
    robust: bool,
    ladder: &[Vec<f64>],
) -> Vec<Candidate> {
    let mut cands: Vec<Candidate> = Vec::new();
    let (ha, hc) = hannan_rissanen(ys, p, q, ladder);
    cands.extend(make_candidate(ys, ha, hc, robust));
    let ba = burg_poly(ys, p, ladder);
    let mut c0 = vec![0.0; q + 1];
    c0[0] = 1.0;
    cands.extend(make_candidate(ys, ba, c0, robust));
    if let Some((a0, c0)) = init {
        let mut a = a0.to_vec();
        a.resize(p + 1, 0.0);
        let mut c = c0.to_vec();
        c.resize(q + 1, 0.0);
        cands.extend(make_candidate(ys, a, c, robust).map(|cand| Candidate { warm: true, ..cand }));
    }
    cands.sort_by(|x, y| x.score.total_cmp(&y.score));
    cands
}

/// Huber threshold `factor x` the robust scale (MAD/0.6745) of the residuals `eps`, falling back
/// to their root mean square when the robust scale is zero or NaN; None when both are zero.
fn huber_threshold(factor: f64, eps: &[f64]) -> Option<f64> {
    let mut s = robust_std(eps);
    if s.is_nan() || s <= 0.0 {
        s = (mean_loss(eps, None)).sqrt();
    }
    if s > 0.0 {
        Some(factor * s)
    } else {
        None
    }
}

/// The white-noise model A = 1, C = 1 as a candidate.
fn white_noise_candidate(ys: &[f64], p: usize, q: usize) -> Candidate {
    let mut a = vec![0.0; p + 1];
    a[0] = 1.0;
    let mut c = vec![0.0; q + 1];
    c[0] = 1.0;
    let mut eps = vec![0.0; ys.len()];
    predict_errors(ys, &a, &c, &mut eps);
    Candidate {
        a,
        c,
        eps,
        score: 0.0,
        warm: false,
    }
}

/// Gauss-Newton from the candidates (sorted, best first, non-empty), keeping the lowest end
/// point; the iterations of all runs are added up.
fn multistart(
    ys: &[f64],
    p: usize,
    q: usize,
    cands: Vec<Candidate>,
    rho: Option<f64>,
    params: &ArmaParams,
) -> SearchOut {
    // Small models: search from every candidate and keep the best end point (guards against
    // neighbouring local minima); larger models, or every model with `SearchStarts::Single`:
    // from the best-scored candidate only.
    let starts = if params.starts == SearchStarts::Multi && p + q <= MULTISTART_MAX_ORDER {
        cands.len()
    } else {
        1
    };
    let mut best: Option<SearchOut> = None;
    let run = |cand: Candidate, best: &mut Option<SearchOut>| {
        let out = gauss_newton(ys, p, q, cand, rho, params);
        match best.as_mut() {
            Some(b) if out.v >= b.v => b.iterations += out.iterations,
            Some(b) => {
                let previous = b.iterations;
                *b = out;
                b.iterations += previous;
            }
            None => *best = Some(out),
        }
    };
    let mut warm_left: Option<Candidate> = None;
    for (i, cand) in cands.into_iter().enumerate() {
        if i < starts {
            run(cand, &mut best);
        } else if cand.warm {
            warm_left = Some(cand);
        }
    }
    // A search that ends above the warm start's own value (it began from a better-scored
    // candidate and fell into a worse minimum) is repeated from the warm start: in a sweep the
    // loss then never rises with the order.
    if let Some(w) = warm_left {
        if best.as_ref().map_or(true, |b| b.v > w.score) {
            run(w, &mut best);
        }
    }
    // `cands` is never empty here, so `best` is set.
    best.unwrap_or(SearchOut {
        a: Vec::new(),
        c: Vec::new(),
        eps: Vec::new(),
        v: f64::NAN,
        rho,
        iterations: 0,
        stop: StopReason::NoImprovement,
        converged: false,
    })
}

/// A trial point accepted by [`LineSearch::run`]: the new model, its loss, and the halvings it took.
struct Trial {
    a: Vec<f64>,
    c: Vec<f64>,
    v: f64,
    halvings: usize,
}

/// What a line search needs besides the current point and the direction.
struct LineSearch<'a> {
    ys: &'a [f64],
    p: usize,
    q: usize,
    rho: Option<f64>,
    max_halvings: usize,
}

impl LineSearch<'_> {
    /// `theta + s d` as (A, C) coefficients.
    fn step(&self, a: &[f64], c: &[f64], d: &[f64], s: f64) -> (Vec<f64>, Vec<f64>) {
        let mut na = a.to_vec();
        let mut nc = c.to_vec();
        for i in 0..self.p {
            na[i + 1] += s * d[i];
        }
        for j in 0..self.q {
            nc[j + 1] += s * d[self.p + j];
        }
        (na, nc)
    }

    /// Line search from `point` = (A, C, loss) along the damped Newton direction `dir`; when no
    /// trial lowers the loss, along the Jacobi-scaled gradient of the normal equations
    /// `(h, -g)` (its halvings counted after the `max_halvings + 1` Newton trials). Returns the
    /// accepted trial, if any, and the gradient model's predicted decrease (infinite when the
    /// gradient was not tried or has no positive curvature).
    fn descend(
        &self,
        point: (&[f64], &[f64], f64),
        dir: &[f64],
        (h, neg_g): (&DMatrix<f64>, &[f64]),
        trial: &mut [f64],
        roots_cache: &mut Vec<Complex64>,
    ) -> (Option<Trial>, f64) {
        let mut reflected = 0usize;
        let accepted = self.run(point, dir, 1.0, trial, &mut reflected, roots_cache);
        if accepted.is_some() {
            return (accepted, f64::INFINITY);
        }
        let (dg, s0, pred_gradient) = scaled_gradient_step(h, neg_g, self.ys.len() - self.p);
        let accepted = self
            .run(point, &dg, s0, trial, &mut reflected, roots_cache)
            .map(|t| Trial {
                halvings: t.halvings + self.max_halvings + 1,
                ..t
            });
        (accepted, pred_gradient)
    }

    /// Trials `theta + s d` for s = s0, s0/2, ... (`max_halvings` halvings) from `(a, c)` with loss
    /// `v`; the first with a lower finite loss is returned with its halving count, its residuals
    /// in `trial`. C must stay minimum phase: the first [`MAX_REFLECTIONS`] trials of an iteration
    /// (counted in `reflected`, shared by the line searches of one iteration) that leave the unit
    /// circle are reflected back (roots z -> 1/conj z, the same |C| on the unit circle); later ones
    /// are just halved (root finding costs more than a trial).
    fn run(
        &self,
        (a, c, v): (&[f64], &[f64], f64),
        d: &[f64],
        s0: f64,
        trial: &mut [f64],
        reflected: &mut usize,
        roots_cache: &mut Vec<Complex64>,
    ) -> Option<Trial> {
        let mut s = s0;
        for hv in 0..=self.max_halvings {
            let (na, mut nc) = self.step(a, c, d, s);
            s *= 0.5;
            if !is_min_phase(&nc) {
                if *reflected >= MAX_REFLECTIONS {
                    continue;
                }
                *reflected += 1;
                stabilise_from(&mut nc, roots_cache);
            }
            predict_errors(self.ys, &na, &nc, trial);
            let vt = mean_loss(&trial[self.p..], self.rho);
            if vt.is_finite() && vt < v {
                return Some(Trial {
                    a: na,
                    c: nc,
                    v: vt,
                    halvings: hv,
                });
            }
        }
        None
    }
}

/// Gauss-Newton step `d0` (with a negligible ridge) and the Newton decrement, the predicted
/// decrease of V per sample `d0 . (-g) / n_eff`. None when the normal matrix cannot be factored.
fn newton_decrement(scaled: &Scaled, neg_g: &[f64], n_eff: usize) -> Option<(Vec<f64>, f64)> {
    let d0 = scaled.solve(NEWTON_DECREMENT_RIDGE)?;
    let pred = d0.iter().zip(neg_g).map(|(x, y)| x * y).sum::<f64>() / n_eff as f64;
    Some((d0, pred))
}

/// Gradient fallback: the Jacobi-scaled steepest-descent direction `D^-1 (-g)` (D = diag h), the
/// exact line minimiser of the quadratic model along it (1 when the curvature is not positive),
/// and the first-order predicted decrease per sample along it (infinite when the curvature is not
/// positive; unlike the Newton decrement, not inflated by an ill-conditioned H).
fn scaled_gradient_step(h: &DMatrix<f64>, neg_g: &[f64], n_eff: usize) -> (Vec<f64>, f64, f64) {
    let k = neg_g.len();
    let dg: Vec<f64> = (0..k)
        .map(|i| {
            let hd = h[(i, i)];
            if hd > 0.0 {
                neg_g[i] / hd
            } else {
                neg_g[i]
            }
        })
        .collect();
    let gd: f64 = dg.iter().zip(neg_g).map(|(x, y)| x * y).sum();
    let mut hdd = 0.0;
    for i in 0..k {
        let mut row = 0.0;
        for j in 0..k {
            row += h[(i, j)] * dg[j];
        }
        hdd += dg[i] * row;
    }
    let mut pred_gradient = f64::INFINITY;
    if hdd > 0.0 {
        pred_gradient = gd * gd / hdd / n_eff as f64;
    }
    let s0 = if hdd > 0.0 { gd / hdd } else { 1.0 };
    (dg, s0, pred_gradient)
}

/// Whether a search that found no lower point has converged: either model predicts only a
/// negligible gain (the numerical floor of the criterion: the Newton decrement `pred` within
/// [`NO_STEP_TOL_FACTOR`] x tol, or the gradient model's `pred_gradient` within tol), or C has a
/// zero on the unit circle (within [`BOUNDARY_MARGIN`]): the minimum then lies on the boundary
/// of the minimum-phase set, where every descent direction leaves it (a constrained optimum).
fn converged_without_step(pred: f64, pred_gradient: f64, v: f64, c: &[f64], tol: f64) -> bool {
    let on_boundary = || {
        polynomial_roots(c)
            .map(|r| r.iter().any(|z| z.norm() > 1.0 - BOUNDARY_MARGIN))
            .unwrap_or(false)
    };
    pred <= NO_STEP_TOL_FACTOR * tol * v || pred_gradient <= tol * v || on_boundary()
}

/// Levenberg-Marquardt ridge after an iteration whose accepted step took `halvings` halvings:
/// decreased after a full step, increased otherwise, within [`MU_MIN`, `MU_MAX`].
fn next_mu(mu: f64, halvings: usize) -> f64 {
    if halvings == 0 {
        (mu * MU_DECREASE).max(MU_MIN)
    } else {
        (mu * MU_INCREASE).min(MU_MAX)
    }
}

/// Damped Gauss-Newton from one starting candidate (see docs/identification.md).
fn gauss_newton(
    ys: &[f64],
    p: usize,
    q: usize,
    start: Candidate,
    rho: Option<f64>,
    params: &ArmaParams,
) -> SearchOut {
    let n = ys.len();
    let Candidate {
        mut a,
        mut c,
        mut eps,
        ..
    } = start;
    let mut search = Search::new(ys, p, q, rho);
    let line = LineSearch {
        ys,
        p,
        q,
        rho,
        max_halvings: params.max_halvings,
    };
    let n_eff = n - p;
    let mut v = mean_loss(&eps[p..], rho);
    let mut mu = MU_INITIAL;
    let mut iterations = 0;
    let mut stop = StopReason::MaxIterations;
    let mut converged = false;
    let mut trial_eps = vec![0.0; n];
    // Roots of the C last reflected into the unit circle: the next reflection's starting point.
    let mut roots_cache: Vec<Complex64> = Vec::new();
    // Loss history for the stall rule.
    let mut history: Vec<f64> = vec![v];
    while iterations < params.max_iterations {
        let (g, h, _) = search.normal_equations(&c, &eps);
        let neg_g: Vec<f64> = g.iter().map(|v| -v).collect();
        // The scaled system is formed once for both solves of the iteration.
        let scaled = Scaled::new(&h, &neg_g);
        let Some((d0, pred)) = newton_decrement(&scaled, &neg_g, n_eff) else {
            stop = StopReason::NoImprovement;
            break;
        };
        if pred.is_nan() || pred <= params.tolerance * v {
            stop = StopReason::Converged;
            converged = true;
            break;
        }
        iterations += 1;
        let dir = if mu > MU_MIN {
            scaled.solve(mu).unwrap_or(d0)
        } else {
            d0
        };
        let (accepted, pred_gradient) = line.descend(
            (&a, &c, v),
            &dir,
            (&h, &neg_g),
            &mut trial_eps,
            &mut roots_cache,
        );
        let Some(t) = accepted else {
            // No step lowers V.
            stop = StopReason::NoImprovement;
            converged = converged_without_step(pred, pred_gradient, v, &c, params.tolerance);
            break;
        };
        a = t.a;
        c = t.c;
        v = t.v;
        std::mem::swap(&mut eps, &mut trial_eps);
        history.push(v);
        if history.len() > STALL_WINDOW
            && history[history.len() - 1 - STALL_WINDOW] - v < params.tolerance * v
        {
            stop = StopReason::Stalled;
            converged = true;
            break;
        }
        mu = next_mu(mu, t.halvings);
    }

    SearchOut {
        a,
        c,
        eps,
        v,
        rho,
        iterations,
        stop,
        converged,
    }
}

fn fit_impl(
    y: &[f64],
    p: usize,
    q: usize,
    init: Option<&ArmaModel>,
    params: &ArmaParams,
) -> Result<ArmaModel, IdentError> {
    params.validate()?;
    let mean = check_signal(y, 3)?;
    check_orders(y.len(), p, q, init)?;
    let prepared = prepare::for_search(y, mean, params)?;
    let out = search(
        &prepared.ys,
        p,
        q,
        init.map(|m| (&m.a[..], &m.c[..])),
        params,
        &[],
    );
    Ok(finish_model(&prepared, p, q, out, params, true))
}

/// Checks the orders against the record length `n` and the warm start against the orders.
fn check_orders(n: usize, p: usize, q: usize, init: Option<&ArmaModel>) -> Result<(), IdentError> {
    if p == 0 {
        return Err(IdentError::ZeroOrder {
            what: "ARMA AR order p",
            fix: "modes come from A(z); choose p >= 1 (e.g. p = q)",
        });
    }
    if q > p {
        return Err(IdentError::MaOrderAboveAr { p, q });
    }
    if p + q > max_arma_order(n) {
        return Err(IdentError::OrderTooHigh {
            what: "ARMA order p + q",
            order: p + q,
            n_samples: n,
            max_order: max_arma_order(n),
        });
    }
    if let Some(m) = init {
        if m.p > p || m.q > q || m.a.len() != m.p + 1 || m.c.len() != m.q + 1 {
            return Err(IdentError::InitMismatch {
                p,
                q,
                init_p: m.p,
                init_q: m.q,
            });
        }
    }
    Ok(())
}

/// Asymptotic variance factor of the estimates: the innovation variance `lambda_s` for the
/// quadratic criterion; for Huber's, `mean(clip(eps, rho)^2) / share_inside^2` (the sandwich
/// estimator's scale), NaN when no residual lies inside the threshold.
fn variance_factor(tail: &[f64], rho: Option<f64>, lambda_s: f64) -> f64 {
    match rho {
        None => lambda_s,
        Some(r) => {
            let n_eff = tail.len();
            let num = tail.iter().map(|e| e.clamp(-r, r).powi(2)).sum::<f64>() / n_eff as f64;
            let inside = tail.iter().filter(|e| e.abs() <= r).count() as f64 / n_eff as f64;
            if inside > 0.0 {
                num / (inside * inside)
            } else {
                f64::NAN
            }
        }
    }
}

/// The fitted model in signal units from the search's result on the prepared signal: standard
/// errors, information criteria, and the scale mapped back.
fn finish_model(
    prepared: &Prepared,
    p: usize,
    q: usize,
    out: SearchOut,
    params: &ArmaParams,
    with_std_errors: bool,
) -> ArmaModel {
    let SearchOut {
        a,
        c,
        eps,
        v,
        rho,
        iterations,
        stop,
        converged,
    } = out;
    let ys = &prepared.ys;
    let n = ys.len();
    let k = p + q;
    let lambda_s = mean_loss(&eps[p..], None);
    let std_errors = if with_std_errors {
        let mut search = Search::new(ys, p, q, rho);
        let (_, _, h_u) = search.normal_equations(&c, &eps);
        let kappa = variance_factor(&eps[p..], rho, lambda_s);
        match spd_inverse_diag(&h_u) {
            Some(d) => d.iter().map(|v| (kappa * v).sqrt()).collect(),
            None => vec![f64::NAN; k],
        }
    } else {
        vec![f64::NAN; k]
    };
    let scale = prepared.scale;
    let s2 = scale * scale;
    let lambda = lambda_s * s2;
    let (aic, bic, fpe) = information_criteria(lambda, n, k);
    ArmaModel {
        p,
        q,
        a,
        c,
        noise_variance: lambda,
        loss: v * s2,
        iterations,
        converged,
        stop_reason: stop,
        aic,
        bic,
        fpe,
        std_errors,
        reflection_coefficients: Vec::new(),
        robust_rho: rho.map(|r| r * scale),
        n_samples: n,
        mean: prepared.offset,
        estimator: Estimator::PredictionError,
        outliers_replaced: prepared.outliers_replaced,
        noise_floor_variance: if prepared.floor_added {
            params.noise_floor * s2
        } else {
            0.0
        },
    }
}

/// Mean squared one-step prediction error `(1/(N-p)) sum_{t=p}^{N-1} eps_t^2` of the model
/// `(a, c)` on `y` (signal units squared), with the conditional predictor of [`fit_arma`]
/// (`eps = w / C`, `w_t = A(q) y_t` for t >= p, zero initial conditions of the noise filter), after
/// subtracting `mean`. This is how [`ArmaModel::noise_variance`] is defined for prediction-error
/// fits; use it to compare models from other tools on equal terms. NaN if `y` has at most p samples.
pub fn prediction_error_variance(y: &[f64], mean: f64, a: &[f64], c: &[f64]) -> f64 {
    let p = a.len().saturating_sub(1);
    if y.len() <= p {
        return f64::NAN;
    }
    let x: Vec<f64> = y.iter().map(|v| v - mean).collect();
    let mut eps = vec![0.0; x.len()];
    predict_errors(&x, a, c, &mut eps);
    mean_loss(&eps[p..], None)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AR columns and Gram blocks built by the shift recursions equal one filter pass per
    /// column (the definition) and direct sums, on seeded random signals and minimum-phase C over many seeds and orders.
    #[test]
    fn exact_ar_columns_and_gram_match_direct_sums() {
        let mut u01 = crate::linalg::xorshift_uniform(0x9e37_79b9_7f4a_7c15_u64);
        let mut uniform = move || u01() - 0.5;
        for case in 0..60 {
            let p = 1 + case % 9;
            let (q, n) = (case % (p + 1), 40 + 3 * case);
            let y: Vec<f64> = (0..n).map(|_| uniform()).collect();
            // C with roots of modulus <= 0.8: minimum phase.
            let roots: Vec<Complex64> = (0..q)
                .map(|_| Complex64::new(1.6 * uniform(), 0.0))
                .collect();
            let c = poly_from_roots(&roots);
            let mut s = Search::new(&y, p, q, None);
            s.ef = (0..n).map(|_| uniform()).collect();
            let mut h = DMatrix::<f64>::zeros(p + q, p + q);
            assert!(s.exact_buffers());
            let mut delta = vec![0.0; n - p];
            delta[0] = 1.0;
            filter_inv_c(&s.z, &c, &mut s.cols[0]);
            filter_inv_c(&delta, &c, &mut s.g);
            s.exact_ar_block(&mut h);
            assert_eq!(s.cols.len(), p);
            // The Gram blocks by their recursion against direct sums over t >= p.
            let close = |a: f64, b: f64, what: &str| {
                assert!(
                    (a - b).abs() <= 1e-11 * (1.0 + b.abs()),
                    "case {case} {what}: {a} vs {b}"
                );
            };
            for i in 0..p {
                for j in 0..p {
                    let direct: f64 = (p..n).map(|t| s.cols[i][t] * s.cols[j][t]).sum();
                    close(h[(i, j)], direct, &format!("G[{i}][{j}]"));
                }
                for j in 1..=q {
                    let direct: f64 = (p..n).map(|t| s.cols[i][t] * s.ef[t - j]).sum();
                    close(h[(i, p + j - 1)], -direct, &format!("M[{i}][{j}]"));
                }
            }
            // The Huber correction as one matrix product against its definition,
            // sum over |eps_t| > r (t >= p) of (r/|eps_t| - 1) psi_t psi_t^T.
            let eps: Vec<f64> = (0..n).map(|_| 2.0 * uniform()).collect();
            let r = 0.4;
            let mut hc = DMatrix::<f64>::zeros(p + q, p + q);
            s.add_huber_correction(&eps, r, &mut hc);
            let k = p + q;
            let mut want = DMatrix::<f64>::zeros(k, k);
            for (t, e) in eps.iter().enumerate().skip(p) {
                if e.abs() <= r {
                    continue;
                }
                let f = r / e.abs() - 1.0;
                let psi: Vec<f64> = (0..k)
                    .map(|i| {
                        if i < p {
                            s.cols[i][t]
                        } else if t > i - p {
                            -s.ef[t - (i - p + 1)]
                        } else {
                            0.0
                        }
                    })
                    .collect();
                for i in 0..k {
                    for j in 0..k {
                        want[(i, j)] += f * psi[i] * psi[j];
                    }
                }
            }
            for i in 0..k {
                for j in 0..k {
                    close(hc[(i, j)], want[(i, j)], &format!("Huber[{i}][{j}]"));
                }
            }
            for i in 1..=p {
                let z: Vec<f64> = (0..n)
                    .map(|t| if t >= p { y[t - i] } else { 0.0 })
                    .collect();
                let mut direct = vec![0.0; n];
                filter_inv_c(&z, &c, &mut direct);
                for (t, (&a, &b)) in s.cols[i - 1].iter().zip(&direct).enumerate() {
                    assert!(
                        (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                        "case {case} col {i} t {t}: {a} vs {b}"
                    );
                }
            }
        }
    }

    /// The sweep (signal prepared once, Burg polynomials from one recursion, no standard errors)
    /// gives, bit for bit, the models of `fit_arma_warm` chained order to order.
    #[test]
    fn sweep_equals_chained_warm_fits() {
        let mut uniform = crate::linalg::xorshift_uniform(0x9e37_79b9_7f4a_7c15_u64);
        let mut noise = move || uniform() - 0.5;
        // A lightly damped resonance plus noise, with one spike for the outlier cleaner.
        let mut y = vec![0.0; 600];
        for t in 2..y.len() {
            y[t] = 1.6 * y[t - 1] - 0.9 * y[t - 2] + noise();
        }
        y[300] += 40.0;
        let params = ArmaParams::default();
        let orders = [1, 2, 3, 5, 4];
        let swept = sweep_arma(&y, &orders, &params);
        let mut prev: Option<ArmaModel> = None;
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for (&o, s) in orders.iter().zip(&swept) {
            let want = match prev.as_ref().filter(|m| m.p <= o) {
                Some(init) => fit_arma_warm(&y, o, o, init, &params),
                None => fit_arma(&y, o, o, &params),
            }
            .unwrap();
            let s = s.as_ref().unwrap();
            assert_eq!(bits(&s.a), bits(&want.a), "order {o}");
            assert_eq!(bits(&s.c), bits(&want.c), "order {o}");
            assert_eq!(s.loss.to_bits(), want.loss.to_bits(), "order {o}");
            assert_eq!(s.iterations, want.iterations, "order {o}");
            assert_eq!(s.outliers_replaced, want.outliers_replaced, "order {o}");
            assert!(s.outliers_replaced > 0);
            assert!(s.std_errors.iter().all(|v| v.is_nan()));
            prev = Some(want);
        }
    }

    /// `SearchStarts::Single` searches from the best-scored candidate only: over 40 seeded
    /// ARMA(2,2) fits (two resonances in noise) the multi-start's loss is never above the single
    /// start's (it keeps the lowest end point of all starts, the single start's among them), at
    /// most 1e-4 below it (one minimum), and it takes more iterations in all; ARMA(9,9)
    /// (p + q = 18 > 16, one start either way) is the same bit for bit.
    #[test]
    fn a_single_start_searches_from_the_best_candidate_only() {
        let single = ArmaParams {
            starts: SearchStarts::Single,
            ..ArmaParams::default()
        };
        let multi = ArmaParams::default();
        let (mut it_single, mut it_multi, mut lower, mut worst) = (0, 0, 0, 0.0_f64);
        for seed in 0..40u64 {
            let mut uniform = crate::linalg::xorshift_uniform(0x2545_f491_4f6c_dd1d ^ (seed + 1));
            let mut noise = move || uniform() - 0.5;
            let mut y = vec![0.0; 512];
            let mut x = vec![0.0; 512];
            for t in 2..y.len() {
                x[t] = 1.2 * x[t - 1] - 0.85 * x[t - 2] + noise();
                y[t] = 0.4 * x[t] + 0.3 * noise();
            }
            let a = fit_arma(&y, 2, 2, &single).unwrap();
            let b = fit_arma(&y, 2, 2, &multi).unwrap();
            assert!(b.loss <= a.loss, "seed {seed}: {} > {}", b.loss, a.loss);
            lower += usize::from(b.loss < a.loss);
            worst = worst.max(a.loss / b.loss - 1.0);
            it_single += a.iterations;
            it_multi += b.iterations;
            if seed < 3 {
                let a = fit_arma(&y, 9, 9, &single).unwrap();
                let b = fit_arma(&y, 9, 9, &multi).unwrap();
                assert_eq!(a.loss.to_bits(), b.loss.to_bits(), "seed {seed}");
                assert_eq!(a.iterations, b.iterations, "seed {seed}");
            }
        }
        assert!(
            it_single < it_multi,
            "iterations: single {it_single}, multi {it_multi}"
        );
        // On this signal every start ends at the same minimum: within ten times the fit's
        // stopping tolerance (FIT_TOLERANCE, 1e-5) of each other.
        assert!(
            worst < 10.0 * crate::FIT_TOLERANCE,
            "single start's loss {worst:.2e} above"
        );
        eprintln!(
            "iterations single {it_single}, multi {it_multi}; lower loss by multi on {lower} of 40, by {worst:.2e} at most"
        );
    }

    #[test]
    fn huber_loss_by_hand() {
        assert_eq!(loss_of(0.5, Some(1.0)), 0.25);
        assert_eq!(loss_of(3.0, Some(1.0)), 5.0);
        assert_eq!(loss_of(-3.0, None), 9.0);
    }

    #[test]
    fn reflect_roots_outside() {
        // C = (1 - 2 z^-1)(1 - 0.5 z^-1) = 1 - 2.5 z^-1 + z^-2 -> root 2 reflected to 0.5.
        let mut c = vec![1.0, -2.5, 1.0];
        stabilise(&mut c);
        assert!(
            (c[1] + 1.0).abs() < 1e-12 && (c[2] - 0.25).abs() < 1e-12,
            "{c:?}"
        );
    }

    #[test]
    fn prediction_errors_by_hand() {
        // A = 1 - 0.5 z^-1, C = 1 + 0.5 z^-1, y = [1, 0, 0]: eps0 = 0 (conditional on y0);
        // eps1 = 0 - 0.5*1 - 0.5*0 = -0.5; eps2 = 0 - 0 - 0.5*(-0.5) = 0.25.
        let mut e = vec![0.0; 3];
        predict_errors(&[1.0, 0.0, 0.0], &[1.0, -0.5], &[1.0, 0.5], &mut e);
        assert_eq!(e, vec![0.0, -0.5, 0.25]);
    }
}
