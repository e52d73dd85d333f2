//! The nominal model set of a vehicle (robust centre and spread of every feature) and the
//! scoring and classification of a record against it.

use std::collections::BTreeMap;
use std::fmt;

use serde::{Deserialize, Serialize};
use vibmode_analysis::{Corner, Role};

use crate::body::{body_response, fit_body_model, BodyModel, BodySpectra};
use crate::config::FleetConfig;
use crate::error::{FleetError, Result};
use crate::features::RecordFeatures;
use crate::stats::{bonferroni_limit, median, robust_sigma};

/// Version of the model-set JSON.
pub const MODEL_SET_SCHEMA: u32 = 1;

/// Which question a feature answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Group {
    /// How hard the road drives the vehicle (unsprung band levels).
    Excitation,
    /// How the vehicle answers (transmissibility, modes).
    Vehicle,
}

/// What a feature measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Kind {
    /// Band RMS of the unsprung channels (mean of their logarithms).
    Level,
    /// Sprung over unsprung band RMS of a corner.
    Transmissibility,
    /// Natural frequency of a mode of a channel.
    ModeFrequency,
    /// Damping ratio of a mode of a channel.
    ModeDamping,
    /// Left over right unsprung level of an axle at and above wheel hop.
    SideRatio,
    /// Front over rear unsprung level of a side (one track) at and above wheel hop.
    TrackRatio,
    /// A sprung channel's measured power in a band over the power its record's own wheel
    /// motions predict through the nominal body response `H(f)`.
    BodyResponse,
    /// A corner's spring fitted to a drive's records, relative to the other corners'
    /// ([`crate::suspension`]; drives only).
    SpringFit,
    /// A corner's damper fitted to a drive's records, relative to the other corners'.
    DamperFit,
}

impl Kind {
    /// The kind's name, as the JSON spells it (`mode-frequency`).
    pub fn name(self) -> &'static str {
        match self {
            Kind::Level => "level",
            Kind::Transmissibility => "transmissibility",
            Kind::ModeFrequency => "mode-frequency",
            Kind::ModeDamping => "mode-damping",
            Kind::SideRatio => "side-ratio",
            Kind::TrackRatio => "track-ratio",
            Kind::BodyResponse => "body-response",
            Kind::SpringFit => "spring-fit",
            Kind::DamperFit => "damper-fit",
        }
    }
}

impl std::fmt::Display for Kind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Every kind, in the order of the model set's limits.
const KINDS: [Kind; 7] = [
    Kind::Level,
    Kind::Transmissibility,
    Kind::ModeFrequency,
    Kind::ModeDamping,
    Kind::SideRatio,
    Kind::TrackRatio,
    Kind::BodyResponse,
];

/// The axles (left and right corner) and the sides (front and rear corner) of the unsprung
/// level ratios.
const AXLES: [(&str, Corner, Corner); 2] = [
    ("front", Corner::FL, Corner::FR),
    ("rear", Corner::RL, Corner::RR),
];
const TRACKS: [(&str, Corner, Corner); 2] = [
    ("left", Corner::FL, Corner::RL),
    ("right", Corner::FR, Corner::RR),
];

/// The key of a level ratio; `line_free` (the unsprung lines replaced by their continuum) has
/// its own.
fn ratio_key(kind: Kind, name: &str, band: &[f64; 2], line_free: bool) -> String {
    let prefix = if kind == Kind::SideRatio {
        "side"
    } else {
        "track"
    };
    let lf = if line_free { ":lf" } else { "" };
    format!("{prefix}:{name}:{}{lf}", band_key(band))
}

/// Largest share of a channel's band power that may be sensor noise for its level to enter a
/// ratio: beyond it the band says more about the sensor than about the wheel, and the ratio is
/// left out (`missing`) rather than computed from a small difference of two noisy powers.
pub const NOISE_SHARE_MAX: f64 = 0.5;

/// The band RMS `level` without the noise power `noise_power` (unit^2) in the band:
/// `sqrt(level^2 - noise_power)`; `None` when the noise is more than [`NOISE_SHARE_MAX`] of the
/// band's power.
pub fn noise_free_level(level: f64, noise_power: f64) -> Option<f64> {
    let power = level * level;
    (noise_power <= NOISE_SHARE_MAX * power).then(|| (power - noise_power.max(0.0)).sqrt())
}

/// Vehicle features that the widening of their spread by the record's own noise
/// ([`FeatureStat::spread`]) kept from being flagged are named in the summary, at most this many
/// (then "and N more").
pub const SPARED_NAMED_MAX: usize = 3;

/// Per feature key, the variance (ln units squared) of the feature's value as the record
/// itself estimates it: its sensors' noise for the level ratios ([`ratio_noise_variances`]),
/// its coherence and averages for the transmissibility ([`transmissibility_variances`])
/// ([`ModelSet::record_variances`]); features without an estimate are absent.
pub type EstimateVariances = BTreeMap<String, f64>;

/// The variance of `ln` of a noise-free band level ([`noise_free_level`]) from the sensor's
/// white noise: the band power `P = level^2` of `cells` independent time-frequency cells
/// ([`welch_band_cells`]) holds the noise power `Pn` and the wheel's `Ps = P - Pn`; the noise's
/// own fluctuation (`Pn^2 / cells`) and its beat with the wheel's motion (`2 Ps Pn / cells`)
/// remain after `Pn` is taken out, so `var ln sqrt(Ps) = (Pn^2 + 2 Ps Pn) / (4 cells Ps^2)`.
/// The wheel's own part is left out: the two wheels of a level ratio roll over the same road
/// (a side's on one track), so it largely cancels in the ratio, and the nominal records' spread
/// holds it. `None` where the noise is more than [`NOISE_SHARE_MAX`] of the band's power or
/// the arguments are not finite and positive.
pub fn noise_free_level_variance(level: f64, noise_power: f64, cells: f64) -> Option<f64> {
    let power = level * level;
    let pn = noise_power.max(0.0);
    if !(power.is_finite() && power > 0.0 && cells.is_finite() && cells > 0.0)
        || pn > NOISE_SHARE_MAX * power
    {
        return None;
    }
    let ps = power - pn;
    Some((pn * pn + 2.0 * ps * pn) / (4.0 * cells * ps * ps))
}

/// The number of independent cells a band power of the fleet's Welch spectra (Hann window,
/// 50 % overlap, `segments` segments averaged) over `bins` frequency bins is worth: its
/// relative variance for white noise is `1 / cells`. Adjacent Hann bins are correlated
/// (complex correlation -2/3, two apart 1/6: a band sum's variance is `35 / 18` times that of
/// independent bins) and so are half-overlapping segments (each bin's variance is
/// [`HANN_HALF_OVERLAP_VARIANCE`] times `S^2 / K`). Three segments (one 10.24 s record at 50 Hz,
/// `nperseg` 256) over 8-20 Hz: 91 cells, where duration x bandwidth would say 123 (scipy's
/// Welch over 4000 seeds: relative variance 0.0111, this formula 0.0110).
pub fn welch_band_cells(bins: usize, segments: usize) -> f64 {
    let k = segments.max(1) as f64;
    let m = bins as f64;
    m * k / (35.0 / 18.0 * HANN_HALF_OVERLAP_VARIANCE)
}

/// The variances the unsprung sensors' noise gives a record's level ratios (the sum of its two
/// wheels' [`noise_free_level_variance`] over the [`welch_band_cells`] of the ratio band),
/// keyed as [`scalar_features`] keys them; empty unless the ratios are noise-free (`line_free`
/// and `noise_free`) and the record keeps its spectra per bin
/// ([`crate::features::LineFree::bins`], for the bins and segments).
pub fn ratio_noise_variances(
    rf: &RecordFeatures,
    cfg: &FleetConfig,
    line_free: bool,
    noise_free: bool,
) -> EstimateVariances {
    let mut out = EstimateVariances::new();
    let Some(lf) = rf.line_free.as_ref().filter(|_| line_free && noise_free) else {
        return out;
    };
    let [lo, hi] = cfg.ratio_band_hz;
    let Some(bins) = lf.bins.as_ref().filter(|b| b.segments > 0) else {
        return out;
    };
    // The bins must span the ratio band (they span the level bands, which a configuration
    // may end below it).
    let df = match bins.freq_hz.as_slice() {
        [a, b, ..] => b - a,
        _ => return out,
    };
    let spans = bins.freq_hz.first().is_some_and(|&f| f <= lo + df)
        && bins.freq_hz.last().is_some_and(|&f| f >= hi - df);
    let in_band = bins.freq_hz.iter().filter(|&&f| f >= lo && f <= hi).count();
    if !spans || in_band == 0 {
        return out;
    }
    let cells = welch_band_cells(in_band, bins.segments);
    let var = |corner: Corner| {
        let i = rf
            .channels
            .iter()
            .position(|c| c.role == Role::Unsprung && c.corner == Some(corner))?;
        let level = lf.ratio_band_rms.get(i).copied().flatten()?;
        let density = lf.noise_density.get(i).copied().unwrap_or(0.0);
        noise_free_level_variance(level, density * (hi - lo), cells)
    };
    for (kind, pairs) in [(Kind::SideRatio, AXLES), (Kind::TrackRatio, TRACKS)] {
        for (name, a, b) in pairs {
            if let (Some(va), Some(vb)) = (var(a), var(b)) {
                out.insert(
                    ratio_key(kind, name, &cfg.ratio_band_hz, line_free),
                    va + vb,
                );
            }
        }
    }
    out
}

/// Where a feature comes from, and its name in tables.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FeatureMeta {
    /// Unique key, e.g. `transrel:RL:8-12Hz`, `mode:RL_unsprung:1:damping`.
    pub key: String,
    /// Excitation or vehicle.
    pub group: Group,
    /// What it measures.
    pub kind: Kind,
    /// The corner, if any.
    pub corner: Option<Corner>,
    /// The channel (for transmissibility, the sprung one).
    pub channel: String,
    /// Name in tables, e.g. `transmissibility 8-12 Hz`, `wheel-hop 10.9 Hz damping`.
    pub label: String,
}

/// Robust statistics of one feature over the nominal records (of ln of the feature).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FeatureStat {
    /// The feature.
    #[serde(flatten)]
    pub meta: FeatureMeta,
    /// Median of ln(value).
    pub centre: f64,
    /// max(1.4826 MAD, floor) of ln(value).
    pub sigma: f64,
    /// Smallest ln(value) of the nominal records.
    pub lo: f64,
    /// Largest ln(value) of the nominal records.
    pub hi: f64,
    /// Nominal records that have the feature.
    pub n: usize,
    /// The mean over the nominal records of the variance their sensors' noise gives ln(value)
    /// ([`EstimateVariances`]; pooled over the kind where `sigma` is), which `sigma` holds. Absent
    /// for features without such an estimate and in model sets stored before it existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub estimate_var: Option<f64>,
}

impl FeatureStat {
    /// The spread a value is scored against when its own noise variance is `v` (ln units
    /// squared): `sigma` widened by the excess of `v` over the nominal records' mean,
    /// `sqrt(sigma^2 + max(0, v - estimate_var))`. A record on a smoother road than the nominal
    /// records', whose wheels' band power is nearer their sensors' noise floor, is judged
    /// against the scatter its own noise gives it; never narrower than `sigma`.
    pub fn spread(&self, v: Option<f64>) -> f64 {
        match (v, self.estimate_var) {
            (Some(v), Some(nominal)) if v.is_finite() && v > nominal => {
                (self.sigma * self.sigma + (v - nominal)).sqrt()
            }
            _ => self.sigma,
        }
    }
}

/// A mode of the model set: one channel's mode found in most nominal records.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModeSlot {
    /// The channel.
    pub channel: String,
    /// Its role.
    pub role: Role,
    /// Its corner.
    pub corner: Option<Corner>,
    /// Median frequency over the nominal records, Hz.
    pub frequency_hz: f64,
    /// `wheel-hop` (unsprung, >= 5 Hz), `body` (< 3 Hz) or `mode`.
    pub name: String,
    /// Share of nominal records that contain it.
    pub share: f64,
    /// Median damping ratio over the nominal records; a record's mode whose damping lies more
    /// than [`MODE_DAMPING_CLASS_RATIO`] from it is another physical mode and is not matched to
    /// the slot. Absent in model sets stored before it existed (then any damping matches).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping_ratio: Option<f64>,
}

/// Two estimates near one frequency whose damping ratios differ by more than this factor are
/// two physical modes (on busgen the 9 Hz cluster of one channel is the body's bending mode,
/// damping 0.02-0.05, in one record and a wheel or axle mode, 0.2-0.33, in the next), so they
/// are not one mode of the model set; a damper at 60 % lowers a wheel mode's damping by a factor
/// of about 0.6-0.8, well inside it.
pub const MODE_DAMPING_CLASS_RATIO: f64 = 3.0;

/// The control limit of one kind of feature.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct KindLimit {
    /// The kind.
    pub kind: Kind,
    /// Its group.
    pub group: Group,
    /// Features of this kind in the model set.
    pub n_features: usize,
    /// Bonferroni limit of the group: `Phi^-1(1 - false_alarm_rate / (2 m))`, m = features of
    /// the group.
    pub bonferroni: f64,
    /// Largest |score| of this kind when each nominal record is scored against the others.
    pub loo_max_abs_z: f64,
    /// The limit in force: `max(bonferroni, LOO_MARGIN * loo_max_abs_z)`.
    pub limit: f64,
}

/// Margin over the largest leave-one-out score of the nominal records.
pub const LOO_MARGIN: f64 = 1.0;

/// The nominal model set of one vehicle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelSet {
    /// [`MODEL_SET_SCHEMA`].
    pub schema: u32,
    /// Vehicle id.
    pub vehicle: String,
    /// Version in the store (1, 2, ...; 0 before it is stored).
    pub version: i64,
    /// Nominal records it was built from (file names).
    pub records: Vec<String>,
    /// Settings it was built with.
    pub config: FleetConfig,
    /// Modes of the model set.
    pub slots: Vec<ModeSlot>,
    /// Statistics per feature.
    pub features: Vec<FeatureStat>,
    /// Control limit per kind of feature.
    pub limits: Vec<KindLimit>,
    /// Channels of the nominal records (a record checked against the set must have these;
    /// empty in model sets stored before this field existed: not checked).
    #[serde(default)]
    pub channels: Vec<String>,
    /// The nominal body response to the wheel motions (absent when the nominal records have no
    /// body spectra, or their pooled wheel cross-spectra are singular: `notes` says so).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<BodyModel>,
    /// What the model set lacks and why.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// Built from the line-free transmissibility ([`RecordFeatures::line_free`]
    /// of every nominal record); false in model sets stored before it existed and in model sets
    /// built from records stored before it: a check against such a set is refused
    /// ([`FleetError::StaleBaseline`]).
    #[serde(default)]
    pub line_free: bool,
    /// Built from unsprung level ratios with each channel's noise power in the band taken out
    /// ([`crate::features::LineFree::noise_density`] of every nominal record): on a smooth road
    /// the sensors' noise, alike in every channel, is a large share of the wheels' band power and
    /// pulls every ratio towards 1. False in model sets stored before it existed and in those
    /// built from records stored before it; their checks keep the ratios as they were.
    #[serde(default)]
    pub noise_free: bool,
    /// Built from the transmissibility and the body's response to wheel motion with each
    /// unsprung channel's noise taken out of its input power
    /// ([`crate::features::TransmissibilityBins::band_value_noise_free`],
    /// [`BodySpectra::without_input_noise`]; with `noise_free` and `vehicle_line_bins_hz`): the
    /// H1 estimate is lowered, and the body's predicted response raised, by the input's noise,
    /// which grows as the road gets smoother and differs between corners. False in model sets
    /// stored before it existed; their checks keep both as they were.
    #[serde(default)]
    pub input_noise_free: bool,
    /// The suspension fitted to the nominal records together, when the vehicle has a
    /// registered model file and at least three nominal records carry its equations
    /// ([`crate::suspension`]); else absent and `notes` says why.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub suspension: Option<crate::suspension::SuspensionReference>,
    /// The baseline's own drives, each checked as a drive against a model set built from the
    /// other nominal records ([`crate::fleet::held_out_drives`]): how often a healthy drive of
    /// this vehicle is flagged. Empty when the nominal records form fewer than two drives
    /// (`notes` says so) and in model sets stored before it existed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub held_out_drives: Vec<HeldOutDrive>,
    /// The bins (Hz) of the vehicle's own periodic lines: those left out of the line-free
    /// transmissibility of at least [`VEHICLE_LINE_MIN_RECORDS`] nominal records. Every record
    /// scored against the set (its nominal records too) has them left out of its transmissibility
    /// besides its own lines' (key `transh1lu:`), so that a line its analysis found in some
    /// records and not in others (a driveline order on a smooth road at low speed, not on the
    /// baseline's rougher one) does not move the feature. `None` in model sets stored before it
    /// existed or built from records without the transmissibility per bin
    /// ([`crate::features::LineFree::bins`]): they score `transh1lf:` as before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vehicle_line_bins_hz: Option<Vec<f64>>,
}

/// A nominal drive of the baseline checked against the other nominal records (leave one drive
/// out): a drive the vehicle drove healthy, so any verdict but `normal` is a false alarm of the
/// drive rule on this vehicle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HeldOutDrive {
    /// The drive's id: its UTC day where every nominal record's start is known, else the
    /// folder its records were given in.
    pub drive: String,
    /// Its records (file names as given at ingest).
    pub records: Vec<String>,
    /// The nominal records the held-out model set was built from.
    pub reference_records: usize,
    /// The drive's verdict against them.
    pub classification: Classification,
    /// The component named first, when a vehicle feature is flagged.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub component: Option<Component>,
    /// The flagged features, as a check's summary (empty when `normal`).
    pub summary: String,
}

impl ModelSet {
    /// A record's scalar features as this model set reads them ([`scalar_features`] with its
    /// modes, body response and variants).
    pub fn record_features(&self, rf: &RecordFeatures) -> Vec<(FeatureMeta, f64)> {
        scalar_features(
            rf,
            &self.slots,
            self.body.as_ref(),
            &self.config,
            self.variants(),
        )
    }

    /// Why a record gives no value of some features ([`noise_unjudged`]).
    pub fn record_unjudged(&self, rf: &RecordFeatures) -> BTreeMap<String, String> {
        noise_unjudged(rf, &self.config, self.variants(), self.body.as_ref())
    }

    /// The variants this model set reads records with.
    pub fn variants(&self) -> Variants<'_> {
        Variants {
            line_free: self.line_free,
            noise_free: self.noise_free,
            input_noise_free: self.input_noise_free,
            vehicle_lines: self.vehicle_line_bins_hz.as_deref(),
        }
    }

    /// The variances of a record's features as this model set reads them
    /// ([`estimate_variances`]); `values` are its features ([`ModelSet::record_features`]).
    pub fn record_variances(
        &self,
        rf: &RecordFeatures,
        values: &[(FeatureMeta, f64)],
    ) -> EstimateVariances {
        estimate_variances(rf, &self.config, self.variants(), values)
    }

    /// The limit of `kind` (infinite for a kind the model set has not).
    pub fn limit(&self, kind: Kind) -> f64 {
        self.limits
            .iter()
            .find(|l| l.kind == kind)
            .map_or(f64::INFINITY, |l| l.limit)
    }
}

/// Classification of a record.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Classification {
    /// Excitation and vehicle inside the nominal set.
    Normal,
    /// Excitation outside, vehicle inside.
    Road,
    /// Vehicle features outside, excitation inside.
    Vehicle,
    /// Both outside.
    Both,
    /// A sensor of the record failed (dead, stuck, clipped or held channel): its scores say nothing
    /// about the vehicle or the road until the sensor is fixed.
    Sensor,
}

impl Classification {
    /// From the two alarms.
    pub fn from_alarms(vehicle: bool, road: bool) -> Self {
        match (vehicle, road) {
            (false, false) => Classification::Normal,
            (false, true) => Classification::Road,
            (true, false) => Classification::Vehicle,
            (true, true) => Classification::Both,
        }
    }
}

impl fmt::Display for Classification {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Classification::Normal => "normal",
            Classification::Road => "road",
            Classification::Vehicle => "vehicle",
            Classification::Both => "both",
            Classification::Sensor => "sensor",
        })
    }
}

/// The component of a corner a vehicle verdict points at (docs/fleet.md, "Which component").
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Component {
    /// The damper: the wheel's level above wheel hop raised against its neighbours.
    Damper,
    /// The spring: the body's response to the wheel motions lowered at the corner while the
    /// wheel's level above wheel hop is not raised.
    Spring,
    /// The tyre: the wheel's level above wheel hop lowered against its neighbours, or its
    /// wheel-hop frequency lowered.
    Tyre,
    /// The corner's suspension, without telling the component: the evidence fits more than one
    /// component, or none of the rules above.
    Suspension,
}

impl fmt::Display for Component {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Component::Damper => "damper",
            Component::Spring => "spring",
            Component::Tyre => "tyre",
            Component::Suspension => "suspension",
        })
    }
}

/// One feature's comparison with the model set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Evidence {
    /// The feature.
    #[serde(flatten)]
    pub meta: FeatureMeta,
    /// The record's value (Hz, ratio, m/s^2 or damping ratio).
    pub value: f64,
    /// The nominal centre in the same unit.
    pub centre: f64,
    /// The score: robust z for vehicle features, distance outside the nominal range in spreads
    /// for excitation features.
    pub z: f64,
    /// Relative change from the centre, %.
    pub change_pct: f64,
    /// The control limit of its kind.
    pub limit: f64,
    /// |z| above the limit.
    pub flagged: bool,
    /// Where the record's (or drive's) own estimate variance widened the feature's spread
    /// ([`FeatureStat::spread`]), the factor (above 1); absent otherwise and in checks stored
    /// before it existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spread_widened_by: Option<f64>,
}

/// Summary scores of a record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// Largest |z| of the vehicle features (0 without any).
    pub vehicle_max_abs_z: f64,
    /// Largest excitation score.
    pub excitation_max_abs_z: f64,
    /// Vehicle features scored.
    pub n_vehicle: usize,
    /// Excitation features scored.
    pub n_excitation: usize,
}

/// The verdict on one record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Assessment {
    /// normal, road, vehicle or both.
    pub classification: Classification,
    /// Summary scores and limits.
    pub scores: Scores,
    /// The flagged features, largest |z| first.
    pub evidence: Vec<Evidence>,
    /// One line: the flagged vehicle features per corner, e.g.
    /// `RL: transmissibility 8-12 Hz +35 %, wheel-hop 10.9 Hz damping -40 %`.
    pub summary: String,
    /// Features of the model set the record lacks (e.g. a mode not identified in it), and for a
    /// drive why its suspension fit or spring trend is absent. The features the record has but
    /// that were not scored are in `not_judged`, each with its reason (checks stored before it
    /// existed list them here, as "feature (not judged: reason)").
    pub missing: Vec<String>,
    /// Features of the model set given no score, and why: too little road input in their band,
    /// or their wheels' motion mostly sensor noise. Empty in checks stored before it existed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub not_judged: Vec<NotJudged>,
    /// The record's failed sensors (the class is then `sensor`); empty in checks stored
    /// before it existed.
    #[serde(default)]
    pub sensor_faults: Vec<crate::features::SensorFault>,
    /// The component of the corner named first (the corner of the first vehicle evidence),
    /// when a vehicle feature is flagged; absent in checks stored before it existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub component: Option<Component>,
}

