//! One parameter struct per analysis stage, each with its defaults defined once and a
//! `validate` that names the offending key. The library, the TOML config, the CLI and the Python
//! package all read these structs.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::ParamError;

fn bad(
    name: &'static str,
    value: impl ToString,
    requirement: &'static str,
    suggestion: impl ToString,
) -> ParamError {
    ParamError::out_of_range(name, value, requirement, suggestion)
}

fn positive(name: &'static str, v: f64, default: f64) -> Result<(), ParamError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(bad(name, crate::Num(v), "must be finite and > 0", default))
    }
}

fn share(name: &'static str, v: f64, default: f64) -> Result<(), ParamError> {
    if (0.0..=1.0).contains(&v) {
        Ok(())
    } else {
        Err(bad(name, crate::Num(v), "must be in [0, 1]", default))
    }
}

/// A cutoff below this share of the Nyquist frequency leaves an *empty band* above it: an ideal
/// DFT low-pass at the paper's 25 Hz followed by resampling to 200 Hz empties 25-100 Hz to
/// rounding error. The one definition used by the resampler, the identification (which adds a
/// numerical noise floor to such signals) and the pole filters (which leave out the filter-edge
/// poles). 0.95: a cutoff within 5 % of Nyquist leaves too few empty bins to matter.
pub const EMPTY_BAND_MAX_CUTOFF_SHARE: f64 = 0.95;

/// Share of the cutoff above which poles are left out when an empty band lies above it: every
/// model spends lightly damped poles of its own on the ideal filter's edge (20-25 Hz for the
/// paper's 25 Hz cutoff), which are no vehicle modes.
pub const EDGE_SHARE: f64 = 0.8;

/// The band a pre-processed signal carries: what the anti-alias filter kept and whether an
/// empty band lies above it. Produced by the resampler, carried as data to every later stage.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BandLimit {
    /// Sampling rate of the signal, Hz.
    pub fs_hz: f64,
    /// Cutoff of the ideal low-pass applied, Hz (the Nyquist frequency when none was applied).
    pub cutoff_hz: f64,
    /// True when the band from the cutoff to Nyquist is empty (cutoff below
    /// [`EMPTY_BAND_MAX_CUTOFF_SHARE`] x Nyquist and an ideal low-pass was applied).
    pub empty_band: bool,
}

impl BandLimit {
    /// A signal that was not low-passed: valid up to Nyquist, no empty band.
    pub fn full(fs_hz: f64) -> BandLimit {
        BandLimit {
            fs_hz,
            cutoff_hz: fs_hz / 2.0,
            empty_band: false,
        }
    }

    /// The band left by an ideal low-pass at `cutoff_hz` on a signal sampled at `fs_hz`
    /// (the cutoff is clamped to Nyquist).
    pub fn ideal_lowpass(fs_hz: f64, cutoff_hz: f64) -> BandLimit {
        let nyquist = fs_hz / 2.0;
        let cutoff_hz = cutoff_hz.min(nyquist);
        BandLimit {
            fs_hz,
            cutoff_hz,
            empty_band: cutoff_hz < EMPTY_BAND_MAX_CUTOFF_SHARE * nyquist,
        }
    }

    /// Highest frequency at which poles describe the signal, Hz: the cutoff, or [`EDGE_SHARE`] x
    /// the cutoff when an empty band lies above it.
    pub fn valid_max_hz(&self) -> f64 {
        if self.empty_band {
            EDGE_SHARE * self.cutoff_hz
        } else {
            self.cutoff_hz
        }
    }
}

/// Pre-processing stage: the paper's ideal DFT anti-alias filter and resampling.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PreprocessParams {
    /// Cutoff of the ideal DFT anti-alias filter, Hz (default 25 Hz, as in the paper).
    pub cutoff_hz: f64,
    /// Sampling rate of the analysis after resampling, Hz (default 50 Hz: twice the cutoff, so no
    /// empty band; the paper uses 200 Hz). Not a one-off resampling target (that is `fs_out_hz`,
    /// `--fs-out`, of `vibmode resample` and the single-record commands): this is the rate every
    /// stage of the analysis after pre-processing works at, and what its spectra, model orders
    /// and SSI lags are counted in; stage 2 resamples each record to it.
    pub analysis_fs_hz: f64,
}

impl Default for PreprocessParams {
    fn default() -> Self {
        PreprocessParams {
            cutoff_hz: 25.0,
            analysis_fs_hz: 50.0,
        }
    }
}

impl PreprocessParams {
    /// Checks ranges.
    pub fn validate(&self) -> Result<(), ParamError> {
        let d = PreprocessParams::default();
        positive("analysis_fs_hz", self.analysis_fs_hz, d.analysis_fs_hz)?;
        positive("cutoff_hz", self.cutoff_hz, d.cutoff_hz)?;
        if self.cutoff_hz > self.analysis_fs_hz / 2.0 + 1e-9 {
            return Err(bad(
                "cutoff_hz",
                self.cutoff_hz,
                "must be at most the Nyquist frequency of analysis_fs_hz",
                self.analysis_fs_hz / 2.0,
            ));
        }
        Ok(())
    }

    /// The band the analysis signals will carry.
    pub fn band_limit(&self) -> BandLimit {
        BandLimit::ideal_lowpass(self.analysis_fs_hz, self.cutoff_hz)
    }
}

/// One identification method of the analysis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum IdentMethod {
    /// The paper's per-channel ARMA (or AR) order sweep (an [`crate::Identifier`]).
    Arma,
    /// Multichannel covariance-driven stochastic subspace identification (all channels of a
    /// record at once, with mode shapes; a [`crate::MultichannelIdentifier`]).
    SsiCov,
}

impl FromStr for IdentMethod {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "arma" => Ok(IdentMethod::Arma),
            "ssi-cov" | "ssi" | "ssicov" => Ok(IdentMethod::SsiCov),
            _ => Err(ParamError::UnknownName {
                what: "method",
                value: s.to_string(),
                valid: "arma, ssi-cov, both (or a list such as arma,ssi-cov)",
            }),
        }
    }
}

