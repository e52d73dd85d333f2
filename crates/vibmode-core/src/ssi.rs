//! Parameters of covariance-driven stochastic subspace identification (SSI-cov) and of its
//! stabilisation diagram. The numerics are in the `vibmode-ssi` crate; these structs are shared
//! by the TOML config, the command line and the Python package.

use serde::{Deserialize, Serialize};

use crate::error::ParamError;
use crate::limits::{SSI_FIRST_LAG_MAX, SSI_ORDER_MAX, SSI_TOEPLITZ_ROWS_MAX};

/// Block rows of SSI-cov on one record ([`SsiParams::default`]; `vibmode ssi`, Python's
/// `ssi_cov`): 20, lags 1..=39, which a single record of a few thousand samples still estimates
/// (each lag's correlation averages `N - lag` products of that record alone).
pub const SINGLE_RECORD_BLOCK_ROWS: usize = 20;

/// Block rows of SSI-cov in the analysis of many records ([`SsiParams::for_analysis`], the
/// `[ssi]` section's default): 40, lags to 1.6 s at 50 Hz. Longer than on one record because the
/// analysis pools the correlations over its records, so the long lags that the lightly damped
/// body modes need are averaged over all of them; chosen on the demo (docs/ssi.md: per record,
/// or pooled with 20 block rows, heave was not found).
pub const ANALYSIS_BLOCK_ROWS: usize = 40;

/// SSI-cov: the block Toeplitz matrix and the model orders identified from it. Two uses, two
/// named defaults: [`SsiParams::default`] for one record, [`SsiParams::for_analysis`] for the
/// analysis of many records (more block rows, correlations pooled over the records).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SsiParams {
    /// Number of block rows `i` of the block Toeplitz matrix of output correlations (default
    /// [`SINGLE_RECORD_BLOCK_ROWS`] = 20; in the analysis [`ANALYSIS_BLOCK_ROWS`] = 40).
    /// The matrix holds the lags 1..=2i-1 and is `(i * l) x (i * l)` for `l` channels; the
    /// highest identifiable order is `(i - 1) * l`, and each channel needs at least `2 i` samples.
    pub block_rows: usize,
    /// Lowest model order (state dimension) identified (default 2: one mode).
    pub order_min: usize,
    /// Highest model order identified (default 60).
    pub order_max: usize,
    /// Step between identified orders (default 2: one mode per step).
    pub order_step: usize,
    /// Reference-based SSI-cov: the 0-based indices of the reference channels `r`, with which
    /// every channel is correlated (`R_k = E[y_{t+k} y_ref,t^T]`, `l x r`). The Toeplitz matrix
    /// is then `(i l) x (i r)`, smaller to decompose, and the highest order also at most `i r`.
    /// Default none: every channel is a reference.
    pub reference_channels: Option<Vec<usize>>,
    /// In the analysis of many records: `true` identifies once from the correlations averaged
    /// over all records used (long data for lightly damped, low modes; the poles then vary over
    /// orders only, the analysis' default, [`SsiParams::for_analysis`]); `false` (the default
    /// of one record, where there is nothing to pool) identifies each record alone, as the ARMA
    /// sweep does, so that a mode must recur over records.
    pub pool_records: bool,
    /// First correlation lag of the Toeplitz matrix, samples (default 1): the matrix holds the
    /// lags `first_lag..=first_lag + 2i - 2`. Lag 0 carries the measurement noise. A larger
    /// first lag skips the lags at which the excitation itself is correlated, such as the
    /// delay between a vehicle's front and rear wheels on the same road (`wheelbase / speed`):
    /// beyond it the correlations are free decays of the modes again (docs/ssi.md).
    pub first_lag: usize,
}

impl Default for SsiParams {
    /// The settings for one record (`vibmode ssi`); the analysis of many records uses
    /// [`SsiParams::for_analysis`].
    fn default() -> Self {
        SsiParams {
            block_rows: SINGLE_RECORD_BLOCK_ROWS,
            order_min: 2,
            order_max: 60,
            order_step: 2,
            reference_channels: None,
            pool_records: false,
            first_lag: 1,
        }
    }
}

