//! Plain input and output types.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::ModalError;

/// One complex pole pair of one fitted model, as a mode: natural frequency and damping ratio,
/// tagged with where it came from.
///
/// This crate does not depend on the identification crates; convert their poles into this type.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoleObservation {
    /// Undamped natural frequency, Hz (`|ln z| / (2 pi T_s)`).
    pub frequency_hz: f64,
    /// Damping ratio (dimensionless, `-Re(s)/|s|`), 0 < zeta < 1 for a stable resonant pole.
    pub damping_ratio: f64,
    /// Model order p of the fit that produced the pole.
    pub order: usize,
    /// Record (segment) index, 0-based, must be `< n_records`.
    pub record: usize,
    /// Channel (sensor) name, e.g. "FR_sprung".
    pub channel: String,
    /// Optional role of the channel, e.g. "sprung" / "unsprung".
    pub role: Option<String>,
}

impl PoleObservation {
    /// Convenience constructor without a role. Frequency in Hz, damping ratio dimensionless.
    pub fn new(
        frequency_hz: f64,
        damping_ratio: f64,
        order: usize,
        record: usize,
        channel: impl Into<String>,
    ) -> Self {
        PoleObservation {
            frequency_hz,
            damping_ratio,
            order,
            record,
            channel: channel.into(),
            role: None,
        }
    }

    /// Checks that frequency and damping ratio are finite; `index` (the pole's position in the
    /// caller's slice) goes into the error. Shared by clustering and the stabilisation diagram.
    pub(crate) fn check_finite(&self, index: usize) -> Result<(), ModalError> {
        if !self.frequency_hz.is_finite() {
            return Err(ModalError::NonFiniteFrequency {
                index,
                value: self.frequency_hz,
            });
        }
        if !self.damping_ratio.is_finite() {
            return Err(ModalError::NonFiniteDamping {
                index,
                value: self.damping_ratio,
            });
        }
        Ok(())
    }
}

/// Class of a pole cluster.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ModeClass {
    /// Invariant mode of the structure (suspension): supported by enough records and orders and
    /// not a periodic disturbance.
    Structural,
    /// Invariant, very lightly damped and frequency-stable cluster: an engine/gear line, not a mode
    /// of the suspension. Filter it out before further identification.
    PeriodicDisturbance,
    /// Dense cluster that fails the support tests (too few records or orders): not invariant.
    Spurious,
}

impl ModeClass {
    const VALID: &'static str = "structural, periodic-disturbance, spurious";
}

impl fmt::Display for ModeClass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ModeClass::Structural => "structural",
            ModeClass::PeriodicDisturbance => "periodic-disturbance",
            ModeClass::Spurious => "spurious",
        })
    }
}

impl FromStr for ModeClass {
    type Err = ModalError;
    /// Case-insensitive; accepts `_` or `-` as separator and the short form `disturbance`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().replace('_', "-").as_str() {
            "structural" => Ok(ModeClass::Structural),
            "periodic-disturbance" | "disturbance" | "periodic" => {
                Ok(ModeClass::PeriodicDisturbance)
            }
            "spurious" => Ok(ModeClass::Spurious),
            _ => Err(ModalError::UnknownName {
                what: "mode class",
                value: s.to_string(),
                valid: Self::VALID,
            }),
        }
    }
}

/// One cluster of poles (an invariant mode, a periodic disturbance, or a spurious cluster).
///
/// Statistics are computed over the cluster's poles after keeping at most one pole per
/// (record, channel, order) fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InvariantMode {
    /// Mean natural frequency of the cluster's poles, Hz.
    pub frequency_hz: f64,
    /// Sample standard deviation (n-1) of the poles' frequencies, Hz (0 for a single pole).
    pub frequency_std_hz: f64,
    /// Median damping ratio of the cluster's poles (dimensionless).
    pub damping_ratio: f64,
    /// 25th and 75th percentiles of the damping ratio (linear interpolation, numpy default).
    pub damping_iqr: (f64, f64),
    /// Share (0..1) of the `n_records x orders.len()` (record, order) fits in which the cluster has
    /// at least one pole (in any channel) = mean over records of the share of orders.
    pub order_share: f64,
    /// Share (0..1) of the `n_records` records that contain the cluster, a record counting when the
    /// cluster has poles in at least `max(1, ceil(record_min_order_share * orders.len()))` of its
    /// orders.
    pub record_share: f64,
    /// Number of poles in the cluster (at most one per (record, channel, order)).
    pub n_poles: usize,
    /// Distinct channels contributing poles, sorted.
    pub channels: Vec<String>,
    /// Distinct roles of the contributing poles (those that have one), sorted.
    pub roles: Vec<String>,
    /// Lowest model order contributing a pole.
    pub min_order: usize,
    /// Classification.
    pub class: ModeClass,
}

impl InvariantMode {
    /// True for `Structural` and `PeriodicDisturbance` (the cluster passed the support tests).
    pub fn is_invariant(&self) -> bool {
        self.class != ModeClass::Spurious
    }
}

/// A mode of a physical reference model (e.g. the full-car model eigenvalues).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceMode {
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio (dimensionless).
    pub damping_ratio: f64,
    /// Label, e.g. "body heave" or "wheel hop FL".
    pub label: String,
}

/// Result of matching one reference mode to the invariant modes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModeMatch {
    /// The reference mode.
    pub reference: ReferenceMode,
    /// Index (into the `modes` slice) of the matched structural mode; `None` when no structural mode
    /// lies within `max_freq_diff_rel`.
    pub invariant: Option<usize>,
    /// Signed relative frequency difference `(f_invariant - f_reference) / f_reference` to the
    /// nearest structural mode (reported even when unmatched); NaN (null in JSON) when there is no
    /// structural mode at all.
    #[serde(deserialize_with = "nan_if_null")]
    pub freq_diff_rel: f64,
    /// Signed damping-ratio difference `zeta_invariant - zeta_reference` to the same nearest mode;
    /// NaN (null in JSON) when there is no structural mode at all.
    #[serde(deserialize_with = "nan_if_null")]
    pub damping_diff: f64,
}

fn nan_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}