impl fmt::Display for IdentMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            IdentMethod::Arma => "arma",
            IdentMethod::SsiCov => "ssi-cov",
        })
    }
}

/// The identification methods an analysis runs: a non-empty set, kept sorted. The default runs
/// both side by side (the ARMA pools find modes of single channels that SSI-cov misses,
/// SSI-cov separates close modes by their shapes; measured on the real recordings in
/// docs/analysis.md).
///
/// Read from a list (`["arma", "ssi-cov"]`, or `arma,ssi-cov` as text) or one name; `"both"`
/// is every method. Written as a list.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(into = "Vec<IdentMethod>")]
pub struct IdentMethods(Vec<IdentMethod>);

impl IdentMethods {
    /// Every method ("both").
    pub fn all() -> IdentMethods {
        IdentMethods(vec![IdentMethod::Arma, IdentMethod::SsiCov])
    }
    /// The given methods, sorted, duplicates removed; `None` when there are none.
    pub fn new(methods: impl IntoIterator<Item = IdentMethod>) -> Option<IdentMethods> {
        let mut v: Vec<IdentMethod> = methods.into_iter().collect();
        v.sort();
        v.dedup();
        (!v.is_empty()).then_some(IdentMethods(v))
    }
    /// True when `m` runs.
    pub fn runs(&self, m: IdentMethod) -> bool {
        self.0.contains(&m)
    }
    /// True when the ARMA/AR sweep runs.
    pub fn runs_arma(&self) -> bool {
        self.runs(IdentMethod::Arma)
    }
    /// True when SSI-cov runs.
    pub fn runs_ssi(&self) -> bool {
        self.runs(IdentMethod::SsiCov)
    }
    /// The methods, sorted.
    pub fn iter(&self) -> impl Iterator<Item = IdentMethod> + '_ {
        self.0.iter().copied()
    }
}

impl Default for IdentMethods {
    fn default() -> IdentMethods {
        IdentMethods::all()
    }
}

impl From<IdentMethod> for IdentMethods {
    fn from(m: IdentMethod) -> IdentMethods {
        IdentMethods(vec![m])
    }
}

impl From<IdentMethods> for Vec<IdentMethod> {
    fn from(m: IdentMethods) -> Vec<IdentMethod> {
        m.0
    }
}

impl FromStr for IdentMethods {
    type Err = ParamError;
    /// `both`, one method, or methods separated by commas.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.trim().eq_ignore_ascii_case("both") {
            return Ok(IdentMethods::all());
        }
        let methods = s
            .split(',')
            .map(str::parse)
            .collect::<Result<Vec<IdentMethod>, _>>()?;
        IdentMethods::new(methods).ok_or_else(|| ParamError::UnknownName {
            what: "method",
            value: s.to_string(),
            valid: "arma, ssi-cov, both (or a list such as arma,ssi-cov)",
        })
    }
}

impl fmt::Display for IdentMethods {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<String> = self.0.iter().map(ToString::to_string).collect();
        f.write_str(&names.join(","))
    }
}

impl<'de> Deserialize<'de> for IdentMethods {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Form {
            Text(String),
            List(Vec<String>),
        }
        let parsed = match Form::deserialize(d)? {
            Form::Text(s) => s.parse(),
            Form::List(v) => v.join(",").parse(),
        };
        parsed.map_err(serde::de::Error::custom)
    }
}

/// Model structure fitted in an order sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum SweepModel {
    /// ARMA(p, p) by robust prediction-error minimisation (the paper's choice).
    #[default]
    Arma,
    /// AR(p) by Burg's method (fast; a useful cross-check).
    Ar,
}

impl FromStr for SweepModel {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "arma" => Ok(SweepModel::Arma),
            "ar" => Ok(SweepModel::Ar),
            _ => Err(ParamError::UnknownName {
                what: "model",
                value: s.to_string(),
                valid: "arma, ar",
            }),
        }
    }
}

impl fmt::Display for SweepModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SweepModel::Arma => "arma",
            SweepModel::Ar => "ar",
        })
    }
}

/// Robustification of the prediction-error criterion: one type, one spelling. In TOML and JSON
/// it is a number (the Huber factor) or `"off"`; on the command line `1.6` or `off`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Robust {
    /// Purely quadratic criterion `l(e) = e^2`.
    Off,
    /// Huber criterion: `l(e) = e^2` for `|e| <= rho`, `2 rho |e| - rho^2` beyond, with
    /// `rho = factor * MAD/0.6745` of the initial residuals (dimensionless factor), fixed during the
    /// search.
    Huber {
        /// Threshold in robust standard deviations (dimensionless, > 0).
        factor: f64,
    },
}

/// The default Huber factor, 1.6 (MATLAB's pem).
pub const DEFAULT_HUBER_FACTOR: f64 = 1.6;

impl Default for Robust {
    /// `Huber { factor: 1.6 }` (as in MATLAB's pem).
    fn default() -> Self {
        Robust::Huber {
            factor: DEFAULT_HUBER_FACTOR,
        }
    }
}

impl FromStr for Robust {
    type Err = ParamError;
    /// Accepts `off` (also `none`, `quadratic`, `0`), `huber` (factor 1.6) or a positive number
    /// (the Huber factor).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim().to_ascii_lowercase();
        match t.as_str() {
            "off" | "none" | "quadratic" => Ok(Robust::Off),
            "huber" | "on" => Ok(Robust::default()),
            _ => match t.parse::<f64>() {
                Ok(0.0) => Ok(Robust::Off),
                Ok(f) if f.is_finite() && f > 0.0 => Ok(Robust::Huber { factor: f }),
                _ => Err(bad(
                    "robust",
                    s,
                    "must be a positive Huber factor or off",
                    DEFAULT_HUBER_FACTOR,
                )),
            },
        }
    }
}

impl fmt::Display for Robust {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Robust::Off => f.write_str("off"),
            Robust::Huber { factor } => write!(f, "{factor}"),
        }
    }
}