/// A feature of the model set that a record or drive was not scored on ([`Assessment::not_judged`]).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct NotJudged {
    /// The feature as the evidence names it, e.g. `RR: transmissibility 2-5 Hz vs the other corners`.
    pub feature: String,
    /// Why, e.g. `its wheel's motion in 2-5 Hz is 67 % sensor noise`; for a drive prefixed with
    /// the share of its records (`in 8 of 8 records: ...`).
    pub reason: String,
}

impl std::fmt::Display for NotJudged {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} (not judged: {})", self.feature, self.reason)
    }
}

#[cfg(test)]
impl Assessment {
    /// A `normal` verdict without evidence, scores 0 (tests build on it).
    pub(crate) fn normal_for_tests() -> Self {
        Assessment {
            classification: Classification::Normal,
            scores: Scores {
                vehicle_max_abs_z: 0.0,
                excitation_max_abs_z: 0.0,
                n_vehicle: 0,
                n_excitation: 0,
            },
            evidence: Vec::new(),
            summary: String::new(),
            missing: Vec::new(),
            not_judged: Vec::new(),
            sensor_faults: Vec::new(),
            component: None,
        }
    }
}

fn band_label(b: &[f64; 2]) -> String {
    format!("{}-{} Hz", b[0], b[1])
}

fn band_key(b: &[f64; 2]) -> String {
    format!("{}-{}Hz", b[0], b[1])
}

/// The noise densities of the inputs of `s` (the record's unsprung channels, by name) from
/// [`crate::features::LineFree::noise_density`]; `None` where the record lacks one.
fn body_input_densities(rf: &RecordFeatures, s: &BodySpectra) -> Option<Vec<f64>> {
    let lf = rf.line_free.as_ref()?;
    s.unsprung
        .iter()
        .map(|name| {
            let i = rf.channels.iter().position(|c| &c.name == name)?;
            lf.noise_density.get(i).copied().filter(|d| d.is_finite())
        })
        .collect()
}

/// The body response features of a record against the nominal body response `body`: per
/// sprung channel and band of `body_response_bands_hz`, `ln(sum_band S_yy / sum_band
/// diag(H S_uu H^H))`, minus the mean of the same over the sprung channels of the other axle
/// (none if the record has no body spectra, or no sprung channel with a corner on each axle).
/// With `input_noise_free` ([`ModelSet::input_noise_free`]) the wheels' sensor noise is taken
/// out of `S_uu` first ([`BodySpectra::without_input_noise`]; it raised the predicted response
/// by `sum_j |H_ij|^2 N_j`, more as the road gets smoother), and a band in which a wheel's
/// motion is more than [`NOISE_SHARE_MAX`] noise gives none.
///
/// Relative to the other axle because a change of load moves every corner alike: 15 % more
/// sprung mass with the air springs' rate following it lowers the response in 2-4 Hz by 15-19 %
/// on every corner (the dampers' share falls), while 20 % softer rear springs lower it by 21 %
/// at the rear and 2 % at the front (docs/fleet.md).
fn body_features(
    rf: &RecordFeatures,
    body: &BodyModel,
    cfg: &FleetConfig,
    input_noise_free: bool,
) -> Vec<(FeatureMeta, f64)> {
    let Some(raw) = &rf.body_spectra else {
        return Vec::new();
    };
    let densities = if input_noise_free {
        match body_input_densities(rf, raw) {
            Some(d) => Some(d),
            None => return Vec::new(),
        }
    } else {
        None
    };
    let corrected = match &densities {
        Some(d) => match raw.without_input_noise(d) {
            Some(c) => Some(c),
            None => return Vec::new(),
        },
        None => None,
    };
    let s = corrected.as_ref().unwrap_or(raw);
    let corner_of = |name: &str| {
        rf.channels
            .iter()
            .find(|c| c.name == name)
            .and_then(|c| c.corner)
    };
    let mut out = Vec::new();
    for band in &cfg.body_response_bands_hz {
        // A band where a wheel's motion is mostly its sensor's noise is not judged (as the
        // transmissibility's): what is left after the noise is taken out is too uncertain.
        if let Some(d) = &densities {
            if raw
                .input_noise_share(d, *band)
                .map_or(true, |share| share > NOISE_SHARE_MAX)
            {
                continue;
            }
        }
        let Some(values) = body_response(body, s, *band) else {
            return Vec::new();
        };
        // (channel, corner, value, front axle?)
        let per: Vec<(&String, Corner, f64, bool)> = body
            .sprung
            .iter()
            .zip(values)
            .filter_map(|(name, v)| {
                let corner = corner_of(name)?;
                Some((name, corner, v?, matches!(corner, Corner::FL | Corner::FR)))
            })
            .collect();
        let axle_mean = |front: bool| {
            let v: Vec<f64> = per.iter().filter(|p| p.3 == front).map(|p| p.2).collect();
            (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
        };
        let (Some(front), Some(rear)) = (axle_mean(true), axle_mean(false)) else {
            continue;
        };
        for (name, corner, v, is_front) in per {
            let (other, other_name) = if is_front {
                (rear, "rear")
            } else {
                (front, "front")
            };
            out.push((
                FeatureMeta {
                    key: format!("body:{name}:{}", band_key(band)),
                    group: Group::Vehicle,
                    kind: Kind::BodyResponse,
                    corner: Some(corner),
                    channel: name.clone(),
                    label: format!(
                        "body response to wheel motion {} vs the {other_name} axle",
                        band_label(band)
                    ),
                },
                v - other,
            ));
        }
    }
    out
}

/// Transmissibility per corner and band (bands starting at or above
/// `transmissibility_min_hz`): ln(sprung / unsprung band RMS) minus its mean over the other
/// corners that have the band, so that what moves every corner alike (the load, whose extra
/// mass lowers every corner's damping per mass; the speed; the road's spectrum) cancels and a
/// corner's own damper, spring or tyre stays. With a single corner the absolute value is kept
/// (a vehicle with one corner pair; a record of more corners with one value left in the band
/// gives none there).
///
/// With `line_free`, the values with the periodic lines left out ([`RecordFeatures::line_free`],
/// key `transh1lf`); a record without them gives none. With `vehicle_lines` (a model set's
/// [`ModelSet::vehicle_line_bins_hz`]), the values from the record's per-bin parts with its own
/// lines' bins and those left out ([`crate::features::TransmissibilityBins::band_value`], key
/// `transh1lu`); a record without the per-bin parts gives none. With `vehicle_lines`' flag
/// true, those values with the unsprung channel's noise taken out of the input power
/// ([`crate::features::TransmissibilityBins::band_value_noise_free`]); a record without the
/// noise density, or whose band is more than [`NOISE_SHARE_MAX`] noise, gives none.
fn transmissibility_features(
    rf: &RecordFeatures,
    cfg: &FleetConfig,
    line_free: bool,
    vehicle_lines: Option<(&[f64], bool)>,
) -> Vec<(FeatureMeta, f64)> {
    let mut out = Vec::new();
    for (k, b) in rf.bands_hz.iter().enumerate() {
        if b[0] < cfg.transmissibility_min_hz {
            continue;
        }
        let logs: Vec<(&crate::features::CornerTransmissibility, &str, f64)> = rf
            .transmissibility
            .iter()
            .enumerate()
            .filter_map(|(i, t)| {
                if let Some((vehicle, input_noise_free)) = vehicle_lines {
                    let lf = rf.line_free.as_ref()?;
                    let bins = lf.bins.as_ref()?;
                    let left_out = [lf.line_bins_hz.as_slice(), vehicle];
                    let v = if input_noise_free {
                        let density = unsprung_noise_density(rf, lf, t)?;
                        bins.band_value_noise_free(i, *b, &left_out, density, NOISE_SHARE_MAX)?
                    } else {
                        bins.band_value(i, *b, &left_out)?
                    };
                    return (v > 0.0).then(|| (t, "transh1lu", v.ln()));
                }
                if line_free {
                    let lf = rf.line_free.as_ref()?.h1.get(i)?;
                    let v = lf.get(k).copied().flatten()?;
                    return (v.is_finite() && v > 0.0).then(|| (t, "transh1lf", v.ln()));
                }
                // The cross-spectral (H1) value where the record has it, under its own key: a
                // model set of band-RMS ratios does not score it, nor the reverse.
                let (v, key) = if t.h1.is_empty() {
                    (&t.values, "transrel")
                } else {
                    (&t.h1, "transh1")
                };
                let v = v.get(k).copied().flatten()?;
                (v.is_finite() && v > 0.0).then(|| (t, key, v.ln()))
            })
            .collect();
        // A record whose other corners give no value in this band (their input below the
        // noise share) gives no relative value: the one corner's own would be scored against
        // the nominal records' relative ones.
        if logs.len() == 1 && rf.transmissibility.len() > 1 {
            continue;
        }
        let total: f64 = logs.iter().map(|(_, _, v)| v).sum();
        for (t, key, v) in &logs {
            let (value, against) = if logs.len() > 1 {
                let others = (total - v) / (logs.len() - 1) as f64;
                (v - others, " vs the other corners")
            } else {
                (*v, "")
            };
            out.push((
                FeatureMeta {
                    key: format!("{key}:{}:{}", t.corner, band_key(b)),
                    group: Group::Vehicle,
                    kind: Kind::Transmissibility,
                    corner: Some(t.corner),
                    channel: t.sprung.clone(),
                    label: format!("transmissibility {}{against}", band_label(b)),
                },
                value,
            ));
        }
    }
    out
}

/// The noise density of the unsprung channel of transmissibility entry `t`
/// ([`crate::features::LineFree::noise_density`]); `None` where the record has none.
fn unsprung_noise_density(
    rf: &RecordFeatures,
    lf: &crate::features::LineFree,
    t: &crate::features::CornerTransmissibility,
) -> Option<f64> {
    let i = rf.channels.iter().position(|c| c.name == t.unsprung)?;
    lf.noise_density.get(i).copied().filter(|d| d.is_finite())
}

/// The variance of `ln |H|` of a band's H1 estimate (`sqrt(sum |S_us|^2 / S_uu / sum S_uu)`,
/// [`crate::features::h1_band_values`]) at coherence `gamma2` (the bias taken out), from
/// `segments` Welch segments (Hann, half overlap: `K = segments / HANN_HALF_OVERLAP_VARIANCE`
/// independent averages per bin) over `cells` ([`welch_band_cells`]). With `q = (1 - gamma^2) /
/// gamma^2`, the incoherent output power over the coherent: the estimate's power ratio is
/// `|H|^2 (1 + q / K)` on average (the incoherent part leaks in as `1 / K` of itself) and
/// scatters by `|H|^4 (2 q + q^2 / K) / cells` (the cross term of the wheel's motion with the
/// incoherent part, and that part's own scatter), so `var ln |H| = (2 q + q^2 / K) / (4 cells
/// (1 + q / K)^2)`, written in `gamma^2` so that it holds down to 0 (`K / (4 cells)`). For
/// many averages it is Bendat and Piersol's `(1 - gamma^2) / (2 gamma^2 cells)` (Random Data,
/// the random error of a frequency response's magnitude); with the fleet's 3 segments per
/// 10.24 s record the second term and the leak matter: over 600 seeds of one record at 50 Hz
/// the scatter is this within 5 % at coherences 0.2 and 0.8, where Bendat and Piersol's
/// formula is 3.6 times too large at 0.2 (numpy and scipy's welch and csd, 1000 seeds: 0.0047
/// and 0.00081, this formula 0.0044 and 0.00082).
pub fn h1_log_variance(gamma2: f64, segments: usize, cells: f64) -> Option<f64> {
    if !(gamma2.is_finite() && cells.is_finite() && cells > 0.0 && segments > 0) {
        return None;
    }
    let g = gamma2.clamp(0.0, 1.0);
    let k = segments as f64 / HANN_HALF_OVERLAP_VARIANCE;
    let num = 2.0 * (1.0 - g) * g + (1.0 - g) * (1.0 - g) / k;
    let den = g + (1.0 - g) / k;
    Some(num / (4.0 * cells * den * den))
}

/// The estimate variances of a record's features read with `variants` ([`EstimateVariances`]):
/// its level ratios' ([`ratio_noise_variances`]) and, with `input_noise_free`, its
/// transmissibility's ([`transmissibility_variances`]); `values` are the record's features as
/// [`scalar_features`] gave them with the same variants.
pub fn estimate_variances(
    rf: &RecordFeatures,
    cfg: &FleetConfig,
    variants: Variants<'_>,
    values: &[(FeatureMeta, f64)],
) -> EstimateVariances {
    let mut v = ratio_noise_variances(rf, cfg, variants.line_free, variants.noise_free);
    if let (true, Some(lines)) = (variants.input_noise_free, variants.vehicle_lines) {
        v.extend(transmissibility_variances(rf, cfg, lines, values));
    }
    v
}

/// The estimate variances of a record's transmissibility features as
/// [`transmissibility_features`] computes them with the vehicle's lines left out and the input
/// noise taken out (key `transh1lu`): a corner's value is its `ln |H|` less the mean over the
/// other corners with the band, so its variance is its own [`h1_log_variance`] plus the
/// others' over `(k - 1)^2`. Corners without a coherence give the feature none. `values` are
/// the record's features ([`scalar_features`] with `input_noise_free` and `vehicle_lines`): the
/// corners they hold a value of in a band are the `k`.
pub fn transmissibility_variances(
    rf: &RecordFeatures,
    cfg: &FleetConfig,
    vehicle_lines: &[f64],
    values: &[(FeatureMeta, f64)],
) -> EstimateVariances {
    let mut out = EstimateVariances::new();
    let Some(lf) = rf.line_free.as_ref() else {
        return out;
    };
    let Some(bins) = lf.bins.as_ref().filter(|b| b.segments > 0) else {
        return out;
    };
    let left_out = [lf.line_bins_hz.as_slice(), vehicle_lines];
    for b in rf
        .bands_hz
        .iter()
        .filter(|b| b[0] >= cfg.transmissibility_min_hz)
    {
        let cells = welch_band_cells(bins.band_bins(*b, &left_out), bins.segments);
        // Per corner with a value in this band, its variance (None: no coherence).
        let per: Vec<(Corner, Option<f64>)> = rf
            .transmissibility
            .iter()
            .enumerate()
            .filter(|(_, t)| {
                let key = format!("transh1lu:{}:{}", t.corner, band_key(b));
                values.iter().any(|(m, _)| m.key == key)
            })
            .map(|(i, t)| {
                let v = bins
                    .band_coherence(i, *b, &left_out)
                    .and_then(|g| corrected_coherence(g, bins.segments))
                    .and_then(|g| h1_log_variance(g, bins.segments, cells));
                (t.corner, v)
            })
            .collect();
        let k = per.len();
        if k < 2 {
            continue;
        }
        for (corner, v) in &per {
            let others: Option<f64> = per
                .iter()
                .filter(|(c, _)| c != corner)
                .map(|(_, w)| *w)
                .sum();
            if let (Some(v), Some(o)) = (v, others) {
                out.insert(
                    format!("transh1lu:{corner}:{}", band_key(b)),
                    v + o / ((k - 1) * (k - 1)) as f64,
                );
            }
        }
    }
    out
}

/// Per feature key, why a record gives no value of it although it has the spectra: its wheels'
/// motion in the band is more than [`NOISE_SHARE_MAX`] sensor noise (transmissibility and body
/// response, with `variants.input_noise_free`), or, for a transmissibility, the other corners'
/// are, so that no relative value is left. Keys are those of [`scalar_features`] (body keys
/// for the sprung channels of `body`).
pub fn noise_unjudged(
    rf: &RecordFeatures,
    cfg: &FleetConfig,
    variants: Variants<'_>,
    body: Option<&BodyModel>,
) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    if !variants.input_noise_free {
        return out;
    }
    let pct = |share: f64| format!("{:.0} %", 100.0 * share);
    if let (Some(lf), Some(vehicle)) = (rf.line_free.as_ref(), variants.vehicle_lines) {
        if let Some(bins) = lf.bins.as_ref() {
            let left_out = [lf.line_bins_hz.as_slice(), vehicle];
            for b in rf
                .bands_hz
                .iter()
                .filter(|b| b[0] >= cfg.transmissibility_min_hz)
            {
                // (corner, the noise share of its wheel's input in the band)
                let shares: Vec<(Corner, Option<f64>)> = rf
                    .transmissibility
                    .iter()
                    .enumerate()
                    .map(|(i, t)| {
                        let share = unsprung_noise_density(rf, lf, t)
                            .and_then(|density| bins.band_noise_share(i, *b, &left_out, density));
                        (t.corner, share)
                    })
                    .collect();
                let quiet = |s: &Option<f64>| s.is_some_and(|s| s > NOISE_SHARE_MAX);
                let kept = shares
                    .iter()
                    .filter(|(_, s)| s.is_some() && !quiet(s))
                    .count();
                for (corner, share) in &shares {
                    let key = format!("transh1lu:{corner}:{}", band_key(b));
                    if let Some(s) = share.filter(|s| *s > NOISE_SHARE_MAX) {
                        out.insert(
                            key,
                            format!(
                                "its wheel's motion in {} is {} sensor noise",
                                band_label(b),
                                pct(s)
                            ),
                        );
                    } else if share.is_some() && kept == 1 && shares.len() > 1 {
                        out.insert(
                            key,
                            format!(
                                "the other corners' wheels' motion in {} is more than half sensor noise: nothing to compare with",
                                band_label(b)
                            ),
                        );
                    }
                }
            }
        }
    }
    if let (Some(model), Some(raw)) = (body, rf.body_spectra.as_ref()) {
        if let Some(d) = body_input_densities(rf, raw) {
            for band in &cfg.body_response_bands_hz {
                if let Some(s) = raw
                    .input_noise_share(&d, *band)
                    .filter(|s| *s > NOISE_SHARE_MAX)
                {
                    for name in &model.sprung {
                        out.insert(
                            format!("body:{name}:{}", band_key(band)),
                            format!(
                                "a wheel's motion in {} is {} sensor noise",
                                band_label(band),
                                pct(s)
                            ),
                        );
                    }
                }
            }
        }
    }
    out
}

/// How a model set reads a record's features ([`ModelSet::variants`]): the variants its
/// nominal records were read with, so that every record it scores is read alike.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Variants<'a> {
    /// [`ModelSet::line_free`]: the transmissibility with the periodic lines left out and the
    /// level ratios with the unsprung lines replaced by their continuum, under their own keys.
    pub line_free: bool,
    /// [`ModelSet::noise_free`] (with `line_free`): each unsprung channel's noise power in the
    /// band taken out of its band power before the level ratios ([`noise_free_level`]).
    pub noise_free: bool,
    /// [`ModelSet::input_noise_free`] (with `vehicle_lines`): the transmissibility with the
    /// unsprung channel's noise taken out of its input power.
    pub input_noise_free: bool,
    /// [`ModelSet::vehicle_line_bins_hz`]: the vehicle's own lines, left out of every record's
    /// transmissibility.
    pub vehicle_lines: Option<&'a [f64]>,
}

/// Scalar features of a record, as ln(value), given the model set's modes and nominal body
/// response, read as `variants` says.
pub fn scalar_features(
    rf: &RecordFeatures,
    slots: &[ModeSlot],
    body: Option<&BodyModel>,
    cfg: &FleetConfig,
    variants: Variants<'_>,
) -> Vec<(FeatureMeta, f64)> {
    let Variants {
        line_free,
        noise_free,
        input_noise_free,
        vehicle_lines,
    } = variants;
    let mut out = body.map_or_else(Vec::new, |b| body_features(rf, b, cfg, input_noise_free));
    // Road level per band: the mean of ln(band RMS) over the unsprung channels that have it.
    for (k, b) in rf.bands_hz.iter().enumerate() {
        let logs: Vec<f64> = rf
            .channels
            .iter()
            .filter(|c| c.role == Role::Unsprung)
            .filter_map(|c| c.band_rms.get(k).copied().flatten())
            .map(f64::ln)
            .collect();
        if !logs.is_empty() {
            out.push((
                FeatureMeta {
                    key: format!("level:unsprung:{}", band_key(b)),
                    group: Group::Excitation,
                    kind: Kind::Level,
                    corner: None,
                    channel: "unsprung".into(),
                    label: format!("road level {}", band_label(b)),
                },
                logs.iter().sum::<f64>() / logs.len() as f64,
            ));
        }
    }
    out.extend(transmissibility_features(
        rf,
        cfg,
        line_free,
        vehicle_lines.map(|l| (l, input_noise_free)),
    ));
    // Unsprung level ratios at and above wheel hop: left over right wheel of each axle, front
    // over rear wheel of each side. Both wheels of a pair roll on the same road class at the same
    // speed (on one side, on the same track), so the road level and its spectrum cancel.
    let unsprung = |corner: Corner| {
        let i = rf
            .channels
            .iter()
            .position(|c| c.role == Role::Unsprung && c.corner == Some(corner))?;
        let c = &rf.channels[i];
        let level = if line_free {
            let lf = rf.line_free.as_ref()?;
            let level = lf.ratio_band_rms.get(i).copied().flatten()?;
            if noise_free {
                let density = lf.noise_density.get(i).copied().unwrap_or(0.0);
                let [lo, hi] = cfg.ratio_band_hz;
                noise_free_level(level, density * (hi - lo))
            } else {
                Some(level)
            }
        } else {
            c.ratio_band_rms
        };
        Some((c, level.and_then(finite_positive)?))
    };
    let band = cfg.ratio_band_hz;
    for (kind, pairs) in [(Kind::SideRatio, AXLES), (Kind::TrackRatio, TRACKS)] {
        for (name, a, b) in pairs {
            let (Some((ca, la)), Some((cb, lb))) = (unsprung(a), unsprung(b)) else {
                continue;
            };
            out.push((
                FeatureMeta {
                    key: ratio_key(kind, name, &band, line_free),
                    group: Group::Vehicle,
                    kind,
                    corner: None,
                    channel: format!("{}/{}", ca.name, cb.name),
                    label: format!("{a}/{b} level {}", band_label(&band)),
                },
                (la / lb).ln(),
            ));
        }
    }
    // Each record mode goes to its nearest slot of the channel (in ln f) among the slots of its
    // damping class (within MODE_DAMPING_CLASS_RATIO of the slot's damping) if within the match
    // tolerance; each slot takes its nearest mode.
    let mut best: BTreeMap<usize, (f64, f64, f64)> = BTreeMap::new();
    for ch in &rf.channels {
        let ch_slots: Vec<(usize, &ModeSlot)> = slots
            .iter()
            .enumerate()
            .filter(|(_, s)| s.channel == ch.name)
            .collect();
        for m in &ch.modes {
            if !(m.frequency_hz > 0.0 && m.damping_ratio > 0.0) {
                continue;
            }
            let lf = m.frequency_hz.ln();
            let nearest = ch_slots
                .iter()
                .filter(|(_, s)| {
                    s.damping_ratio.map_or(true, |z| {
                        (m.damping_ratio.ln() - z.ln()).abs() <= MODE_DAMPING_CLASS_RATIO.ln()
                    })
                })
                .map(|(i, s)| (*i, (lf - s.frequency_hz.ln()).abs()))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((i, d)) = nearest {
                let better = match best.get(&i) {
                    Some((bd, _, _)) => d < *bd,
                    None => true,
                };
                if d <= (1.0 + cfg.mode_match_tol).ln() && better {
                    best.insert(i, (d, m.frequency_hz, m.damping_ratio));
                }
            }
        }
    }
    for (i, (_, f, z)) in best {
        let s = &slots[i];
        let meta = |kind: Kind, what: &str| FeatureMeta {
            key: format!("mode:{}:{}:{}", s.channel, i, what),
            group: Group::Vehicle,
            kind,
            corner: s.corner,
            channel: s.channel.clone(),
            label: format!("{} {:.1} Hz {}", s.name, s.frequency_hz, what),
        };
        out.push((meta(Kind::ModeFrequency, "frequency"), f.ln()));
        out.push((meta(Kind::ModeDamping, "damping"), z.ln()));
    }
    out
}

