//! Analysis settings: every knob of the paper's method, with documented defaults and presets.

use serde::{Deserialize, Serialize};
use std::path::Path;

use crate::AnalysisError;

/// Named sets of defaults.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Preset {
    /// vibmode's defaults: 25 Hz ideal cutoff, analysis at 50 Hz (twice the cutoff, so no empty
    /// band), ARMA(p,p) for p = 2..30 (the same pole density per Hz as p = 2..120 at 200 Hz),
    /// robust criterion. See `docs/analysis.md` for the measurements behind the choice.
    #[default]
    Vibmode,
    /// The paper's exact settings: 25 Hz ideal cutoff, resampling to 200 Hz, ARMA(p,p) for
    /// p = 2..60, robust criterion. At 200 Hz the band 25-100 Hz is empty, which makes high
    /// orders ill-conditioned and spends most poles outside the band of interest.
    Paper,
}

impl std::str::FromStr for Preset {
    type Err = AnalysisError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "vibmode" | "default" => Ok(Preset::Vibmode),
            "paper" => Ok(Preset::Paper),
            _ => Err(AnalysisError::Config(format!(
                "unknown preset '{s}'; use 'vibmode' or 'paper'"
            ))),
        }
    }
}

/// Model structure fitted in the order sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum SweepModel {
    /// ARMA(p, p) by robust prediction-error minimisation (the paper's choice).
    #[default]
    Arma,
    /// AR(p) by Burg's method (fast; a useful cross-check).
    Ar,
}

/// Role of a channel on the vehicle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Hash, PartialOrd, Ord)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// On the body (floor), above the suspension.
    Sprung,
    /// On a wheel spindle or axle, below the suspension.
    Unsprung,
    /// Anything else.
    Other,
}

impl std::fmt::Display for Role {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Role::Sprung => "sprung",
            Role::Unsprung => "unsprung",
            Role::Other => "other",
        })
    }
}

/// A channel's role and corner, given in the `[[channels]]` table of the config.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelRole {
    /// Channel name as in the input files.
    pub name: String,
    /// sprung, unsprung or other.
    pub role: Role,
    /// Corner label (FL, FR, RL, RR) if any.
    #[serde(default)]
    pub corner: Option<String>,
}

/// Clustering settings (see `vibmode_modal::ClusterParams`; documented in `docs/modal.md`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ClusterConfig {
    /// Relative frequency neighbourhood of the density clustering for lightly damped poles
    /// (default 0.02 = 2 %).
    pub freq_tol_rel: f64,
    /// Growth of the frequency neighbourhood with damping: the relative radius is
    /// `max(freq_tol_rel, freq_tol_per_damping * zeta)` (geometric-mean damping of the pair).
    /// A mode of damping zeta has a half-power bandwidth `2 zeta f` and its poles scatter in
    /// proportion; 0.5 = a quarter of that bandwidth (15 % at zeta = 0.3). 0 = fixed radius.
    /// Default 0.5.
    pub freq_tol_per_damping: f64,
    /// Neighbourhood in log10 damping (default 0.2 decades).
    pub log_damping_tol: f64,
    /// Share of records a mode must appear in to be invariant (default 0.5).
    pub min_record_share: f64,
    /// Share of the model orders (per record) a mode must appear in (default 0.5: a vehicle
    /// mode shows at most orders of a sweep, a spurious pole at a few).
    pub min_order_share: f64,
    /// Median damping ratio below which a stable line is a periodic disturbance (default 0.005).
    pub disturbance_damping_max: f64,
    /// Poles with damping above this are ignored (default 0.6).
    pub max_damping_ratio: f64,
    /// Lowest frequency considered, Hz (default 0.3).
    pub freq_min_hz: f64,
    /// Highest frequency considered, Hz. Default (None): the cutoff, or 0.8 x the cutoff when the
    /// analysis rate leaves an empty band above it (cutoff below 0.95 x the analysis Nyquist, as
    /// in the paper's 25 Hz at 200 Hz): every model then spends lightly damped poles of its own on
    /// the ideal filter's edge, 20-25 Hz, which are no vehicle modes.
    pub freq_max_hz: Option<f64>,
    /// Largest relative frequency spread (std / mean) of a periodic disturbance (default 0.02:
    /// engine lines drift slowly with engine speed).
    pub disturbance_freq_spread_max: f64,
    /// Pole-zero cancellation: a pole z_p of an ARMA fit is dropped when a zero z_c of C lies
    /// within `pole_zero_tol * (1 - |z_p|)` of it (the pole's own bandwidth in the z-plane),
    /// since such a pair shapes the spectrum locally but is no mode. 0 disables (default 1.0).
    pub pole_zero_tol: f64,
}

