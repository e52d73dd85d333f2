//! AR estimation: Yule-Walker, Burg, forward-backward least squares.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use nalgebra::DMatrix;

use crate::linalg::{
    check_signal, cholesky_solve_ridged, dot, lagged_dot, lagged_gram, spd_inverse_diag, Lags,
};
use crate::model::{information_criteria, ArmaModel, Estimator, StopReason};
use crate::IdentError;

/// AR estimation method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum ArMethod {
    /// Yule-Walker with the biased (1/N) autocorrelation, solved by Levinson-Durbin; equals
    /// `statsmodels.regression.linear_model.yule_walker(x, order, method="mle")`.
    YuleWalker,
    /// Burg's method; equals `statsmodels.regression.linear_model.burg(x, order)`. Default.
    #[default]
    Burg,
    /// Forward-backward least squares (modified covariance method).
    LeastSquares,
}

impl FromStr for ArMethod {
    type Err = IdentError;
    /// Accepts `yule-walker`, `yw`, `burg`, `ls`, `least-squares` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "yule-walker" | "yw" | "yulewalker" | "yule_walker" => Ok(ArMethod::YuleWalker),
            "burg" => Ok(ArMethod::Burg),
            "ls" | "least-squares" | "least_squares" | "fbls" => Ok(ArMethod::LeastSquares),
            _ => Err(vibmode_core::ParamError::UnknownName {
                what: "AR method",
                value: s.to_string(),
                valid: "yule-walker (or yw), burg, ls",
            }
            .into()),
        }
    }
}

impl fmt::Display for ArMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ArMethod::YuleWalker => "yule-walker",
            ArMethod::Burg => "burg",
            ArMethod::LeastSquares => "ls",
        })
    }
}

/// Largest AR order allowed for `n` samples: `n / 3` (integer division).
pub fn max_ar_order(n: usize) -> usize {
    n / 3
}

/// Fits an AR(p) model `A(q) y_t = e_t` to `y` after subtracting its mean (as statsmodels does).
///
/// * `YuleWalker`: biased autocorrelation `r_k = (1/N) sum x_t x_{t+k}`, Levinson-Durbin;
///   `noise_variance = r_0 + sum a_k r_k`.
/// * `Burg`: forward/backward lattice; `noise_variance` = (sum of squared forward and backward
///   order-p errors) / (2 (N - p)), as statsmodels' `burg`.
/// * `LeastSquares`: minimises the sum of squared forward and backward prediction errors over
///   t = p..N-1; `noise_variance` = that minimum / (2 (N - p)).
///
/// YW and Burg report reflection coefficients (A(z) convention). `std_errors` are the asymptotic
/// `sqrt(lambda [R^-1]_kk / N)` with R the biased autocovariance Toeplitz matrix, for all methods.
/// Information criteria use `lambda = noise_variance` and `k = p`.
///
/// Errors: empty, non-finite or constant input; `p = 0`; `p > N/3`.
pub fn fit_ar(y: &[f64], p: usize, method: ArMethod) -> Result<ArmaModel, IdentError> {
    let mean = check_signal(y, 3)?;
    if p == 0 {
        return Err(IdentError::ZeroOrder {
            what: "AR order p",
            fix: "choose p >= 1, e.g. 2 per expected mode",
        });
    }
    let n = y.len();
    if p > max_ar_order(n) {
        return Err(IdentError::OrderTooHigh {
            what: "AR order p",
            order: p,
            n_samples: n,
            max_order: max_ar_order(n),
        });
    }
    let x: Vec<f64> = y.iter().map(|v| v - mean).collect();
    let r = autocorr_biased(&x, p);
    let (a, lambda, refl, estimator) = match method {
        ArMethod::YuleWalker => {
            let (a, refl) = levinson(&r, p);
            let lambda = r[0] + (1..=p).map(|k| a[k] * r[k]).sum::<f64>();
            (a, lambda, refl, Estimator::YuleWalker)
        }
        ArMethod::Burg => {
            let (a, refl, lambda) = burg(&x, p);
            (a, lambda, refl, Estimator::Burg)
        }
        ArMethod::LeastSquares => {
            let (a, lambda) = fb_least_squares(&x, p);
            (a, lambda, Vec::new(), Estimator::LeastSquares)
        }
    };
    // Asymptotic standard errors from the autocovariance matrix.
    let rm = DMatrix::from_fn(p, p, |i, j| r[i.abs_diff(j)]);
    let std_errors = match spd_inverse_diag(&rm) {
        Some(d) => d.iter().map(|v| (lambda * v / n as f64).sqrt()).collect(),
        None => vec![f64::NAN; p],
    };
    let (aic, bic, fpe) = information_criteria(lambda, n, p);
    Ok(ArmaModel {
        p,
        q: 0,
        a,
        c: vec![1.0],
        noise_variance: lambda,
        loss: lambda,
        iterations: 0,
        converged: true,
        stop_reason: StopReason::ClosedForm,
        aic,
        bic,
        fpe,
        std_errors,
        reflection_coefficients: refl,
        robust_rho: None,
        n_samples: n,
        mean,
        estimator,
        outliers_replaced: 0,
        noise_floor_variance: 0.0,
    })
}