fn finite_positive(x: f64) -> Option<f64> {
    (x.is_finite() && x > 0.0).then_some(x)
}

/// A channel's role, corner and (record, frequency, damping ratio) of its modes.
type ChannelModes = (Role, Option<Corner>, Vec<(usize, f64, f64)>);

fn mode_name(role: Role, f: f64) -> &'static str {
    if role == Role::Unsprung && f >= 5.0 {
        "wheel-hop"
    } else if f < 3.0 {
        "body"
    } else {
        "mode"
    }
}

/// The modes of the model set: per channel, groups of modes whose neighbours lie within
/// `mode_group_tol` of each other in frequency and within [`MODE_DAMPING_CLASS_RATIO`] in
/// damping (a group is split where its sorted damping ratios jump by more than that factor:
/// two physical modes near one frequency), present in at least `mode_min_share` of the records.
pub fn mode_slots(records: &[RecordFeatures], cfg: &FleetConfig) -> Vec<ModeSlot> {
    let mut by_channel: BTreeMap<String, ChannelModes> = BTreeMap::new();
    for (r, rf) in records.iter().enumerate() {
        for ch in &rf.channels {
            let e = by_channel
                .entry(ch.name.clone())
                .or_insert((ch.role, ch.corner, Vec::new()));
            for m in &ch.modes {
                if m.frequency_hz > 0.0 && m.frequency_hz.is_finite() && m.damping_ratio > 0.0 {
                    e.2.push((r, m.frequency_hz, m.damping_ratio));
                }
            }
        }
    }
    let n = records.len().max(1) as f64;
    let mut slots = Vec::new();
    for (name, (role, corner, mut modes)) in by_channel {
        modes.sort_by(|a, b| a.1.total_cmp(&b.1));
        let mut groups: Vec<Vec<(usize, f64, f64)>> = Vec::new();
        for m in modes {
            match groups.last_mut() {
                Some(g)
                    if g.last()
                        .is_some_and(|l| m.1 / l.1 - 1.0 <= cfg.mode_group_tol) =>
                {
                    g.push(m)
                }
                _ => groups.push(vec![m]),
            }
        }
        let groups = groups.into_iter().flat_map(split_by_damping);
        for g in groups {
            let mut recs: Vec<usize> = g.iter().map(|m| m.0).collect();
            recs.sort_unstable();
            recs.dedup();
            let share = recs.len() as f64 / n;
            if share + 1e-12 < cfg.mode_min_share {
                continue;
            }
            let freqs: Vec<f64> = g.iter().map(|m| m.1).collect();
            let Some(f) = median(&freqs) else { continue };
            let dampings: Vec<f64> = g.iter().map(|m| m.2).collect();
            slots.push(ModeSlot {
                channel: name.clone(),
                role,
                corner,
                frequency_hz: f,
                name: mode_name(role, f).to_string(),
                share,
                damping_ratio: median(&dampings),
            });
        }
    }
    slots
}

/// Splits a frequency group of (record, frequency, damping) where its damping ratios, sorted,
/// jump by more than [`MODE_DAMPING_CLASS_RATIO`].
fn split_by_damping(mut g: Vec<(usize, f64, f64)>) -> Vec<Vec<(usize, f64, f64)>> {
    g.sort_by(|a, b| a.2.total_cmp(&b.2));
    let mut out: Vec<Vec<(usize, f64, f64)>> = Vec::new();
    for m in g {
        match out.last_mut() {
            Some(cur)
                if cur
                    .last()
                    .is_some_and(|l| m.2 <= l.2 * MODE_DAMPING_CLASS_RATIO) =>
            {
                cur.push(m)
            }
            _ => out.push(vec![m]),
        }
    }
    out
}

fn floor_of(kind: Kind, cfg: &FleetConfig) -> f64 {
    match kind {
        Kind::Level => cfg.floor_level,
        Kind::Transmissibility => cfg.floor_transmissibility,
        Kind::ModeFrequency => cfg.floor_frequency,
        Kind::ModeDamping => cfg.floor_damping,
        Kind::SideRatio => cfg.floor_side_ratio,
        Kind::TrackRatio => cfg.floor_track_ratio,
        Kind::BodyResponse => cfg.floor_body_response,
        // Scored from the fits' own standard deviations, never from a spread.
        Kind::SpringFit | Kind::DamperFit => 0.0,
    }
}

/// Kinds whose features are one estimator applied alike to every corner or axle, with one
/// noise level: their spread is pooled over the features of the kind (the deviations of every
/// feature from its own median), which a handful of nominal records alone would estimate badly.
fn pooled(kind: Kind) -> bool {
    matches!(
        kind,
        Kind::SideRatio | Kind::TrackRatio | Kind::BodyResponse
    )
}

/// The nominal body response from the records' body spectra, and each record's body features
/// against the response fitted on the other records (leave-one-out: a record's own spectra
/// pull `H` towards it, so its in-sample residual would understate the scatter of a new
/// record's). `None` (with a note) when not every record has body spectra or the fit fails.
type BodyFit = (BodyModel, Vec<Vec<(FeatureMeta, f64)>>);

fn fit_body(
    records: &[RecordFeatures],
    cfg: &FleetConfig,
    input_noise_free: bool,
    notes: &mut Vec<String>,
) -> Option<BodyFit> {
    if cfg.body_response_bands_hz.is_empty() {
        return None;
    }
    // `H` is fitted from the spectra as measured, not with the wheels' noise taken out:
    // `S_yu (S_uu - N)^-1` from one drive's records was unstable where `S_uu - N` is nearly
    // singular (busgen buses 21074 and 59930: a held-out baseline drive flagged at +659 % and
    // +735 %). The noise is taken out of each record's prediction ([`body_features`]).
    let spectra: Vec<&BodySpectra> = records
        .iter()
        .filter_map(|r| r.body_spectra.as_ref())
        .collect();
    if spectra.len() < records.len() {
        notes.push(format!(
            "no body response to wheel motion: {} of {} nominal records have body spectra (records stored before them, or without sprung and unsprung channels)",
            spectra.len(),
            records.len()
        ));
        return None;
    }
    let model = match fit_body_model(&spectra) {
        Ok(m) => m,
        Err(e) => {
            notes.push(format!("no {e}"));
            return None;
        }
    };
    let loo = records
        .iter()
        .enumerate()
        .map(|(i, record)| {
            let others: Vec<&BodySpectra> = spectra
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, s)| *s)
                .collect();
            // A record whose others are singular is left out of the statistics.
            fit_body_model(&others).map_or_else(
                |_| Vec::new(),
                |m| body_features(record, &m, cfg, input_noise_free),
            )
        })
        .collect();
    Some((model, loo))
}

/// Statistics of every feature present in at least `max(3, mode_min_share * n)` records;
/// `noise` holds each record's [`EstimateVariances`] (same order as `values`; may be shorter).
fn feature_stats(
    values: &[Vec<(FeatureMeta, f64)>],
    noise: &[EstimateVariances],
    cfg: &FleetConfig,
) -> Vec<FeatureStat> {
    let mut by_key: BTreeMap<String, (FeatureMeta, Vec<f64>)> = BTreeMap::new();
    // Per key, the noise variances of the records that have the feature (None: one lacks it).
    let mut var_of: BTreeMap<String, Option<Vec<f64>>> = BTreeMap::new();
    for (i, rec) in values.iter().enumerate() {
        for (meta, v) in rec {
            by_key
                .entry(meta.key.clone())
                .or_insert_with(|| (meta.clone(), Vec::new()))
                .1
                .push(*v);
            let nv = noise.get(i).and_then(|n| n.get(&meta.key)).copied();
            let e = var_of
                .entry(meta.key.clone())
                .or_insert_with(|| Some(Vec::new()));
            match (e.as_mut(), nv) {
                (Some(list), Some(x)) => list.push(x),
                _ => *e = None,
            }
        }
    }
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    // Pooled kinds: every record variance of the kind's features, or none if one lacks it.
    let mut pooled_var: BTreeMap<Kind, Option<Vec<f64>>> = BTreeMap::new();
    let need = ((cfg.mode_min_share * values.len() as f64).ceil() as usize).max(3);
    let mut out = Vec::new();
    // Deviations from the feature's median, per pooled kind.
    let mut deviations: BTreeMap<Kind, Vec<f64>> = BTreeMap::new();
    for (_, (meta, v)) in by_key {
        if v.len() < need {
            continue;
        }
        let floor = floor_of(meta.kind, cfg);
        let (Some(centre), Some(sigma)) = (median(&v), robust_sigma(&v, floor)) else {
            continue;
        };
        let own_var = var_of.get(&meta.key).cloned().flatten();
        if pooled(meta.kind) {
            deviations
                .entry(meta.kind)
                .or_default()
                .extend(v.iter().filter(|x| x.is_finite()).map(|x| x - centre));
            let e = pooled_var
                .entry(meta.kind)
                .or_insert_with(|| Some(Vec::new()));
            match (e.as_mut(), &own_var) {
                (Some(all), Some(list)) => all.extend_from_slice(list),
                _ => *e = None,
            }
        }
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        out.push(FeatureStat {
            meta,
            centre,
            sigma,
            lo,
            hi,
            n: v.len(),
            estimate_var: own_var.as_deref().and_then(mean),
        });
    }
    for f in out.iter_mut().filter(|f| pooled(f.meta.kind)) {
        if let Some(s) = deviations
            .get(&f.meta.kind)
            .and_then(|d| robust_sigma(d, floor_of(f.meta.kind, cfg)))
        {
            f.sigma = s;
        }
        f.estimate_var = pooled_var
            .get(&f.meta.kind)
            .cloned()
            .flatten()
            .as_deref()
            .and_then(mean);
    }
    out
}

/// Builds the model set of `vehicle` from its nominal records (`names` for the record list).
///
/// Errors: fewer than `cfg.min_nominal` records; no feature present in enough records.
pub fn build_model_set(
    vehicle: &str,
    names: &[String],
    records: &[RecordFeatures],
    cfg: &FleetConfig,
) -> Result<ModelSet> {
    cfg.validate()?;
    if records.len() < cfg.min_nominal {
        return Err(FleetError::TooFewNominal {
            vehicle: vehicle.to_string(),
            found: records.len(),
            needed: cfg.min_nominal,
        });
    }
    let slots = mode_slots(records, cfg);
    let line_free = records.iter().all(|r| r.line_free.is_some());
    let noise_free = line_free
        && records.iter().all(|r| {
            r.line_free
                .as_ref()
                .is_some_and(|l| !l.noise_density.is_empty())
        });
    let vehicle_lines = vehicle_line_bins(records);
    let input_noise_free = noise_free && vehicle_lines.is_some();
    let mut notes = Vec::new();
    let low = match vehicle_lines.as_deref() {
        Some(lines) if cfg.transmissibility_min_coherence > 0.0 => {
            low_coherence(records, lines, cfg)
        }
        _ => Vec::new(),
    };
    for (_, corner, band, coherence) in &low {
        notes.push(format!(
            "{corner}: transmissibility {} left out: its sprung channel's coherence with its wheel there is {:.2} over the nominal records (median, the estimate's bias taken out), below transmissibility_min_coherence {}",
            band_label(band),
            coherence,
            vibmode_core::Num(cfg.transmissibility_min_coherence)
        ));
    }
    let body = fit_body(records, cfg, input_noise_free, &mut notes);
    let variants = Variants {
        line_free,
        noise_free,
        input_noise_free,
        vehicle_lines: vehicle_lines.as_deref(),
    };
    // Each record's features and their estimate variances (from the features as read, before
    // the low-coherence ones are dropped: a corner's relative value counts every corner).
    let mut noise: Vec<EstimateVariances> = Vec::with_capacity(records.len());
    let values: Vec<Vec<(FeatureMeta, f64)>> = records
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let mut v = scalar_features(r, &slots, None, cfg, variants);
            noise.push(estimate_variances(r, cfg, variants, &v));
            v.retain(|(m, _)| !low.iter().any(|(key, ..)| *key == m.key));
            if let Some((_, loo)) = &body {
                v.extend(loo[i].iter().cloned());
            }
            v
        })
        .collect();
    let features = feature_stats(&values, &noise, cfg);
    if !features.iter().any(|f| f.meta.group == Group::Vehicle) {
        return Err(FleetError::NoVehicleFeature {
            vehicle: vehicle.to_string(),
        });
    }
    let count = |g: Group| features.iter().filter(|f| f.meta.group == g).count();
    // Leave-one-out: record i against the statistics of the others (same modes).
    let mut loo_max: BTreeMap<Kind, f64> = BTreeMap::new();
    for i in 0..values.len() {
        let others: Vec<Vec<(FeatureMeta, f64)>> = values
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, v)| v.clone())
            .collect();
        let others_noise: Vec<EstimateVariances> = noise
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, v)| v.clone())
            .collect();
        let stats = feature_stats(&others, &others_noise, cfg);
        let by_key: BTreeMap<&str, f64> = values[i]
            .iter()
            .map(|(m, v)| (m.key.as_str(), *v))
            .collect();
        for f in &stats {
            if let Some(&x) = by_key.get(f.meta.key.as_str()) {
                let z = score(f, x, noise[i].get(&f.meta.key).copied(), cfg).abs();
                let e = loo_max.entry(f.meta.kind).or_insert(0.0);
                *e = e.max(z);
            }
        }
    }
    let mut limits = Vec::new();
    for kind in KINDS {
        let n_features = features.iter().filter(|f| f.meta.kind == kind).count();
        if n_features == 0 {
            continue;
        }
        let group = group_of(kind);
        let bonferroni = bonferroni_limit(cfg.false_alarm_rate, count(group));
        let loo_max_abs_z = loo_max.get(&kind).copied().unwrap_or(0.0);
        // Never a NaN limit (stored as null, the model set unreadable, every check failing):
        // refused with the setting that gave it.
        if !(bonferroni.is_finite() && loo_max_abs_z.is_finite()) {
            return Err(FleetError::Config {
                key: "false_alarm_rate",
                value: vibmode_core::Num(cfg.false_alarm_rate).to_string(),
                fix: format!(
                    "gives a control limit of {} (leave-one-out {}) for {} features; use e.g. 0.01",
                    vibmode_core::Num(bonferroni),
                    vibmode_core::Num(loo_max_abs_z),
                    count(group)
                ),
            });
        }
        limits.push(KindLimit {
            kind,
            group,
            n_features,
            bonferroni,
            loo_max_abs_z,
            limit: bonferroni.max(LOO_MARGIN * loo_max_abs_z),
        });
    }
    Ok(ModelSet {
        schema: MODEL_SET_SCHEMA,
        vehicle: vehicle.to_string(),
        version: 0,
        records: names.to_vec(),
        config: cfg.clone(),
        slots,
        features,
        limits,
        channels: records
            .first()
            .map(|r| r.channels.iter().map(|c| c.name.clone()).collect())
            .unwrap_or_default(),
        body: body.map(|b| b.0),
        notes,
        line_free,
        noise_free,
        input_noise_free,
        suspension: None,
        held_out_drives: Vec::new(),
        vehicle_line_bins_hz: vehicle_lines,
    })
}

/// Welch's variance ratio of averaged Hann-windowed segments overlapping by half (Welch 1967:
/// `1 + 2 rho^2`, `rho` = 1/6 the window's correlation at half a segment): `n` segments average
/// like `n / HANN_HALF_OVERLAP_VARIANCE` independent ones.
pub const HANN_HALF_OVERLAP_VARIANCE: f64 = 1.0 + 2.0 / 36.0;

/// A band's coherence as estimated from `segments` Welch segments (Hann, half overlap), with
/// the finite-average bias taken out: `E[g] = gamma^2 + (1 - gamma^2) / n` for `n` independent
/// averages, so `gamma^2 = (n g - 1) / (n - 1)` (may be below 0 where the estimate is at its
/// floor). `None` with fewer than 2 averages.
pub fn corrected_coherence(estimated: f64, segments: usize) -> Option<f64> {
    let n = segments as f64 / HANN_HALF_OVERLAP_VARIANCE;
    (n > 1.0 && estimated.is_finite()).then(|| (n * estimated - 1.0) / (n - 1.0))
}

/// The transmissibility features (key, corner, band, median corrected coherence) whose sprung
/// channel's coherence with its wheel over `records` is below
/// [`FleetConfig::transmissibility_min_coherence`], with `lines` (the vehicle's) and each
/// record's own lines left out; a feature whose coherence no record gives is kept.
fn low_coherence(
    records: &[RecordFeatures],
    lines: &[f64],
    cfg: &FleetConfig,
) -> Vec<(String, Corner, [f64; 2], f64)> {
    let mut per: BTreeMap<String, (Corner, [f64; 2], Vec<f64>)> = BTreeMap::new();
    for r in records {
        let Some(lf) = r.line_free.as_ref() else {
            continue;
        };
        let Some(bins) = lf.bins.as_ref() else {
            continue;
        };
        for (i, t) in r.transmissibility.iter().enumerate() {
            for b in r
                .bands_hz
                .iter()
                .filter(|b| b[0] >= cfg.transmissibility_min_hz)
            {
                let g = bins
                    .band_coherence(i, *b, &[lf.line_bins_hz.as_slice(), lines])
                    .and_then(|g| corrected_coherence(g, bins.segments));
                if let Some(g) = g {
                    per.entry(format!("transh1lu:{}:{}", t.corner, band_key(b)))
                        .or_insert_with(|| (t.corner, *b, Vec::new()))
                        .2
                        .push(g);
                }
            }
        }
    }
    per.into_iter()
        .filter_map(|(key, (corner, band, g))| {
            let m = median(&g)?;
            (m < cfg.transmissibility_min_coherence).then_some((key, corner, band, m))
        })
        .collect()
}

/// A periodic line's bins found in at least this many nominal records are the vehicle's
/// ([`ModelSet::vehicle_line_bins_hz`]): more than one, so that a false line of one record's
/// analysis (1 % per pool and analysis, docs/analysis.md) does not enter.
pub const VEHICLE_LINE_MIN_RECORDS: usize = 2;

/// The bins (Hz) left out of the line-free transmissibility of at least
/// [`VEHICLE_LINE_MIN_RECORDS`] of `records`, ascending; `None` unless every record keeps the
/// transmissibility per bin ([`crate::features::LineFree::bins`]).
fn vehicle_line_bins(records: &[RecordFeatures]) -> Option<Vec<f64>> {
    let mut seen: Vec<(f64, usize)> = Vec::new();
    for r in records {
        let lf = r.line_free.as_ref().filter(|l| l.bins.is_some())?;
        for &f in &lf.line_bins_hz {
            match seen
                .iter_mut()
                .find(|(x, _)| (*x - f).abs() <= 1e-9 * f.abs().max(1.0))
            {
                Some((_, n)) => *n += 1,
                None => seen.push((f, 1)),
            }
        }
    }
    let mut out: Vec<f64> = seen
        .into_iter()
        .filter(|(_, n)| *n >= VEHICLE_LINE_MIN_RECORDS)
        .map(|(f, _)| f)
        .collect();
    out.sort_by(f64::total_cmp);
    Some(out)
}

fn group_of(kind: Kind) -> Group {
    match kind {
        Kind::Level => Group::Excitation,
        _ => Group::Vehicle,
    }
}

/// The score of ln-value `x` against `f`: the robust z for vehicle features (against
/// [`FeatureStat::spread`] of the value's own estimate variance `var`); for excitation
/// features the distance above the nominal range's top `hi` plus `road_margin`, in units of
/// `floor_level` (0 below it: a smoother road, or one up to a road class rougher, is normal).
fn score(f: &FeatureStat, x: f64, var: Option<f64>, cfg: &FleetConfig) -> f64 {
    match f.meta.group {
        Group::Vehicle => (x - f.centre) / f.spread(var),
        Group::Excitation => (x - f.hi - cfg.road_margin).max(0.0) / cfg.floor_level,
    }
}

/// Scores a record against the model set.
///
/// A record with a failed sensor is classed [`Classification::Sensor`] whatever its scores
/// (which cover its working channels only); the summary names the channels first.
pub fn assess(set: &ModelSet, rf: &RecordFeatures) -> Assessment {
    let values = set.record_features(rf);
    let noise = set.record_variances(rf, &values);
    let unjudged = set.record_unjudged(rf);
    let mut a = score_values(set, &values, &noise, &unjudged, &[], None);
    if !rf.sensor_faults.is_empty() {
        a.classification = Classification::Sensor;
        let faults: Vec<String> = rf.sensor_faults.iter().map(|f| f.to_string()).collect();
        let mut summary = format!("sensor: {}", faults.join(", "));
        if !a.summary.is_empty() {
            summary.push_str("; ");
            summary.push_str(&a.summary);
        }
        a.summary = summary;
        a.sensor_faults = rf.sensor_faults.clone();
    }
    a
}

/// Fewest records a drive's statistic is computed from.
pub const MIN_DRIVE_RECORDS: usize = 3;