impl Robust {
    /// Checks that a Huber factor is positive and finite.
    pub fn validate(&self) -> Result<(), ParamError> {
        match *self {
            Robust::Huber { factor } if !(factor.is_finite() && factor > 0.0) => Err(bad(
                "robust",
                factor,
                "must be a positive Huber factor or off",
                DEFAULT_HUBER_FACTOR,
            )),
            _ => Ok(()),
        }
    }
}

impl Serialize for Robust {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Robust::Off => s.serialize_str("off"),
            Robust::Huber { factor } => s.serialize_f64(*factor),
        }
    }
}

impl<'de> Deserialize<'de> for Robust {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        /// vibmode 0.1 wrote `{"Huber": {"factor": 1.6}}`; still read.
        #[derive(Deserialize)]
        enum Tagged {
            Huber { factor: f64 },
        }
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Repr {
            Num(f64),
            Int(i64),
            Text(String),
            Tagged(Tagged),
        }
        match Repr::deserialize(d)? {
            Repr::Num(f) => f.to_string().parse(),
            Repr::Int(i) => i.to_string().parse(),
            Repr::Text(t) => t.parse(),
            Repr::Tagged(Tagged::Huber { factor }) => factor.to_string().parse(),
        }
        .map_err(serde::de::Error::custom)
    }
}

/// Identification stage: the order sweep fitted to every record and channel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SweepParams {
    /// Model structure (default ARMA(p,p)).
    pub model: SweepModel,
    /// Lowest model order (default 2).
    pub order_min: usize,
    /// Highest model order (default 30; the paper's 60 at 200 Hz has the same pole density per
    /// Hz as 15 at 50 Hz).
    pub order_max: usize,
    /// Criterion (default Huber with factor 1.6).
    pub robust: Robust,
    /// Iteration cap of each prediction-error fit of the sweep (default
    /// [`SWEEP_MAX_ITERATIONS`]). A fit that reaches it is kept (`converged: false`).
    pub max_iterations: usize,
    /// Stopping tolerance of each fit: relative predicted improvement of the next Gauss-Newton
    /// step below which the search stops (default [`SWEEP_TOLERANCE`]).
    pub tolerance: f64,
    /// Where each ARMA fit's search starts (default [`SearchStarts::Multi`]; the fleet's
    /// records use [`SearchStarts::Single`]).
    pub starts: SearchStarts,
}

/// Where a prediction-error fit's Gauss-Newton search starts. The candidates are the
/// Hannan-Rissanen estimate, Burg's AR(p) with `C = 1` and, in a sweep, the previous order's
/// model (the warm start).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum SearchStarts {
    /// Models with `p + q <= 16` are searched from every candidate and the lowest end point is
    /// kept (a guard against neighbouring local minima); larger ones from the best-scored
    /// candidate only. The default.
    #[default]
    Multi,
    /// Every model from the best-scored candidate only (in a sweep, again from the warm start
    /// when the search ends above the warm start's own loss). About a third of the cost of a
    /// small model's fit; the fleet's records use it (docs/fleet.md, "The fleet's order sweep").
    Single,
}

/// Default [`SweepParams::max_iterations`]: 20, MATLAB's `MaxIterations`. The sweep's fits are
/// many and warm-started from the order below, so they are capped sooner than a single fit from
/// its cold start (`vibmode_ident::FIT_MAX_ITERATIONS`, 100, `vibmode fit`).
pub const SWEEP_MAX_ITERATIONS: usize = 20;

/// Default [`SweepParams::tolerance`]: 1e-4, MATLAB's `Tolerance` of 0.01 % (a single fit:
/// `vibmode_ident::FIT_TOLERANCE`, 1e-5).
pub const SWEEP_TOLERANCE: f64 = 1e-4;

impl Default for SweepParams {
    fn default() -> Self {
        SweepParams {
            model: SweepModel::Arma,
            order_min: 2,
            order_max: 30,
            robust: Robust::default(),
            max_iterations: SWEEP_MAX_ITERATIONS,
            tolerance: SWEEP_TOLERANCE,
            starts: SearchStarts::Multi,
        }
    }
}

impl SweepParams {
    /// The model orders of the sweep, `order_min..=order_max`.
    pub fn orders(&self) -> Vec<usize> {
        (self.order_min..=self.order_max).collect()
    }

    /// Checks ranges.
    pub fn validate(&self) -> Result<(), ParamError> {
        let d = SweepParams::default();
        if self.order_min < 1 {
            return Err(bad(
                "order_min",
                self.order_min,
                "must be >= 1",
                d.order_min,
            ));
        }
        if self.order_max < self.order_min {
            return Err(bad(
                "order_max",
                self.order_max,
                "must be >= order_min",
                self.order_min.max(d.order_max),
            ));
        }
        if self.max_iterations == 0 {
            return Err(bad("max_iterations", 0, "must be >= 1", d.max_iterations));
        }
        positive("tolerance", self.tolerance, d.tolerance)?;
        self.robust.validate()
    }
}

/// Pole filters applied to every fit before its modes are used (by `fit`, `sweep` and the
/// analysis alike).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PoleFilterParams {
    /// Pole-zero cancellation: a pole `z_p` of an ARMA fit is dropped when a zero `z_c` of C lies
    /// within `pole_zero_tol * (1 - |z_p|)` of it (the pole's own bandwidth in the z-plane): such
    /// a pair shapes the spectrum locally (a notch next to a peak) but is no mode. 0 disables
    /// (default 1.0).
    pub pole_zero_tol: f64,
    /// Drop the poles above [`BandLimit::valid_max_hz`] when an empty band lies above the
    /// cutoff (the ideal filter's edge poles). Default true.
    pub drop_band_edge: bool,
}

impl Default for PoleFilterParams {
    fn default() -> Self {
        PoleFilterParams {
            pole_zero_tol: 1.0,
            drop_band_edge: true,
        }
    }
}

