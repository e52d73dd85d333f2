//! # vibmode-ident
//!
//! Parametric identification of vibration modes from a single measured signal (e.g. a vertical
//! acceleration sampled at `fs_hz`):
//!
//! * AR(p) by Yule-Walker, Burg or forward-backward least squares ([`fit_ar`]);
//! * ARMA(p, q) by quadratic or Huber-robustified prediction-error minimisation
//!   ([`fit_arma`], [`fit_arma_warm`], [`sweep_arma`]), the method of MATLAB's `armax`/`pem`;
//! * additive outliers (spikes in the signal) removed before robust fits by a robust AR
//!   filter-cleaner ([`clean_additive_outliers`], [`OutlierCleaning`]);
//! * model spectra in the units of a one-sided Welch density ([`ArmaModel::model_psd`]);
//! * poles (Aberth-Ehrlich or balanced companion matrix, polished: [`polynomial_roots`]) and modes: natural frequency in Hz
//!   and damping ratio ([`ArmaModel::modes`]).
//!
//! Sign convention: `A(q) y_t = C(q) e_t`, `A(z) = 1 + a1 z^-1 + ... + ap z^-p`,
//! `C(z) = 1 + c1 z^-1 + ... + cq z^-q`; `a` and `c` include the leading 1.
//! The exact definitions (criterion, robustification, search, stopping rule) are in
//! `docs/identification.md`.
//!
//! ## Example
//!
//! Simulate a lightly damped 9 Hz mode sampled at 200 Hz and recover it with ARMA(2, 2):
//!
//! ```
//! use vibmode_ident::{fit_arma, sim, ArmaParams, Robust};
//!
//! let fs_hz = 200.0;
//! let a = sim::ar_from_modes(&[(9.0, 0.05)], fs_hz);
//! let y = sim::simulate_arma(&a, &[1.0, 0.3, 0.1], 1.0, 8000, 7).unwrap();
//! let params = ArmaParams { robust: Robust::Off, ..ArmaParams::default() };
//! let model = fit_arma(&y, 2, 2, &params).unwrap();
//! assert!(model.converged);
//! let modes = model.modes(fs_hz).modes;
//! assert_eq!(modes.len(), 1);
//! assert!((modes[0].frequency_hz - 9.0).abs() < 0.1);
//! assert!((modes[0].damping_ratio - 0.05).abs() < 0.01);
//! // The innovation variance is close to the simulated one (1.0).
//! assert!((model.noise_variance - 1.0).abs() < 0.05);
//! ```
//!
//! ## Panics
//!
//! No function panics on input data; bad input gives an [`IdentError`] whose message names the
//! offending value and the fix.

#![warn(missing_docs)]

mod ar;
mod arma;
mod error;
mod linalg;
mod model;
mod outliers;
mod params;
mod poles;
mod prepare;
mod roots;
pub mod sim;
mod sweep;

pub use ar::{fit_ar, max_ar_order, ArMethod};
pub use arma::{fit_arma, fit_arma_warm, max_arma_order, prediction_error_variance, sweep_arma};
pub use error::IdentError;
pub use model::{
    arma_psd, information_criteria, modes_from_poles, ArmaModel, Estimator, Mode, ModeSet, Pole,
    StopReason,
};
pub use num_complex::Complex64;
pub use outliers::{clean_additive_outliers, CleanedSignal, CleanerParams, OutlierCleaning};
pub use params::{ArmaParams, Robust, SearchStarts, FIT_MAX_ITERATIONS, FIT_TOLERANCE};
pub use poles::{cancelled_by_zero, filter_mode_set, filter_modes, FilteredMode, PoleRejection};
pub use roots::polynomial_roots;
pub use sweep::sweep_fits;
