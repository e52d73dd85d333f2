//! Settings of the prediction-error search: the criterion ([`Robust`]) and [`ArmaParams`].
//!
//! Kept apart from `arma.rs` so that the signal preparation (`prepare.rs`) and the search
//! (`arma.rs`) both depend on the settings, and the outlier cleaner depends on neither.

use serde::{Deserialize, Serialize};

use crate::outliers::OutlierCleaning;
use crate::IdentError;

/// Robustification of the prediction-error criterion: defined once, in `vibmode-core` (a Huber
/// factor or `off`, one spelling in TOML, JSON, the command line and Python).
pub use vibmode_core::Robust;
/// Where each fit's search starts: defined once, in `vibmode-core`.
pub use vibmode_core::SearchStarts;
use vibmode_core::{BandLimit, ParamError};

/// Settings of the prediction-error search.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ArmaParams {
    /// Criterion. Default `Robust::Huber { factor: 1.6 }`.
    pub robust: Robust,
    /// Maximum Gauss-Newton iterations. Default [`FIT_MAX_ITERATIONS`] (100); the analysis sweep
    /// sets `SweepParams::max_iterations` instead. (`max_iter` is read as this, the spelling
    /// before the one name.)
    #[serde(alias = "max_iter")]
    pub max_iterations: usize,
    /// Stopping tolerance (dimensionless): the search stops when the predicted relative
    /// improvement of a Gauss-Newton step `(V - V_pred) / V` is below `tolerance`, or when the
    /// loss dropped by less than `tolerance` (relative) over the last 5 iterations. Default
    /// [`FIT_TOLERANCE`] (1e-5); the analysis sweep sets `SweepParams::tolerance` instead. (`tol`
    /// is read as this.)
    #[serde(alias = "tol")]
    pub tolerance: f64,
    /// Maximum step halvings per direction. Default 10.
    pub max_halvings: usize,
    /// Subtract the mean of `y` before fitting. Default true.
    pub demean: bool,
    /// Additive-outlier (spike) cleaning before a `Robust::Huber` fit (unused by `Robust::Off`).
    /// Default `OutlierCleaning::RobustFilter` with default [`crate::CleanerParams`].
    #[serde(default)]
    pub outlier_cleaning: OutlierCleaning,
    /// Numerical noise floor for signals with an empty band (dimensionless, >= 0; 0 = off).
    /// Default 1e-3 (-30 dB of the signal's mean square).
    ///
    /// After an ideal low-pass (the paper's 25 Hz cutoff at 200 Hz) the band above the cutoff is
    /// empty to rounding error, the signal is almost perfectly predictable there, and the
    /// prediction-error criterion has no minimum: C's zeros run to the unit circle, the loss falls
    /// to 1e-20 of the signal's, fits hit the iteration cap and their poles are meaningless. When
    /// the signal has such a band (more than 1 % of its periodogram bins below 1e-20 of the
    /// largest: only rounding error is left there), white noise of variance `noise_floor x` its
    /// mean square, from a fixed-seed generator (the same bytes every run), is added to the signal
    /// the search works on. That bounds the prediction gain at 1/noise_floor and gives the
    /// criterion a well-defined minimum. A floor only just deep enough for a minimum (1e-8) leaves
    /// C with zeros within ~1e-8 of the unit circle: the predictor's start-up transient then
    /// never decays within the record, the loss depends on where its sum starts, warm starts are
    /// useless and half the fits reach the iteration cap; at 1e-3 the fits are sound (see
    /// docs/identification.md for the measurements). White noise added to an ARMA(p, q <= p)
    /// process leaves its poles where they are. Signals without an empty band are fitted as they
    /// are.
    /// The reported `noise_variance` and `loss` are those of the signal the search saw.
    #[serde(default = "default_noise_floor")]
    pub noise_floor: f64,
    /// The band the signal carries, as the pre-processing reported it
    /// ([`vibmode_core::BandLimit`]: whether an ideal low-pass left an empty band). Its
    /// `empty_band` decides whether the noise floor is added. `None` (default) for a signal of
    /// unknown provenance: the band is then judged from the signal itself (more than 1 % of its
    /// periodogram bins below 1e-20 of the largest, which is what an ideal DFT low-pass leaves).
    #[serde(default)]
    pub band: Option<BandLimit>,
    /// Where the search starts: from every candidate for small models
    /// ([`SearchStarts::Multi`], the default) or from the best-scored one only.
    #[serde(default)]
    pub starts: SearchStarts,
}

