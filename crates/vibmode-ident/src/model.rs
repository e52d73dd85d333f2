//! The fitted model (AR or ARMA), its spectrum, poles and modes.

use num_complex::Complex64;
use serde::{Deserialize, Serialize};

use crate::roots::polynomial_roots;

/// Which estimator produced a model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Estimator {
    /// Yule-Walker (biased autocorrelation, Levinson-Durbin).
    YuleWalker,
    /// Burg.
    Burg,
    /// Forward-backward least squares.
    LeastSquares,
    /// Prediction-error minimisation (Gauss-Newton / Levenberg-Marquardt), quadratic or Huber.
    PredictionError,
}

impl Estimator {
    /// The names [`Estimator::from_str`](std::str::FromStr) accepts first (the command line's
    /// `--estimator` values), in the order of the enum.
    pub const NAMES: [&'static str; 4] = ["yule-walker", "burg", "ls", "pem"];

    /// The estimator's name as [`Estimator::NAMES`] spells it.
    pub fn name(self) -> &'static str {
        match self {
            Estimator::YuleWalker => "yule-walker",
            Estimator::Burg => "burg",
            Estimator::LeastSquares => "ls",
            Estimator::PredictionError => "pem",
        }
    }

    /// The AR method of a closed-form estimator; `None` for prediction-error minimisation
    /// (which fits ARMA models).
    pub fn ar_method(self) -> Option<crate::ArMethod> {
        match self {
            Estimator::YuleWalker => Some(crate::ArMethod::YuleWalker),
            Estimator::Burg => Some(crate::ArMethod::Burg),
            Estimator::LeastSquares => Some(crate::ArMethod::LeastSquares),
            Estimator::PredictionError => None,
        }
    }
}

impl std::str::FromStr for Estimator {
    type Err = vibmode_core::ParamError;
    /// Accepts the [`Estimator::NAMES`], `pem`'s long form `prediction-error`, and the AR
    /// spellings of [`crate::ArMethod`] (`yw`, `least-squares`, ...; case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim().to_ascii_lowercase();
        if matches!(t.as_str(), "pem" | "prediction-error" | "prediction_error") {
            return Ok(Estimator::PredictionError);
        }
        match t.parse::<crate::ArMethod>() {
            Ok(crate::ArMethod::YuleWalker) => Ok(Estimator::YuleWalker),
            Ok(crate::ArMethod::Burg) => Ok(Estimator::Burg),
            Ok(crate::ArMethod::LeastSquares) => Ok(Estimator::LeastSquares),
            Err(_) => Err(vibmode_core::ParamError::UnknownName {
                what: "estimator",
                value: s.to_string(),
                valid: "yule-walker, burg, ls, pem",
            }),
        }
    }
}

/// Why the prediction-error search stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum StopReason {
    /// Closed-form estimator (AR methods): no iterations.
    ClosedForm,
    /// The predicted relative improvement of a Gauss-Newton step fell below `tol`.
    Converged,
    /// The loss dropped by less than `tol` (relative) over the last 5 iterations; counted as
    /// converged.
    Stalled,
    /// No trial step (Gauss-Newton with halvings, then gradient) lowered the loss.
    NoImprovement,
    /// `max_iterations` reached.
    MaxIterations,
}

