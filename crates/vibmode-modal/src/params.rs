//! Parameters of the clustering and of the stabilisation diagram.

use serde::{Deserialize, Serialize};

use crate::ModalError;

/// Parameters of [`crate::find_invariant_modes`]. See `docs/modal.md` for the reasoning.
///
/// Poles are placed in the plane `u = ln(f) / ln(1 + freq_tol_rel)`,
/// `v = log10(zeta) / log_damping_tol`; two poles are neighbours when their distance in that plane
/// is at most 1, the `u` difference being shrunk for damped poles so that, at equal damping zeta,
/// they are neighbours when their frequency ratio is within
/// `1 + max(freq_tol_rel, freq_tol_per_damping * zeta)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ClusterParams {
    /// Relative frequency neighbourhood radius (dimensionless). Default 0.02 (2 %).
    pub freq_tol_rel: f64,
    /// Growth of the frequency neighbourhood with damping (dimensionless, >= 0): the relative
    /// frequency radius for two poles of damping ratios `zeta_a`, `zeta_b` is
    /// `max(freq_tol_rel, freq_tol_per_damping * sqrt(zeta_a * zeta_b))`. A mode of damping ratio
    /// zeta has a half-power bandwidth of `2 zeta f`, and its identified poles scatter in frequency
    /// roughly in proportion to it; 0.5 makes the radius a quarter of that bandwidth (7.5 % at
    /// zeta = 0.15, 15 % at zeta = 0.3), so heavily damped modes are not fragmented, while lightly
    /// damped lines keep the `freq_tol_rel` radius. Larger neighbourhoods also gather more
    /// background poles, so use it with a strict `min_order_share` (`vibmode analyze` uses 0.5
    /// with 0.5). Default 0 (fixed radius).
    pub freq_tol_per_damping: f64,
    /// Damping neighbourhood radius in decades of the damping ratio (log10 units). Default 0.2
    /// (a factor 1.58).
    pub log_damping_tol: f64,
    /// Absolute minimum number of poles (the pole itself included) in a neighbourhood for the pole
    /// to be a core pole. Default 5.
    pub min_points: usize,
    /// Relative core threshold: a neighbourhood must also hold at least
    /// `min_density_share * n_fits` poles, where `n_fits = n_records * orders.len() * n_channels`.
    /// The core threshold is `max(min_points, ceil(min_density_share * n_fits))`. Default 0.03.
    pub min_density_share: f64,
    /// Minimum share (0..1) of the records in which a cluster must appear to be invariant (ignored
    /// when `n_records == 1`). Default 0.5.
    pub min_record_share: f64,
    /// A record counts as containing a cluster (for `record_share`) only when the cluster has poles
    /// in at least `max(1, ceil(record_min_order_share * orders.len()))` of that record's model
    /// orders (any channel), so that a few stray poles do not make a record "support" a mode.
    /// Default 0.1.
    pub record_min_order_share: f64,
    /// Minimum `order_share` (0..1) of the (record, order) fits in which a cluster must appear to be
    /// invariant. Default 0.25.
    pub min_order_share: f64,
    /// A cluster is a periodic disturbance when its median damping ratio is below this value
    /// (dimensionless) and its frequency spread is below `disturbance_freq_spread_max`.
    /// Default 5e-3.
    pub disturbance_damping_max: f64,
    /// Maximum relative frequency spread (`frequency_std_hz / frequency_hz`) of a periodic
    /// disturbance (dimensionless). Default 0.01.
    pub disturbance_freq_spread_max: f64,
    /// Poles below this natural frequency (Hz) are ignored. Default 0.1 Hz.
    pub freq_min_hz: f64,
    /// Poles above this natural frequency (Hz) are ignored. Default 30 Hz.
    pub freq_max_hz: f64,
    /// Poles with a damping ratio above this value are ignored (overdamped-like, not resonant).
    /// Default 0.6.
    pub max_damping_ratio: f64,
    /// Damping ratios in `[0, min_damping_ratio)` are raised to this floor for the log10 coordinate
    /// (statistics use the true values); negative damping ratios (unstable poles) are ignored.
    /// Default 1e-6.
    pub min_damping_ratio: f64,
}

impl Default for ClusterParams {
    fn default() -> Self {
        ClusterParams {
            freq_tol_rel: 0.02,
            freq_tol_per_damping: 0.0,
            log_damping_tol: 0.2,
            min_points: 5,
            min_density_share: 0.03,
            min_record_share: 0.5,
            record_min_order_share: 0.1,
            min_order_share: 0.25,
            disturbance_damping_max: 5e-3,
            disturbance_freq_spread_max: 0.01,
            freq_min_hz: 0.1,
            freq_max_hz: 30.0,
            max_damping_ratio: 0.6,
            min_damping_ratio: 1e-6,
        }
    }
}

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

fn share(name: &'static str, v: f64, default: f64) -> Result<(), ModalError> {
    if (0.0..=1.0).contains(&v) {
        Ok(())
    } else {
        Err(bad(name, v, "must be in [0, 1]", default))
    }
}

impl ClusterParams {
    /// Check every field; returns the first invalid one.
    pub fn validate(&self) -> Result<(), ModalError> {
        let d = ClusterParams::default();
        positive("freq_tol_rel", self.freq_tol_rel, d.freq_tol_rel)?;
        if !(self.freq_tol_per_damping.is_finite() && self.freq_tol_per_damping >= 0.0) {
            return Err(bad(
                "freq_tol_per_damping",
                self.freq_tol_per_damping,
                "must be finite and >= 0",
                d.freq_tol_per_damping,
            ));
        }
        positive("log_damping_tol", self.log_damping_tol, d.log_damping_tol)?;
        if self.min_points == 0 {
            return Err(bad("min_points", 0, "must be >= 1", d.min_points));
        }
        share(
            "min_density_share",
            self.min_density_share,
            d.min_density_share,
        )?;
        share(
            "min_record_share",
            self.min_record_share,
            d.min_record_share,
        )?;
        share(
            "record_min_order_share",
            self.record_min_order_share,
            d.record_min_order_share,
        )?;
        share("min_order_share", self.min_order_share, d.min_order_share)?;
        positive(
            "disturbance_damping_max",
            self.disturbance_damping_max,
            d.disturbance_damping_max,
        )?;
        positive(
            "disturbance_freq_spread_max",
            self.disturbance_freq_spread_max,
            d.disturbance_freq_spread_max,
        )?;
        positive("freq_min_hz", self.freq_min_hz, d.freq_min_hz)?;
        if self.freq_max_hz.is_nan() || self.freq_max_hz <= self.freq_min_hz {
            return Err(bad(
                "freq_max_hz",
                self.freq_max_hz,
                "must be > freq_min_hz",
                if self.freq_min_hz < d.freq_max_hz {
                    d.freq_max_hz
                } else {
                    2.0 * self.freq_min_hz
                },
            ));
        }
        positive(
            "max_damping_ratio",
            self.max_damping_ratio,
            d.max_damping_ratio,
        )?;
        positive(
            "min_damping_ratio",
            self.min_damping_ratio,
            d.min_damping_ratio,
        )?;
        if self.min_damping_ratio >= self.max_damping_ratio {
            return Err(bad(
                "min_damping_ratio",
                self.min_damping_ratio,
                "must be < max_damping_ratio",
                d.min_damping_ratio,
            ));
        }
        Ok(())
    }
}

/// Parameters of [`crate::stabilisation()`] (classic stabilisation diagram criteria).
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
