//! The pole filters every user of a fit applies before calling its poles modes: `vibmode fit`,
//! `vibmode sweep` and the analysis read the same rules from [`PoleFilterParams`].

use serde::{Deserialize, Serialize};
use vibmode_core::{BandLimit, PoleFilterParams};

use crate::model::{ArmaModel, Mode, ModeSet};
use crate::Complex64;

/// Why a pole pair of a fit is not taken for a mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PoleRejection {
    /// A zero of C lies within the pole's own bandwidth: the pair shapes the spectrum locally (a
    /// notch beside a peak) but is no resonance.
    PoleZeroCancellation,
    /// The pole lies above the valid band of a signal with an empty band (the ideal filter's
    /// edge, or the numerical noise floor in the empty band).
    BandEdge,
}

impl std::fmt::Display for PoleRejection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            PoleRejection::PoleZeroCancellation => "cancelled by a zero of C",
            PoleRejection::BandEdge => "above the valid band (empty band above the cutoff)",
        })
    }
}

/// One mode of a fit with the verdict of the pole filters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FilteredMode {
    /// The mode (stable complex pole pair).
    pub mode: Mode,
    /// `None` when the mode passes every filter.
    pub rejected: Option<PoleRejection>,
}

/// Whether the discrete pole `(re, im)` has a zero within `tol * (1 - |pole|)` of it.
pub fn cancelled_by_zero(re: f64, im: f64, zeros: &[Complex64], tol: f64) -> bool {
    let r = (re * re + im * im).sqrt();
    let radius = tol * (1.0 - r).max(0.0);
    zeros
        .iter()
        .any(|z| ((z.re - re).powi(2) + (z.im - im).powi(2)).sqrt() < radius)
}

/// The modes of `model` (fitted at `band.fs_hz`) with the filters' verdicts, ascending in
/// frequency. The band-edge rule acts only when `band.empty_band` and
/// `params.drop_band_edge`; the cancellation rule only when `params.pole_zero_tol > 0`.
pub fn filter_modes(
    model: &ArmaModel,
    band: &BandLimit,
    params: &PoleFilterParams,
) -> Vec<FilteredMode> {
    filter_mode_set(model, &model.modes(band.fs_hz), band, params)
}

/// [`filter_modes`] for a [`ModeSet`] already computed from `model` (saves a root finding).
pub fn filter_mode_set(
    model: &ArmaModel,
    set: &ModeSet,
    band: &BandLimit,
    params: &PoleFilterParams,
) -> Vec<FilteredMode> {
    let zeros = if params.pole_zero_tol > 0.0 {
        model.zeros()
    } else {
        Vec::new()
    };
    let f_max = band.valid_max_hz();
    set.modes
        .iter()
        .map(|&mode| {
            let rejected = if params.drop_band_edge && band.empty_band && mode.frequency_hz > f_max
            {
                Some(PoleRejection::BandEdge)
            } else if cancelled_by_zero(mode.pole_re, mode.pole_im, &zeros, params.pole_zero_tol) {
                Some(PoleRejection::PoleZeroCancellation)
            } else {
                None
            };
            FilteredMode { mode, rejected }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cancellation_radius_is_the_pole_bandwidth() {
        // Pole at radius 0.9 (1 - |z| = 0.1); a zero 0.05 away cancels it at tol 1, not at 0.4.
        let zeros = [Complex64::new(0.0, 0.95)];
        assert!(cancelled_by_zero(0.0, 0.9, &zeros, 1.0));
        assert!(!cancelled_by_zero(0.0, 0.9, &zeros, 0.4));
        assert!(!cancelled_by_zero(0.0, 0.9, &zeros, 0.0));
    }
}