impl PoleFilterParams {
    /// Checks ranges.
    pub fn validate(&self) -> Result<(), ParamError> {
        if !(self.pole_zero_tol.is_finite() && self.pole_zero_tol >= 0.0) {
            return Err(bad(
                "pole_zero_tol",
                self.pole_zero_tol,
                "must be finite and >= 0 (0 = off)",
                1.0,
            ));
        }
        Ok(())
    }
}

/// Stop detection: records in which the vehicle stood still carry no road input and are left
/// out of the mode statistics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StopParams {
    /// A record whose activity (RMS acceleration in `activity_min_hz..cutoff_hz` relative to the
    /// median record) is below this ratio is a stop. 0 disables. Default 0.4 (a record driven at
    /// typical intensity for less than about 0.4^2 = 16 % of its length).
    pub stop_rms_ratio: f64,
    /// Lower edge of the activity band, Hz (default 0.5 Hz: above drift and gravity changes).
    pub activity_min_hz: f64,
}

impl Default for StopParams {
    fn default() -> Self {
        StopParams {
            stop_rms_ratio: 0.4,
            activity_min_hz: 0.5,
        }
    }
}

impl StopParams {
    /// Checks ranges; the activity band must lie below `cutoff_hz`.
    pub fn validate(&self, cutoff_hz: f64) -> Result<(), ParamError> {
        if !(0.0..1.0).contains(&self.stop_rms_ratio) {
            return Err(bad(
                "stop_rms_ratio",
                self.stop_rms_ratio,
                "must be in [0, 1) (0 = no stop detection)",
                0.4,
            ));
        }
        if !(self.activity_min_hz.is_finite()
            && self.activity_min_hz >= 0.0
            && self.activity_min_hz < cutoff_hz)
        {
            return Err(bad(
                "activity_min_hz",
                self.activity_min_hz,
                "must be >= 0 and below cutoff_hz",
                0.5,
            ));
        }
        Ok(())
    }
}

/// Spectra of each record (scipy.signal's vocabulary).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpectrumParams {
    /// Welch segment length in samples at the analysis rate (default 128: 2.56 s at 50 Hz,
    /// 0.39 Hz resolution).
    pub nperseg: usize,
}

impl Default for SpectrumParams {
    fn default() -> Self {
        SpectrumParams { nperseg: 128 }
    }
}

impl SpectrumParams {
    /// Checks ranges.
    pub fn validate(&self) -> Result<(), ParamError> {
        if self.nperseg < 8 {
            return Err(bad("nperseg", self.nperseg, "must be at least 8", 128));
        }
        Ok(())
    }
}

/// Parameters of the clustering stage (`vibmode_modal::find_invariant_modes`); the one definition
/// of every clustering setting and its default, read by the library, the TOML config (`[cluster]`),
/// the CLI and Python alike. See `docs/modal.md` for the reasoning behind each default.
///
/// Poles are placed in the plane `u = ln(f) / ln(1 + freq_tol_rel)`,
/// `v = log10(zeta) / log_damping_tol`; two poles are neighbours when their distance in that plane
/// is at most 1, the `u` difference being shrunk for damped poles so that, at equal damping zeta,
/// they are neighbours when their frequency ratio is within
/// `1 + max(freq_tol_rel, freq_tol_per_damping * zeta)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
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
    /// background poles, so use it with a strict `min_order_share`. Default 0.5 (0 = fixed
    /// radius).
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
    /// invariant. Default 0.5 (a vehicle mode shows at most orders of a sweep, a spurious pole at
    /// a few).
    pub min_order_share: f64,
    /// A cluster is a periodic disturbance when its median damping ratio is below this value
    /// (dimensionless) and its frequency spread is below `disturbance_freq_spread_max`.
    /// Default 5e-3.
    pub disturbance_damping_max: f64,
    /// Maximum relative frequency spread (`frequency_std_hz / frequency_hz`) of a periodic
    /// disturbance (dimensionless). Default 0.02 (engine lines drift slowly with engine speed).
    pub disturbance_freq_spread_max: f64,
    /// Poles below this natural frequency (Hz) are ignored. Default 0.3 Hz (below it lie drift and
    /// the slow manoeuvres, not suspension modes).
    pub freq_min_hz: f64,
    /// Poles above this natural frequency (Hz) are ignored. Default `None`: the band the
    /// pre-processing left valid ([`crate::BandLimit::valid_max_hz`]: the cutoff, or
    /// `EDGE_SHARE` x the cutoff when an empty band lies above it), or no limit when the caller
    /// gives none.
    pub freq_max_hz: Option<f64>,
    /// Poles with a damping ratio above this value are ignored (overdamped-like, not resonant).
    /// Default 0.6.
    pub max_damping_ratio: f64,
    /// Damping ratios in `[0, min_damping_ratio)` are raised to this floor for the log10 coordinate
    /// (statistics use the true values); negative damping ratios (unstable poles) are ignored.
    /// Default 1e-6.
    pub min_damping_ratio: f64,
    /// Mode-shape tolerance: when two poles both carry a shape (multichannel identification),
    /// `((1 - MAC) / shape_tol)^2` is added to their squared distance, so poles whose shapes
    /// have MAC below `1 - shape_tol` are never neighbours. Default 0.2; 0 ignores shapes.
    #[serde(default = "default_shape_tol")]
    pub shape_tol: f64,
}

fn default_shape_tol() -> f64 {
    0.2
}

impl Default for ClusterParams {
    fn default() -> Self {
        ClusterParams {
            freq_tol_rel: 0.02,
            freq_tol_per_damping: 0.5,
            log_damping_tol: 0.2,
            min_points: 5,
            min_density_share: 0.03,
            min_record_share: 0.5,
            record_min_order_share: 0.1,
            min_order_share: 0.5,
            disturbance_damping_max: 5e-3,
            disturbance_freq_spread_max: 0.02,
            freq_min_hz: 0.3,
            freq_max_hz: None,
            max_damping_ratio: 0.6,
            min_damping_ratio: 1e-6,
            shape_tol: default_shape_tol(),
        }
    }
}

