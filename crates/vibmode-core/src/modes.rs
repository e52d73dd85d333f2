//! Poles, invariant modes and model fits: what identification and clustering exchange.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::ParamError;
use crate::placement::Role;

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
    /// Optional role of the channel (sprung / unsprung / other).
    pub role: Option<Role>,
    /// Mode shape at the sensors, one complex amplitude `[re, im]` per channel, when the
    /// identification method gives one (multichannel methods); `None` for single-channel fits.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<Vec<[f64; 2]>>,
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
            shape: None,
        }
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
    type Err = ParamError;
    /// Case-insensitive; accepts `_` or `-` as separator and the short form `disturbance`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().replace('_', "-").as_str() {
            "structural" => Ok(ModeClass::Structural),
            "periodic-disturbance" | "disturbance" | "periodic" => {
                Ok(ModeClass::PeriodicDisturbance)
            }
            "spurious" => Ok(ModeClass::Spurious),
            _ => Err(ParamError::UnknownName {
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
    pub roles: Vec<Role>,
    /// Lowest model order contributing a pole.
    pub min_order: usize,
    /// Classification.
    pub class: ModeClass,
    /// Median kurtosis of the signal band-passed around the mode's frequency over the records
    /// and channels of its pool (1.5 for a sine, 3 for a randomly excited mode), when the
    /// analysis computed it (line detection on).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_kurtosis: Option<f64>,
    /// Mean mode shape of the cluster's poles (one complex `[re, im]` per channel of the
    /// identification, largest modulus 1 + 0i), when its poles carry shapes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<Vec<[f64; 2]>>,
    /// Median and lowest MAC of the poles' shapes with the mean shape (the shape spread).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape_mac: Option<(f64, f64)>,
    /// Standard deviations of the frequency and damping estimates themselves (not the spread
    /// of the poles over orders), when the analysis computed them: SSI-cov from correlations
    /// pooled over the records, by a leave-one-record-out jackknife.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uncertainty: Option<ModeUncertainty>,
}

/// Standard deviations of an identified mode's frequency and damping ratio (of the estimate,
/// not the spread of its poles), by one of two methods ([`UncertaintyMethod`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModeUncertainty {
    /// Standard deviation of the frequency, Hz.
    pub frequency_std_hz: f64,
    /// Standard deviation of the damping ratio.
    pub damping_std: f64,
    /// Estimates behind the standard deviations: jackknife repetitions (groups of records
    /// left out) that found the mode; first-order: the model orders whose pole near the mode
    /// had a finite standard deviation (the median over them is given).
    pub replicates: usize,
    /// Jackknife: repetitions tried (groups of records); first-order: the mode's orders tried.
    pub of: usize,
    /// How the standard deviations were obtained (default, when absent from JSON: jackknife).
    #[serde(default)]
    pub method: UncertaintyMethod,
}

/// How a [`ModeUncertainty`] was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum UncertaintyMethod {
    /// A delete-a-group jackknife over records: the identification repeated without each group
    /// of records, the mode's median frequency and damping over its orders taken each time, and
    /// `sqrt((m - 1) / m * sum (theta_s - mean)^2)` over the `m` repetitions that found it.
    #[default]
    Jackknife,
    /// First-order propagation of the block Toeplitz matrix's scatter over blocks of one
    /// record to each pole (Döhler & Mevel 2013; `vibmode_ssi::SsiPerturbation`); the median
    /// over the mode's orders.
    FirstOrder,
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
    /// Mode shape at the sensors (one complex `[re, im]` per entry of `shape_channels`), when
    /// the model knows its sensors.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<Vec<[f64; 2]>>,
    /// Channel names of the entries of `shape`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shape_channels: Vec<String>,
}

impl ReferenceMode {
    /// A reference mode without a shape.
    pub fn new(frequency_hz: f64, damping_ratio: f64, label: impl Into<String>) -> Self {
        ReferenceMode {
            frequency_hz,
            damping_ratio,
            label: label.into(),
            shape: None,
            shape_channels: Vec::new(),
        }
    }