/// Scores a drive (records of one vehicle on one day) against the model set.
///
/// The drive's value of a feature is the median of its ln values over the drive's records that
/// have it (at least half of the records with working sensors must have it, else it is
/// `missing`); that value is scored and flagged as one record's would be, with the same
/// limits. A feature flagged for the drive is thus beyond the limit, in the same direction, in
/// at least half of its records: a scatter that moves one record in eight (a mode identified
/// as another in one record, a gust of road) does not flag the drive, while a fault, which
/// moves every record, does. The false-alarm rate per drive is at most the one per record
/// (`false_alarm_rate`, reached when the records of a drive are fully correlated; far lower
/// when they are independent).
///
/// Records with a failed sensor are left out of the medians (the summary says how many); with
/// fewer than [`MIN_DRIVE_RECORDS`] records left the drive is classed
/// [`Classification::Sensor`].
pub fn assess_drive(set: &ModelSet, records: &[&RecordFeatures]) -> Assessment {
    assess_drive_fitted(set, records, &[], None)
}

/// As [`assess_drive`], with the drive's suspension scores against the model set's fitted
/// suspension ([`crate::suspension::corner_scores`]) and its springs pooled over the vehicle's
/// last drives (`trend`, [`crate::suspension::spring_trend`], where made): a drive's score below
/// minus the model set's suspension limit, or a trend's below minus its own limit, is vehicle
/// evidence at its corner, naming the spring or the damper.
pub fn assess_drive_fitted(
    set: &ModelSet,
    records: &[&RecordFeatures],
    fitted: &[crate::suspension::CornerScore],
    trend: Option<&crate::suspension::SpringTrend>,
) -> Assessment {
    let usable: Vec<&RecordFeatures> = records
        .iter()
        .copied()
        .filter(|r| r.sensor_faults.is_empty())
        .collect();
    // Each record's features once: for the medians and for the records' own road verdicts.
    let per_record: Vec<Vec<(FeatureMeta, f64)>> =
        usable.iter().map(|rf| set.record_features(rf)).collect();
    let per_record_noise: Vec<EstimateVariances> = usable
        .iter()
        .zip(&per_record)
        .map(|(rf, values)| set.record_variances(rf, values))
        .collect();
    let mut by_key: BTreeMap<String, (FeatureMeta, Vec<f64>)> = BTreeMap::new();
    for (m, x) in per_record.iter().flatten() {
        by_key
            .entry(m.key.clone())
            .or_insert_with(|| (m.clone(), Vec::new()))
            .1
            .push(*x);
    }
    let need = usable.len().div_ceil(2).max(1);
    let values: Vec<(FeatureMeta, f64)> = by_key
        .into_values()
        .filter(|(_, xs)| xs.len() >= need)
        .filter_map(|(m, xs)| median(&xs).map(|x| (m, x)))
        .collect();
    let noise = drive_noise(&values, &per_record, &per_record_noise);
    let unjudged = drive_unjudged(usable.iter().map(|rf| set.record_unjudged(rf)));
    let mut a = score_values(set, &values, &noise, &unjudged, fitted, trend);
    rough_in_many_records(set, &per_record, &per_record_noise, &mut a);
    let left_out = records.len() - usable.len();
    if left_out > 0 {
        let mut faults: Vec<String> = records
            .iter()
            .flat_map(|r| r.sensor_faults.iter().map(|f| f.to_string()))
            .collect();
        faults.sort();
        faults.dedup();
        let mut summary = format!(
            "sensor: {left_out} of {} record(s) left out ({})",
            records.len(),
            faults.join(", ")
        );
        if usable.len() < MIN_DRIVE_RECORDS {
            a.classification = Classification::Sensor;
        }
        if !a.summary.is_empty() {
            summary.push_str("; ");
            summary.push_str(&a.summary);
        }
        a.summary = summary;
        let mut sf: Vec<crate::features::SensorFault> = Vec::new();
        for r in records {
            for f in &r.sensor_faults {
                if !sf.contains(f) {
                    sf.push(f.clone());
                }
            }
        }
        a.sensor_faults = sf;
    }
    a
}

/// The noise variance of a drive's median of each feature that its records have one for: the
/// median of a sample of `n` values whose noise variance is `v` has about `pi / 2 * v / n`
/// (the records' median `v`); a feature some of whose records lack one gets none.
fn drive_noise(
    values: &[(FeatureMeta, f64)],
    per_record: &[Vec<(FeatureMeta, f64)>],
    per_record_noise: &[EstimateVariances],
) -> EstimateVariances {
    let mut out = EstimateVariances::new();
    for (m, _) in values {
        let mut vars = Vec::new();
        for (rec, noise) in per_record.iter().zip(per_record_noise) {
            if rec.iter().any(|(k, _)| k.key == m.key) {
                match noise.get(&m.key) {
                    Some(v) => vars.push(*v),
                    None => {
                        vars.clear();
                        break;
                    }
                }
            }
        }
        if let Some(v) = median(&vars) {
            out.insert(
                m.key.clone(),
                std::f64::consts::FRAC_PI_2 * v / vars.len() as f64,
            );
        }
    }
    out
}

/// Why a drive gives no value of a feature: the records' reasons ([`noise_unjudged`]),
/// "in N of M records: <the first record's reason>".
fn drive_unjudged(
    per_record: impl Iterator<Item = BTreeMap<String, String>>,
) -> BTreeMap<String, String> {
    let mut count: BTreeMap<String, (usize, String)> = BTreeMap::new();
    let mut n = 0usize;
    for reasons in per_record {
        n += 1;
        for (key, why) in reasons {
            count.entry(key).or_insert((0, why)).0 += 1;
        }
    }
    count
        .into_iter()
        .map(|(key, (k, why))| (key, format!("in {k} of {n} records: {why}")))
        .collect()
}

/// A drive's road alarm from its records' own: a rough road raises the levels of every record,
/// but a record's alarm may come from any of the road's bands (and the per-band medians then
/// stay below the limit: busgen bus 11219's class D drive, 6 of 8 records `road`, was `normal`).
/// When at least half of the drive's records without a failed sensor (`per_record`: their
/// features, at least [`MIN_DRIVE_RECORDS`]) are `road` or `both` on their own (scored as
/// [`assess`] scores a record), the drive has a road alarm too: the same rule as a feature's
/// median (at least half of the records beyond a limit) and the same bound on its false-alarm
/// rate. The drive's summary says how many records, and in which bands (the strongest of each).
fn rough_in_many_records(
    set: &ModelSet,
    per_record: &[Vec<(FeatureMeta, f64)>],
    per_record_noise: &[EstimateVariances],
    a: &mut Assessment,
) {
    let road = |c: Classification| matches!(c, Classification::Road | Classification::Both);
    if road(a.classification) || per_record.len() < MIN_DRIVE_RECORDS {
        return;
    }
    let rough: Vec<Assessment> = per_record
        .iter()
        .zip(per_record_noise)
        .map(|(values, noise)| score_values(set, values, noise, &BTreeMap::new(), &[], None))
        .filter(|x| road(x.classification))
        .collect();
    if 2 * rough.len() < per_record.len() {
        return;
    }
    let mut bands: BTreeMap<&str, usize> = BTreeMap::new();
    for x in &rough {
        if let Some(e) = x
            .evidence
            .iter()
            .find(|e| e.meta.group == Group::Excitation)
        {
            *bands.entry(e.meta.label.as_str()).or_default() += 1;
        }
    }
    let mut counts: Vec<(&str, usize)> = bands.into_iter().collect();
    counts.sort_by_key(|x| std::cmp::Reverse(x.1));
    let most = if counts.is_empty() {
        String::new()
    } else {
        let parts: Vec<String> = counts.iter().map(|(l, n)| format!("{l} in {n}")).collect();
        format!(" ({})", parts.join(", "))
    };
    let vehicle = matches!(a.classification, Classification::Vehicle);
    a.classification = Classification::from_alarms(vehicle, true);
    let line = format!(
        "road: {} of {} records beyond the road's nominal levels on their own{most}",
        rough.len(),
        per_record.len()
    );
    a.summary = if a.summary.is_empty() {
        line
    } else {
        format!("{}; {line}", a.summary)
    };
}

/// The evidence of a drive's suspension scores: every corner's spring and damper scored, and
/// every corner's spring over the last drives (`trend`), those below minus the limit flagged.
fn fitted_evidence(
    set: &ModelSet,
    fitted: &[crate::suspension::CornerScore],
    trend: Option<&crate::suspension::SpringTrend>,
    scores: &mut Scores,
) -> Vec<Evidence> {
    let Some(reference) = &set.suspension else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let tagged = fitted.iter().map(|f| (f, false, reference.limit)).chain(
        trend
            .into_iter()
            .flat_map(|t| t.scores.iter().map(|f| (f, true, t.limit))),
    );
    for (f, pooled, limit) in tagged {
        let (kind, what) = match f.part {
            crate::suspension::Part::Spring => (Kind::SpringFit, "spring"),
            crate::suspension::Part::Damper => (Kind::DamperFit, "damper"),
        };
        let (key, label) = if pooled {
            (
                format!("fit:{what}-trend:{}", f.corner),
                format!(
                    "{what} (fitted over the last {} drives) vs the other corners",
                    crate::suspension::TREND_DRIVES
                ),
            )
        } else {
            (
                format!("fit:{what}:{}", f.corner),
                format!("{what} (fitted) vs the other corners"),
            )
        };
        scores.n_vehicle += 1;
        scores.vehicle_max_abs_z = scores.vehicle_max_abs_z.max(f.z.abs());
        if f.flagged(limit) {
            out.push(Evidence {
                meta: FeatureMeta {
                    key,
                    group: Group::Vehicle,
                    kind,
                    corner: Some(f.corner),
                    channel: String::new(),
                    label,
                },
                value: f.value,
                centre: f.centre,
                z: f.z,
                change_pct: 100.0 * f.change(),
                limit,
                flagged: true,
                spread_widened_by: None,
            });
        }
    }
    out
}

fn score_values(
    set: &ModelSet,
    values: &[(FeatureMeta, f64)],
    noise: &EstimateVariances,
    unjudged: &BTreeMap<String, String>,
    fitted: &[crate::suspension::CornerScore],
    trend: Option<&crate::suspension::SpringTrend>,
) -> Assessment {
    let by_key: BTreeMap<&str, f64> = values.iter().map(|(m, v)| (m.key.as_str(), *v)).collect();
    let mut evidence = Vec::new();
    let mut missing = Vec::new();
    let mut unscored: Vec<NotJudged> = Vec::new();
    let mut scores = Scores {
        vehicle_max_abs_z: 0.0,
        excitation_max_abs_z: 0.0,
        n_vehicle: 0,
        n_excitation: 0,
    };
    let quiet = quiet_bands(set, &by_key);
    let mut quiet_unjudged = 0usize;
    // Vehicle features not given because their wheels' motion is mostly sensor noise.
    let mut noisy_unjudged = 0usize;
    // The quiet bands that left a feature unjudged, for the summary.
    let mut quiet_used: Vec<&QuietBand> = Vec::new();
    // Vehicle features beyond their limit on the nominal spread and within it on the spread
    // widened by the record's own noise: (name, change %, z on the nominal spread, z).
    let mut spared: Vec<(String, f64, f64, f64)> = Vec::new();
    for f in &set.features {
        let where_ = || {
            f.meta
                .corner
                .map_or(f.meta.channel.clone(), |c| c.to_string())
        };
        let Some(&x) = by_key.get(f.meta.key.as_str()) else {
            match unjudged.get(&f.meta.key) {
                Some(why) => {
                    unscored.push(NotJudged {
                        feature: format!("{}: {}", where_(), f.meta.label),
                        reason: why.clone(),
                    });
                    noisy_unjudged += 1;
                }
                None => missing.push(format!("{}: {}", where_(), f.meta.label)),
            }
            continue;
        };
        if let Some(q) = quiet_for(f, &quiet) {
            unscored.push(NotJudged {
                feature: format!("{}: {}", where_(), f.meta.label),
                reason: format!(
                    "little road input: the road level {} is {:.0} % of the nominal records' lowest",
                    band_label(&q.hz),
                    100.0 * (q.x - q.lo).exp()
                ),
            });
            quiet_unjudged += 1;
            if !quiet_used.iter().any(|u| u.hz == q.hz) {
                quiet_used.push(q);
            }
            continue;
        }
        let var = noise.get(f.meta.key.as_str()).copied();
        let z = score(f, x, var, &set.config);
        let limit = set.limit(f.meta.kind);
        if f.meta.group == Group::Vehicle && z.abs() <= limit {
            let z_nominal = score(f, x, None, &set.config);
            if z_nominal.abs() > limit {
                // A level ratio's label names its wheels.
                let name = match f.meta.kind {
                    Kind::SideRatio | Kind::TrackRatio => f.meta.label.clone(),
                    _ => format!("{}: {}", where_(), f.meta.label),
                };
                spared.push((name, 100.0 * ((x - f.centre).exp() - 1.0), z_nominal, z));
            }
        }
        let (n, max) = match f.meta.group {
            Group::Vehicle => (&mut scores.n_vehicle, &mut scores.vehicle_max_abs_z),
            Group::Excitation => (&mut scores.n_excitation, &mut scores.excitation_max_abs_z),
        };
        *n += 1;
        *max = max.max(z.abs());
        if z.abs() > limit {
            let widened = f.spread(var) / f.sigma;
            evidence.push(Evidence {
                meta: f.meta.clone(),
                value: x.exp(),
                centre: f.centre.exp(),
                z,
                change_pct: 100.0 * ((x - f.centre).exp() - 1.0),
                limit,
                flagged: true,
                spread_widened_by: (f.meta.group == Group::Vehicle && widened > 1.0)
                    .then_some(widened),
            });
        }
    }
    attribute_ratios(set, values, noise, &mut evidence);
    evidence.extend(fitted_evidence(set, fitted, trend, &mut scores));
    evidence.sort_by(|a, b| b.z.abs().total_cmp(&a.z.abs()));
    let vehicle = evidence.iter().any(|e| e.meta.group == Group::Vehicle);
    let road = evidence.iter().any(|e| e.meta.group == Group::Excitation);
    let mut summary = summary(&evidence);
    // One note for the features given no score, by reason (the JSON's `not_judged` lists them).
    let mut unjudged_parts: Vec<String> = Vec::new();
    if quiet_unjudged > 0 {
        quiet_used.sort_by(|p, q| p.hz[0].total_cmp(&q.hz[0]));
        let bands: Vec<String> = quiet_used.iter().map(|q| band_label(&q.hz)).collect();
        unjudged_parts.push(format!(
            "{quiet_unjudged} vehicle feature(s) for little road input ({})",
            bands.join(", ")
        ));
    }
    if noisy_unjudged > 0 {
        unjudged_parts.push(format!(
            "{noisy_unjudged}{} for the wheels' sensor noise",
            if unjudged_parts.is_empty() {
                " vehicle feature(s)"
            } else {
                ""
            }
        ));
    }
    if !unjudged_parts.is_empty() {
        let note = format!("not judged: {}", unjudged_parts.join(" and "));
        summary = if summary.is_empty() {
            note
        } else {
            format!("{summary}; {note}")
        };
    }
    if !spared.is_empty() {
        spared.sort_by(|a, b| b.2.abs().total_cmp(&a.2.abs()));
        let mut named: Vec<String> = spared
            .iter()
            .take(SPARED_NAMED_MAX)
            .map(|(name, pct, z0, z)| {
                format!("{name} {pct:+.0} % (z {z0:.1} on the nominal spread, {z:.1} on its own)")
            })
            .collect();
        if spared.len() > SPARED_NAMED_MAX {
            named.push(format!("and {} more", spared.len() - SPARED_NAMED_MAX));
        }
        let note = format!(
            "not flagged, within their own noisy estimates' scatter: {}",
            named.join(", ")
        );
        summary = if summary.is_empty() {
            note
        } else {
            format!("{summary}; {note}")
        };
    }
    Assessment {
        classification: Classification::from_alarms(vehicle, road),
        scores,
        summary,
        component: component(set, values, noise, &evidence),
        evidence,
        missing,
        not_judged: unscored,
        sensor_faults: Vec::new(),
    }
}

/// A road-level band in which the record (or drive) had too little road input to judge the
/// vehicle features that depend on it: its level `x` (ln) more than `road_margin` (ln 2) below
/// the nominal records' lowest `lo`, the mirror of a road rougher than `hi + road_margin`.
#[derive(Clone, Debug)]
struct QuietBand {
    hz: [f64; 2],
    x: f64,
    lo: f64,
}

/// The road-level bands with too little road input ([`QuietBand`]).
fn quiet_bands(set: &ModelSet, by_key: &BTreeMap<&str, f64>) -> Vec<QuietBand> {
    set.features
        .iter()
        .filter(|f| f.meta.kind == Kind::Level)
        .filter_map(|f| {
            let x = *by_key.get(f.meta.key.as_str())?;
            let hz = key_band(&f.meta.key)?;
            (x < f.lo - set.config.road_margin).then_some(QuietBand { hz, x, lo: f.lo })
        })
        .collect()
}

/// The quiet band that leaves `f` unjudged, if any: the transmissibility and the body's
/// response to wheel motion are ratios of the body's motion to the wheels', whose sensor noise
/// and engine share (the same on any road) weigh more as the road's input falls, and their
/// spread was measured only over the nominal records' road levels (docs/fleet.md, "Little
/// road input"). The wheels' level ratios stay judged: a worn damper raises its wheel's level
/// by 25-40 % on a smooth road too, and that is how such a drive is found. Of the quiet bands
/// overlapping the feature's own, the one furthest below.
fn quiet_for<'q>(f: &FeatureStat, quiet: &'q [QuietBand]) -> Option<&'q QuietBand> {
    if !matches!(f.meta.kind, Kind::Transmissibility | Kind::BodyResponse) {
        return None;
    }
    let [a, b] = key_band(&f.meta.key)?;
    quiet
        .iter()
        .filter(|q| q.hz[0] < b && a < q.hz[1])
        .min_by(|p, q| (p.x - p.lo).total_cmp(&(q.x - q.lo)))
}

/// The band `[a, b]` Hz a feature key carries (`transh1lu:FR:12-20Hz`, `level:unsprung:2-5Hz`,
/// `body:FR_sprung:2-4Hz`), if any: the inverse of [`band_key`], which writes it.
fn key_band(key: &str) -> Option<[f64; 2]> {
    key.split(':').find_map(|part| {
        let (a, b) = part.strip_suffix("Hz")?.split_once('-')?;
        Some([a.parse().ok()?, b.parse().ok()?])
    })
}

/// Signed score of the level ratio of `kind` that `corner` takes part in, read from that corner
/// (its unsprung level over its neighbour's), if the values and the model set have it.
fn corner_ratio_z(
    set: &ModelSet,
    values: &[(FeatureMeta, f64)],
    noise: &EstimateVariances,
    kind: Kind,
    corner: Corner,
) -> Option<f64> {
    let pairs = if kind == Kind::SideRatio {
        AXLES
    } else {
        TRACKS
    };
    let (name, first, _) = pairs
        .iter()
        .find(|(_, a, b)| *a == corner || *b == corner)?;
    let key = ratio_key(kind, name, &set.config.ratio_band_hz, set.line_free);
    let f = set.features.iter().find(|f| f.meta.key == key)?;
    let x = values.iter().find(|(m, _)| m.key == key).map(|(_, v)| *v)?;
    let z = score(f, x, noise.get(&key).copied(), &set.config);
    Some(if *first == corner { z } else { -z })
}

/// The component of the corner named first (that of the strongest flagged vehicle feature),
/// from the flagged vehicle features of that corner:
///
/// - the drive's fitted spring lowered (and no raised level ratio): the spring; its fitted
///   damper lowered (and no lowered level ratio or wheel hop): the damper;
/// - a level ratio at and above wheel hop read from the corner (after [`attribute_ratios`]):
///   lowered is the tyre (a softer tyre lowers the wheel hop and the wheel's response above
///   it), raised is the damper (a weaker damper lets the wheel move more at and above wheel
///   hop);
/// - a wheel-hop frequency of the corner lowered: the tyre;
/// - the body's response to the wheel motions lowered at the corner, with neither of the
///   above: the spring, if the corner's unsprung level ratios are present and none of them,
///   read from the corner, lies more than [`SPRING_MAX_LEVEL_Z`] spreads above its centre (a
///   damper weak enough to lower the body's response raises the wheel's level); else the
///   suspension;
/// - tyre and damper evidence together, or only other features (transmissibility, mode
///   damping, a raised response): the suspension.
///
/// `None` without a flagged vehicle feature on a corner.
fn component(
    set: &ModelSet,
    values: &[(FeatureMeta, f64)],
    noise: &EstimateVariances,
    evidence: &[Evidence],
) -> Option<Component> {
    let corner = evidence
        .iter()
        .find(|e| e.meta.group == Group::Vehicle)?
        .meta
        .corner?;
    let at: Vec<&Evidence> = evidence
        .iter()
        .filter(|e| e.meta.group == Group::Vehicle && e.meta.corner == Some(corner))
        .collect();
    let tyre = at.iter().any(|e| match e.meta.kind {
        Kind::SideRatio | Kind::TrackRatio => e.z < 0.0,
        Kind::ModeFrequency => e.meta.label.starts_with("wheel-hop") && e.z < 0.0,
        _ => false,
    });
    let damper = at
        .iter()
        .any(|e| matches!(e.meta.kind, Kind::SideRatio | Kind::TrackRatio) && e.z > 0.0);
    let body_lowered = at
        .iter()
        .any(|e| e.meta.kind == Kind::BodyResponse && e.z < 0.0);
    // The suspension fitted to the drive names its part directly.
    let fit_spring = at.iter().any(|e| e.meta.kind == Kind::SpringFit);
    let fit_damper = at.iter().any(|e| e.meta.kind == Kind::DamperFit);
    match (fit_spring, fit_damper) {
        (true, false) if !damper => return Some(Component::Spring),
        (false, true) if !tyre => return Some(Component::Damper),
        _ => {}
    }
    Some(match (tyre, damper) {
        (true, false) => Component::Tyre,
        (false, true) => Component::Damper,
        (true, true) => Component::Suspension,
        (false, false) if body_lowered => {
            let levels: Vec<f64> = [Kind::SideRatio, Kind::TrackRatio]
                .into_iter()
                .filter_map(|k| corner_ratio_z(set, values, noise, k, corner))
                .collect();
            if !levels.is_empty() && levels.iter().all(|z| *z <= SPRING_MAX_LEVEL_Z) {
                Component::Spring
            } else {
                Component::Suspension
            }
        }
        (false, false) => Component::Suspension,
    })
}

/// Largest score (spreads above the centre) of a corner's unsprung level ratio, read from the
/// corner, at which a lowered body response is named the spring rather than the suspension.
pub const SPRING_MAX_LEVEL_Z: f64 = 1.0;

/// What a wheel of a flagged level ratio's pair says besides that ratio (see
/// [`attribute_ratios`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct WheelEvidence {
    /// The wheel's other level ratio, read from the wheel, in spreads, positive in the flagged
    /// ratio's direction (it moved the same way); `None` without it.
    other_z: Option<f64>,
    /// The largest `|z| / limit` of the wheel's own flagged vehicle features that are not level
    /// ratios (transmissibility, body response, its channels' modes); 0 without any.
    own: f64,
}