impl Default for ClusterConfig {
    fn default() -> Self {
        ClusterConfig {
            freq_tol_rel: 0.02,
            freq_tol_per_damping: 0.5,
            log_damping_tol: 0.2,
            min_record_share: 0.5,
            min_order_share: 0.5,
            disturbance_damping_max: 0.005,
            max_damping_ratio: 0.6,
            freq_min_hz: 0.3,
            freq_max_hz: None,
            disturbance_freq_spread_max: 0.02,
            pole_zero_tol: 1.0,
        }
    }
}

/// Every setting of `vibmode analyze`, readable from a TOML file (`--config analysis.toml`).
///
/// Keys not given take the preset's value; unknown keys are an error.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AnalysisConfig {
    /// Preset the defaults come from (vibmode or paper).
    pub preset: Preset,
    /// Length of one record in seconds when long recordings are cut (default 10.24 s).
    pub record_length_s: f64,
    /// Cutoff of the ideal DFT anti-alias filter, Hz (default 25 Hz, as in the paper).
    pub cutoff_hz: f64,
    /// Sampling rate of the analysis after resampling, Hz (vibmode 50 Hz, paper 200 Hz).
    pub analysis_fs_hz: f64,
    /// Model structure of the sweep (default ARMA(p,p)).
    pub model: SweepModel,
    /// Lowest model order of the sweep (default 2).
    pub order_min: usize,
    /// Highest model order of the sweep (vibmode 30, paper 60).
    pub order_max: usize,
    /// Robust criterion factor (times the robust std of the initial residuals); 0 = quadratic.
    pub robust_factor: f64,
    /// Iteration cap of each prediction-error fit of the sweep (default 20, MATLAB's
    /// `MaxIterations`). A fit that reaches it is kept (`converged: false`).
    pub max_iterations: usize,
    /// Stopping tolerance of each fit: relative predicted improvement of the next Gauss-Newton
    /// step below which the search stops (default 1e-4, MATLAB's `Tolerance` of 0.01 %).
    pub tolerance: f64,
    /// Welch segment length in samples at the analysis rate (default 256).
    pub welch_nperseg: usize,
    /// Orders whose model PSD is drawn over the Welch estimate (the paper's Fig. 6-7: 10 and 20).
    pub psd_orders: Vec<usize>,
    /// Roles of the channels; channels not listed are guessed from their names
    /// (containing "unsprung"/"wheel"/"axle" -> unsprung, "sprung"/"body"/"floor" -> sprung).
    pub channels: Vec<ChannelRole>,
    /// Stops: a record whose activity (RMS acceleration in `activity_min_hz..cutoff_hz`, relative
    /// to the median over the records; see [`crate::RecordSummary::activity_ratio`]) is below
    /// this ratio is `stationary` (vehicle at rest: no road input) and left out of the mode
    /// statistics. 0 disables. Default 0.4 (a record driven at typical intensity for less than
    /// about 0.4^2 = 16 % of its length).
    pub stop_rms_ratio: f64,
    /// Lower edge of the activity band, Hz (default 0.5 Hz: above drift and gravity changes).
    pub activity_min_hz: f64,
    /// Clustering settings.
    pub cluster: ClusterConfig,
}

impl Default for AnalysisConfig {
    fn default() -> Self {
        AnalysisConfig::preset(Preset::Vibmode)
    }
}

impl AnalysisConfig {
    /// The defaults of a preset.
    pub fn preset(p: Preset) -> Self {
        let base = AnalysisConfig {
            preset: p,
            record_length_s: 10.24,
            cutoff_hz: 25.0,
            analysis_fs_hz: 50.0,
            model: SweepModel::Arma,
            order_min: 2,
            order_max: 30,
            robust_factor: 1.6,
            max_iterations: 20,
            tolerance: 1e-4,
            welch_nperseg: 128,
            psd_orders: vec![5, 10],
            channels: Vec::new(),
            stop_rms_ratio: 0.4,
            activity_min_hz: 0.5,
            cluster: ClusterConfig::default(),
        };
        match p {
            Preset::Vibmode => base,
            Preset::Paper => AnalysisConfig {
                analysis_fs_hz: 200.0,
                order_max: 60,
                welch_nperseg: 256,
                psd_orders: vec![10, 20],
                ..base
            },
        }
    }

    /// Reads a TOML config. A `preset = "paper"` key selects the base the other keys override.
    pub fn from_toml_str(text: &str) -> Result<Self, AnalysisError> {
        let value: toml::Value = toml::from_str(text)
            .map_err(|e| AnalysisError::Config(e.to_string().replace('\n', " ")))?;
        let preset = match value.get("preset").and_then(|v| v.as_str()) {
            Some(s) => s.parse::<Preset>()?,
            None => Preset::Vibmode,
        };
        // Merge the file over the preset's defaults.
        let mut base = toml::Value::try_from(AnalysisConfig::preset(preset))
            .map_err(|e| AnalysisError::Config(e.to_string()))?;
        merge(&mut base, value);
        let cfg: AnalysisConfig = base.try_into().map_err(|e: toml::de::Error| {
            AnalysisError::Config(e.to_string().replace('\n', " "))
        })?;
        cfg.validate()?;
        Ok(cfg)
    }