/// A linear time-series model `A(q) y_t = C(q) e_t` with
/// `A(z) = 1 + a1 z^-1 + ... + ap z^-p`, `C(z) = 1 + c1 z^-1 + ... + cq z^-q`,
/// `e_t` white with variance `noise_variance`. AR models have `q = 0`, `c = [1]`.
///
/// All variances are in the units of the signal squared (e.g. (m/s^2)^2). The model describes the
/// signal after subtracting `mean` (0 if the fit did not demean).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ArmaModel {
    /// AR order p.
    pub p: usize,
    /// MA order q.
    pub q: usize,
    /// A coefficients, leading 1 included (length p + 1), dimensionless.
    pub a: Vec<f64>,
    /// C coefficients, leading 1 included (length q + 1), dimensionless.
    pub c: Vec<f64>,
    /// Innovation variance lambda (signal units squared). For prediction-error fits: the mean
    /// squared one-step prediction error `(1/(N-p)) sum_{t>=p} eps_t^2` of the conditional
    /// predictor (see [`crate::prediction_error_variance`]), also for robust fits. For AR fits: the
    /// method's own estimate (see `fit_ar`).
    pub noise_variance: f64,
    /// Value of the minimised criterion V (signal units squared): equal to `noise_variance` for the
    /// quadratic criterion and AR fits; `(1/(N-p)) sum_{t>=p} l(eps_t)` with the Huber loss
    /// otherwise.
    pub loss: f64,
    /// Gauss-Newton iterations taken (0 for AR methods).
    pub iterations: usize,
    /// Whether the search met its stopping rule (always true for AR methods).
    pub converged: bool,
    /// Why the search stopped.
    pub stop_reason: StopReason,
    /// Akaike information criterion `N ln(lambda) + 2 (p + q)`.
    pub aic: f64,
    /// Bayesian information criterion `N ln(lambda) + (p + q) ln N`.
    pub bic: f64,
    /// Akaike final prediction error `lambda (N + p + q) / (N - p - q)` (signal units squared).
    pub fpe: f64,
    /// Standard errors of `[a1..ap, c1..cq]` (dimensionless); NaN where not available.
    pub std_errors: Vec<f64>,
    /// Reflection coefficients in the A(z) convention (`k_m` = last coefficient of the order-m
    /// polynomial, i.e. minus the partial autocorrelation); empty when the method has none.
    pub reflection_coefficients: Vec<f64>,
    /// Huber threshold rho used (signal units); `None` for quadratic criteria.
    pub robust_rho: Option<f64>,
    /// Number of samples N used.
    pub n_samples: usize,
    /// Mean subtracted before fitting (signal units; 0 when not demeaned).
    pub mean: f64,
    /// Estimator used.
    pub estimator: Estimator,
    /// Samples replaced by the additive-outlier cleaner before fitting (robust prediction-error
    /// fits with [`crate::OutlierCleaning::RobustFilter`]; 0 otherwise).
    #[serde(default)]
    pub outliers_replaced: usize,
    /// Variance of the white noise floor added to a signal with an empty band before the search
    /// (signal units squared; `ArmaParams::noise_floor` x the signal's variance), 0 when none was
    /// added. When it is not 0, `noise_variance` and `loss` are those of the signal plus the floor.
    #[serde(default)]
    pub noise_floor_variance: f64,
}

/// One vibration mode from a stable complex pole pair.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Mode {
    /// Natural frequency `|ln z| / (2 pi Ts)` (Hz).
    pub frequency_hz: f64,
    /// Damping ratio `-Re(ln z) / |ln z|` (dimensionless).
    pub damping_ratio: f64,
    /// Damped frequency `Im(ln z) / (2 pi Ts)` (Hz).
    pub damped_frequency_hz: f64,
    /// Real part of the discrete-time pole z (dimensionless).
    pub pole_re: f64,
    /// Imaginary part of the discrete-time pole z (> 0, dimensionless).
    pub pole_im: f64,
}

/// A discrete-time pole `re + i im` (dimensionless).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pole {
    /// Real part.
    pub re: f64,
    /// Imaginary part.
    pub im: f64,
}

/// Poles of a model sorted into modes, stable real poles and unstable poles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct ModeSet {
    /// Modes (one per stable complex pair with Im z > 0), ascending in frequency.
    pub modes: Vec<Mode>,
    /// Stable real poles (|z| < 1, Im z = 0), ascending (dimensionless).
    pub real_poles: Vec<f64>,
    /// Poles with |z| >= 1 (both members of a complex pair listed), dimensionless.
    pub unstable_poles: Vec<Pole>,
}

impl Mode {
    /// Mode from a discrete-time pole z (Im z > 0) at sampling frequency `fs_hz`.
    pub fn from_pole(z: Complex64, fs_hz: f64) -> Mode {
        let s = z.ln();
        let mag = s.norm();
        let two_pi_ts = 2.0 * std::f64::consts::PI / fs_hz;
        Mode {
            frequency_hz: mag / two_pi_ts,
            damping_ratio: if mag > 0.0 { -s.re / mag } else { 1.0 },
            damped_frequency_hz: s.im / two_pi_ts,
            pole_re: z.re,
            pole_im: z.im,
        }
    }
}

/// Information criteria `(aic, bic, fpe)` for innovation variance `lambda`, `n` samples and `k`
/// estimated parameters (see [`ArmaModel`] for the formulas).
pub fn information_criteria(lambda: f64, n: usize, k: usize) -> (f64, f64, f64) {
    let nf = n as f64;
    let kf = k as f64;
    let ln_l = lambda.ln();
    let aic = nf * ln_l + 2.0 * kf;
    let bic = nf * ln_l + kf * nf.ln();
    let fpe = if n > k {
        lambda * (nf + kf) / (nf - kf)
    } else {
        f64::INFINITY
    };
    (aic, bic, fpe)
}

/// `sum_k coef[k] e^{-i w k}`.
fn eval_on_circle(coef: &[f64], w: f64) -> Complex64 {
    // Horner in z^-1.
    let zi = Complex64::from_polar(1.0, -w);
    let mut acc = Complex64::new(0.0, 0.0);
    for &ck in coef.iter().rev() {
        acc = acc * zi + ck;
    }
    acc
}