impl SsiParams {
    /// The settings of the analysis of many records (the `[ssi]` section's defaults):
    /// [`ANALYSIS_BLOCK_ROWS`] block rows and the correlations pooled over the records; the
    /// orders and lags as [`SsiParams::default`].
    pub fn for_analysis() -> Self {
        SsiParams {
            block_rows: ANALYSIS_BLOCK_ROWS,
            pool_records: true,
            ..SsiParams::default()
        }
    }

    /// The largest correlation lag of the block Toeplitz matrix, samples:
    /// `first_lag + 2 block_rows - 2`.
    pub fn last_lag(&self) -> usize {
        self.first_lag + 2 * self.block_rows - 2
    }

    /// The span of the lags in seconds at `fs_hz` (`last_lag / fs_hz`). A mode whose period is
    /// longer (below `1 / span` Hz) completes less than one period within the lags, and in
    /// noise SSI-cov seldom identifies it (docs/ssi.md, "What the lags reach").
    pub fn lag_span_s(&self, fs_hz: f64) -> f64 {
        self.last_lag() as f64 / fs_hz
    }

    /// The identified orders: `order_min, order_min + order_step, ...` up to `order_max`
    /// (inclusive when reached). Empty only for parameters that fail [`SsiParams::validate`].
    pub fn orders(&self) -> Vec<usize> {
        if self.order_step == 0 || self.order_max < self.order_min {
            return Vec::new();
        }
        (self.order_min..=self.order_max)
            .step_by(self.order_step)
            .collect()
    }

    /// Checks ranges: `1 <= block_rows <= 1024` ([`SSI_TOEPLITZ_ROWS_MAX`]; with the channels,
    /// `block_rows x channels <= 1024` is checked against the data), `order_min >= 2`,
    /// `order_step >= 1`, `order_min <= order_max <= 1024` ([`SSI_ORDER_MAX`]),
    /// `1 <= first_lag <= 2^30` ([`SSI_FIRST_LAG_MAX`]), and `reference_channels` (when given)
    /// not empty and without repeated indices. Whether the indices exist, and whether the
    /// record is long enough, is checked against the data.
    pub fn validate(&self) -> Result<(), ParamError> {
        let d = SsiParams::default();
        if self.block_rows < 1 {
            return Err(ParamError::out_of_range(
                "block_rows",
                self.block_rows,
                "must be >= 1",
                d.block_rows,
            ));
        }
        if self.block_rows > SSI_TOEPLITZ_ROWS_MAX {
            return Err(ParamError::out_of_range(
                "block_rows",
                self.block_rows,
                "is too large: block_rows x channels must be at most 1024 (the Toeplitz matrix's rows)",
                d.block_rows,
            ));
        }
        if self.first_lag > SSI_FIRST_LAG_MAX {
            return Err(ParamError::out_of_range(
                "first_lag",
                self.first_lag,
                "must be at most 2^30 = 1073741824 samples (and below the record's length)",
                d.first_lag,
            ));
        }
        if self.order_min < 2 {
            return Err(ParamError::out_of_range(
                "order_min",
                self.order_min,
                "must be >= 2 (one mode needs two states)",
                d.order_min,
            ));
        }
        if self.first_lag < 1 {
            return Err(ParamError::out_of_range(
                "first_lag",
                self.first_lag,
                "must be >= 1 (lag 0 carries the measurement noise)",
                d.first_lag,
            ));
        }
        if self.order_step < 1 {
            return Err(ParamError::out_of_range(
                "order_step",
                self.order_step,
                "must be >= 1",
                d.order_step,
            ));
        }
        if self.order_max < self.order_min {
            return Err(ParamError::out_of_range(
                "order_max",
                self.order_max,
                "must be >= order_min",
                self.order_min.max(d.order_max),
            ));
        }
        if self.order_max > SSI_ORDER_MAX {
            return Err(ParamError::out_of_range(
                "order_max",
                self.order_max,
                "must be at most 1024 (an order is at most block_rows x channels)",
                d.order_max,
            ));
        }
        if let Some(refs) = &self.reference_channels {
            if refs.is_empty() {
                return Err(ParamError::out_of_range(
                    "reference_channels",
                    "[]",
                    "must list at least one channel (or be left out: all channels)",
                    "[0]",
                ));
            }
            let mut sorted = refs.clone();
            sorted.sort_unstable();
            if sorted.windows(2).any(|w| w[0] == w[1]) {
                sorted.dedup();
                return Err(ParamError::out_of_range(
                    "reference_channels",
                    format!("{refs:?}"),
                    "must not repeat a channel",
                    format!("{sorted:?}"),
                ));
            }
        }
        Ok(())
    }
}