    /// Reads a TOML config file.
    pub fn from_path(path: &Path) -> Result<Self, AnalysisError> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            AnalysisError::Config(format!("cannot read config {}: {e}", path.display()))
        })?;
        Self::from_toml_str(&text).map_err(|e| match e {
            AnalysisError::Config(m) => AnalysisError::Config(format!("{}: {m}", path.display())),
            other => other,
        })
    }

    /// The model orders of the sweep.
    pub fn orders(&self) -> Vec<usize> {
        (self.order_min..=self.order_max).collect()
    }

    /// Checks ranges; errors name the key and the fix.
    pub fn validate(&self) -> Result<(), AnalysisError> {
        let bad =
            |k: &str, v: String, fix: &str| Err(AnalysisError::Config(format!("{k} = {v} {fix}")));
        if !(self.record_length_s.is_finite() && self.record_length_s > 0.0) {
            return bad(
                "record_length_s",
                self.record_length_s.to_string(),
                "must be positive",
            );
        }
        if let Some(f) = self.cluster.freq_max_hz {
            if !(f.is_finite() && f > self.cluster.freq_min_hz) {
                return bad(
                    "cluster.freq_max_hz",
                    f.to_string(),
                    "must be above cluster.freq_min_hz (or left out for the default)",
                );
            }
        }
        if !(self.analysis_fs_hz.is_finite() && self.analysis_fs_hz > 0.0) {
            return bad(
                "analysis_fs_hz",
                self.analysis_fs_hz.to_string(),
                "must be positive",
            );
        }
        if !(self.cutoff_hz.is_finite() && self.cutoff_hz > 0.0) {
            return bad("cutoff_hz", self.cutoff_hz.to_string(), "must be positive");
        }
        if self.cutoff_hz > self.analysis_fs_hz / 2.0 + 1e-9 {
            return bad(
                "cutoff_hz",
                self.cutoff_hz.to_string(),
                &format!(
                    "is above the Nyquist frequency of analysis_fs_hz = {} Hz; lower it to at most {}",
                    self.analysis_fs_hz,
                    self.analysis_fs_hz / 2.0
                ),
            );
        }
        if self.order_min < 1 || self.order_max < self.order_min {
            return bad(
                "order_min..order_max",
                format!("{}..{}", self.order_min, self.order_max),
                "must satisfy 1 <= order_min <= order_max",
            );
        }
        if self.max_iterations == 0 {
            return bad("max_iterations", "0".to_string(), "must be >= 1 (e.g. 20)");
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return bad(
                "tolerance",
                self.tolerance.to_string(),
                "must be a small positive number (e.g. 1e-4)",
            );
        }
        if self.robust_factor < 0.0 || !self.robust_factor.is_finite() {
            return bad(
                "robust_factor",
                self.robust_factor.to_string(),
                "must be >= 0 (0 = quadratic)",
            );
        }
        if !(0.0..1.0).contains(&self.stop_rms_ratio) {
            return bad(
                "stop_rms_ratio",
                self.stop_rms_ratio.to_string(),
                "must be in [0, 1) (0 = no stop detection; default 0.4)",
            );
        }
        if !(self.activity_min_hz.is_finite()
            && self.activity_min_hz >= 0.0
            && self.activity_min_hz < self.cutoff_hz)
        {
            return bad(
                "activity_min_hz",
                self.activity_min_hz.to_string(),
                &format!(
                    "must be in [0, cutoff_hz = {}) (default 0.5)",
                    self.cutoff_hz
                ),
            );
        }
        if self.welch_nperseg < 8 {
            return bad(
                "welch_nperseg",
                self.welch_nperseg.to_string(),
                "must be at least 8",
            );
        }
        Ok(())
    }

    /// Role of a channel: from `channels`, else guessed from its name.
    pub fn role_of(&self, name: &str) -> Role {
        if let Some(c) = self.channels.iter().find(|c| c.name == name) {
            return c.role;
        }
        let n = name.to_ascii_lowercase();
        if n.contains("unsprung") || n.contains("wheel") || n.contains("axle") {
            Role::Unsprung
        } else if n.contains("sprung") || n.contains("body") || n.contains("floor") {
            Role::Sprung
        } else {
            Role::Other
        }
    }
}

fn merge(base: &mut toml::Value, over: toml::Value) {
    match (base, over) {
        (toml::Value::Table(b), toml::Value::Table(o)) => {
            for (k, v) in o {
                match b.get_mut(&k) {
                    Some(bv) if bv.is_table() && v.is_table() => merge(bv, v),
                    _ => {
                        b.insert(k, v);
                    }
                }
            }
        }
        (b, o) => *b = o,
    }
}