impl ArmaModel {
    /// Poles: roots of `z^p + a1 z^(p-1) + ... + ap` (balanced companion matrix, see
    /// [`crate::polynomial_roots`]). Empty if p = 0 or if root finding fails (it does not for
    /// finite coefficients in practice).
    pub fn poles(&self) -> Vec<Complex64> {
        polynomial_roots(&self.a).unwrap_or_default()
    }

    /// Zeros: roots of `z^q + c1 z^(q-1) + ... + cq`.
    pub fn zeros(&self) -> Vec<Complex64> {
        polynomial_roots(&self.c).unwrap_or_default()
    }

    /// Sorts the poles into modes (stable complex pairs, Im z > 0), stable real poles and unstable
    /// poles, at sampling frequency `fs_hz` (Hz).
    pub fn modes(&self, fs_hz: f64) -> ModeSet {
        modes_from_poles(&self.poles(), fs_hz)
    }

    /// One-sided model power spectral density `2 lambda Ts |C(e^{iwTs}) / A(e^{iwTs})|^2` at each
    /// frequency in `freq_hz` (Hz), in signal units squared per Hz, directly comparable with a
    /// one-sided Welch density (e.g. `scipy.signal.welch(..., scaling="density")`).
    pub fn model_psd(&self, freq_hz: &[f64], fs_hz: f64) -> Vec<f64> {
        arma_psd(&self.a, &self.c, self.noise_variance, freq_hz, fs_hz)
    }
}

/// One-sided PSD `2 lambda Ts |C(e^{iwTs}) / A(e^{iwTs})|^2` of the ARMA model with
/// coefficients `a = [1, a1, ...]`, `c = [1, c1, ...]` and innovation variance `lambda`
/// (signal units squared) at each frequency in `freq_hz` (Hz), sampled at `fs_hz`.
pub fn arma_psd(
    a: &[f64],
    c: &[f64],
    noise_variance: f64,
    freq_hz: &[f64],
    fs_hz: f64,
) -> Vec<f64> {
    let ts = 1.0 / fs_hz;
    freq_hz
        .iter()
        .map(|&f| {
            let w = 2.0 * std::f64::consts::PI * f * ts;
            let num = eval_on_circle(c, w).norm_sqr();
            let den = eval_on_circle(a, w).norm_sqr();
            2.0 * noise_variance * ts * num / den
        })
        .collect()
}

/// Sorts discrete-time poles into a [`ModeSet`] at sampling frequency `fs_hz` (Hz).
pub fn modes_from_poles(poles: &[Complex64], fs_hz: f64) -> ModeSet {
    let mut set = ModeSet::default();
    for &z in poles {
        if z.norm() >= 1.0 {
            set.unstable_poles.push(Pole { re: z.re, im: z.im });
        } else if z.im == 0.0 {
            set.real_poles.push(z.re);
        } else if z.im > 0.0 {
            set.modes.push(Mode::from_pole(z, fs_hz));
        }
    }
    set.modes
        .sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    set.real_poles.sort_by(f64::total_cmp);
    set
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn estimator_names_parse_back_and_map_to_the_ar_methods() {
        for name in Estimator::NAMES {
            let e: Estimator = name.parse().unwrap();
            assert_eq!(e.name(), name);
        }
        assert_eq!("YW".parse::<Estimator>().unwrap(), Estimator::YuleWalker);
        assert_eq!(
            "prediction-error".parse::<Estimator>().unwrap(),
            Estimator::PredictionError
        );
        assert_eq!(
            Estimator::LeastSquares.ar_method(),
            Some(crate::ArMethod::LeastSquares)
        );
        assert_eq!(Estimator::PredictionError.ar_method(), None);
        let e = "newton".parse::<Estimator>().unwrap_err().to_string();
        assert!(e.contains("'newton'") && e.contains("burg"), "{e}");
    }

    #[test]
    fn mode_from_known_pole() {
        // Continuous pole s = -zeta w0 + i w0 sqrt(1 - zeta^2), z = exp(s Ts).
        let (f0, zeta, fs) = (9.0, 0.05, 200.0);
        let w0 = 2.0 * std::f64::consts::PI * f0;
        let s = Complex64::new(-zeta * w0, w0 * (1.0 - zeta * zeta).sqrt());
        let z = (s / fs).exp();
        let m = Mode::from_pole(z, fs);
        assert!((m.frequency_hz - f0).abs() < 1e-12);
        assert!((m.damping_ratio - zeta).abs() < 1e-12);
        assert!((m.damped_frequency_hz - f0 * (1.0 - zeta * zeta).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn information_criteria_by_hand() {
        let (aic, bic, fpe) = information_criteria(std::f64::consts::E, 100, 4);
        assert!((aic - 108.0).abs() < 1e-12);
        assert!((bic - (100.0 + 4.0 * 100f64.ln())).abs() < 1e-12);
        assert!((fpe - std::f64::consts::E * 104.0 / 96.0).abs() < 1e-12);
    }
}