/// Log-odds (natural) between the two wheels of a flagged level ratio above which their other
/// ratios decide alone: ln 20, odds of 20 to 1.
pub const RATIO_DECISIVE_LOG_ODDS: f64 = 2.995_732_273_553_991;

/// True when the flagged ratio is charged to the first wheel `a` of its pair, false for `b`.
/// `shift` is the flagged ratio's change from its centre (ln units) over the spread of the
/// other ratios.
///
/// If wheel `a` moved by that change, its other ratio moves by `shift` spreads and `b`'s stays
/// (and the reverse): with unit-variance scores the log-likelihood ratio of `a` against `b` is
/// `(a.other_z - b.other_z) shift`. The other ratios decide when its magnitude is at least
/// [`RATIO_DECISIVE_LOG_ODDS`], or when neither wheel has flagged features of its own; else the
/// wheel whose own features are flagged (the stronger, in limits, if both are) takes the ratio:
/// a fault at a wheel station moves that corner's transmissibility, body response or wheel-hop
/// mode, while the left/right ratio's spread (0.10 in ln) is the size of a weak damper's effect
/// on it, so its other ratios may not tell the wheels apart (busgen bus 43872, RL damper at 60 %:
/// FL's other ratio 1.8 spreads, RL's 1.5, log-odds 1.0 for FL; RL's transmissibility 5-8 Hz
/// -37 %).
fn charge_to_first(a: WheelEvidence, b: WheelEvidence, shift: f64) -> bool {
    let (za, zb) = (a.other_z.unwrap_or(0.0), b.other_z.unwrap_or(0.0));
    let log_odds = (za - zb) * shift;
    if (a.own > 0.0 || b.own > 0.0) && log_odds.abs() < RATIO_DECISIVE_LOG_ODDS {
        return a.own >= b.own;
    }
    za >= zb
}

/// A level ratio of two wheels says that one of them moved, not which. A wheel station's fault
/// moves the two ratios it takes part in (its axle's left/right and its side's front/rear) the
/// same way when both are read from that wheel (its level against each neighbour); a healthy
/// wheel's other ratio stays; and it moves the corner's own features where the corner has them
/// (a weak damper lowers its transmissibility: busgen bus 43872, RL damper at 60 %, "RL:
/// transmissibility 5-8 Hz vs the other corners -37 %"). A flagged ratio is charged to a wheel of
/// its pair by [`charge_to_first`] and turned to read from that wheel (`FL: level vs FR 8-20 Hz
/// -40 %`). Without either other ratio it stays on its channel pair.
fn attribute_ratios(
    set: &ModelSet,
    values: &[(FeatureMeta, f64)],
    noise: &EstimateVariances,
    evidence: &mut [Evidence],
) {
    let band = set.config.ratio_band_hz;
    let signed_z = |key: &str| -> Option<f64> {
        let f = set.features.iter().find(|f| f.meta.key == key)?;
        let x = values.iter().find(|(m, _)| m.key == key).map(|(_, v)| *v)?;
        Some(score(f, x, noise.get(key).copied(), &set.config))
    };
    // The spread of a ratio kind (pooled: one per kind).
    let sigma_of = |kind: Kind| -> Option<f64> {
        set.features
            .iter()
            .find(|f| f.meta.kind == kind)
            .map(|f| f.sigma)
    };
    // The largest |z| / limit of a corner's own flagged vehicle features that are not ratios.
    let own = |corner: Corner| -> f64 {
        evidence
            .iter()
            .filter(|e| {
                e.meta.group == Group::Vehicle
                    && e.meta.corner == Some(corner)
                    && !matches!(e.meta.kind, Kind::SideRatio | Kind::TrackRatio)
            })
            .map(|e| e.z.abs() / e.limit)
            .fold(0.0, f64::max)
    };
    // The other ratio of a corner (its side's for an axle ratio, its axle's for a side's), as
    // a z-score of the corner's level over its neighbour's.
    let other = |kind: Kind, corner: Corner| -> Option<f64> {
        let (other_kind, pairs) = if kind == Kind::SideRatio {
            (Kind::TrackRatio, TRACKS)
        } else {
            (Kind::SideRatio, AXLES)
        };
        let (name, first, _) = pairs
            .iter()
            .find(|(_, a, b)| *a == corner || *b == corner)?;
        let z = signed_z(&ratio_key(other_kind, name, &band, set.line_free))?;
        Some(if *first == corner { z } else { -z })
    };
    // Computed before the loop changes the evidence (the ratios only; their corners move).
    let own_of: BTreeMap<Corner, f64> = [Corner::FL, Corner::FR, Corner::RL, Corner::RR]
        .into_iter()
        .map(|c| (c, own(c)))
        .collect();
    for e in evidence
        .iter_mut()
        .filter(|e| matches!(e.meta.kind, Kind::SideRatio | Kind::TrackRatio))
    {
        let pairs = if e.meta.kind == Kind::SideRatio {
            AXLES
        } else {
            TRACKS
        };
        let Some((_, a, b)) = pairs
            .iter()
            .find(|(name, _, _)| e.meta.key == ratio_key(e.meta.kind, name, &band, set.line_free))
            .copied()
        else {
            continue;
        };
        let (za, zb) = (other(e.meta.kind, a), other(e.meta.kind, b));
        if za.is_none() && zb.is_none() {
            continue;
        }
        // Read from a, the flagged ratio moved by sign(e.z); read from b, by -sign(e.z).
        let dir = e.z.signum();
        let wa = WheelEvidence {
            other_z: za.map(|z| dir * z),
            own: own_of.get(&a).copied().unwrap_or(0.0),
        };
        let wb = WheelEvidence {
            other_z: zb.map(|z| -dir * z),
            own: own_of.get(&b).copied().unwrap_or(0.0),
        };
        // The flagged ratio's change in spreads of the other kind (spreads are pooled per
        // kind, so both other ratios have one).
        let other_kind = if e.meta.kind == Kind::SideRatio {
            Kind::TrackRatio
        } else {
            Kind::SideRatio
        };
        let shift = match (sigma_of(e.meta.kind), sigma_of(other_kind)) {
            (Some(s), Some(so)) if so > 0.0 => e.z.abs() * s / so,
            _ => 0.0,
        };
        let label = |o: Corner| format!("level vs {o} {}", band_label(&band));
        if charge_to_first(wa, wb, shift) {
            e.meta.corner = Some(a);
            e.meta.label = label(b);
        } else {
            e.meta.corner = Some(b);
            e.meta.label = label(a);
            e.value = 1.0 / e.value;
            e.centre = 1.0 / e.centre;
            e.z = -e.z;
            e.change_pct = 100.0 * (e.value / e.centre - 1.0);
        }
    }
}

/// `RL: transmissibility 8-12 Hz +35 %, ...; RR: ...` for the flagged vehicle features, then
/// `road: ...` for the flagged excitation features (at most three).
fn summary(evidence: &[Evidence]) -> String {
    let mut parts: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for e in evidence.iter().filter(|e| e.meta.group == Group::Vehicle) {
        let place = e
            .meta
            .corner
            .map_or_else(|| e.meta.channel.clone(), |c| c.to_string());
        parts
            .entry(place)
            .or_default()
            .push(format!("{} {:+.0} %", e.meta.label, e.change_pct));
    }
    let mut out: Vec<String> = parts
        .into_iter()
        .map(|(place, items)| format!("{place}: {}", items.join(", ")))
        .collect();
    let road: Vec<String> = evidence
        .iter()
        .filter(|e| e.meta.group == Group::Excitation)
        .take(3)
        .map(|e| format!("{} {:+.0} %", e.meta.label, e.change_pct))
        .collect();
    if !road.is_empty() {
        out.push(format!("road: {}", road.join(", ")));
    }
    out.join("; ")
}

