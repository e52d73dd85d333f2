//! Parameters of the stabilisation diagram. The clustering's [`ClusterParams`] are defined once,
//! in `vibmode-core`, and re-exported here.

pub use vibmode_core::ClusterParams;

use serde::{Deserialize, Serialize};

use crate::ModalError;

pub(crate) fn bad(
    name: &'static str,
    value: impl ToString,
    requirement: &'static str,
    suggestion: impl ToString,
) -> ModalError {
    ModalError::InvalidParam {
        name,
        value: value.to_string(),
        requirement,
        suggestion: suggestion.to_string(),
    }
}

fn positive(name: &'static str, v: f64, default: f64) -> Result<(), ModalError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(bad(name, v, "must be finite and > 0", default))
    }
}

/// Parameters of [`crate::stabilisation`] (classic stabilisation diagram criteria).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct StabilisationParams {
    /// A pole is frequency-stable when a pole of the previous order (same record and channel) has a
    /// frequency within this relative difference (dimensionless). Default 0.01 (1 %).
    pub freq_tol_rel: f64,
    /// ... and damping-stable when that pole's damping ratio is also within this relative
    /// difference (dimensionless). Default 0.05 (5 %).
    pub damping_tol_rel: f64,
}

impl Default for StabilisationParams {
    fn default() -> Self {
        StabilisationParams {
            freq_tol_rel: 0.01,
            damping_tol_rel: 0.05,
        }
    }
}

impl StabilisationParams {
    /// Check every field.
    pub fn validate(&self) -> Result<(), ModalError> {
        let d = StabilisationParams::default();
        positive("freq_tol_rel", self.freq_tol_rel, d.freq_tol_rel)?;
        positive("damping_tol_rel", self.damping_tol_rel, d.damping_tol_rel)?;
        Ok(())
    }
}
