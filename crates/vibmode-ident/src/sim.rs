//! Simulation helpers: ARMA processes and AR polynomials from modes (for tests and demos).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::linalg::is_min_phase;
use crate::roots::polynomial_roots;
use crate::IdentError;

/// `ln(1e-12)` (rounded): the burn-in lets the slowest pole's transient decay by 1e-12, below
/// double-precision rounding relative to the stationary signal.
const BURN_IN_DECAY_LN: f64 = -27.6;

/// Cap of the burn-in, samples: a pole within ~3e-5 of the unit circle would otherwise ask for
/// more (and such a process is practically non-stationary anyway).
const MAX_BURN_IN: usize = 1_000_000;

/// A(z) coefficients (leading 1, length 2 * modes.len() + 1) whose poles are the discrete-time
/// images `z = exp(s / fs_hz)` of the continuous poles `s = -zeta w0 +- i w0 sqrt(1 - zeta^2)`,
/// `w0 = 2 pi frequency_hz`, for each `(frequency_hz, damping_ratio)` in `modes`
/// (0 <= damping_ratio < 1).
pub fn ar_from_modes(modes: &[(f64, f64)], fs_hz: f64) -> Vec<f64> {
    let mut a = vec![1.0];
    for &(f, zeta) in modes {
        let w0 = 2.0 * std::f64::consts::PI * f;
        let re = (-zeta * w0 / fs_hz).exp();
        let th = w0 * (1.0 - zeta * zeta).max(0.0).sqrt() / fs_hz;
        // 1 - 2 r cos(th) z^-1 + r^2 z^-2
        let fac = [1.0, -2.0 * re * th.cos(), re * re];
        let mut next = vec![0.0; a.len() + 2];
        for (i, &ai) in a.iter().enumerate() {
            for (j, &fj) in fac.iter().enumerate() {
                next[i + j] += ai * fj;
            }
        }
        a = next;
    }
    a
}

/// Multiplies two polynomials in z^-1 (coefficient vectors, lowest delay first).
pub fn poly_mul(x: &[f64], z: &[f64]) -> Vec<f64> {
    if x.is_empty() || z.is_empty() {
        return Vec::new();
    }
    let mut out = vec![0.0; x.len() + z.len() - 1];
    for (i, &xi) in x.iter().enumerate() {
        for (j, &zj) in z.iter().enumerate() {
            out[i + j] += xi * zj;
        }
    }
    out
}

/// Simulates `n` samples of `A(q) y_t = C(q) e_t`, `e_t ~ N(0, lambda)` (lambda in signal units
/// squared), from a ChaCha8 generator seeded with `seed`. `a[0]` and `c[0]` must be nonzero (the
/// recursion divides by `a[0]`). A burn-in long enough for the slowest pole to decay by 1e-12
/// (at most 10^6 samples) is discarded, so the output is (nearly) stationary.
///
/// Errors: non-finite or zero-leading coefficients, A with a root on or outside the unit circle,
/// lambda negative or not finite.
pub fn simulate_arma(
    a: &[f64],
    c: &[f64],
    lambda: f64,
    n: usize,
    seed: u64,
) -> Result<Vec<f64>, IdentError> {
    for poly in [a, c] {
        if let Some((index, &value)) = poly.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(IdentError::BadCoefficient { index, value });
        }
        match poly.first() {
            Some(&v) if v != 0.0 => {}
            Some(&v) => return Err(IdentError::ZeroLeading { value: v }),
            None => return Err(IdentError::ZeroLeading { value: 0.0 }),
        }
    }
    if !(lambda.is_finite() && lambda >= 0.0) {
        return Err(vibmode_core::ParamError::out_of_range(
            "lambda",
            lambda,
            "must be a finite, non-negative innovation variance",
            1.0,
        )
        .into());
    }
    let an: Vec<f64> = a.iter().map(|v| v / a[0]).collect();
    let rmax = polynomial_roots(&an)?
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max);
    if !is_min_phase(&an) || rmax >= 1.0 {
        return Err(IdentError::UnstableModel { modulus: rmax });
    }
    let burn = if rmax > 0.0 {
        ((BURN_IN_DECAY_LN / rmax.ln()).ceil() as usize).min(MAX_BURN_IN)
    } else {
        0
    } + 10 * (a.len() + c.len());
    let total = burn + n;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let sd = lambda.sqrt();
    let e: Vec<f64> = (0..total)
        .map(|_| {
            let z: f64 = StandardNormal.sample(&mut rng);
            sd * z
        })
        .collect();
    let mut y = filter_arma(a, c, &e);
    Ok(y.split_off(burn))
}

/// `y = (C/A) e`: `a[0] y_t = sum_k c_k e_{t-k} - sum_{k>=1} a_k y_{t-k}`, zero initial state (no
/// burn-in: discard a warm-up if stationarity matters). `a[0]` must be nonzero (it divides);
/// empty `a` or `c` give zeros.
pub fn filter_arma(a: &[f64], c: &[f64], e: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; e.len()];
    let Some(&a0) = a.first() else {
        return y;
    };
    for t in 0..e.len() {
        let mut v = 0.0;
        for k in 0..c.len().min(t + 1) {
            v += c[k] * e[t - k];
        }
        for k in 1..a.len().min(t + 1) {
            v -= a[k] * y[t - k];
        }
        y[t] = v / a0;
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filter_arma_by_hand() {
        // (1 - 0.5 q^-1) y = (1 + 0.5 q^-1) e, e = [1, 0, 0]: y0 = 1, y1 = 0.5 + 0.5 = 1,
        // y2 = 0.5; with a0 = 2 every term is halved recursively: y0 = 0.5, y1 = (0.5 + 0.25)/2.
        assert_eq!(
            filter_arma(&[1.0, -0.5], &[1.0, 0.5], &[1.0, 0.0, 0.0]),
            vec![1.0, 1.0, 0.5]
        );
        assert_eq!(
            filter_arma(&[2.0, -0.5], &[1.0, 0.5], &[1.0, 0.0]),
            vec![0.5, 0.375]
        );
        assert_eq!(filter_arma(&[], &[1.0], &[1.0, 2.0]), vec![0.0, 0.0]);
    }

    #[test]
    fn ar_from_one_mode_by_hand() {
        // Undamped mode at fs/4: z = +-i -> 1 + z^-2.
        let a = ar_from_modes(&[(50.0, 0.0)], 200.0);
        assert!((a[0] - 1.0).abs() < 1e-15 && a[1].abs() < 1e-15 && (a[2] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn simulate_white_noise_variance_and_errors() {
        let y = simulate_arma(&[1.0], &[1.0], 4.0, 20000, 3).unwrap();
        let var = y.iter().map(|v| v * v).sum::<f64>() / y.len() as f64;
        assert!((var - 4.0).abs() < 0.15, "{var}");
        // Same seed, same output.
        assert_eq!(
            y[..10],
            simulate_arma(&[1.0], &[1.0], 4.0, 10, 3).unwrap()[..]
        );
        assert!(matches!(
            simulate_arma(&[1.0, -1.5], &[1.0], 1.0, 10, 0),
            Err(IdentError::UnstableModel { .. })
        ));
        assert!(simulate_arma(&[1.0, -0.5], &[1.0], -1.0, 10, 0).is_err());
        assert!(simulate_arma(&[0.0, 1.0], &[1.0], 1.0, 10, 0).is_err());
    }
}