/// The verdict on a drive: records of one vehicle checked together ([`assess_drive`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Drive {
    /// The drive id (`--drive ID`, else the day, else the records' folder or `all given records`).
    pub drive: String,
    /// The model-set version it was scored against.
    pub model_version: i64,
    /// Its records (file names as given), whose own verdicts are in the check's `records`.
    pub records: Vec<String>,
    /// When it was driven: the earliest start of its records (Unix time, s), where every
    /// record's start is known (a time column of date-times, or a sidecar's `start_time`);
    /// absent otherwise and in drives stored before it existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_unix_s: Option<f64>,
    /// The corner of the strongest flagged vehicle feature (the one named first), if any.
    pub corner: Option<vibmode_analysis::Corner>,
    /// Upper bound of the false-alarm rate per drive and feature group: the model set's
    /// `false_alarm_rate` per record (docs/fleet.md, "Drives"), twice it when the drive's
    /// suspension fit is scored too (its tests have the same rate of their own).
    pub false_alarm_rate: f64,
    /// The verdict from the medians of the features over the records.
    #[serde(flatten)]
    pub assessment: Assessment,
    /// The suspension fitted to the drive's records and every corner's score, when the vehicle
    /// has a registered model file and the model set a fitted suspension.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub suspension: Option<crate::suspension::DriveSuspension>,
    /// Its records whose content is a record the model set was built from (their file names
    /// in the model set): scored against a baseline that holds them, so the drive's verdict
    /// leans toward `normal`. Empty (and absent from the JSON) otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub in_baseline: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::{ChannelFeatures, CornerTransmissibility, ModeEstimate};
    use crate::stats::MAD_TO_SIGMA;

    #[test]
    fn a_kind_prints_as_its_json_name() {
        for k in KINDS.into_iter().chain([Kind::SpringFit, Kind::DamperFit]) {
            assert_eq!(
                serde_json::to_value(k).unwrap(),
                serde_json::Value::String(k.to_string())
            );
        }
    }

    /// A record with one unsprung level and one transmissibility in band 2-5 Hz.
    fn record(level: f64, trans: f64) -> RecordFeatures {
        RecordFeatures {
            analysis_fs_hz: 50.0,
            duration_s: 10.0,
            n_segments: 1,
            bands_hz: vec![[2.0, 5.0]],
            channels: vec![ChannelFeatures {
                name: "RL_unsprung".into(),
                role: Role::Unsprung,
                corner: Some(Corner::RL),
                band_rms: vec![Some(level)],
                modes: Vec::new(),
                ratio_band_rms: None,
            }],
            transmissibility: vec![CornerTransmissibility {
                corner: Corner::RL,
                sprung: "RL_sprung".into(),
                unsprung: "RL_unsprung".into(),
                values: vec![Some(trans)],
                h1: Vec::new(),
            }],
            notes: Vec::new(),
            body_spectra: None,
            sensor_faults: Vec::new(),
            line_free: None,
            suspension: None,
            start_unix_s: None,
        }
    }

    fn baseline() -> ModelSet {
        // Levels 1.0 .. 1.2 and transmissibility 0.20 .. 0.22 over six records.
        let recs: Vec<RecordFeatures> = (0..6)
            .map(|i| record(1.0 + 0.04 * i as f64, 0.20 + 0.004 * i as f64))
            .collect();
        let names: Vec<String> = (0..6).map(|i| format!("n{i}")).collect();
        build_model_set("bus", &names, &recs, &FleetConfig::default()).expect("model set")
    }

    /// Two corners with per-bin transmissibility parts in 2-5 Hz (bins 2, 3, 4, 5 Hz): the
    /// coherent power `t^2 S_uu` (transmissibility `t`) in every bin, except that a line at 4 Hz
    /// adds `line` to the first corner's coherent power. `found`: the record's analysis found the
    /// line (its bins left out of the line-free values).
    fn lined(t: [f64; 2], line: f64, found: bool) -> RecordFeatures {
        let mut r = record(1.0, 1.0);
        let input = vec![1.0, 2.0, 2.0, 1.0];
        let coherent = |k: usize| -> Vec<f64> {
            input
                .iter()
                .enumerate()
                .map(|(j, p)| t[k] * t[k] * p + if k == 0 && j == 2 { line } else { 0.0 })
                .collect()
        };
        r.transmissibility = [Corner::RL, Corner::RR]
            .into_iter()
            .map(|corner| CornerTransmissibility {
                corner,
                sprung: format!("{corner}_sprung"),
                unsprung: format!("{corner}_unsprung"),
                values: vec![Some(1.0)],
                h1: Vec::new(),
            })
            .collect();
        let lines: Vec<f64> = if found { vec![4.0] } else { Vec::new() };
        let bins = crate::features::TransmissibilityBins {
            freq_hz: vec![2.0, 3.0, 4.0, 5.0],
            coherent: vec![coherent(0), coherent(1)],
            input: vec![input.clone(), input.clone()],
            ..crate::features::TransmissibilityBins::default()
        };
        // The stored line-free value as feature extraction makes it (the record's own lines out).
        let h1 = (0..2)
            .map(|k| vec![bins.band_value(k, [2.0, 5.0], &[&lines])])
            .collect();
        r.line_free = Some(crate::features::LineFree {
            line_bins_hz: lines,
            h1,
            bins: Some(bins),
            ..crate::features::LineFree::default()
        });
        r
    }

    /// The coherence with its bias out, by hand: 7 Hann segments at half overlap average as
    /// 7 / (1 + 2/36) = 6.63 independent ones; an estimate of 1 stays 1, the floor 1 / n gives
    /// 0, 0.3 gives (6.63 * 0.3 - 1) / 5.63 = 0.1757; one segment gives none.
    #[test]
    fn corrected_coherence_by_hand() {
        let n = 7.0 / (1.0 + 2.0 / 36.0);
        let c = |g: f64| corrected_coherence(g, 7).unwrap_or(f64::NAN);
        assert!((c(1.0) - 1.0).abs() < 1e-12);
        assert!(c(1.0 / n).abs() < 1e-12);
        assert!((c(0.3) - (n * 0.3 - 1.0) / (n - 1.0)).abs() < 1e-12);
        assert!((c(0.3) - 0.1757).abs() < 1e-4, "{}", c(0.3));
        assert_eq!(corrected_coherence(0.5, 1), None);
        assert_eq!(corrected_coherence(f64::NAN, 7), None);
    }

    /// A corner whose sprung channel is barely coherent with its wheel in the band (estimated
    /// 0.2 from 7 segments: 0.05 with the bias out) is left out of the model set at
    /// `transmissibility_min_coherence` 0.1 and named in a note; the other corner (0.9) is kept;
    /// at 0 both are kept.
    #[test]
    fn a_band_whose_coherence_is_at_its_floor_is_left_out() {
        let coherent = |r: &mut RecordFeatures, g: [f64; 2]| {
            if let Some(bins) = r.line_free.as_mut().and_then(|l| l.bins.as_mut()) {
                bins.output = (0..2)
                    .map(|k| bins.coherent[k].iter().map(|c| c / g[k]).collect())
                    .collect();
                bins.segments = 7;
            }
        };
        let nominal: Vec<RecordFeatures> = (0..6)
            .map(|i| {
                let mut r = lined([0.6, 0.3 + 0.01 * i as f64], 0.0, false);
                coherent(&mut r, [0.2, 0.9]);
                r
            })
            .collect();
        let names: Vec<String> = (0..6).map(|i| format!("n{i}")).collect();
        let cfg = FleetConfig {
            transmissibility_min_coherence: 0.1,
            ..FleetConfig::default()
        };
        let set = build_model_set("bus", &names, &nominal, &cfg).expect("model set");
        let keys: Vec<&str> = set
            .features
            .iter()
            .filter(|f| f.meta.kind == Kind::Transmissibility)
            .map(|f| f.meta.key.as_str())
            .collect();
        assert_eq!(keys, vec!["transh1lu:RR:2-5Hz"]);
        let g = corrected_coherence(0.2, 7).unwrap_or(f64::NAN);
        assert!(
            set.notes.contains(&format!(
                "RL: transmissibility 2-5 Hz left out: its sprung channel's coherence with its wheel there is {g:.2} over the nominal records (median, the estimate's bias taken out), below transmissibility_min_coherence 0.1"
            )),
            "{:?}",
            set.notes
        );
        let off = FleetConfig {
            transmissibility_min_coherence: 0.0,
            ..FleetConfig::default()
        };
        let all = build_model_set("bus", &names, &nominal, &off).expect("set");
        assert_eq!(
            all.features
                .iter()
                .filter(|f| f.meta.kind == Kind::Transmissibility)
                .count(),
            2
        );
    }

    /// The vehicle's lines: bins left out in two or more nominal records, not one; none without
    /// the per-bin parts in every record.
    #[test]
    fn vehicle_line_bins_are_those_of_two_or_more_records() {
        let with = |bins: &[f64]| {
            let mut r = lined([0.5, 0.5], 0.0, false);
            if let Some(lf) = r.line_free.as_mut() {
                lf.line_bins_hz = bins.to_vec();
            }
            r
        };
        let recs = vec![
            with(&[7.0, 7.5, 12.0]),
            with(&[12.0]),
            with(&[7.5]),
            with(&[]),
        ];
        assert_eq!(vehicle_line_bins(&recs), Some(vec![7.5, 12.0]));
        assert_eq!(vehicle_line_bins(&recs[3..]), Some(vec![]));
        let mut old = recs.clone();
        if let Some(lf) = old[1].line_free.as_mut() {
            lf.bins = None;
        }
        assert_eq!(vehicle_line_bins(&old), None);
    }

    /// A line that the analysis found in some nominal records and not in others, and in every
    /// record checked: with the vehicle's lines left out of every record the checked record's
    /// transmissibility is the nominal one (RL 0.6 against RR 0.3: ln 2), as without any line;
    /// with each record's own lines only (the older key) the nominal records that kept the line
    /// pull the model set's centre up and the checked record scores below it.
    #[test]
    fn a_line_found_in_some_records_does_not_move_the_transmissibility() {
        let cfg = FleetConfig::default();
        let nominal: Vec<RecordFeatures> = (0..6).map(|i| lined([0.6, 0.3], 4.0, i < 2)).collect();
        let names: Vec<String> = (0..6).map(|i| format!("n{i}")).collect();
        let set = build_model_set("bus", &names, &nominal, &cfg).expect("model set");
        assert_eq!(set.vehicle_line_bins_hz, Some(vec![4.0]));
        let key = "transh1lu:RL:2-5Hz";
        let centre = set
            .features
            .iter()
            .find(|f| f.meta.key == key)
            .map(|f| f.centre)
            .expect("feature");
        assert!((centre - 2f64.ln()).abs() < 1e-12, "{centre}");
        let checked = lined([0.6, 0.3], 4.0, true);
        let value = set
            .record_features(&checked)
            .into_iter()
            .find(|(m, _)| m.key == key)
            .map(|(_, v)| v)
            .expect("value");
        assert!((value - 2f64.ln()).abs() < 1e-12, "{value}");
        // Each record's own lines only: 4 of 6 nominal records keep the line (RL's coherent
        // power 0.72 + 4 over 6 of input: 0.886 against RR's 0.3), the checked record not.
        let old = scalar_features(
            &checked,
            &set.slots,
            None,
            &cfg,
            Variants {
                line_free: true,
                noise_free: false,
                ..Variants::default()
            },
        )
        .into_iter()
        .find(|(m, _)| m.key == "transh1lf:RL:2-5Hz")
        .map(|(_, v)| v)
        .expect("old value");
        let kept = ((0.36 * 6.0 + 4.0) / 6.0f64).sqrt() / 0.3;
        assert!((old - 2f64.ln()).abs() < 1e-12, "{old}");
        let old_set = {
            let mut s = set.clone();
            s.vehicle_line_bins_hz = None;
            s
        };
        let old_nominal: Vec<f64> = nominal
            .iter()
            .map(|r| {
                old_set
                    .record_features(r)
                    .into_iter()
                    .find(|(m, _)| m.key == "transh1lf:RL:2-5Hz")
                    .map(|(_, v)| v)
                    .expect("nominal value")
            })
            .collect();
        assert!(
            (old_nominal[5] - kept.ln()).abs() < 1e-12,
            "{old_nominal:?}"
        );
        assert!(
            (old_nominal[0] - 2f64.ln()).abs() < 1e-12,
            "{old_nominal:?}"
        );
    }

    /// Transmissibility of three corners relative to the other two, by hand: every corner
    /// scaled alike (a load) leaves the features unchanged; RL halved gives RL ln(0.5) and the
    /// others -ln(0.5)/2; the band below `transmissibility_min_hz` gives no feature.
    #[test]
    fn transmissibility_relative_to_the_other_corners_by_hand() {
        let cfg = FleetConfig::default();
        let rec = |fl: f64, fr: f64, rl: f64| {
            let mut r = record(1.0, 1.0);
            r.bands_hz = vec![[0.5, 2.0], [2.0, 5.0]];
            r.transmissibility = [(Corner::FL, fl), (Corner::FR, fr), (Corner::RL, rl)]
                .into_iter()
                .map(|(corner, v)| CornerTransmissibility {
                    corner,
                    sprung: format!("{corner}_sprung"),
                    unsprung: format!("{corner}_unsprung"),
                    values: vec![Some(1.0), Some(v)],
                    h1: Vec::new(),
                })
                .collect();
            transmissibility_features(&r, &cfg, false, None)
        };
        let base = rec(0.2, 0.3, 0.4);
        assert_eq!(base.len(), 3, "one band of three corners: {base:?}");
        let want_rl = 0.4f64.ln() - 0.5 * (0.2f64.ln() + 0.3f64.ln());
        let rl = base.iter().find(|(m, _)| m.corner == Some(Corner::RL));
        let (meta, v) = rl.expect("RL");
        assert!((v - want_rl).abs() < 1e-12, "{v} {want_rl}");
        assert_eq!(meta.label, "transmissibility 2-5 Hz vs the other corners");
        for ((_, a), (_, b)) in base.iter().zip(&rec(0.2 * 0.8, 0.3 * 0.8, 0.4 * 0.8)) {
            assert!(
                (a - b).abs() < 1e-12,
                "a common factor must cancel: {a} {b}"
            );
        }
        let halved = rec(0.2, 0.3, 0.2);
        for ((m, a), (_, b)) in base.iter().zip(&halved) {
            let want = if m.corner == Some(Corner::RL) {
                0.5f64.ln()
            } else {
                -0.5 * 0.5f64.ln()
            };
            assert!((b - a - want).abs() < 1e-12, "{m:?}: {a} -> {b}");
        }
    }

    #[test]
    fn centre_spread_and_limits_by_hand() {
        let set = baseline();
        let t = set
            .features
            .iter()
            .find(|f| f.meta.kind == Kind::Transmissibility)
            .expect("trans");
        // Median of ln(0.208) and ln(0.212); MAD of the logs is below the floor 0.10.
        let want = 0.5 * (0.208f64.ln() + 0.212f64.ln());
        assert!((t.centre - want).abs() < 1e-12);
        assert_eq!(t.sigma, 0.10);
        // One vehicle feature: Bonferroni limit Phi^-1(1 - 0.01 / 2) = 2.5758.
        let l = set
            .limits
            .iter()
            .find(|l| l.kind == Kind::Transmissibility)
            .expect("limit");
        assert!((l.bonferroni - 2.575_829_304).abs() < 1e-6);
        assert!(l.limit >= l.bonferroni);
    }

    #[test]
    fn classification_of_constructed_records() {
        let set = baseline();
        // Inside both ranges.
        let a = assess(&set, &record(1.1, 0.21));
        assert_eq!(a.classification, Classification::Normal, "{a:?}");
        // Level 3x the largest nominal one, transmissibility unchanged: road.
        let a = assess(&set, &record(3.6, 0.21));
        assert_eq!(a.classification, Classification::Road, "{a:?}");
        // Transmissibility -50 % (z = ln(0.5) / 0.1 = -6.9), level nominal: vehicle, named.
        let a = assess(&set, &record(1.1, 0.105));
        assert_eq!(a.classification, Classification::Vehicle, "{a:?}");
        assert!(
            a.summary.starts_with("RL: transmissibility 2-5 Hz -5"),
            "{}",
            a.summary
        );
        let e = &a.evidence[0];
        assert!((e.change_pct - 100.0 * (0.105 / e.centre - 1.0)).abs() < 1e-9);
        assert!((e.z - (0.105f64.ln() - e.centre.ln()) / 0.10).abs() < 1e-9);
        // Both.
        let a = assess(&set, &record(3.6, 0.105));
        assert_eq!(a.classification, Classification::Both, "{a:?}");
        // A record without the transmissibility: the feature is listed as missing, not scored.
        let mut r = record(1.1, 0.21);
        r.transmissibility.clear();
        let a = assess(&set, &r);
        assert_eq!(a.classification, Classification::Normal);
        assert_eq!(a.missing, vec!["RL: transmissibility 2-5 Hz".to_string()]);
        assert_eq!(a.scores.n_vehicle, 0);
    }

    /// The road level is scored only above the nominal range's top plus `road_margin` (ln 2):
    /// a smoother road and one up to a road class rougher are normal; beyond, the score is the
    /// distance in `floor_level` units.
    #[test]
    fn road_level_scored_above_the_range_plus_one_road_class() {
        let set = baseline();
        let cfg = FleetConfig::default();
        let hi = 1.2f64;
        for level in [0.1, 0.5, 1.0, 2.0 * hi * 0.99] {
            let a = assess(&set, &record(level, 0.21));
            assert_eq!(a.classification, Classification::Normal, "{level}: {a:?}");
            assert_eq!(a.scores.excitation_max_abs_z, 0.0, "{level}");
        }
        // 3 floors above the margin: score 3 (above the limit 2.58 of one feature).
        let level = 2.0 * hi * (3.0 * cfg.floor_level).exp();
        let a = assess(&set, &record(level, 0.21));
        assert!((a.scores.excitation_max_abs_z - 3.0).abs() < 1e-9, "{a:?}");
        assert_eq!(a.classification, Classification::Road);
    }

    /// Little road input, by hand: the nominal levels are 1.0-1.2 in 2-5 Hz, so below half the
    /// lowest (0.5, `road_margin` ln 2 below `lo` = ln 1.0) the transmissibility of 2-5 Hz is not
    /// judged: a record at 0.45 whose transmissibility is 2.3 times the nominal is `normal`,
    /// the feature listed under `not_judged` with the level's share (45 %) and the summary saying
    /// why; at 0.55 the same transmissibility is `vehicle`. The excitation is never scored
    /// below the range (a smoother road is normal).
    #[test]
    fn little_road_input_leaves_the_transmissibility_unjudged() {
        let set = baseline();
        let quiet = assess(&set, &record(0.45, 0.5));
        assert_eq!(quiet.classification, Classification::Normal, "{quiet:?}");
        assert!(quiet.evidence.is_empty(), "{quiet:?}");
        assert!(quiet.missing.is_empty(), "{quiet:?}");
        assert_eq!(
            quiet.not_judged,
            vec![NotJudged {
                feature: "RL: transmissibility 2-5 Hz".to_string(),
                reason: "little road input: the road level 2-5 Hz is 45 % of the nominal records' lowest"
                    .to_string()
            }]
        );
        assert_eq!(
            quiet.summary,
            "not judged: 1 vehicle feature(s) for little road input (2-5 Hz)"
        );
        assert_eq!(quiet.scores.excitation_max_abs_z, 0.0);
        let judged = assess(&set, &record(0.55, 0.5));
        assert_eq!(judged.classification, Classification::Vehicle, "{judged:?}");
        assert!(
            judged.missing.is_empty() && judged.not_judged.is_empty(),
            "{judged:?}"
        );
        // The same for a drive of such records (its medians).
        let recs: Vec<RecordFeatures> = (0..3).map(|_| record(0.45, 0.5)).collect();
        let refs: Vec<&RecordFeatures> = recs.iter().collect();
        let d = assess_drive(&set, &refs);
        assert_eq!(d.classification, Classification::Normal, "{d:?}");
        assert!(d.missing.is_empty(), "{d:?}");
        assert_eq!(d.not_judged.len(), 1, "{d:?}");
        assert_eq!(d.not_judged[0].feature, "RL: transmissibility 2-5 Hz");
    }

    #[test]
    fn key_band_by_hand() {
        assert_eq!(key_band("transh1lu:FR:12-20Hz"), Some([12.0, 20.0]));
        assert_eq!(key_band("level:unsprung:0.5-2Hz"), Some([0.5, 2.0]));
        assert_eq!(key_band("track:left:8-20Hz:lf"), Some([8.0, 20.0]));
        assert_eq!(key_band("body:FR_sprung:2-4Hz"), Some([2.0, 4.0]));
        assert_eq!(key_band("mode:RL_unsprung:1:damping"), None);
    }

    /// A record with one mode of `RL_unsprung`.
    fn moded(f: f64, zeta: f64) -> RecordFeatures {
        let mut r = record(1.0, 1.0);
        r.channels[0].modes = vec![ModeEstimate {
            frequency_hz: f,
            damping_ratio: zeta,
        }];
        r
    }

    /// A 9 Hz cluster that is the bending mode (damping 0.03) in some records and an axle mode
    /// (0.28) in others is two modes: with 4 and 4 of 8 records neither is in 60 % of them and
    /// the model set has no slot; with 6 axle and 2 bending it has one, the axle mode (damping
    /// the median of 0.28-0.33, 0.305), which a record's bending mode (0.03) is not matched to while a damping
    /// of 0.18 (a weaker damper) is, and scored.
    #[test]
    fn modes_of_two_damping_classes_near_one_frequency_are_not_one_slot() {
        let cfg = FleetConfig::default();
        let half: Vec<RecordFeatures> = (0..8)
            .map(|i| {
                if i % 2 == 0 {
                    moded(9.0 + 0.02 * i as f64, 0.03)
                } else {
                    moded(9.2 + 0.02 * i as f64, 0.28)
                }
            })
            .collect();
        assert!(mode_slots(&half, &cfg).is_empty());
        let mostly: Vec<RecordFeatures> = (0..8)
            .map(|i| {
                if i < 2 {
                    moded(9.0, 0.03)
                } else {
                    moded(9.1 + 0.02 * i as f64, 0.26 + 0.01 * i as f64)
                }
            })
            .collect();
        let slots = mode_slots(&mostly, &cfg);
        assert_eq!(slots.len(), 1, "{slots:?}");
        let z = slots[0].damping_ratio.expect("damping");
        assert!((z - 0.305).abs() < 1e-9, "{z}");
        let damping = |r: &RecordFeatures| {
            scalar_features(
                r,
                &slots,
                None,
                &cfg,
                Variants {
                    line_free: false,
                    noise_free: false,
                    ..Variants::default()
                },
            )
            .into_iter()
            .find(|(m, _)| m.kind == Kind::ModeDamping)
            .map(|(_, x)| x.exp())
        };
        assert_eq!(damping(&moded(9.1, 0.03)), None);
        let weaker = damping(&moded(9.1, 0.18)).expect("matched");
        assert!((weaker - 0.18).abs() < 1e-12);
        // A model set stored before the damping class matches any damping.
        let mut old = slots.clone();
        old[0].damping_ratio = None;
        let any = scalar_features(
            &moded(9.1, 0.03),
            &old,
            None,
            &cfg,
            Variants {
                line_free: false,
                noise_free: false,
                ..Variants::default()
            },
        );
        assert!(any.iter().any(|(m, _)| m.kind == Kind::ModeDamping));
    }

    /// A rough road seen in a different band by each record: no band's median is beyond its
    /// limit, but two of four records are `road` on their own, so the drive is `road` (and says
    /// so); one of four leaves it `normal`; a vehicle alarm stays beside it (`both`).
    #[test]
    fn a_drive_whose_records_are_rough_in_different_bands_is_road() {
        let two_band = |l: [f64; 2], t: f64| {
            let mut r = record(1.0, t);
            r.bands_hz = vec![[2.0, 5.0], [5.0, 8.0]];
            r.channels[0].band_rms = vec![Some(l[0]), Some(l[1])];
            r.transmissibility[0].values = vec![Some(t), Some(t)];
            r
        };
        let recs: Vec<RecordFeatures> = (0..6)
            .map(|i| two_band([1.0 + 0.04 * i as f64; 2], 0.20 + 0.004 * i as f64))
            .collect();
        let names: Vec<String> = (0..6).map(|i| format!("n{i}")).collect();
        let set = build_model_set("bus", &names, &recs, &FleetConfig::default()).expect("set");
        let rough = 2.0 * 1.2 * (5.0 * set.config.floor_level).exp();
        let (a, b, ok) = (
            two_band([rough, 1.1], 0.21),
            two_band([1.1, rough], 0.21),
            two_band([1.1, 1.1], 0.21),
        );
        assert_eq!(assess(&set, &a).classification, Classification::Road);
        assert_eq!(assess(&set, &b).classification, Classification::Road);
        let drive = assess_drive(&set, &[&a, &b, &ok, &ok]);
        assert_eq!(drive.classification, Classification::Road, "{drive:?}");
        assert!(drive.evidence.is_empty(), "no band's median: {drive:?}");
        assert_eq!(
            drive.summary,
            "road: 2 of 4 records beyond the road's nominal levels on their own (road level 2-5 Hz in 1, road level 5-8 Hz in 1)"
        );
        let drive = assess_drive(&set, &[&a, &ok, &ok, &ok]);
        assert_eq!(drive.classification, Classification::Normal, "{drive:?}");
        // With a vehicle alarm of the medians: both.
        let (va, vb, vok) = (
            two_band([rough, 1.1], 0.105),
            two_band([1.1, rough], 0.105),
            two_band([1.1, 1.1], 0.105),
        );
        let drive = assess_drive(&set, &[&va, &vb, &vok, &vok]);
        assert_eq!(drive.classification, Classification::Both, "{drive:?}");
        assert!(
            drive.summary.starts_with("RL: transmissibility"),
            "{}",
            drive.summary
        );
        assert!(
            drive.summary.contains("; road: 2 of 4 records"),
            "{}",
            drive.summary
        );
    }

    /// A drive's value of a feature is the median over its records: one record in five moved
    /// (a vehicle alarm on its own) leaves the drive normal; three in five moved flag the drive
    /// with the median's score; a feature missing in more than half the records is missing.
    #[test]
    fn drive_is_scored_on_the_medians_by_hand() {
        let set = baseline();
        let ok = record(1.1, 0.21);
        let moved = record(1.1, 0.105);
        assert_eq!(assess(&set, &moved).classification, Classification::Vehicle);
        let one = [&moved, &ok, &ok, &ok, &ok];
        let a = assess_drive(&set, &one);
        assert_eq!(a.classification, Classification::Normal, "{a:?}");
        let three = [&moved, &ok, &moved, &ok, &moved];
        let a = assess_drive(&set, &three);
        assert_eq!(a.classification, Classification::Vehicle, "{a:?}");
        let single = assess(&set, &moved);
        assert!((a.evidence[0].z - single.evidence[0].z).abs() < 1e-12);
        assert!((a.evidence[0].value - 0.105).abs() < 1e-12);
        // Medians of an even count: the mean of the two middle logs.
        let four = [&moved, &moved, &ok, &ok];
        let a = assess_drive(&set, &four);
        let t = set
            .features
            .iter()
            .find(|f| f.meta.kind == Kind::Transmissibility)
            .expect("trans");
        let want = (0.5 * (0.105f64.ln() + 0.21f64.ln()) - t.centre) / t.sigma;
        assert!(
            (a.scores.vehicle_max_abs_z - want.abs()).abs() < 1e-12,
            "{a:?}"
        );
        let mut without = record(1.1, 0.105);
        without.transmissibility.clear();
        let a = assess_drive(&set, &[&without, &without, &without, &moved, &moved]);
        assert_eq!(a.classification, Classification::Normal, "{a:?}");
        assert_eq!(a.missing, vec!["RL: transmissibility 2-5 Hz".to_string()]);
        // Records with a failed sensor are left out of the medians and named.
        let mut dead = record(1.1, 0.105);
        dead.sensor_faults.push(crate::features::SensorFault {
            channel: "RL_sprung".into(),
            fault: crate::features::FaultKind::Dead,
            detail: "every sample is 0".into(),
        });
        let a = assess_drive(&set, &[&dead, &dead, &ok, &ok, &ok]);
        assert_eq!(a.classification, Classification::Normal, "{a:?}");
        assert!(
            a.summary.starts_with("sensor: 2 of 5 record(s) left out"),
            "{}",
            a.summary
        );
        let a = assess_drive(&set, &[&dead, &dead, &dead, &ok, &ok]);
        assert_eq!(a.classification, Classification::Sensor, "{a:?}");
    }

    #[test]
    fn records_without_body_spectra_give_no_body_response_and_say_so() {
        // The records of `baseline()` have no body spectra (as records stored before them).
        let set = baseline();
        assert!(set.body.is_none());
        assert!(
            set.notes
                .iter()
                .any(|n| n.contains("no body response to wheel motion: 0 of 6")),
            "{:?}",
            set.notes
        );
        assert!(!set
            .features
            .iter()
            .any(|f| f.meta.kind == Kind::BodyResponse));
        // A model set stored before the body response (no `body`, no `notes`) reads.
        let mut json = serde_json::to_value(&set).expect("json");
        if let Some(map) = json.as_object_mut() {
            map.remove("notes");
        }
        let back: ModelSet = serde_json::from_value(json).expect("old model set");
        assert!(back.body.is_none() && back.notes.is_empty());
    }

    /// A record whose body spectra come from the FIR system `b` of the body tests, with
    /// unsprung channels FL, FR, RL and sprung channels RL, RR.
    fn body_record(
        rng: &mut crate::body::tests::Rng,
        b: &[[[f64; crate::body::tests::TAPS]; 3]; 2],
        lag: usize,
    ) -> RecordFeatures {
        let mut s = crate::body::tests::fir_record(rng, b, lag);
        s.unsprung = vec![
            "FL_unsprung".into(),
            "FR_unsprung".into(),
            "RL_unsprung".into(),
        ];
        s.sprung = vec!["FR_sprung".into(), "RL_sprung".into()];
        let ch = |name: &str, role: Role, corner: Corner| ChannelFeatures {
            name: name.into(),
            role,
            corner: Some(corner),
            band_rms: vec![Some(1.0)],
            modes: Vec::new(),
            ratio_band_rms: None,
        };
        RecordFeatures {
            analysis_fs_hz: 50.0,
            duration_s: 10.24,
            n_segments: 1,
            bands_hz: vec![[2.0, 5.0]],
            channels: vec![
                ch("FL_unsprung", Role::Unsprung, Corner::FL),
                ch("FR_unsprung", Role::Unsprung, Corner::FR),
                ch("RL_unsprung", Role::Unsprung, Corner::RL),
                ch("FR_sprung", Role::Sprung, Corner::FR),
                ch("RL_sprung", Role::Sprung, Corner::RL),
            ],
            transmissibility: Vec::new(),
            notes: Vec::new(),
            body_spectra: Some(s),
            sensor_faults: Vec::new(),
            line_free: None,
            suspension: None,
            start_unix_s: None,
        }
    }

    #[test]
    fn a_weaker_body_response_is_flagged_on_its_corner() {
        let mut rng = crate::body::tests::Rng(0x5eed);
        let mut b = [[[0.0; crate::body::tests::TAPS]; 3]; 2];
        b.iter_mut()
            .flatten()
            .flatten()
            .for_each(|x| *x = rng.normal());
        let recs: Vec<RecordFeatures> = (0..8)
            .map(|r| body_record(&mut rng, &b, 3 + 2 * r))
            .collect();
        let names: Vec<String> = (0..8).map(|i| format!("n{i}")).collect();
        let cfg = FleetConfig {
            body_band_hz: [1.0, 10.0],
            body_response_bands_hz: vec![[2.0, 8.0]],
            ..FleetConfig::default()
        };
        let set = build_model_set("bus", &names, &recs, &cfg).expect("set");
        assert!(
            set.body.is_some() && set.notes.is_empty(),
            "{:?}",
            set.notes
        );
        let body: Vec<&FeatureStat> = set
            .features
            .iter()
            .filter(|f| f.meta.kind == Kind::BodyResponse)
            .collect();
        assert_eq!(body.len(), 2);
        for f in &body {
            // Leave-one-out values of an exact linear system: centred near 0, spread at the
            // floor.
            assert!(f.centre.abs() < 0.05 && f.sigma == 0.03, "{f:?}");
            assert!(f
                .meta
                .label
                .starts_with("body response to wheel motion 2-8 Hz vs the "));
        }
        // The same system: normal.
        let a = assess(&set, &body_record(&mut rng, &b, 6));
        assert_eq!(a.classification, Classification::Normal, "{a:?}");
        // Both body channels 20 % weaker (as a heavier load does): each relative to the other
        // axle is unchanged, so normal.
        let mut both = b;
        both.iter_mut().flatten().flatten().for_each(|x| *x *= 0.8);
        let a = assess(&set, &body_record(&mut rng, &both, 6));
        assert_eq!(a.classification, Classification::Normal, "{a:?}");
        // RL's body channel alone answers 20 % weaker (ln 0.64 = -0.45 in power, about -15
        // spreads): vehicle, RL down against the front axle and FR up against the rear.
        let mut weak = b;
        weak[1].iter_mut().flatten().for_each(|x| *x *= 0.8);
        let a = assess(&set, &body_record(&mut rng, &weak, 6));
        assert_eq!(a.classification, Classification::Vehicle, "{a:?}");
        assert!(
            a.summary
                .contains("RL: body response to wheel motion 2-8 Hz vs the front axle -3"),
            "{}",
            a.summary
        );
        assert!(
            a.summary
                .contains("FR: body response to wheel motion 2-8 Hz vs the rear axle +5"),
            "{}",
            a.summary
        );
    }

    #[test]
    fn too_few_nominal_records_is_an_error() {
        let recs: Vec<RecordFeatures> = (0..4).map(|_| record(1.0, 0.2)).collect();
        let e = build_model_set("bus", &[], &recs, &FleetConfig::default()).expect_err("4 < 5");
        assert!(e.to_string().contains("needs at least 5"), "{e}");
    }

    /// Four unsprung channels with levels `l` (FL, FR, RL, RR) in the ratio band.
    fn wheels(l: [f64; 4]) -> RecordFeatures {
        let channels = [Corner::FL, Corner::FR, Corner::RL, Corner::RR]
            .into_iter()
            .zip(l)
            .map(|(corner, level)| ChannelFeatures {
                name: format!("{corner}_unsprung"),
                role: Role::Unsprung,
                corner: Some(corner),
                band_rms: vec![Some(1.0)],
                modes: Vec::new(),
                ratio_band_rms: Some(level),
            })
            .collect();
        RecordFeatures {
            analysis_fs_hz: 50.0,
            duration_s: 10.0,
            n_segments: 1,
            bands_hz: vec![[2.0, 5.0]],
            channels,
            transmissibility: Vec::new(),
            notes: Vec::new(),
            body_spectra: None,
            sensor_faults: Vec::new(),
            line_free: None,
            suspension: None,
            start_unix_s: None,
        }
    }

    /// Four wheels' line-free levels `l` and their noise densities `d` (unit^2/Hz).
    fn noisy_wheels(l: [f64; 4], d: [f64; 4]) -> RecordFeatures {
        let mut r = wheels([1.0; 4]);
        r.line_free = Some(crate::features::LineFree {
            line_bins_hz: Vec::new(),
            h1: Vec::new(),
            ratio_band_rms: l.iter().map(|v| Some(*v)).collect(),
            noise_density: d.to_vec(),
            bins: None,
        });
        r
    }

    /// By hand, the band 8-20 Hz (12 Hz wide): FL's level 2 with a density 1/12 (noise power 1)
    /// becomes sqrt(4 - 1) = sqrt(3); RL's level 1 without noise stays 1; the left front/rear
    /// ratio is then ln sqrt(3) = 0.549 instead of ln 2. FR's level 1 with a noise power of
    /// 0.6 (> half its power) leaves the ratios with FR out.
    #[test]
    fn noise_power_comes_out_of_the_level_ratios_by_hand() {
        let cfg = FleetConfig::default();
        assert_eq!(cfg.ratio_band_hz, [8.0, 20.0]);
        assert_eq!(noise_free_level(2.0, 1.0), Some(3f64.sqrt()));
        assert_eq!(noise_free_level(2.0, 0.0), Some(2.0));
        assert_eq!(noise_free_level(1.0, 0.5), Some(0.5f64.sqrt()));
        assert_eq!(noise_free_level(1.0, 0.6), None);
        let r = noisy_wheels([2.0, 1.0, 1.0, 1.0], [1.0 / 12.0, 0.6 / 12.0, 0.0, 0.0]);
        let get = |noise_free: bool, key: &str| {
            scalar_features(
                &r,
                &[],
                None,
                &cfg,
                Variants {
                    line_free: true,
                    noise_free,
                    ..Variants::default()
                },
            )
            .into_iter()
            .find(|(m, _)| m.key == key)
            .map(|(_, v)| v)
        };
        let left = ratio_key(Kind::TrackRatio, "left", &cfg.ratio_band_hz, true);
        let right = ratio_key(Kind::TrackRatio, "right", &cfg.ratio_band_hz, true);
        let front = ratio_key(Kind::SideRatio, "front", &cfg.ratio_band_hz, true);
        let x = get(true, &left).unwrap_or(f64::NAN);
        assert!((x - 0.5 * 3f64.ln()).abs() < 1e-12, "{x}");
        assert_eq!(get(false, &left), Some(2f64.ln()));
        assert_eq!(get(true, &right), None);
        assert_eq!(get(true, &front), None);
        assert_eq!(get(false, &right), Some(0.0));
        // A record without densities (stored before them) keeps its levels.
        let mut old = r.clone();
        if let Some(lf) = old.line_free.as_mut() {
            lf.noise_density.clear();
        }
        let x = scalar_features(
            &old,
            &[],
            None,
            &cfg,
            Variants {
                line_free: true,
                noise_free: true,
                ..Variants::default()
            },
        )
        .into_iter()
        .find(|(m, _)| m.key == left)
        .map(|(_, v)| v);
        assert_eq!(x, Some(2f64.ln()));
    }

    /// A model set is noise-free when every nominal record has the densities; one record without
    /// them (stored before) leaves the whole set as it was.
    #[test]
    fn a_model_set_takes_the_noise_out_only_when_every_record_has_it() {
        let cfg = FleetConfig::default();
        let recs: Vec<RecordFeatures> = (0..6)
            .map(|i| noisy_wheels([1.0 + 0.01 * i as f64, 1.0, 1.0, 1.0], [0.01; 4]))
            .collect();
        let names: Vec<String> = (0..6).map(|i| format!("n{i}")).collect();
        let set = build_model_set("v", &names, &recs, &cfg).expect("set");
        assert!(set.line_free && set.noise_free);
        let mut older = recs.clone();
        if let Some(lf) = older[3].line_free.as_mut() {
            lf.noise_density.clear();
        }
        let set = build_model_set("v", &names, &older, &cfg).expect("set");
        assert!(set.line_free && !set.noise_free);
        // A model set stored before the flag reads as not noise-free.
        let mut json = serde_json::to_value(&set).expect("json");
        if let Some(o) = json.as_object_mut() {
            o.remove("noise_free");
        }
        let back: ModelSet = serde_json::from_value(json).expect("old set");
        assert!(!back.noise_free);
    }

    #[test]
    fn records_stored_before_the_ratios_read_and_score_without_them() {
        // JSON of a channel as stored before `ratio_band_rms` existed.
        let json =
            r#"{"name":"FL_unsprung","role":"unsprung","corner":"FL","band_rms":[1.0],"modes":[]}"#;
        let ch: ChannelFeatures = serde_json::from_str(json).expect("old channel");
        assert_eq!(ch.ratio_band_rms, None);
        // A model set with the ratios scores a record without them as missing, not as moved.
        let recs: Vec<RecordFeatures> = (0..6)
            .map(|i| wheels([1.0 + 0.01 * i as f64, 1.0, 1.0, 1.0]))
            .collect();
        let names: Vec<String> = (0..6).map(|i| format!("n{i}")).collect();
        let set = build_model_set("bus", &names, &recs, &FleetConfig::default()).expect("set");
        let mut old = wheels([1.0; 4]);
        for c in &mut old.channels {
            c.ratio_band_rms = None;
        }
        let a = assess(&set, &old);
        assert_eq!(a.classification, Classification::Normal);
        assert_eq!(a.missing.len(), 4, "{:?}", a.missing);
        assert!(a
            .missing
            .contains(&"FL_unsprung/FR_unsprung: FL/FR level 8-20 Hz".to_string()));
    }

    #[test]
    fn ratio_spreads_are_pooled_by_hand() {
        // FL level exp(d) with d = 0, 0.1, ..., 0.5, the others 1: ln(FL/FR) = ln(FL/RL) = d,
        // ln(RL/RR) = ln(FR/RR) = 0. Deviations from each feature's median (0.25 and 0):
        // +-0.05, +-0.15, +-0.25 and six zeros; their median is 0, the median of the absolute
        // values (0 x 6, 0.05, 0.05, 0.15, ...) is (0 + 0.05) / 2 = 0.025.
        let recs: Vec<RecordFeatures> = (0..6)
            .map(|i| wheels([(0.1 * i as f64).exp(), 1.0, 1.0, 1.0]))
            .collect();
        let cfg = FleetConfig {
            floor_side_ratio: 1e-3,
            floor_track_ratio: 1e-3,
            ..FleetConfig::default()
        };
        let names: Vec<String> = (0..6).map(|i| format!("n{i}")).collect();
        let set = build_model_set("bus", &names, &recs, &cfg).expect("model set");
        for key in ["side:front:8-20Hz", "side:rear:8-20Hz", "track:left:8-20Hz"] {
            let f = set
                .features
                .iter()
                .find(|f| f.meta.key == key)
                .expect("ratio feature");
            // Unpooled, ln(FL/FR) alone would have 1.4826 x 0.15.
            assert!(
                (f.sigma - MAD_TO_SIGMA * 0.025).abs() < 1e-12,
                "{key}: {}",
                f.sigma
            );
        }
        let front = set
            .features
            .iter()
            .find(|f| f.meta.key == "side:front:8-20Hz")
            .expect("front");
        assert!((front.centre - 0.25).abs() < 1e-12);
        assert_eq!(front.meta.label, "FL/FR level 8-20 Hz");
        // With the default floors: 0.10 takes over, 0.03 does not.
        let set = build_model_set("bus", &names, &recs, &FleetConfig::default()).expect("set");
        let sigma = |key: &str| {
            set.features
                .iter()
                .find(|f| f.meta.key == key)
                .map_or(f64::NAN, |f| f.sigma)
        };
        assert_eq!(sigma("side:rear:8-20Hz"), 0.10);
        assert!((sigma("track:right:8-20Hz") - MAD_TO_SIGMA * 0.025).abs() < 1e-12);
    }

    #[test]
    fn a_wheel_station_fault_is_named_by_its_two_ratios() {
        // Nominal: levels within +-2 % of 1 (a different pattern per record).
        let recs: Vec<RecordFeatures> = (0..8)
            .map(|i| {
                let e = |k: usize| 1.0 + 0.02 * (((i * 3 + k * 5) % 7) as f64 / 3.0 - 1.0);
                wheels([e(0), e(1), e(2), e(3)])
            })
            .collect();
        let names: Vec<String> = (0..8).map(|i| format!("n{i}")).collect();
        let set = build_model_set("bus", &names, &recs, &FleetConfig::default()).expect("set");
        // A rougher road: every wheel 3x; the ratios do not move.
        let a = assess(&set, &wheels([3.0, 3.0, 3.0, 3.0]));
        assert_eq!(a.classification, Classification::Normal, "{a:?}");
        // FL 40 % lower (a softer tyre): FL/FR and FL/RL move, both named FL.
        let a = assess(&set, &wheels([0.6, 1.0, 1.0, 1.0]));
        assert_eq!(a.classification, Classification::Vehicle, "{a:?}");
        assert!(a.summary.starts_with("FL: level vs "), "{}", a.summary);
        assert!(!a.summary.contains("RL:") && !a.summary.contains("FR:"));
        for e in &a.evidence {
            assert_eq!(e.meta.corner, Some(Corner::FL));
            assert!((e.value - 0.6).abs() < 1e-12, "{e:?}");
            assert!((e.change_pct - 100.0 * (0.6 / e.centre - 1.0)).abs() < 1e-9);
        }
        // RL 50 % higher (a weak damper): FL/RL and RL/RR move; read from RL, +50 %.
        let a = assess(&set, &wheels([1.0, 1.0, 1.5, 1.0]));
        assert_eq!(a.classification, Classification::Vehicle, "{a:?}");
        assert!(a.summary.starts_with("RL: level vs "), "{}", a.summary);
        let e = a
            .evidence
            .iter()
            .find(|e| e.meta.kind == Kind::TrackRatio)
            .expect("track ratio flagged");
        assert_eq!(e.meta.label, "level vs FL 8-20 Hz");
        assert!((e.value - 1.5).abs() < 1e-12 && e.z > 0.0, "{e:?}");
        // Without the right-hand channels only the left track's ratio exists: flagged, it
        // stays on its channel pair (no corner, so no component).
        let mut r = wheels([0.6, 1.0, 1.0, 1.0]);
        r.channels
            .retain(|c| matches!(c.corner, Some(Corner::FL | Corner::RL)));
        let a = assess(&set, &r);
        assert_eq!(a.classification, Classification::Vehicle, "{a:?}");
        assert!(
            a.summary
                .starts_with("FL_unsprung/RL_unsprung: FL/RL level 8-20 Hz -"),
            "{}",
            a.summary
        );
        assert_eq!(a.component, None);
    }

    #[test]
    fn the_wheel_a_ratio_is_charged_to_by_hand() {
        let w = |other_z: Option<f64>, own: f64| WheelEvidence { other_z, own };
        // Neither wheel's own features flagged: the further other ratio (the rule before),
        // whatever the odds.
        assert!(charge_to_first(w(Some(1.8), 0.0), w(Some(1.5), 0.0), 3.2));
        assert!(!charge_to_first(w(Some(1.5), 0.0), w(Some(1.8), 0.0), 3.2));
        assert!(charge_to_first(w(None, 0.0), w(Some(-0.5), 0.0), 3.2));
        // Bus 43872's RL damper (FL/RL -27 %, 0.32 in ln, 3.2 side-ratio spreads): FL's other
        // ratio 1.8, RL's 1.5, log-odds 0.96 for FL; RL's transmissibility flagged at 1.3
        // limits, FL has no feature of its own: RL.
        assert!(!charge_to_first(w(Some(1.8), 0.0), w(Some(1.5), 1.3), 3.2));
        // Log-odds (1.8 - 0.8) x 3.2 = 3.2, above ln 20 = 3.0: the ratios decide.
        assert!(charge_to_first(w(Some(1.8), 0.0), w(Some(0.8), 1.3), 3.2));
        // 2.8 below it: the own features.
        assert!(!charge_to_first(
            w(Some(1.8), 0.0),
            w(Some(0.925), 1.3),
            3.2
        ));
        // Both corners' own features flagged, the ratios undecided: the stronger.
        assert!(charge_to_first(w(Some(0.2), 2.0), w(Some(0.5), 1.1), 3.2));
        assert!(!charge_to_first(w(Some(0.5), 1.1), w(Some(0.2), 2.0), 3.2));
        // Busgen bus 43872's RR tyre, one record: RR's other ratio 3.2 spreads, FR's 0.5, the
        // flagged ratio 6.1 track spreads (3.2 side spreads): log-odds 8.6, so FR's lone
        // transmissibility flag (1.5 limits) does not take it.
        assert!(!charge_to_first(w(Some(0.5), 1.5), w(Some(3.2), 0.0), 3.2));
    }

    /// Four wheels with levels `l` and a wheel-hop mode each at `f` Hz (FL, FR, RL, RR).
    fn wheels_with_modes(l: [f64; 4], f: [f64; 4]) -> RecordFeatures {
        let mut r = wheels(l);
        for (c, f) in r.channels.iter_mut().zip(f) {
            c.modes = vec![ModeEstimate {
                frequency_hz: f,
                damping_ratio: 0.2,
            }];
        }
        r
    }

    #[test]
    fn a_ratio_goes_to_the_wheel_whose_own_features_moved() {
        let recs: Vec<RecordFeatures> = (0..8)
            .map(|i| {
                let e = |k: usize| 1.0 + 0.02 * (((i * 3 + k * 5) % 7) as f64 / 3.0 - 1.0);
                wheels_with_modes([e(0), e(1), e(2), e(3)], [10.0 * e(1); 4])
            })
            .collect();
        let names: Vec<String> = (0..8).map(|i| format!("n{i}")).collect();
        // A frequency floor below the nominal scatter (0.02 in ln), so that a wheel hop within
        // the match tolerance (15 %) can pass its limit.
        let cfg = FleetConfig {
            floor_frequency: 0.01,
            ..FleetConfig::default()
        };
        let set = build_model_set("bus", &names, &recs, &cfg).expect("set");
        let nominal = [10.0; 4];
        // FL 15 % lower and RL 15 % higher: FL/RL moves by ln(0.85 / 1.15) = -0.30, flagged;
        // the other ratios, FL/FR -0.16 and RL/RR +0.14 (spread 0.10), stay within their
        // limits, FL's a little further: the ratio alone goes to FL.
        let levels = [0.85, 1.0, 1.15, 1.0];
        let a = assess(&set, &wheels_with_modes(levels, nominal));
        assert!(a.summary.starts_with("FL: level vs RL"), "{}", a.summary);
        // RL's wheel hop 11 % lower as well (ln 0.89 / 0.015 = -8 spreads, flagged): RL.
        let a = assess(&set, &wheels_with_modes(levels, [10.0, 10.0, 8.9, 10.0]));
        assert!(
            a.evidence
                .iter()
                .any(|e| e.meta.kind == Kind::ModeFrequency && e.meta.corner == Some(Corner::RL)),
            "{}",
            a.summary
        );
        let e = a
            .evidence
            .iter()
            .find(|e| e.meta.kind == Kind::TrackRatio)
            .expect("track ratio flagged");
        assert_eq!(e.meta.corner, Some(Corner::RL), "{}", a.summary);
        assert_eq!(e.meta.label, "level vs FL 8-20 Hz");
        assert!(e.z > 0.0 && (e.value - 1.15 / 0.85).abs() < 1e-12, "{e:?}");
        // FL 45 % lower: FL/FR -6 spreads (ln 0.55 / 0.10), RL/RR +1.4, the flagged FL/RL
        // ln(0.55 / 1.15) = -0.74, 7.4 side-ratio spreads: log-odds (6 - 1.4) x 7.4 = 34 for FL,
        // so the ratios decide, whatever RL's wheel hop says.
        let a = assess(
            &set,
            &wheels_with_modes([0.55, 1.0, 1.15, 1.0], [10.0, 10.0, 8.9, 10.0]),
        );
        let e = a
            .evidence
            .iter()
            .find(|e| e.meta.kind == Kind::TrackRatio)
            .expect("track ratio flagged");
        assert_eq!(e.meta.corner, Some(Corner::FL), "{}", a.summary);
    }

    /// Nominal wheel levels within +-2 % of 1, a different pattern per record.
    fn wheel_set() -> ModelSet {
        let recs: Vec<RecordFeatures> = (0..8)
            .map(|i| {
                let e = |k: usize| 1.0 + 0.02 * (((i * 3 + k * 5) % 7) as f64 / 3.0 - 1.0);
                wheels([e(0), e(1), e(2), e(3)])
            })
            .collect();
        let names: Vec<String> = (0..8).map(|i| format!("n{i}")).collect();
        build_model_set("bus", &names, &recs, &FleetConfig::default()).expect("set")
    }

    #[test]
    fn the_component_follows_the_direction_of_the_wheel_level() {
        let set = wheel_set();
        // A healthy record: no vehicle evidence, no component.
        let a = assess(&set, &wheels([3.0, 3.0, 3.0, 3.0]));
        assert_eq!(
            (a.classification, a.component),
            (Classification::Normal, None)
        );
        // FL 40 % lower: the tyre; RL 50 % higher: the damper.
        let a = assess(&set, &wheels([0.6, 1.0, 1.0, 1.0]));
        assert_eq!(a.component, Some(Component::Tyre), "{a:?}");
        let a = assess(&set, &wheels([1.0, 1.0, 1.5, 1.0]));
        assert_eq!(a.component, Some(Component::Damper), "{a:?}");
        // JSON: `component` beside the classification; an assessment stored before it existed
        // reads as none.
        let json = serde_json::to_value(&a).expect("json");
        assert_eq!(json["component"], "damper");
        let mut old = json.clone();
        old.as_object_mut().expect("object").remove("component");
        let back: Assessment = serde_json::from_value(old).expect("old assessment");
        assert_eq!(back.component, None);
    }

    /// A flagged body response of `corner` with score `z`.
    fn body_evidence(corner: Corner, z: f64) -> Evidence {
        Evidence {
            meta: FeatureMeta {
                key: format!("body:{corner}_sprung:2-4Hz"),
                group: Group::Vehicle,
                kind: Kind::BodyResponse,
                corner: Some(corner),
                channel: format!("{corner}_sprung"),
                label: "body response to wheel motion 2-4 Hz vs the front axle".into(),
            },
            value: 1.0,
            centre: 1.0,
            z,
            change_pct: 0.0,
            limit: 4.0,
            flagged: true,
            spread_widened_by: None,
        }
    }

    #[test]
    fn a_lowered_body_response_is_the_spring_only_when_the_wheel_level_is_not_raised() {
        let set = wheel_set();
        let cfg = &set.config;
        let values =
            |l: [f64; 4]| scalar_features(&wheels(l), &set.slots, None, cfg, set.variants());
        let lowered = [body_evidence(Corner::RL, -6.0)];
        // The wheel levels as nominal: the spring.
        assert_eq!(
            component(&set, &values([1.0; 4]), &EstimateVariances::new(), &lowered),
            Some(Component::Spring)
        );
        // RL's level 8 % up: against FL (nominal centre ln(FL/RL) = -0.020, pooled spread
        // 0.035) (0.077 - 0.020) / 0.035 = 1.6 spreads above, below the limit (the record alone
        // is normal) but above SPRING_MAX_LEVEL_Z: a weak damper cannot be excluded.
        assert_eq!(
            assess(&set, &wheels([1.0, 1.0, 1.08, 1.0])).classification,
            Classification::Normal
        );
        assert_eq!(
            component(
                &set,
                &values([1.0, 1.0, 1.08, 1.0]),
                &EstimateVariances::new(),
                &lowered
            ),
            Some(Component::Suspension)
        );
        // RL's level 2 % down (within the scatter): still the spring.
        assert_eq!(
            component(
                &set,
                &values([1.0, 1.0, 0.98, 1.0]),
                &EstimateVariances::new(),
                &lowered
            ),
            Some(Component::Spring)
        );
        // Without the wheel levels it cannot tell the spring from the damper.
        assert_eq!(
            component(&set, &[], &EstimateVariances::new(), &lowered),
            Some(Component::Suspension)
        );
        // A raised body response is no spring sign.
        assert_eq!(
            component(
                &set,
                &values([1.0; 4]),
                &EstimateVariances::new(),
                &[body_evidence(Corner::RL, 6.0)]
            ),
            Some(Component::Suspension)
        );
        // Nothing flagged: nothing named.
        assert_eq!(
            component(&set, &values([1.0; 4]), &EstimateVariances::new(), &[]),
            None
        );
    }
}