impl ClusterParams {
    /// These settings for signals of band `band`: an unset `freq_max_hz` becomes the band's valid
    /// maximum.
    pub fn for_band(&self, band: &BandLimit) -> ClusterParams {
        ClusterParams {
            freq_max_hz: Some(self.freq_max_hz.unwrap_or_else(|| band.valid_max_hz())),
            ..self.clone()
        }
    }

    /// Check every field; returns the first invalid one.
    pub fn validate(&self) -> Result<(), ParamError> {
        let d = ClusterParams::default();
        // Below 1e-4 the clustering grid has more cells than poles can fill (and hangs).
        if !(1e-4..=1.0).contains(&self.freq_tol_rel) {
            return Err(bad(
                "freq_tol_rel",
                crate::Num(self.freq_tol_rel),
                "must be in [1e-4, 1]",
                d.freq_tol_rel,
            ));
        }
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
        if let Some(f) = self.freq_max_hz {
            if f.is_nan() || f <= self.freq_min_hz {
                return Err(bad(
                    "freq_max_hz",
                    f,
                    "must be > freq_min_hz (or left out for the valid band)",
                    2.0 * self.freq_min_hz.max(1.0),
                ));
            }
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
        if !(self.shape_tol.is_finite() && (0.0..=1.0).contains(&self.shape_tol)) {
            return Err(bad(
                "shape_tol",
                self.shape_tol,
                "must be in [0, 1] (0 = ignore mode shapes)",
                d.shape_tol,
            ));
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn methods_are_a_list_read_from_a_list_a_name_or_both() {
        use IdentMethod::{Arma, SsiCov};
        #[derive(Deserialize, Serialize)]
        struct T {
            method: IdentMethods,
        }
        let read = |s: &str| toml::from_str::<T>(s).map(|t| t.method);
        let both = IdentMethods::new([Arma, SsiCov]).unwrap();
        assert_eq!(read("method = \"both\"").unwrap(), both);
        assert_eq!(read("method = [\"ssi-cov\", \"arma\"]").unwrap(), both);
        assert_eq!(read("method = \"ssi-cov,arma,arma\"").unwrap(), both);
        assert_eq!(read("method = \"arma\"").unwrap(), Arma.into());
        assert_eq!(read("method = [\"ssi\"]").unwrap(), SsiCov.into());
        assert!(read("method = []").is_err());
        assert!(read("method = \"magic\"").is_err());
        assert!(read("method = \"arma,\"").is_err());
        // Written as a list, read back the same.
        let text = toml::to_string(&T {
            method: both.clone(),
        })
        .unwrap();
        assert_eq!(text.trim(), "method = [\"arma\", \"ssi-cov\"]");
        assert_eq!(read(&text).unwrap(), both);
        assert_eq!(IdentMethods::default(), both);
        assert!(both.runs_arma() && both.runs_ssi());
        let only: IdentMethods = "ssi-cov".parse().unwrap();
        assert!(!only.runs_arma() && only.runs_ssi());
        assert_eq!(both.to_string(), "arma,ssi-cov");
        let e = "arma,fft".parse::<IdentMethods>().unwrap_err().to_string();
        assert!(
            e.contains("fft") && e.contains("arma, ssi-cov, both"),
            "{e}"
        );
    }

    #[test]
    fn robust_has_one_spelling_in_toml_and_text() {
        #[derive(Deserialize, Serialize)]
        struct T {
            robust: Robust,
        }
        let t: T = toml::from_str("robust = 1.6").unwrap();
        assert_eq!(t.robust, Robust::Huber { factor: 1.6 });
        let t: T = toml::from_str("robust = \"off\"").unwrap();
        assert_eq!(t.robust, Robust::Off);
        let t: T = toml::from_str("robust = 0").unwrap();
        assert_eq!(t.robust, Robust::Off);
        assert!(toml::from_str::<T>("robust = -1").is_err());
        assert_eq!("2".parse::<Robust>(), Ok(Robust::Huber { factor: 2.0 }));
        let back = toml::to_string(&T {
            robust: Robust::Off,
        })
        .unwrap();
        assert_eq!(back.trim(), "robust = \"off\"");
    }

    #[test]
    fn empty_band_rule() {
        // The paper: 25 Hz at 200 Hz leaves 25-100 Hz empty; poles above 20 Hz are edge poles.
        let b = BandLimit::ideal_lowpass(200.0, 25.0);
        assert!(b.empty_band);
        assert_eq!(b.valid_max_hz(), 20.0);
        // vibmode's default: 25 Hz at 50 Hz is Nyquist, nothing empty.
        let b = BandLimit::ideal_lowpass(50.0, 25.0);
        assert!(!b.empty_band);
        assert_eq!(b.valid_max_hz(), 25.0);
        // 0.95 x Nyquist is the boundary.
        assert!(!BandLimit::ideal_lowpass(100.0, 47.5).empty_band);
        assert!(BandLimit::ideal_lowpass(100.0, 47.4).empty_band);
    }

    #[test]
    fn defaults_validate_and_bad_values_name_the_key() {
        ClusterParams::default().validate().unwrap();
        SweepParams::default().validate().unwrap();
        PreprocessParams::default().validate().unwrap();
        let e = SweepParams {
            order_max: 1,
            order_min: 3,
            ..SweepParams::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("order_max = 1"), "{e}");
        let e = PreprocessParams {
            cutoff_hz: 30.0,
            ..PreprocessParams::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("cutoff_hz = 30") && e.contains("25"), "{e}");
    }

    #[test]
    fn body_ssi_first_lag_and_checks() {
        let p = BodySsiParams::default();
        // 0.71 s at 10 Hz: ceil(7.1) = 8 lags of delay, 2 of margin, from lag 1
        assert_eq!(p.first_lag(0.71), 11);
        assert_eq!(p.first_lag(0.7), 10);
        assert_eq!(
            BodySsiParams {
                margin_s: 0.0,
                ..p.clone()
            }
            .first_lag(0.0),
            1
        );
        let s = p.ssi_params();
        assert!(s.pool_records && s.first_lag == 1 && s.orders() == [10, 12, 14, 16, 18]);
        assert!(p.validate().is_ok());
        for bad in [
            BodySsiParams {
                fs_hz: 0.0,
                ..p.clone()
            },
            BodySsiParams {
                block_rows: 1,
                ..p.clone()
            },
            BodySsiParams {
                order_min: 20,
                ..p.clone()
            },
            BodySsiParams {
                margin_s: f64::NAN,
                ..p.clone()
            },
            BodySsiParams {
                min_delay_correlation: 1.0,
                ..p.clone()
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        let e = BodySsiParams { order_min: 20, ..p }.validate().unwrap_err();
        assert!(e.to_string().contains("order_min"), "{e}");
    }
}

/// Detection of periodic lines (engine / gear orders) from evidence that does not depend on a
/// pole's damping: a prominent, narrow spectral peak whose narrow-band signal has the kurtosis
/// of a sine (1.5) rather than that of a randomly excited mode (3, Gaussian). Lines are then
/// tracked from record to record, so a line whose frequency moves with the engine speed is
/// reported per record instead of being lost.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LineParams {
    /// A narrow-band signal whose kurtosis (`E[x^4] / E[x^2]^2`) is below this is periodic.
    /// Default 2.0: a sine has 1.5, a sine with as much Gaussian power in the band as one fifth
    /// of its own ~1.96, Gaussian noise 3. 0 disables line detection.
    pub max_kurtosis: f64,
    /// Half-width of the band around a peak whose signal is tested, Hz (default 0.25: wider
    /// than the ~0.1 Hz resolution of a 10 s record, narrower than a mode damped by more than
    /// ~0.03 at 4 Hz).
    pub half_width_hz: f64,
    /// A spectral peak is a candidate when it rises this far above the median of the
    /// periodogram within +-1 Hz, dB (default 10).
    pub min_prominence_db: f64,
    /// Lines of two records belong to one track when their frequencies differ by less than this
    /// fraction (default 0.05: engine speed changes of a few percent between records).
    pub track_rel_tol: f64,
    /// A track is reported when it is found in at least this share of the records used
    /// (default 0.3: in the demo a body-roll peak looked periodic in 2 of 8 records).
    pub min_record_share: f64,
    /// Swept lines (a line whose frequency moves within a record): segment length of the
    /// short-time spectra, samples at the analysis rate (scipy's `nperseg`; default 96, 1.92 s
    /// at 50 Hz, resolution 0.52 Hz: long enough for a 7 Hz line to stand 8 dB above the body's
    /// response, short enough that braking at 1.3 Hz/s smears it over a few bins; 64 found 5
    /// of the demo's 10 sweeps).
    /// Longer than the record: no swept lines.
    pub stft_nperseg: usize,
    /// Overlap of successive short-time segments, samples (scipy's `noverlap`; default 48: a
    /// slice every 0.32 s at 50 Hz). Must be below `stft_nperseg`.
    pub stft_noverlap: usize,
    /// A peak of a short-time spectrum is followed when it rises this far above the slice's
    /// median within +-max(1 Hz, 4 fs/stft_nperseg), dB (default 6: a 1.92 s slice gains 7 dB
    /// less on a line than the 10 s periodogram; 8 dB found 9 of the demo's 10 sweeps, 6 dB all).
    pub stft_min_prominence_db: f64,
    /// Largest rate of change of a ridge's frequency followed from slice to slice, Hz/s
    /// (default 2.5; braking at 1.5 m/s^2 from 30 km/h sweeps a 7 Hz line at up to 1.3 Hz/s).
    pub sweep_rate_max_hz_per_s: f64,
    /// A ridge whose frequency (per slice, median of three) spans at least this much within the
    /// record is tested as a swept line, Hz (default 0.5; a lightly damped mode does not move,
    /// and narrower ridges are left to the steady test). 0 = no swept lines.
    pub sweep_min_range_hz: f64,
    /// Steady lines are found by Thomson's multitaper harmonic F-test in each record and
    /// channel: a line where F peaks with `P(F > F_obs) < f_test_alpha` under F(2, 2K - 2), the
    /// distribution of F without a line over a spectrum smooth within the tapers' band
    /// (docs/analysis.md, "Lines"). Default 1e-4: the false-alarm probability per record,
    /// channel and frequency of the search grid (4 per `1 / T`), so over 3-24 Hz a record of
    /// white noise on one channel has a false detection with probability about 8 %; a track
    /// needs detections in `min_record_share` of the records and in two at least. In (0, 0.1].
    pub f_test_alpha: f64,
    /// False-alarm probability of the F-test combined over the records (Fisher over the records
    /// per channel, Bonferroni over the pool's channels) per pool and analysis, over the whole
    /// band searched: the combined p-value at one frequency must be below this divided by the
    /// number of frequencies searched, the points of the F-test's 4x zero-padded grid in the
    /// band (Bonferroni over them). Default 0.01: 1.1e-5 per frequency for 10.24 s records over
    /// 3-24.6 Hz (docs/analysis.md, "Periodic lines"). In (0, 0.1].
    pub f_test_combined_alpha: f64,
    /// Time-half-bandwidth product `NW` of the F-test's Slepian tapers (default 4: a 10.24 s
    /// record's tapers are concentrated in +-0.39 Hz). In [1, 20].
    pub f_test_nw: f64,
    /// Number of Slepian tapers `K` of the F-test (default 7 = 2 NW - 1, F with 2 and 12
    /// degrees of freedom). In [2, 2 NW].
    pub f_test_tapers: usize,
    /// Lowest frequency of a line, steady or swept, Hz (default 3). Below it the F-test's null
    /// fails on road vehicles: the body's modes (half-power half-width ~0.25 Hz at 1.2 Hz with
    /// damping 0.2) are narrower than the tapers' +-0.39 Hz and braking and turning add
    /// deterministic transients; busgen's nominal bus gave a steady "line" at 1.25 Hz.
    pub min_frequency_hz: f64,
}

impl Default for LineParams {
    fn default() -> Self {
        LineParams {
            max_kurtosis: 2.0,
            half_width_hz: 0.25,
            min_prominence_db: 10.0,
            track_rel_tol: 0.05,
            min_record_share: 0.3,
            stft_nperseg: 96,
            stft_noverlap: 80,
            stft_min_prominence_db: 6.0,
            sweep_rate_max_hz_per_s: 2.5,
            sweep_min_range_hz: 0.5,
            f_test_alpha: 1e-4,
            f_test_combined_alpha: 1e-2,
            f_test_nw: 4.0,
            f_test_tapers: 7,
            min_frequency_hz: 3.0,
        }
    }
}

impl LineParams {
    /// Checks ranges.
    pub fn validate(&self) -> Result<(), ParamError> {
        if !(self.max_kurtosis.is_finite() && (0.0..=3.0).contains(&self.max_kurtosis)) {
            return Err(bad(
                "max_kurtosis",
                self.max_kurtosis,
                "must be in [0, 3] (0 = no line detection; a sine has 1.5, noise 3)",
                2.0,
            ));
        }
        if !(self.half_width_hz.is_finite()
            && self.half_width_hz > 0.0
            && self.half_width_hz <= 10.0)
        {
            return Err(bad(
                "half_width_hz",
                self.half_width_hz,
                "must be > 0 and at most 10 Hz",
                0.25,
            ));
        }
        if !(self.min_prominence_db.is_finite() && (0.0..=100.0).contains(&self.min_prominence_db))
        {
            return Err(bad(
                "min_prominence_db",
                self.min_prominence_db,
                "must be in [0, 100] dB",
                10.0,
            ));
        }
        if !(self.track_rel_tol.is_finite() && self.track_rel_tol > 0.0 && self.track_rel_tol < 0.5)
        {
            return Err(bad(
                "track_rel_tol",
                self.track_rel_tol,
                "must be in (0, 0.5)",
                0.05,
            ));
        }
        if !(self.min_record_share.is_finite() && (0.0..=1.0).contains(&self.min_record_share)) {
            return Err(bad(
                "min_record_share",
                self.min_record_share,
                "must be in [0, 1]",
                0.3,
            ));
        }
        let d = LineParams::default();
        if !(4..=1 << 20).contains(&self.stft_nperseg) {
            return Err(bad(
                "stft_nperseg",
                self.stft_nperseg as f64,
                "must be 4 to 1048576 samples",
                d.stft_nperseg as f64,
            ));
        }
        if self.stft_noverlap >= self.stft_nperseg {
            return Err(bad(
                "stft_noverlap",
                self.stft_noverlap as f64,
                "must be below stft_nperseg",
                d.stft_noverlap as f64,
            ));
        }
        if !(self.stft_min_prominence_db.is_finite()
            && (0.0..=100.0).contains(&self.stft_min_prominence_db))
        {
            return Err(bad(
                "stft_min_prominence_db",
                self.stft_min_prominence_db,
                "must be in [0, 100] dB",
                d.stft_min_prominence_db,
            ));
        }
        if !(self.sweep_rate_max_hz_per_s.is_finite()
            && self.sweep_rate_max_hz_per_s > 0.0
            && self.sweep_rate_max_hz_per_s <= 1000.0)
        {
            return Err(bad(
                "sweep_rate_max_hz_per_s",
                self.sweep_rate_max_hz_per_s,
                "must be > 0 and at most 1000 Hz/s",
                d.sweep_rate_max_hz_per_s,
            ));
        }
        if !(self.sweep_min_range_hz.is_finite()
            && (0.0..=100.0).contains(&self.sweep_min_range_hz))
        {
            return Err(bad(
                "sweep_min_range_hz",
                self.sweep_min_range_hz,
                "must be in [0, 100] Hz (0 = no swept lines)",
                d.sweep_min_range_hz,
            ));
        }
        if !(self.f_test_alpha.is_finite() && self.f_test_alpha > 0.0 && self.f_test_alpha <= 0.1) {
            return Err(bad(
                "f_test_alpha",
                self.f_test_alpha,
                "must be in (0, 0.1] (false-alarm probability per record, channel and frequency)",
                d.f_test_alpha,
            ));
        }
        if !(self.f_test_combined_alpha.is_finite()
            && self.f_test_combined_alpha > 0.0
            && self.f_test_combined_alpha <= 0.1)
        {
            return Err(bad(
                "f_test_combined_alpha",
                self.f_test_combined_alpha,
                "must be in (0, 0.1] (false-alarm probability of the combined test per pool and analysis)",
                d.f_test_combined_alpha,
            ));
        }
        if !(self.f_test_nw.is_finite() && (1.0..=20.0).contains(&self.f_test_nw)) {
            return Err(bad(
                "f_test_nw",
                self.f_test_nw,
                "must be in [1, 20]",
                d.f_test_nw,
            ));
        }
        if !(2..=(2.0 * self.f_test_nw).floor() as usize).contains(&self.f_test_tapers) {
            return Err(bad(
                "f_test_tapers",
                self.f_test_tapers as f64,
                "must be 2 to 2 f_test_nw (2 NW - 1 tapers are well concentrated)",
                (2.0 * self.f_test_nw - 1.0).max(2.0).floor(),
            ));
        }
        if !(self.min_frequency_hz.is_finite() && (0.0..=1e6).contains(&self.min_frequency_hz)) {
            return Err(bad(
                "min_frequency_hz",
                self.min_frequency_hz,
                "must be in [0, 1e6] Hz",
                d.min_frequency_hz,
            ));
        }
        Ok(())
    }
}

/// Settings of the model update: the fit of a vehicle file's suspension to the records from the
/// full-car model's body equations (`vibmode_vehicle::update`, `[model_update]` in the analysis
/// TOML).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BodyFitParams {
    /// Band of the fitted equations, Hz. `None` (default): from the vehicle file's body modes,
    /// `[0.45 f_min, 1.6 f_max]` over heave, pitch and roll (0.46-2.1 Hz on the demo bus), or
    /// the wide band `[0.45 f_min, 3 f_max]` fitted beside it, taken where its body modes agree
    /// with the default band's (`vibmode_vehicle::update::choose_band`). A band from 0 Hz lets
    /// the manoeuvres' body moments in; one above ~2 Hz can let in the body's bending, which
    /// three sprung sensors cannot see (docs/model_update.md, "Band").
    pub band_hz: Option<[f64; 2]>,
    /// Samples dropped at each end of a record, s (default 1.0; the band-pass rings there).
    pub edge_s: f64,
    /// Which anti-roll bars are fitted (default [`AntiRollBars::Both`]: a front and a rear bar
    /// whatever the vehicle file holds, so that the fit does not depend on whether the file
    /// has a bar; one the bus does not have comes out as 0).
    pub anti_roll_bars: AntiRollBars,
}

/// Which anti-roll bars the model update fits (`anti_roll_bars` in `[model_update]`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum AntiRollBars {
    /// A front and a rear bar, whether or not the vehicle file has them: the body equations are
    /// linear in the bars, so the fit is the same from a file with a bar or without one, and a
    /// bar the bus lacks comes out as 0 (the bounded fit holds it there).
    #[default]
    Both,
    /// Only the bars the vehicle file has (a stiffness above 0): one unknown fewer per bar the
    /// file lacks, for a bus known to have none.
    File,
}

impl Default for BodyFitParams {
    fn default() -> Self {
        BodyFitParams {
            band_hz: None,
            edge_s: 1.0,
            anti_roll_bars: AntiRollBars::Both,
        }
    }
}

impl BodyFitParams {
    /// Checks the values (finite, positive, an increasing band).
    pub fn validate(&self) -> Result<(), ParamError> {
        if !(self.edge_s.is_finite() && self.edge_s >= 0.0) {
            return Err(bad(
                "edge_s",
                crate::Num(self.edge_s),
                "must be a duration >= 0 s",
                1.0,
            ));
        }
        if let Some([lo, hi]) = self.band_hz {
            if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
                return Err(bad(
                    "band_hz",
                    format!("[{lo}, {hi}]"),
                    "must be two frequencies 0 < low < high in Hz",
                    "[0.5, 2.0]",
                ));
            }
        }
        Ok(())
    }
}

/// Settings of the body-band SSI-cov (`[body_ssi]` in the analysis TOML): all channels
/// resampled to a low rate that keeps only the body band, and each record's Toeplitz matrix
/// begun beyond that record's own front-to-rear wheel delay, so that the road's delayed
/// excitation does not bias body heave and pitch (docs/ssi.md, "Body modes beyond each
/// record's wheelbase delay"). The delay is measured in each record as the peak of the
/// cross-correlation of a front and a rear wheel channel on the same side.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BodySsiParams {
    /// Run it when the method runs SSI-cov and the records have wheel channels at a front and a
    /// rear corner of one side (default true).
    pub enabled: bool,
    /// Rate the records are resampled to, Hz (default 10: the band up to 4 Hz).
    pub fs_hz: f64,
    /// Block rows of each record's Toeplitz matrix (default 5: lags over 0.9 s at 10 Hz).
    pub block_rows: usize,
    /// Lowest identified order (default 10; heave and pitch merge at lower orders).
    pub order_min: usize,
    /// Highest identified order (default 18).
    pub order_max: usize,
    /// Lags skipped beyond each record's measured delay, s (default 0.2).
    pub margin_s: f64,
    /// Longest front-to-rear delay searched, s (default 3.0: a 6 m wheelbase down to 7 km/h).
    pub max_delay_s: f64,
    /// Lowest peak of the normalised front/rear cross-correlation that counts as a measured
    /// delay (default 0.2); records below it are left out, with the reason.
    pub min_delay_correlation: f64,
}