/// Default [`ArmaParams::max_iterations`] of a single fit (`vibmode fit`, Python's `fit_arma`):
/// 100 Gauss-Newton iterations, enough for a fit from its cold start to converge. The analysis
/// sweep uses `vibmode_core::SWEEP_MAX_ITERATIONS` (20, MATLAB's `MaxIterations`) instead: its
/// fits are warm-started from the order below and many, so they are capped sooner.
pub const FIT_MAX_ITERATIONS: usize = 100;

/// Default [`ArmaParams::tolerance`] of a single fit: 1e-5 (relative predicted improvement). The
/// analysis sweep uses `vibmode_core::SWEEP_TOLERANCE` (1e-4, MATLAB's `Tolerance` of 0.01 %)
/// instead, for the same reason as [`FIT_MAX_ITERATIONS`].
pub const FIT_TOLERANCE: f64 = 1e-5;

/// Default [`ArmaParams::noise_floor`] (relative variance): -30 dB, see the field's documentation.
const DEFAULT_NOISE_FLOOR: f64 = 1e-3;

/// Largest accepted [`ArmaParams::noise_floor`] (exclusive): -10 dB; more noise than that would
/// visibly bias the fit rather than only bound the prediction gain.
const MAX_NOISE_FLOOR: f64 = 0.1;

fn default_noise_floor() -> f64 {
    DEFAULT_NOISE_FLOOR
}

impl Default for ArmaParams {
    fn default() -> Self {
        ArmaParams {
            robust: Robust::default(),
            max_iterations: FIT_MAX_ITERATIONS,
            tolerance: FIT_TOLERANCE,
            max_halvings: 10,
            demean: true,
            outlier_cleaning: OutlierCleaning::default(),
            noise_floor: default_noise_floor(),
            band: None,
            starts: SearchStarts::Multi,
        }
    }
}

impl ArmaParams {
    pub(crate) fn validate(&self) -> Result<(), IdentError> {
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(ParamError::out_of_range(
                "tolerance",
                self.tolerance,
                "must be a small positive number",
                FIT_TOLERANCE,
            )
            .into());
        }
        if !(self.noise_floor.is_finite() && (0.0..MAX_NOISE_FLOOR).contains(&self.noise_floor)) {
            return Err(ParamError::out_of_range(
                "noise_floor",
                self.noise_floor,
                "must be a relative variance in [0, 0.1) (0 for none)",
                ArmaParams::default().noise_floor,
            )
            .into());
        }
        if let Robust::Huber { factor } = self.robust {
            if !(factor.is_finite() && factor > 0.0) {
                return Err(ParamError::out_of_range(
                    "robust",
                    factor,
                    "must be a positive Huber factor, or off",
                    Robust::default(),
                )
                .into());
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn robust_parse_display() {
        assert_eq!("off".parse::<Robust>().unwrap(), Robust::Off);
        assert_eq!(
            "2.5".parse::<Robust>().unwrap(),
            Robust::Huber { factor: 2.5 }
        );
        assert_eq!(Robust::default(), Robust::Huber { factor: 1.6 });
        assert_eq!(Robust::default().to_string(), "1.6");
        let e = "-1".parse::<Robust>().unwrap_err().to_string();
        assert!(e.contains("-1") && e.contains("off"), "{e}");
    }
}