/// The estimate variances of the level ratios and the transmissibility (records judged against
/// the scatter their own noise gives them).
#[cfg(test)]
mod variance_tests {
    use super::*;
    use vibmode_spectra::{band_rms, WelchParams, Window};

    /// A seeded standard normal generator (xorshift64 and Box-Muller).
    fn normal_source(seed: u64) -> impl FnMut() -> f64 {
        let mut state: u64 = 0x9e37_79b9_7f4a_7c15 ^ seed.wrapping_mul(0x2545_f491_4f6c_dd1d);
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        move || {
            let (a, b) = (uniform().max(1e-300), uniform());
            (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
        }
    }

    fn welch_params() -> WelchParams {
        WelchParams {
            window: Window::Hann,
            nperseg: Some(256),
            ..WelchParams::default()
        }
    }

    fn var(x: &[f64]) -> f64 {
        let m = x.iter().sum::<f64>() / x.len() as f64;
        x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (x.len() - 1) as f64
    }

    /// By hand: 62 bins (8-20 Hz at 50/256 Hz) of 3 segments: 62 x 3 / (35/18 x (1 + 2/36))
    /// = 90.62; one segment of one bin: 18/35 / (1 + 1/18).
    #[test]
    fn welch_band_cells_by_hand() {
        assert!(
            (welch_band_cells(62, 3) - 186.0 / (35.0 / 18.0 * (1.0 + 2.0 / 36.0))).abs() < 1e-9
        );
        assert!((welch_band_cells(62, 3) - 90.62).abs() < 0.01);
        assert!((welch_band_cells(1, 0) - welch_band_cells(1, 1)).abs() < 1e-15);
    }

    /// Over 1500 seeds of white noise (512 samples at 50 Hz, one 10.24 s record of the fleet's
    /// analysis): the relative variance of the Welch band sum over 8-20 Hz is `1 / cells`
    /// within 12 % (the estimate's own sampling error is about 4 %); duration x bandwidth
    /// would be 36 % low. scipy.signal.welch gives 0.0111 over 4000 seeds
    /// (tools/reference/welch_band_variance.py).
    #[test]
    fn welch_band_cells_match_the_band_sums_variance_over_seeds() {
        let mut normal = normal_source(1);
        let wp = welch_params();
        let mut sums = Vec::new();
        let mut bins = 0;
        for _ in 0..1500 {
            let x: Vec<f64> = (0..512).map(|_| normal()).collect();
            let w = vibmode_spectra::welch(&x, 50.0, &wp).unwrap();
            let keep: Vec<usize> = (0..w.freq_hz.len())
                .filter(|&k| w.freq_hz[k] >= 8.0 && w.freq_hz[k] <= 20.0)
                .collect();
            bins = keep.len();
            sums.push(keep.iter().map(|&k| w.psd[k]).sum::<f64>());
        }
        let mean = sums.iter().sum::<f64>() / sums.len() as f64;
        let rel = var(&sums) / (mean * mean);
        assert_eq!(bins, 62);
        let want = 1.0 / welch_band_cells(bins, 3);
        assert!(
            (rel / want - 1.0).abs() < 0.12,
            "relative variance {rel}, formula {want}"
        );
        assert!(rel > 1.2 / (10.24 * 12.0), "{rel}");
    }

    /// By hand: level 2 (power 4), noise power 1, 100 cells: Ps = 3, (1 + 6) / (4 x 100 x 9)
    /// = 7/3600; without noise 0; noise above half the power, or no cells: none.
    #[test]
    fn noise_free_level_variance_by_hand() {
        let v = noise_free_level_variance(2.0, 1.0, 100.0).unwrap_or(f64::NAN);
        assert!((v - 7.0 / 3600.0).abs() < 1e-15, "{v}");
        assert_eq!(noise_free_level_variance(2.0, 0.0, 100.0), Some(0.0));
        assert_eq!(noise_free_level_variance(2.0, 2.5, 100.0), None);
        assert_eq!(noise_free_level_variance(2.0, 1.0, 0.0), None);
        assert_eq!(noise_free_level_variance(f64::NAN, 1.0, 10.0), None);
    }

    /// One wheel signal (a fixed realisation) with fresh sensor noise per seed, 600 seeds, at
    /// noise shares of 10 % and 33 % of the 8-20 Hz band power: the spread of ln(noise-free
    /// level) over the seeds is [`noise_free_level_variance`]'s within 20 %, so a smoother
    /// road's record is judged against the scatter its noise gives it. The noise-free level's
    /// mean stays within 2 % of the wheel's own level (no bias).
    #[test]
    fn noise_free_level_variance_matches_the_scatter_over_seeds() {
        let wp = welch_params();
        let mut wheel_source = normal_source(99);
        let wheel: Vec<f64> = (0..512).map(|_| wheel_source()).collect();
        let ww = vibmode_spectra::welch(&wheel, 50.0, &wp).unwrap();
        let ps = band_rms(&ww.freq_hz, &ww.psd, 8.0, 20.0).powi(2);
        for (seed, noise_sd) in [(7u64, 0.33), (8, 0.7)] {
            let density = 2.0 * noise_sd * noise_sd / 50.0;
            let pn = density * 12.0;
            let mut normal = normal_source(seed);
            let mut logs = Vec::new();
            let mut predicted = Vec::new();
            for _ in 0..600 {
                let x: Vec<f64> = wheel.iter().map(|w| w + noise_sd * normal()).collect();
                let w = vibmode_spectra::welch(&x, 50.0, &wp).unwrap();
                let level = band_rms(&w.freq_hz, &w.psd, 8.0, 20.0);
                let Some(l) = noise_free_level(level, pn) else {
                    continue;
                };
                logs.push(l.ln());
                predicted
                    .push(noise_free_level_variance(level, pn, welch_band_cells(62, 3)).unwrap());
            }
            assert!(logs.len() > 590);
            let got = var(&logs);
            let want = predicted.iter().sum::<f64>() / predicted.len() as f64;
            assert!(
                (got / want - 1.0).abs() < 0.2,
                "noise sd {noise_sd}: scatter {got}, formula {want}"
            );
            let mean = logs.iter().sum::<f64>() / logs.len() as f64;
            assert!(
                (mean - 0.5 * ps.ln()).abs() < 0.02,
                "noise sd {noise_sd}: mean {mean}, wheel {}",
                0.5 * ps.ln()
            );
        }
    }

    /// Two corners (RL, RR) with per-bin parts in 2-5 Hz (bins 2, 3, 4, 5 Hz, 3 segments): input
    /// `[1, 2, 2, 1]` and coherent power `t^2` times it, the unsprung channels' noise densities
    /// `density`.
    fn two_corners(t: [f64; 2], density: [f64; 2]) -> RecordFeatures {
        let input = vec![1.0, 2.0, 2.0, 1.0];
        let corners = [Corner::RL, Corner::RR];
        let bins = crate::features::TransmissibilityBins {
            freq_hz: vec![2.0, 3.0, 4.0, 5.0],
            coherent: t
                .iter()
                .map(|t| input.iter().map(|p| t * t * p).collect())
                .collect(),
            input: vec![input.clone(), input.clone()],
            output: Vec::new(),
            segments: 3,
        };
        RecordFeatures {
            analysis_fs_hz: 50.0,
            duration_s: 10.24,
            n_segments: 1,
            bands_hz: vec![[2.0, 5.0]],
            channels: corners
                .iter()
                .map(|c| crate::features::ChannelFeatures {
                    name: format!("{c}_unsprung"),
                    role: Role::Unsprung,
                    corner: Some(*c),
                    band_rms: vec![Some(1.0)],
                    modes: Vec::new(),
                    ratio_band_rms: None,
                })
                .collect(),
            transmissibility: corners
                .iter()
                .map(|c| crate::features::CornerTransmissibility {
                    corner: *c,
                    sprung: format!("{c}_sprung"),
                    unsprung: format!("{c}_unsprung"),
                    values: vec![Some(1.0)],
                    h1: Vec::new(),
                })
                .collect(),
            notes: Vec::new(),
            body_spectra: None,
            sensor_faults: Vec::new(),
            line_free: Some(crate::features::LineFree {
                noise_density: density.to_vec(),
                bins: Some(bins),
                ..crate::features::LineFree::default()
            }),
            suspension: None,
            start_unix_s: None,
        }
    }

    /// By hand: input sums to 6 over the four bins, coherent power 0.25 x 6 = 1.5: H1 =
    /// sqrt(1.5 / 6) = 0.5. With a noise density 0.5 the band's noise is 4 x 0.5 = 2 of the 6
    /// (a third): sqrt(1.5 x 6 / 4 / 4) = 0.75; with 1 (4 of 6, above half): none.
    #[test]
    fn band_value_noise_free_by_hand() {
        let r = two_corners([0.5, 0.5], [0.5, 0.5]);
        let bins = r.line_free.as_ref().and_then(|l| l.bins.as_ref()).unwrap();
        assert_eq!(bins.band_value(0, [2.0, 5.0], &[]), Some(0.5));
        let v = bins.band_value_noise_free(0, [2.0, 5.0], &[], 0.5, NOISE_SHARE_MAX);
        assert!((v.unwrap_or(f64::NAN) - 0.75).abs() < 1e-15, "{v:?}");
        assert_eq!(
            bins.band_value_noise_free(0, [2.0, 5.0], &[], 0.0, 0.5),
            Some(0.5)
        );
        assert_eq!(
            bins.band_value_noise_free(0, [2.0, 5.0], &[], 1.0, 0.5),
            None
        );
        assert_eq!(bins.band_bins([2.0, 5.0], &[&[3.0]]), 3);
    }

    /// A record whose other corner's wheel is below its noise (RR: density 1, two thirds of
    /// its input) gives no relative transmissibility in the band, not RL's own value under the
    /// relative feature's key (ln 0.75 scored against relative values near 0: -93 % on busgen's
    /// slow drives before); with both corners' inputs above their noise both are relative.
    #[test]
    fn one_corner_left_in_a_band_gives_no_relative_transmissibility() {
        let cfg = FleetConfig::default();
        let features = |r: &RecordFeatures, input_noise_free: bool| {
            transmissibility_features(r, &cfg, true, Some((&[], input_noise_free)))
        };
        let quiet = two_corners([0.5, 0.5], [0.5, 1.0]);
        assert!(
            features(&quiet, true).is_empty(),
            "{:?}",
            features(&quiet, true)
        );
        assert_eq!(features(&quiet, false).len(), 2);
        let both = two_corners([0.5, 0.25], [0.5, 0.0]);
        let got = features(&both, true);
        assert_eq!(got.len(), 2);
        // RL 0.75, RR 0.25: RL is ln 3 above the other corner, RR ln 3 below.
        assert!((got[0].1 - 3f64.ln()).abs() < 1e-12, "{got:?}");
        assert!((got[1].1 + 3f64.ln()).abs() < 1e-12, "{got:?}");
    }

    /// Over 100 seeds of 102.4 s (39 segments, so that the finite-average leak of
    /// [`h1_log_variance`] is small): the wheel's input white (sd 1) measured with sensor noise
    /// of sd 0.7 (a third of the measured input), the body's `y = 0.5 u + e` (e of sd 0.05).
    /// The H1 estimate over 2-20 Hz comes out about 0.5 / (1 + 0.49) = 0.34 (the noise share
    /// lowers it); with the known noise density taken out of the input, its mean of ln is
    /// within 5 % of ln 0.5.
    #[test]
    fn the_input_noise_comes_out_of_the_transmissibility_over_seeds() {
        let wp = welch_params();
        let mut normal = normal_source(3);
        let (mut raw, mut free) = (Vec::new(), Vec::new());
        let density = 2.0 * 0.49 / 50.0;
        for _ in 0..100 {
            let u: Vec<f64> = (0..5120).map(|_| normal()).collect();
            let um: Vec<f64> = u.iter().map(|x| x + 0.7 * normal()).collect();
            let y: Vec<f64> = u.iter().map(|x| 0.5 * x + 0.05 * normal()).collect();
            let pu = vibmode_spectra::welch(&um, 50.0, &wp).unwrap();
            let c = vibmode_spectra::csd(&um, &y, 50.0, &wp).unwrap();
            let bins = crate::features::TransmissibilityBins {
                freq_hz: pu.freq_hz.clone(),
                coherent: vec![c
                    .csd
                    .iter()
                    .zip(&pu.psd)
                    .map(|(z, p)| z.norm_sqr() / p)
                    .collect()],
                input: vec![pu.psd.clone()],
                output: Vec::new(),
                segments: 39,
            };
            raw.push(bins.band_value(0, [2.0, 20.0], &[]).unwrap().ln());
            free.push(
                bins.band_value_noise_free(0, [2.0, 20.0], &[], density, NOISE_SHARE_MAX)
                    .unwrap()
                    .ln(),
            );
        }
        let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
        assert!(
            (mean(&raw) - (0.5f64 / 1.49).ln()).abs() < 0.05,
            "raw {}",
            mean(&raw).exp()
        );
        assert!(
            (mean(&free) - 0.5f64.ln()).abs() < 0.05,
            "noise-free {}",
            mean(&free).exp()
        );
    }

    /// By hand: coherence 0.5 from 19 segments (K = 18 averages) over 100 cells: q = 1,
    /// (2 + 1/18) / (400 (1 + 1/18)^2) = 0.0046122; coherence 1: 0; coherence 0: K / (4 x 100)
    /// = 0.045; no cells, no segments or a NaN: none.
    #[test]
    fn h1_log_variance_by_hand() {
        let k = 19.0 / HANN_HALF_OVERLAP_VARIANCE;
        assert!((k - 18.0).abs() < 1e-12);
        let v = h1_log_variance(0.5, 19, 100.0).unwrap_or(f64::NAN);
        let want = (2.0 + 1.0 / 18.0) / (400.0 * (1.0f64 + 1.0 / 18.0).powi(2));
        assert!(
            (v - want).abs() < 1e-15 && (v - 0.0046122).abs() < 1e-7,
            "{v}"
        );
        assert_eq!(h1_log_variance(1.0, 19, 100.0), Some(0.0));
        assert!((h1_log_variance(0.0, 19, 100.0).unwrap_or(f64::NAN) - 0.045).abs() < 1e-15);
        assert_eq!(h1_log_variance(0.5, 19, 0.0), None);
        assert_eq!(h1_log_variance(0.5, 0, 10.0), None);
        assert_eq!(h1_log_variance(f64::NAN, 19, 10.0), None);
    }

    /// Over 600 seeds of one 10.24 s record at 50 Hz (3 Welch segments): `y = 0.5 u + e` at
    /// coherences 0.2 and 0.8; the scatter of ln H1 over 2-20 Hz is [`h1_log_variance`]'s at
    /// the band's [`welch_band_cells`] within 20 % (sampling error of the scatter about 6 %);
    /// Bendat and Piersol's large-sample formula would be 3.6 times too large at 0.2.
    #[test]
    fn h1_log_variance_matches_the_scatter_over_seeds() {
        let wp = welch_params();
        for (seed, e_sd) in [(11u64, 1.0), (12, 0.25)] {
            let gamma2 = 0.25 / (0.25 + e_sd * e_sd);
            let mut normal = normal_source(seed);
            let mut logs = Vec::new();
            let mut bins_in = 0;
            for _ in 0..600 {
                let u: Vec<f64> = (0..512).map(|_| normal()).collect();
                let y: Vec<f64> = u.iter().map(|x| 0.5 * x + e_sd * normal()).collect();
                let pu = vibmode_spectra::welch(&u, 50.0, &wp).unwrap();
                let c = vibmode_spectra::csd(&u, &y, 50.0, &wp).unwrap();
                let sus: Vec<(f64, f64)> = c.csd.iter().map(|z| (z.re, z.im)).collect();
                let h = crate::features::h1_band_values(&pu.freq_hz, &sus, &pu.psd, &[[2.0, 20.0]]);
                logs.push(h[0].unwrap().ln());
                bins_in = pu
                    .freq_hz
                    .iter()
                    .filter(|&&f| (2.0..=20.0).contains(&f))
                    .count();
            }
            let got = var(&logs);
            let want = h1_log_variance(gamma2, 3, welch_band_cells(bins_in, 3)).unwrap();
            assert!(
                (got / want - 1.0).abs() < 0.2,
                "coherence {gamma2}: scatter {got}, formula {want}"
            );
            let bendat_piersol = (1.0 - gamma2) / (2.0 * gamma2 * welch_band_cells(bins_in, 3));
            if gamma2 < 0.5 {
                assert!(bendat_piersol > 2.5 * got, "{bendat_piersol} {got}");
            }
        }
    }

    /// By hand: sigma 0.05 and a nominal estimate variance 0.001; a record's 0.01 widens it to
    /// sqrt(0.0025 + 0.009) = 0.1072; one below the nominal's, or none, keeps 0.05; a model set
    /// without the nominal variance keeps 0.05 for any record.
    #[test]
    fn spread_by_hand() {
        let mut f = FeatureStat {
            meta: FeatureMeta {
                key: "k".into(),
                group: Group::Vehicle,
                kind: Kind::TrackRatio,
                corner: None,
                channel: "c".into(),
                label: "l".into(),
            },
            centre: 0.0,
            sigma: 0.05,
            lo: -0.1,
            hi: 0.1,
            n: 8,
            estimate_var: Some(0.001),
        };
        assert!((f.spread(Some(0.01)) - 0.0115f64.sqrt()).abs() < 1e-15);
        assert_eq!(f.spread(Some(0.0005)), 0.05);
        assert_eq!(f.spread(None), 0.05);
        assert_eq!(f.spread(Some(f64::NAN)), 0.05);
        f.estimate_var = None;
        assert_eq!(f.spread(Some(0.01)), 0.05);
    }

    /// By hand: a drive of 4 records with a feature's variances 0.01, 0.02, 0.03, 0.05 has the
    /// median's `pi / 2 x 0.025 / 4`; a feature one of whose records has no variance gets none.
    #[test]
    fn drive_noise_by_hand() {
        let meta = |key: &str| FeatureMeta {
            key: key.into(),
            group: Group::Vehicle,
            kind: Kind::TrackRatio,
            corner: None,
            channel: "c".into(),
            label: "l".into(),
        };
        let per_record: Vec<Vec<(FeatureMeta, f64)>> = (0..4)
            .map(|_| vec![(meta("a"), 0.0), (meta("b"), 0.0)])
            .collect();
        let noise: Vec<EstimateVariances> = [0.01, 0.02, 0.03, 0.05]
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let mut m = EstimateVariances::new();
                m.insert("a".into(), *v);
                if i != 2 {
                    m.insert("b".into(), *v);
                }
                m
            })
            .collect();
        let values = vec![(meta("a"), 0.0), (meta("b"), 0.0)];
        let d = drive_noise(&values, &per_record, &noise);
        let want = std::f64::consts::FRAC_PI_2 * 0.025 / 4.0;
        assert!((d["a"] - want).abs() < 1e-15, "{d:?}");
        assert!(!d.contains_key("b"));
    }

    /// Four unsprung wheels whose noise-free band powers in 8-20 Hz are `p` (FL, FR, RL, RR),
    /// measured with sensor noise of density `d` (noise power `12 d` added to each), one 10.24 s
    /// record at 50 Hz (3 Welch segments, the bins of 0.5-20 Hz).
    fn wheels_with_noise(p: [f64; 4], d: f64) -> RecordFeatures {
        let corners = [Corner::FL, Corner::FR, Corner::RL, Corner::RR];
        let measured: Vec<Option<f64>> = p.iter().map(|p| Some((p + 12.0 * d).sqrt())).collect();
        RecordFeatures {
            analysis_fs_hz: 50.0,
            duration_s: 10.24,
            n_segments: 1,
            bands_hz: vec![[2.0, 5.0]],
            channels: corners
                .iter()
                .zip(&measured)
                .map(|(c, m)| crate::features::ChannelFeatures {
                    name: format!("{c}_unsprung"),
                    role: Role::Unsprung,
                    corner: Some(*c),
                    band_rms: vec![Some(1.0)],
                    modes: Vec::new(),
                    ratio_band_rms: *m,
                })
                .collect(),
            transmissibility: Vec::new(),
            notes: Vec::new(),
            body_spectra: None,
            sensor_faults: Vec::new(),
            line_free: Some(crate::features::LineFree {
                ratio_band_rms: measured,
                noise_density: vec![d; 4],
                bins: Some(crate::features::TransmissibilityBins {
                    freq_hz: (3..=102).map(|k| k as f64 * 50.0 / 256.0).collect(),
                    segments: 3,
                    ..crate::features::TransmissibilityBins::default()
                }),
                ..crate::features::LineFree::default()
            }),
            suspension: None,
            start_unix_s: None,
        }
    }

    /// A baseline of 8 records with little sensor noise (1.2 % of the band power) keeps its
    /// records' mean estimate variance; a record whose left front wheel is 0.4 (ln level) above
    /// its rear one is flagged at z = 0.4 / 0.03 = 13 without noise and, with the noise power
    /// 0.8 in every wheel (44 % of the rear wheel's measured band power), at 0.4 over the
    /// spread widened by its own variance (`sqrt(0.03^2 + v - v_nominal)`, about 3.2 times: z
    /// 4.1), which its evidence states. Half that change is within the widened spread but not
    /// the nominal one: not flagged, and the summary names it with both scores.
    #[test]
    fn a_record_near_its_noise_floor_is_judged_against_its_own_scatter() {
        let cfg = FleetConfig::default();
        let recs: Vec<RecordFeatures> = (0..8)
            .map(|i| wheels_with_noise([1.0 + 0.002 * (i % 3) as f64, 1.0, 1.0, 1.0], 0.001))
            .collect();
        let names: Vec<String> = (0..8).map(|i| format!("n{i}")).collect();
        let set = build_model_set("bus", &names, &recs, &cfg).expect("model set");
        assert!(set.noise_free);
        let key = ratio_key(Kind::TrackRatio, "left", &cfg.ratio_band_hz, true);
        let f = set
            .features
            .iter()
            .find(|f| f.meta.key == key)
            .expect("left track ratio");
        assert_eq!(f.sigma, cfg.floor_track_ratio);
        let cells = welch_band_cells(62, 3);
        let v_nominal = 2.0 * noise_free_level_variance(1.012f64.sqrt(), 0.012, cells).unwrap();
        let nominal = f.estimate_var.unwrap_or(f64::NAN);
        assert!(
            (nominal / v_nominal - 1.0).abs() < 0.01,
            "{nominal} {v_nominal}"
        );
        let raised = [0.8f64.exp(), 1.0, 1.0, 1.0];
        let clean = assess(&set, &wheels_with_noise(raised, 0.001));
        let e = clean
            .evidence
            .iter()
            .find(|e| e.meta.key == key)
            .expect("flagged");
        assert!(
            e.z > 12.0 && e.spread_widened_by.map_or(true, |w| w < 1.01),
            "{e:?}"
        );
        let noisy = assess(&set, &wheels_with_noise(raised, 0.8 / 12.0));
        let v = noise_free_level_variance((raised[0] + 0.8).sqrt(), 0.8, cells).unwrap()
            + noise_free_level_variance(1.8f64.sqrt(), 0.8, cells).unwrap();
        let spread = (0.03f64 * 0.03 + v - nominal).sqrt();
        // z about 4.1, still beyond the limit (3.02, Bonferroni over the vehicle features).
        let e = noisy
            .evidence
            .iter()
            .find(|e| e.meta.key == key)
            .expect("flagged");
        let z = (0.4 - f.centre) / spread;
        assert!(
            (e.z - z).abs() < 1e-9 && z > set.limit(Kind::TrackRatio),
            "{} {z}",
            e.z
        );
        let w = e.spread_widened_by.unwrap_or(f64::NAN);
        assert!((w - spread / 0.03).abs() < 1e-9 && w > 3.0, "{w}");
        // Flagged either way: the summary names it as evidence, not as spared (the FL/FR ratio,
        // which the raised wheel moves too, may be spared).
        let label = &f.meta.label;
        assert!(
            !noisy.summary.contains(&format!("{label} +")),
            "{}",
            noisy.summary
        );
        // Half the change (0.2): z 6.7 on the nominal spread (0.03), about 2 on the record's own,
        // within the limit. Not flagged, and the summary names it with both scores.
        let half = [0.4f64.exp(), 1.0, 1.0, 1.0];
        let spared = assess(&set, &wheels_with_noise(half, 0.8 / 12.0));
        assert!(
            !spared.evidence.iter().any(|e| e.meta.key == key),
            "{spared:?}"
        );
        let v = noise_free_level_variance((half[0] + 0.8).sqrt(), 0.8, cells).unwrap()
            + noise_free_level_variance(1.8f64.sqrt(), 0.8, cells).unwrap();
        let z0 = (0.2 - f.centre) / 0.03;
        let z = (0.2 - f.centre) / (0.03f64 * 0.03 + v - nominal).sqrt();
        assert!(z0 > 6.0 && z < set.limit(Kind::TrackRatio), "{z0} {z}");
        let expected = format!(
            "{label} +{:.0} % (z {z0:.1} on the nominal spread, {z:.1} on its own)",
            100.0 * ((0.2 - f.centre).exp() - 1.0)
        );
        assert!(
            spared
                .summary
                .contains("not flagged, within their own noisy estimates' scatter: ")
                && spared.summary.contains(&expected),
            "{}\n{expected}",
            spared.summary
        );
        // The clean record with the same change is flagged: it is not named as spared.
        let flagged = assess(&set, &wheels_with_noise(half, 0.001));
        assert!(
            flagged.evidence.iter().any(|e| e.meta.key == key)
                && !flagged.summary.contains(&format!("{label} +")),
            "{flagged:?}"
        );
    }

    /// A baseline of 6 records of two corners with little noise; a record whose RR wheel is
    /// two thirds sensor noise in 2-5 Hz (density 1 over 4 bins of input 6) gives neither
    /// corner's transmissibility, and its check says why: RR's wheel is 67 % noise, RL has
    /// nothing to compare with; the summary counts them. A drive of such records says in how
    /// many of its records.
    #[test]
    fn features_not_given_for_their_wheels_noise_say_why() {
        let cfg = FleetConfig::default();
        let recs: Vec<RecordFeatures> = (0..6)
            .map(|i| two_corners([0.5, 0.5 + 0.01 * i as f64], [0.01, 0.01]))
            .collect();
        let names: Vec<String> = (0..6).map(|i| format!("n{i}")).collect();
        let set = build_model_set("bus", &names, &recs, &cfg).expect("model set");
        assert!(set.input_noise_free);
        let quiet = two_corners([0.5, 0.5], [0.01, 1.0]);
        let why = set.record_unjudged(&quiet);
        assert_eq!(
            why.get("transh1lu:RR:2-5Hz").map(String::as_str),
            Some("its wheel's motion in 2-5 Hz is 67 % sensor noise")
        );
        assert!(why["transh1lu:RL:2-5Hz"].contains("nothing to compare with"));
        let a = assess(&set, &quiet);
        // Given no score, with the reason: under `not_judged`, not `missing`.
        assert!(a.missing.is_empty(), "{:?}", a.missing);
        assert!(
            a.not_judged.iter().any(|m| m.to_string()
                == "RR: transmissibility 2-5 Hz vs the other corners (not judged: its wheel's motion in 2-5 Hz is 67 % sensor noise)"),
            "{:?}",
            a.not_judged
        );
        assert!(
            a.summary
                .contains("not judged: 2 vehicle feature(s) for the wheels' sensor noise"),
            "{}",
            a.summary
        );
        let d = assess_drive(&set, &[&quiet, &quiet, &quiet]);
        assert!(
            d.not_judged
                .iter()
                .any(|m| m.reason.starts_with("in 3 of 3 records: its wheel's")),
            "{:?}",
            d.not_judged
        );
        // The same record with the wheel's noise as the baseline's: both judged, no reason.
        let clean = assess(&set, &two_corners([0.5, 0.5], [0.01, 0.01]));
        assert!(
            clean.missing.is_empty()
                && clean.not_judged.is_empty()
                && !clean.summary.contains("sensor noise"),
            "{clean:?}"
        );
    }
}