impl Default for BodySsiParams {
    fn default() -> Self {
        BodySsiParams {
            enabled: true,
            fs_hz: 10.0,
            block_rows: 5,
            order_min: 10,
            order_max: 18,
            margin_s: 0.2,
            max_delay_s: 3.0,
            min_delay_correlation: 0.2,
        }
    }
}

impl BodySsiParams {
    /// Checks the values.
    pub fn validate(&self) -> Result<(), ParamError> {
        let d = BodySsiParams::default();
        positive("fs_hz", self.fs_hz, d.fs_hz)?;
        positive("max_delay_s", self.max_delay_s, d.max_delay_s)?;
        if self.block_rows < 2 {
            return Err(bad(
                "block_rows",
                self.block_rows,
                "must be >= 2",
                d.block_rows,
            ));
        }
        if self.order_min < 2 || self.order_max < self.order_min {
            return Err(bad(
                "order_min",
                format!("{} (order_max {})", self.order_min, self.order_max),
                "must be >= 2 and at most order_max",
                format!("{} (order_max {})", d.order_min, d.order_max),
            ));
        }
        if !(self.margin_s.is_finite() && self.margin_s >= 0.0) {
            return Err(bad(
                "margin_s",
                crate::Num(self.margin_s),
                "must be a duration >= 0 s",
                d.margin_s,
            ));
        }
        if !(self.min_delay_correlation.is_finite()
            && (0.0..1.0).contains(&self.min_delay_correlation))
        {
            return Err(bad(
                "min_delay_correlation",
                crate::Num(self.min_delay_correlation),
                "must be in [0, 1)",
                d.min_delay_correlation,
            ));
        }
        Ok(())
    }

    /// The SSI-cov settings of the pooled identification (orders step 2, records pooled).
    pub fn ssi_params(&self) -> crate::SsiParams {
        crate::SsiParams {
            block_rows: self.block_rows,
            order_min: self.order_min,
            order_max: self.order_max,
            order_step: 2,
            reference_channels: None,
            pool_records: true,
            first_lag: 1,
        }
    }

    /// The first lag (samples at `fs_hz`) of a record whose front-to-rear delay is `delay_s`:
    /// `1 + ceil(delay_s fs_hz) + round(margin_s fs_hz)`.
    pub fn first_lag(&self, delay_s: f64) -> usize {
        1 + (delay_s * self.fs_hz).ceil().max(0.0) as usize
            + (self.margin_s * self.fs_hz).round() as usize
    }
}