/// Biased autocorrelation `r_k = (1/N) sum_{t} x_t x_{t+k}`, k = 0..=p.
pub(crate) fn autocorr_biased(x: &[f64], p: usize) -> Vec<f64> {
    let n = x.len();
    (0..=p)
        .map(|k| {
            if k < n {
                dot(&x[..n - k], &x[k..]) / n as f64
            } else {
                0.0
            }
        })
        .collect()
}

/// Levinson-Durbin: A coefficients (leading 1) and reflection coefficients (A convention).
pub(crate) fn levinson(r: &[f64], p: usize) -> (Vec<f64>, Vec<f64>) {
    let mut a = vec![0.0; p + 1];
    a[0] = 1.0;
    let mut refl = Vec::with_capacity(p);
    let mut err = r[0];
    for m in 1..=p {
        let mut acc = r[m];
        for i in 1..m {
            acc += a[i] * r[m - i];
        }
        let k = if err > 0.0 { -acc / err } else { 0.0 };
        let prev = a.clone();
        for i in 1..m {
            a[i] = prev[i] + k * prev[m - i];
        }
        a[m] = k;
        err *= 1.0 - k * k;
        refl.push(k);
    }
    (a, refl)
}

/// Burg's method on demeaned `x`: (A coefficients, reflection coefficients, noise variance).
pub(crate) fn burg(x: &[f64], p: usize) -> (Vec<f64>, Vec<f64>, f64) {
    burg_visiting(x, p, |_, _| {})
}

/// The Burg AR polynomials of every order `0..=p` of `x` (`[1]`, `[1, a_1]`, ...): the order-m
/// polynomial of Burg's recursion does not depend on the final order, so one pass to order `p`
/// gives, bit for bit, what [`burg`] of each order `m <= p` returns.
pub(crate) fn burg_ladder(x: &[f64], p: usize) -> Vec<Vec<f64>> {
    let mut ladder = Vec::with_capacity(p + 1);
    ladder.push(vec![1.0]);
    burg_visiting(x, p, |m, a| ladder.push(a[..=m].to_vec()));
    ladder
}

/// Burg's recursion to order `p`, calling `visit(m, a)` with the order-m coefficients (`a[..=m]`)
/// after each step.
fn burg_visiting(
    x: &[f64],
    p: usize,
    mut visit: impl FnMut(usize, &[f64]),
) -> (Vec<f64>, Vec<f64>, f64) {
    let n = x.len();
    let mut f = x.to_vec();
    let mut b = x.to_vec();
    let mut a = vec![0.0; p + 1];
    a[0] = 1.0;
    let mut refl = Vec::with_capacity(p);
    let mut energy = 0.0;
    let mut prev = a.clone();
    for m in 1..=p {
        // Errors f_{m-1}(t), b_{m-1}(t-1) for t = m..N-1.
        let num = dot(&f[m..n], &b[m - 1..n - 1]);
        let den = dot(&f[m..n], &f[m..n]) + dot(&b[m - 1..n - 1], &b[m - 1..n - 1]);
        let k = if den > 0.0 { -2.0 * num / den } else { 0.0 };
        for t in (m..n).rev() {
            let ft = f[t];
            let bt = b[t - 1];
            f[t] = ft + k * bt;
            b[t] = bt + k * ft;
        }
        prev[..m].copy_from_slice(&a[..m]);
        for i in 1..m {
            a[i] = prev[i] + k * prev[m - i];
        }
        a[m] = k;
        refl.push(k);
        visit(m, &a);
        if m == p {
            energy = dot(&f[m..n], &f[m..n]) + dot(&b[m..n], &b[m..n]);
        }
    }
    let lambda = energy / (2.0 * (n - p) as f64);
    (a, refl, lambda)
}

/// Refinement steps of [`fb_least_squares`] (corrected semi-normal equations): each gains about
/// as many digits as the normal equations lose to the squared condition number; three reach full
/// precision for the orders used here.
const FB_LS_REFINEMENTS: usize = 3;