/// How a mode at one order relates to the modes of the previous identified order (the symbols of
/// a stabilisation diagram). Each label implies the ones before it. One enum for the
/// single-channel poles of an order sweep (`vibmode_modal::stabilisation`) and the shaped modes
/// of SSI-cov (`vibmode_ssi::stabilisation`); a pole without a shape is [`Stability::Stable`] once
/// its frequency and damping match.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Stability {
    /// No mode of the previous order within the frequency tolerance (always at the first order).
    /// Plot symbol `o`.
    New,
    /// A mode of the previous order within the frequency tolerance, none also within the damping
    /// tolerance. Plot symbol `f`.
    Frequency,
    /// A mode of the previous order within the frequency and damping tolerances, none also
    /// within the MAC limit (both shapes known). Plot symbol `d`.
    FrequencyDamping,
    /// A mode of the previous order within every tolerance that applies: frequency, damping and,
    /// when both have shapes, MAC. Plot symbol `s`.
    Stable,
}

impl Stability {
    /// The one-letter plot symbol: `o`, `f`, `d` or `s`.
    pub fn symbol(&self) -> char {
        match self {
            Stability::New => 'o',
            Stability::Frequency => 'f',
            Stability::FrequencyDamping => 'd',
            Stability::Stable => 's',
        }
    }
}

impl std::fmt::Display for Stability {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Stability::New => "new",
            Stability::Frequency => "frequency",
            Stability::FrequencyDamping => "frequency_damping",
            Stability::Stable => "stable",
        })
    }
}

impl std::str::FromStr for Stability {
    type Err = ParamError;
    /// Case-insensitive names (`new`, `frequency`, `frequency_damping`, `stable`; `-` for `_`)
    /// or symbols (`o`, `f`, `d`, `s`).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().replace('-', "_").as_str() {
            "new" | "o" => Ok(Stability::New),
            "frequency" | "f" => Ok(Stability::Frequency),
            "frequency_damping" | "d" => Ok(Stability::FrequencyDamping),
            "stable" | "s" => Ok(Stability::Stable),
            _ => Err(ParamError::UnknownName {
                what: "stability",
                value: s.to_string(),
                valid: "new (o), frequency (f), frequency_damping (d), stable (s)",
            }),
        }
    }
}

/// Stabilisation criteria between the modes of consecutive identified orders (a stabilisation
/// diagram): a mode is *stable* when a mode of the previous order lies within all three
/// tolerances (the MAC only where both modes have shapes).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StabilityParams {
    /// Largest relative frequency difference `|f - f_prev| / f_prev` (default 0.01).
    pub freq_tol_rel: f64,
    /// Largest relative damping difference `|z - z_prev| / z_prev` (default 0.05).
    pub damping_tol_rel: f64,
    /// Smallest modal assurance criterion between the two mode shapes (default 0.98).
    pub mac_min: f64,
}

impl Default for StabilityParams {
    fn default() -> Self {
        StabilityParams {
            freq_tol_rel: 0.01,
            damping_tol_rel: 0.05,
            mac_min: 0.98,
        }
    }
}