    /// The shape reordered to `channels` (by name); `None` when the mode has no shape or a
    /// channel is not among `shape_channels`.
    pub fn shape_for(&self, channels: &[String]) -> Option<Vec<[f64; 2]>> {
        let shape = self.shape.as_ref()?;
        channels
            .iter()
            .map(|c| {
                self.shape_channels
                    .iter()
                    .position(|n| n == c)
                    .and_then(|i| shape.get(i).copied())
            })
            .collect()
    }
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
    /// MAC between the matched mode's shape and the reference shape, when both have one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mac: Option<f64>,
}

fn nan_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// Summary of one model fit of a sweep (one record, channel and order).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitSummary {
    /// Record index.
    pub record: usize,
    /// Model order p.
    pub order: usize,
    /// Criterion value at the optimum (signal units squared); NaN when the fit failed.
    #[serde(deserialize_with = "nan_if_null")]
    pub loss: f64,
    /// Innovation variance estimate (signal units squared); NaN when the fit failed.
    #[serde(deserialize_with = "nan_if_null")]
    pub noise_variance: f64,
    /// Whether the search ended by its own stopping rule (not at the iteration cap).
    pub converged: bool,
    /// Number of poles outside the unit circle.
    pub n_unstable: usize,
    /// Whether the fit failed outright (then `error` says why).
    pub failed: bool,
    /// Why the fit failed (the identification error's message); `None` when it did not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// The coefficients of one fitted ARMA / AR model, enough to evaluate its spectrum and poles
/// again: `A(z) = 1 + a1 z^-1 + ...`, `C(z) = 1 + c1 z^-1 + ...`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelCoefficients {
    /// Model order p.
    pub order: usize,
    /// Sampling rate the model was fitted at, Hz.
    pub fs_hz: f64,
    /// `[1, a1, ..., ap]`.
    pub a: Vec<f64>,
    /// `[1, c1, ..., cq]` (`[1]` for an AR model).
    pub c: Vec<f64>,
    /// Innovation variance (signal units squared).
    pub noise_variance: f64,
}

/// A support test of the clustering that a cluster failed (why it is `Spurious`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "test", rename_all = "snake_case")]
pub enum SupportFailure {
    /// Found in too few records.
    RecordShare {
        /// Share of the records that contain the cluster.
        share: f64,
        /// The required share (`min_record_share`).
        min: f64,
    },
    /// Found at too few model orders.
    OrderShare {
        /// Share of the (record, order) fits that contain the cluster.
        share: f64,
        /// The required share (`min_order_share`).
        min: f64,
    },
}

impl fmt::Display for SupportFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SupportFailure::RecordShare { share, min } => write!(
                f,
                "in {:.0} % of records, below min_record_share {}",
                100.0 * share,
                min
            ),
            SupportFailure::OrderShare { share, min } => write!(
                f,
                "in {:.0} % of orders, below min_order_share {}",
                100.0 * share,
                min
            ),
        }
    }
}

impl InvariantMode {
    /// The support tests this cluster fails under `params` with `n_records` records (empty for
    /// an invariant mode): the same rule the clustering classifies by.
    pub fn support_failures(
        &self,
        params: &crate::ClusterParams,
        n_records: usize,
    ) -> Vec<SupportFailure> {
        let mut out = Vec::new();
        if n_records > 1 && self.record_share < params.min_record_share {
            out.push(SupportFailure::RecordShare {
                share: self.record_share,
                min: params.min_record_share,
            });
        }
        if self.order_share < params.min_order_share {
            out.push(SupportFailure::OrderShare {
                share: self.order_share,
                min: params.min_order_share,
            });
        }
        out
    }
}

/// A true mode or line of a simulation, printed beside the identified ones: label, frequency in
/// Hz, damping ratio (0 for a line).
pub type TruthRow = (String, f64, f64);