/// Forward-backward least squares on demeaned `x`: (A coefficients, noise variance).
pub(crate) fn fb_least_squares(x: &[f64], p: usize) -> (Vec<f64>, f64) {
    let n = x.len();
    let xr: Vec<f64> = x.iter().rev().copied().collect();
    let mut g = DMatrix::<f64>::zeros(p, p);
    let mut gb = DMatrix::<f64>::zeros(p, p);
    lagged_gram(
        Lags::new(x, p),
        Lags::new(x, p),
        p,
        g.view_mut((0, 0), (p, p)),
        1.0,
    );
    lagged_gram(
        Lags::new(&xr, p),
        Lags::new(&xr, p),
        p,
        gb.view_mut((0, 0), (p, p)),
        1.0,
    );
    let mut rhs = vec![0.0; p];
    for i in 1..=p {
        rhs[i - 1] = -(lagged_dot(x, i, x, 0, p) + lagged_dot(&xr, i, &xr, 0, p));
    }
    g += &gb;
    let solve = |b: &[f64]| cholesky_solve_ridged(&g, b);
    let mut a = vec![1.0];
    a.extend(solve(&rhs).unwrap_or_else(|| vec![0.0; p]));
    // The normal equations square the condition number: refine with the exact gradient
    // (corrected semi-normal equations), O(N p) per step.
    let mut fe = vec![0.0; n];
    let mut be = vec![0.0; n];
    let mut ss = 0.0;
    for step in 0..=FB_LS_REFINEMENTS {
        ss = 0.0;
        for t in p..n {
            let (mut f, mut b) = (0.0, 0.0);
            for k in 0..=p {
                f += a[k] * x[t - k];
                b += a[k] * x[t - p + k];
            }
            fe[t] = f;
            be[t] = b;
            ss += f * f + b * b;
        }
        if step == FB_LS_REFINEMENTS {
            break;
        }
        let grad: Vec<f64> = (1..=p)
            .map(|k| -(dot(&fe[p..n], &x[p - k..n - k]) + dot(&be[p..n], &x[k..n - p + k])))
            .collect();
        match solve(&grad) {
            Some(d) => {
                for k in 0..p {
                    a[k + 1] += d[k];
                }
            }
            None => break,
        }
    }
    (a, ss / (2.0 * (n - p) as f64))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One Burg pass gives, bit for bit, the polynomial [`burg`] returns for every lower order.
    #[test]
    fn burg_ladder_matches_burg_of_each_order() {
        let mut uniform = crate::linalg::xorshift_uniform(0x2545_f491_4f6c_dd1d_u64);
        let x: Vec<f64> = (0..300)
            .map(|t| (t as f64 * 0.3).sin() + uniform() - 0.5)
            .collect();
        let ladder = burg_ladder(&x, 40);
        assert_eq!(ladder.len(), 41);
        for (m, a) in ladder.iter().enumerate() {
            let want = burg(&x, m).0;
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(a), bits(&want), "order {m}");
        }
    }

    #[test]
    fn ar1_yule_walker_by_hand() {
        // x = [1, -1, 1, -1] has mean 0; r0 = 1, r1 = -3/4 -> a1 = 0.75, lambda = 1 - 0.5625.
        let m = fit_ar(&[1.0, -1.0, 1.0, -1.0], 1, ArMethod::YuleWalker).unwrap();
        assert!((m.a[1] - 0.75).abs() < 1e-15);
        assert!((m.noise_variance - 0.4375).abs() < 1e-15);
        assert!((m.reflection_coefficients[0] - 0.75).abs() < 1e-15);
    }

    #[test]
    fn ar1_burg_by_hand() {
        // x = [1, 2, 0, -3] (mean 0). m = 1: sum f(t) b(t-1) over t = 1..3 = 2*1 + 0*2 + (-3)*0 = 2;
        // den = (4 + 0 + 9) + (1 + 4 + 0) = 18 -> k = -4/18.
        let m = fit_ar(&[1.0, 2.0, 0.0, -3.0], 1, ArMethod::Burg).unwrap();
        let k = -4.0 / 18.0;
        assert!((m.a[1] - k).abs() < 1e-15);
        // lambda = (1 - k^2) den / (2 (N - 1)).
        assert!((m.noise_variance - (1.0 - k * k) * 18.0 / 6.0).abs() < 1e-14);
    }

    #[test]
    fn ar1_ls_by_hand() {
        // Forward-backward LS, p = 1: a1 = -2 sum x_t x_{t-1} / sum (x_t^2 + x_{t-1}^2) (t = 1..N-1),
        // identical to Burg at order 1.
        let x = [1.0, 2.0, 0.0, -3.0];
        let ls = fit_ar(&x, 1, ArMethod::LeastSquares).unwrap();
        assert!((ls.a[1] + 4.0 / 18.0).abs() < 1e-14);
    }

    #[test]
    fn parse_and_display() {
        for m in [ArMethod::YuleWalker, ArMethod::Burg, ArMethod::LeastSquares] {
            assert_eq!(m.to_string().parse::<ArMethod>().unwrap(), m);
        }
        assert_eq!("YW".parse::<ArMethod>().unwrap(), ArMethod::YuleWalker);
        let e = "levinson".parse::<ArMethod>().unwrap_err().to_string();
        assert!(e.contains("levinson") && e.contains("burg") && e.contains("yule-walker"));
    }
}