impl StabilityParams {
    /// Checks ranges: both tolerances finite and >= 0, `mac_min` in [0, 1].
    pub fn validate(&self) -> Result<(), ParamError> {
        let d = StabilityParams::default();
        for (name, v, default) in [
            ("freq_tol_rel", self.freq_tol_rel, d.freq_tol_rel),
            ("damping_tol_rel", self.damping_tol_rel, d.damping_tol_rel),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(ParamError::out_of_range(
                    name,
                    v,
                    "must be finite and >= 0",
                    default,
                ));
            }
        }
        if !(0.0..=1.0).contains(&self.mac_min) {
            return Err(ParamError::out_of_range(
                "mac_min",
                self.mac_min,
                "must be in [0, 1]",
                d.mac_min,
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orders_and_defaults() {
        let p = SsiParams::default();
        assert!(p.validate().is_ok());
        let o = p.orders();
        assert_eq!(o.first(), Some(&2));
        assert_eq!(o.last(), Some(&60));
        assert_eq!(o.len(), 30);
        let p = SsiParams {
            order_min: 3,
            order_max: 10,
            order_step: 3,
            reference_channels: Some(vec![0, 2]),
            ..p
        };
        assert!(p.validate().is_ok());
        assert_eq!(p.orders(), vec![3, 6, 9]);
        assert!(StabilityParams::default().validate().is_ok());
        // The largest values accepted.
        let p = SsiParams {
            block_rows: SSI_TOEPLITZ_ROWS_MAX,
            order_max: SSI_ORDER_MAX,
            first_lag: SSI_FIRST_LAG_MAX,
            ..SsiParams::default()
        };
        assert!(p.validate().is_ok());
        assert_eq!(SSI_FIRST_LAG_MAX, 1_073_741_824);
    }

    #[test]
    fn validation_names_the_key() {
        let cases = [
            (
                SsiParams {
                    block_rows: 0,
                    ..Default::default()
                },
                "block_rows = 0",
            ),
            (
                SsiParams {
                    order_min: 1,
                    ..Default::default()
                },
                "order_min = 1",
            ),
            (
                SsiParams {
                    order_step: 0,
                    ..Default::default()
                },
                "order_step = 0",
            ),
            (
                SsiParams {
                    order_min: 10,
                    order_max: 4,
                    ..Default::default()
                },
                "order_max = 4",
            ),
            (
                SsiParams {
                    block_rows: usize::MAX,
                    ..Default::default()
                },
                "block_rows = 18446744073709551615 is too large",
            ),
            (
                SsiParams {
                    block_rows: SSI_TOEPLITZ_ROWS_MAX + 1,
                    ..Default::default()
                },
                "at most 1024",
            ),
            (
                SsiParams {
                    first_lag: usize::MAX,
                    ..Default::default()
                },
                "first_lag = 18446744073709551615 must be at most 2^30 = 1073741824",
            ),
            (
                SsiParams {
                    order_max: SSI_ORDER_MAX + 1,
                    ..Default::default()
                },
                "order_max = 1025 must be at most 1024",
            ),
        ];
        for (p, text) in cases {
            let e = p.validate().unwrap_err().to_string();
            assert!(e.contains(text), "{e}");
        }
        let s = StabilityParams {
            mac_min: 1.5,
            ..Default::default()
        };
        assert!(s
            .validate()
            .unwrap_err()
            .to_string()
            .contains("mac_min = 1.5"));
        let s = StabilityParams {
            freq_tol_rel: f64::NAN,
            ..Default::default()
        };
        assert!(s
            .validate()
            .unwrap_err()
            .to_string()
            .contains("freq_tol_rel = NaN"));
    }

    #[test]
    fn toml_round_trip_and_unknown_keys() {
        let p: SsiParams = toml::from_str("block_rows = 30\norder_max = 40").unwrap();
        assert_eq!(p.block_rows, 30);
        assert_eq!(p.order_max, 40);
        assert_eq!(p.order_min, 2);
        assert_eq!(p.reference_channels, None);
        let p: SsiParams = toml::from_str("reference_channels = [0, 3]").unwrap();
        assert_eq!(p.reference_channels, Some(vec![0, 3]));
        assert!(toml::from_str::<SsiParams>("block_row = 30").is_err());
        let s: StabilityParams = toml::from_str("mac_min = 0.9").unwrap();
        assert_eq!(s.mac_min, 0.9);
    }
}
