//! Model updating: the full-car model's suspension and body inertias fitted to measured records
//! from the body's equations of motion, which carry no road input.
//!
//! The road enters the full-car model only through the tyres. The three body rows of
//! `M q'' + C q' + K q = f` (heave, pitch, roll) therefore hold with the measured motions alone:
//! the body coordinates come from the sprung sensors (`z + x theta + y phi` at each sensor, least
//! squares over three or more sensors), the wheel coordinates from the unsprung sensors. With the
//! sprung mass fixed at the vehicle file's value, the rows are linear in the pitch and roll
//! inertias, the four suspension springs and dampers and the two anti-roll bars (by default
//! whether or not the file has them; [`AntiRollBars`]):
//! a least-squares problem whose normal equations are summed record by record, with the
//! sensors' noise share taken out (every regressor is a measured, noisy signal; the noise
//! densities come from each channel's spectrum above the band; as much of the share as leaves
//! the equations positive semi-definite, at most all of it: generalized total least squares,
//! [`noise_scale`]), and whose parameters and body modes get jackknife standard deviations over
//! the records (docs/model_update.md).
//!
//! The rows are differentiated twice, so that they hold for the measured accelerations and their
//! first and second derivatives (`M a'' + C a' + K a = 0`): nothing is integrated. The
//! derivatives are taken in the frequency domain under a band-pass with cosine tapers (30 % of
//! each edge frequency) around the body modes; `edge_s` at each record end is dropped. The band
//! keeps out the body bending modes (three sprung sensors cannot tell them from pitch) and the
//! slow manoeuvres (braking, turns), which put moments on the body.
//!
//! The updated model keeps the vehicle file's masses, geometry, tyres and bending mode; its
//! eigenvalues give the body modes of the vehicle that was measured. Units: SI throughout
//! (N/m, N s/m, N m/rad, kg m^2), accelerations in any consistent unit (the fit is scale-free).
use crate::error::{Result, VehicleError};
use crate::model::{FullCar, ModeInfo, ModeLabel};
use crate::params::{CornerCondition, VehicleParams};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use vibmode_core::{Channel, Corner, Direction, Placement, Recording, Role};
// FFT plans are shared by every record of the process (vibmode_fft caches them: their twiddle
// factors are the costly part of a plan at a record's length).
use vibmode_fft::{forward as plan_forward, inverse as plan_inverse};

pub use vibmode_core::{AntiRollBars, BodyFitParams};

/// Unknowns (per unit sprung mass): pitch inertia, roll inertia, springs FL..RR, dampers FL..RR,
/// then the anti-roll bars fitted (both axles', or those the file has: [`AntiRollBars`]).
const N_BASE: usize = 10;

/// Where the fit takes each body and wheel coordinate from.
#[derive(Debug, Clone)]
struct Layout {
    /// Channel index of the unsprung sensor at FL, FR, RL, RR.
    wheels: [usize; 4],
    /// Channel indices of the sprung sensors.
    sprung: Vec<usize>,
    /// Body coordinates [z, theta, phi] = `body` * (sprung samples): rows of the pseudo-inverse.
    body: DMatrix<f64>,
}

/// Accumulates the body equations of many records and solves for the suspension.
///
/// ```no_run
/// # fn demo(records: &[vibmode_core::Recording]) -> vibmode_vehicle::Result<()> {
/// use vibmode_vehicle::{update::{BodyFit, BodyFitParams}, VehicleParams};
/// let mut fit = BodyFit::new(&VehicleParams::city_bus_flexible(), BodyFitParams::default())?;
/// for r in records {
///     fit.add_record(r)?;
/// }
/// let updated = fit.solve()?;
/// for m in &updated.modes {
///     println!("{} {:.3} Hz", m.label, m.frequency_hz);
/// }
/// # Ok(()) }
/// ```
#[derive(Debug, Clone)]
pub struct BodyFit {
    vehicle: VehicleParams,
    params: BodyFitParams,
    band_hz: [f64; 2],
    /// Anti-roll bars fitted: front, rear.
    bars: [bool; 2],
    /// Row weights of pitch and roll (1 / radius of gyration, 1/m).
    row_weight: [f64; 2],
    /// The vehicle file's own modes.
    nominal_modes: Vec<ModeInfo>,
    /// Sum over records of `Z^T Z`, `Z = [X | y]` the equations' regressors and right side.
    gram: DMatrix<f64>,
    /// Per record: its `Z^T Z` and the share its sensors' noise is expected to add to it
    /// (the fit and the jackknife sum these and take out the noise's share, scaled by
    /// [`noise_scale`]).
    per_record: Vec<(DMatrix<f64>, DMatrix<f64>)>,
    /// Per record and used channel: the noise density estimated from the channel's spectrum
    /// above the band, (m/s^2)^2/Hz (0 where no such band exists).
    noise: Vec<(String, f64)>,
    equations: usize,
    records: usize,
}

/// One record's body equations, summed ([`BodyFit::record_equations`]): enough to fit
/// records together later without reading them again ([`BodyFit::add_equations`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct RecordEquations {
    /// Unknowns of the fit (pitch and roll inertias, four springs, four dampers, the bars).
    pub unknowns: usize,
    /// `Z^T Z` of the record's equations, `Z = [X | y]`, column-major, `(unknowns + 1)^2`.
    pub gram: Vec<f64>,
    /// The share its sensors' white noise is expected to add to `gram`, same layout.
    pub noise_gram: Vec<f64>,
    /// Each used channel's noise density from its spectrum above the band, (m/s^2)^2/Hz.
    pub noise: Vec<(String, f64)>,
    /// Equations (instants x 3 body rows).
    pub equations: usize,
}

/// One fitted parameter beside the vehicle file's value.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct ParameterChange {
    /// What it is, e.g. "spring RL" or "pitch inertia".
    pub name: String,
    /// Unit of both values, e.g. "kN/m".
    pub unit: &'static str,
    /// The vehicle file's value.
    pub file: f64,
    /// The fitted value.
    pub fitted: f64,
    /// Its standard deviation (jackknife over the records), same unit; `None` with fewer than
    /// three records.
    pub sd: Option<f64>,
}

/// The updated model and how well the equations fitted.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct BodyFitResult {
    /// The vehicle file with the fitted springs, dampers (per corner, as `corner_condition`
    /// factors on the axle means), anti-roll bars and pitch and roll inertias.
    pub vehicle: VehicleParams,
    /// The updated model's modes (the body modes are the fitted ones; wheel modes keep the
    /// file's tyres and unsprung masses).
    pub modes: Vec<ModeInfo>,
    /// The vehicle file's own modes, for comparison.
    pub nominal_modes: Vec<ModeInfo>,
    /// Records that entered the fit.
    pub records: usize,
    /// Equations (time instants x 3 body rows).
    pub equations: usize,
    /// Band of the equations, Hz.
    pub band_hz: [f64; 2],
    /// Share of the equations' variance the fit explains (1 = exact), dimensionless.
    pub explained: f64,
    /// Parameters of the vehicle file the records put at 0 (the bounded fit held them there):
    /// an anti-roll bar the measured bus does not have, e.g. "front anti-roll bar". The updated
    /// vehicle has them at 0.
    pub absent: Vec<String>,
    /// Every fitted parameter in SI units with its standard deviation (jackknife over the
    /// records; `None` with fewer than three records).
    pub parameters: Vec<FittedParameter>,
    /// The jackknife's replicates: per record left out, every parameter's value in the order of
    /// `parameters` (empty with fewer than three records or when a replicate fails). For the
    /// standard deviation of a function of several parameters, whose errors are correlated.
    #[serde(skip)]
    pub replicates: Vec<Vec<f64>>,
    /// The standard deviations of the updated body modes' frequency and damping (jackknife over
    /// the records; empty with fewer than three records).
    pub mode_sd: Vec<ModeSpread>,
    /// Whether the records support the fit: every body mode's frequency within
    /// [`MODE_TOLERANCE`] and every spring and damper within [`PARAM_TOLERANCE`] at
    /// [`SUPPORT_CONFIDENCE`] together ([`support_factor`] jackknife standard deviations), and the
    /// fit possible without any one record. When not, `updated_vehicle.toml` is not written.
    pub supported: bool,
    /// Why the records do not support the fit.
    pub not_supported: Option<String>,
    /// Each used channel's noise density, estimated from its spectrum above the band and
    /// subtracted from the equations (median over the records), (m/s^2)^2/Hz.
    pub noise_density: Vec<ChannelNoise>,
    /// The share of the noise's expected contribution taken out of the normal equations
    /// ([`noise_scale`]): 1 = all of it (bias-compensated least squares); below 1 when the
    /// equations become singular before (generalized total least squares).
    pub noise_share: f64,
    /// With the default band: whether the wide band's fit was taken instead, and why
    /// ([`choose_band`]); `None` when the band was given or the comparison was not made.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub band_choice: Option<BandChoice>,
}

/// The default band's fit against the wide band's ([`choose_band`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct BandChoice {
    /// The default band, Hz (`[0.45 f_min, 1.6 f_max]` over the file's body modes).
    pub default_band_hz: [f64; 2],
    /// The wide band, Hz (`[0.45 f_min, 3 f_max]`).
    pub wide_band_hz: [f64; 2],
    /// Whether the fit reported is the wide band's.
    pub wide_taken: bool,
    /// The largest shift of a body mode's frequency from the default band's fit to the wide
    /// band's, in standard deviations of the default band's fit (`None` where not compared).
    pub largest_shift_sd: Option<f64>,
    /// Why, in one line.
    pub reason: String,
}

/// The relative error of a body mode's frequency a supported fit meets (issue 30's goal: 3 %).
pub const MODE_TOLERANCE: f64 = 0.03;
/// The relative error of a spring or damper a supported fit meets (10 %).
pub const PARAM_TOLERANCE: f64 = 0.10;
/// The confidence, simultaneous over every body mode, spring and damper, with which a supported
/// fit meets [`MODE_TOLERANCE`] and [`PARAM_TOLERANCE`].
pub const SUPPORT_CONFIDENCE: f64 = 0.95;

/// How many jackknife standard deviations a supported fit's quantities must lie within their
/// tolerance: the Student t quantile with `records - 1` degrees of freedom at
/// `1 - (1 - SUPPORT_CONFIDENCE) / (2 quantities)` (two-sided intervals, Bonferroni over the
/// quantities judged together). The jackknife's standard deviation from R records is itself an
/// estimate with R - 1 degrees of freedom, hence t rather than the normal quantile: 4.10 for 8
/// records and 11 quantities, 3.33 for 16 records.
///
/// Returns infinity with fewer than two records or no quantity (nothing can be supported).
pub fn support_factor(records: usize, quantities: usize) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    if records < 2 || quantities == 0 {
        return f64::INFINITY;
    }
    let p = 1.0 - (1.0 - SUPPORT_CONFIDENCE) / (2.0 * quantities as f64);
    StudentsT::new(0.0, 1.0, (records - 1) as f64)
        .map(|t| t.inverse_cdf(p))
        .unwrap_or(f64::INFINITY)
}

/// The fewest records of the same kind that would support a fit: the smallest `R' >= records`
/// with `support_factor(R', quantities) * worst * sqrt(records / R') <= 1`, where `worst` is the
/// largest ratio of a judged quantity's relative standard deviation to its tolerance from
/// `records` records. It assumes the spread falls as `1 / sqrt(records)` (measured: 32 records
/// of busgen's bus 0 halved the sd of 8, docs/model_update.md) and that the fit is unbiased.
/// `None` when `worst` is not finite or more than 100 000 records would be needed.
pub fn records_to_support(records: usize, quantities: usize, worst: f64) -> Option<usize> {
    const MOST: usize = 100_000;
    if !worst.is_finite() || worst < 0.0 || records < 2 || quantities == 0 {
        return None;
    }
    let holds = |r: usize| {
        support_factor(r, quantities) * worst * (records as f64 / r as f64).sqrt() <= 1.0
    };
    if holds(records) {
        return Some(records);
    }
    if !holds(MOST) {
        return None;
    }
    // The left side falls with r (t's quantile and 1/sqrt(r) both do): bisection.
    let (mut lo, mut hi) = (records, MOST);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if holds(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// One fitted parameter, SI units.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct FittedParameter {
    /// What it is, e.g. "spring RL", "pitch inertia", "anti-roll bar rear".
    pub name: String,
    /// Its unit: "N/m", "N s/m", "kg m^2" or "N m/rad".
    pub unit: &'static str,
    /// The fitted value.
    pub value: f64,
    /// Its standard deviation (jackknife over the records), same unit.
    pub sd: Option<f64>,
}

/// The spread of an updated mode over the records.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct ModeSpread {
    /// Which mode.
    pub label: ModeLabel,
    /// Standard deviation of its natural frequency, Hz.
    pub frequency_hz_sd: f64,
    /// Standard deviation of its damping ratio.
    pub damping_ratio_sd: f64,
}

/// A channel's noise density.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct ChannelNoise {
    /// The channel.
    pub channel: String,
    /// One-sided noise density, (m/s^2)^2/Hz (the channel's unit squared per Hz).
    pub density_per_hz: f64,
}

impl BodyFitResult {
    /// The updated model's mode with this label, if any.
    pub fn mode(&self, label: ModeLabel) -> Option<&ModeInfo> {
        self.modes.iter().find(|m| m.label == label)
    }

    /// The fitted spring of a corner, N/m, with its standard deviation.
    pub fn spring(&self, corner: Corner) -> Option<&FittedParameter> {
        let name = format!("spring {corner}");
        self.parameters.iter().find(|p| p.name == name)
    }

    /// The fitted damper of a corner, N s/m, with its standard deviation.
    pub fn damper(&self, corner: Corner) -> Option<&FittedParameter> {
        let name = format!("damper {corner}");
        self.parameters.iter().find(|p| p.name == name)
    }

    /// The standard deviations of the updated mode with this label (frequency Hz, damping ratio).
    pub fn mode_spread(&self, label: ModeLabel) -> Option<&ModeSpread> {
        self.mode_sd.iter().find(|m| m.label == label)
    }

    /// The vehicle file's mode with this label, if any.
    pub fn nominal_mode(&self, label: ModeLabel) -> Option<&ModeInfo> {
        self.nominal_modes.iter().find(|m| m.label == label)
    }

    /// The body modes (pitch, heave, roll, in that order) of the vehicle file and of the updated
    /// model, as `(file, updated)` pairs; a mode missing from either model is left out.
    pub fn body_mode_pairs(&self) -> Vec<(&ModeInfo, &ModeInfo)> {
        [
            ModeLabel::BodyPitch,
            ModeLabel::BodyHeave,
            ModeLabel::BodyRoll,
        ]
        .into_iter()
        .filter_map(|l| Some((self.nominal_mode(l)?, self.mode(l)?)))
        .collect()
    }

    /// Every fitted parameter beside the vehicle file's value: the springs and dampers per
    /// corner, the pitch and roll inertias and the anti-roll bars.
    pub fn parameter_changes(&self, file: &VehicleParams) -> Vec<ParameterChange> {
        let mut out = Vec::new();
        let mut push = |name: String, unit: &'static str, a: f64, b: f64| {
            // The fitted parameters' sd in SI; the table's kN units scale it.
            let scale = if unit.starts_with("kN") { 1e-3 } else { 1.0 };
            let sd = self
                .parameters
                .iter()
                .find(|p| p.name == name)
                .and_then(|p| p.sd)
                .map(|v| v * scale);
            out.push(ParameterChange {
                name,
                unit,
                file: a,
                fitted: b,
                sd,
            })
        };
        type Get = fn(&crate::params::Axle) -> f64;
        let per_corner: [(&str, &'static str, Get); 2] = [
            ("spring", "kN/m", |a| a.spring_stiffness_n_per_m),
            ("damper", "kN s/m", |a| a.damper_n_s_per_m),
        ];
        for (what, unit, get) in per_corner {
            for c in Corner::ALL {
                push(
                    format!("{what} {c}"),
                    unit,
                    get(&file.axle(c)) / 1e3,
                    get(&self.vehicle.axle(c)) / 1e3,
                );
            }
        }
        push(
            "pitch inertia".into(),
            "kg m^2",
            file.body.pitch_inertia_kgm2,
            self.vehicle.body.pitch_inertia_kgm2,
        );
        push(
            "roll inertia".into(),
            "kg m^2",
            file.body.roll_inertia_kgm2,
            self.vehicle.body.roll_inertia_kgm2,
        );
        for (name, a, b) in [
            ("anti-roll bar front", &file.front, &self.vehicle.front),
            ("anti-roll bar rear", &file.rear, &self.vehicle.rear),
        ] {
            // Every bar fitted, including one the file lacks (file value 0).
            if self.parameters.iter().any(|p| p.name == name) {
                push(
                    name.into(),
                    "kN m/rad",
                    a.anti_roll_stiffness_nm_per_rad / 1e3,
                    b.anti_roll_stiffness_nm_per_rad / 1e3,
                );
            }
        }
        out
    }

    /// The anti-roll bars the vehicle file lacks and the records put above 0 (with
    /// [`AntiRollBars::Both`]), e.g. "front anti-roll bar of 118 kN m/rad".
    pub fn found_bars(&self, file: &VehicleParams) -> Vec<String> {
        [
            ("front", &file.front, &self.vehicle.front),
            ("rear", &file.rear, &self.vehicle.rear),
        ]
        .into_iter()
        .filter(|(_, f, u)| {
            f.anti_roll_stiffness_nm_per_rad <= 0.0 && u.anti_roll_stiffness_nm_per_rad > 0.0
        })
        .map(|(name, _, u)| {
            format!(
                "{name} anti-roll bar of {:.0} kN m/rad",
                u.anti_roll_stiffness_nm_per_rad / 1e3
            )
        })
        .collect()
    }

    /// A plain-text summary: the body modes of the file and of the updated model, then the
    /// fitted parameters beside the file's.
    pub fn summary_text(&self, file: &VehicleParams) -> String {
        let mut s = format!(
            "Full-car model updated from the body's equations ({} records, {} equations in {:.2}-{:.2} Hz, {:.1} % of their variance explained):\n",
            self.records,
            self.equations,
            self.band_hz[0],
            self.band_hz[1],
            100.0 * self.explained
        );
        if let Some(c) = &self.band_choice {
            s.push_str(&format!("  {}\n", c.reason));
        }
        s.push_str(&format!(
            "  {:<12} {:>9} {:>11} {:>8} {:>8} {:>13} {:>16} {:>8}\n",
            "mode",
            "file Hz",
            "updated Hz",
            "change",
            "sd Hz",
            "file damping",
            "updated damping",
            "sd"
        ));
        for (n, u) in self.body_mode_pairs() {
            let sd = self.mode_spread(u.label);
            let f = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
            s.push_str(&format!(
                "  {:<12} {:>9.3} {:>11.3} {:>7.1}% {:>8} {:>13.3} {:>16.3} {:>8}\n",
                n.label.to_string(),
                n.frequency_hz,
                u.frequency_hz,
                100.0 * (u.frequency_hz / n.frequency_hz - 1.0),
                f(sd.map(|m| m.frequency_hz_sd)),
                n.damping_ratio,
                u.damping_ratio,
                f(sd.map(|m| m.damping_ratio_sd))
            ));
        }
        let per = |v: &VehicleParams, f: fn(&crate::params::Axle) -> f64, scale: f64| {
            Corner::ALL
                .iter()
                .map(|&c| format!("{:.1}", f(&v.axle(c)) / scale))
                .collect::<Vec<_>>()
                .join("/")
        };
        s.push_str(&format!(
            "  springs FL/FR/RL/RR, kN/m: file {}, fitted {}\n",
            per(file, |a| a.spring_stiffness_n_per_m, 1e3),
            per(&self.vehicle, |a| a.spring_stiffness_n_per_m, 1e3)
        ));
        s.push_str(&format!(
            "  dampers FL/FR/RL/RR, kN s/m: file {}, fitted {}\n",
            per(file, |a| a.damper_n_s_per_m, 1e3),
            per(&self.vehicle, |a| a.damper_n_s_per_m, 1e3)
        ));
        s.push_str(&format!(
            "  pitch / roll inertia, kg m^2: file {:.0} / {:.0}, fitted {:.0} / {:.0}\n",
            file.body.pitch_inertia_kgm2,
            file.body.roll_inertia_kgm2,
            self.vehicle.body.pitch_inertia_kgm2,
            self.vehicle.body.roll_inertia_kgm2
        ));
        s.push_str(&format!(
            "  anti-roll bars front / rear, kN m/rad: file {:.0} / {:.0}, fitted {:.0} / {:.0}\n",
            file.front.anti_roll_stiffness_nm_per_rad / 1e3,
            file.rear.anti_roll_stiffness_nm_per_rad / 1e3,
            self.vehicle.front.anti_roll_stiffness_nm_per_rad / 1e3,
            self.vehicle.rear.anti_roll_stiffness_nm_per_rad / 1e3
        ));
        let found = self.found_bars(file);
        if !found.is_empty() {
            s.push_str(&format!(
                "  found where the file has none: {}\n",
                found.join(", ")
            ));
        }
        let sds: Vec<String> = self
            .parameters
            .iter()
            .filter_map(|p| {
                let sd = p.sd?;
                (p.value > 0.0).then(|| format!("{} {:.1} %", p.name, 100.0 * sd / p.value))
            })
            .collect();
        if !sds.is_empty() {
            s.push_str(&format!(
                "  standard deviations (jackknife over the records): {}\n",
                sds.join(", ")
            ));
        }
        let floorless: Vec<&str> = self
            .noise_density
            .iter()
            .filter(|c| c.density_per_hz <= 0.0)
            .map(|c| c.channel.as_str())
            .collect();
        s.push_str(&format!(
            "  (sprung mass, unsprung masses, tyres and bending are the file's; the sensors' white noise, measured above the band, taken out of the equations{}{})\n",
            if self.noise_share < 1.0 {
                format!(
                    " ({:.0} % of its expected share, where the equations become singular: generalized total least squares)",
                    100.0 * self.noise_share
                )
            } else {
                String::new()
            },
            if floorless.is_empty() {
                String::new()
            } else {
                format!(
                    "; no flat noise floor on {}, so none taken out there",
                    floorless.join(", ")
                )
            }
        ));
        s
    }
}

/// The default band's lower edge over the file's lowest body mode (heave, pitch or roll).
pub const BAND_LOW_FACTOR: f64 = 0.45;
/// The default band's upper edge over the file's highest body mode.
pub const BAND_HIGH_FACTOR: f64 = 1.6;
/// The wide band's upper edge over the file's highest body mode ([`choose_band`]).
pub const WIDE_BAND_HIGH_FACTOR: f64 = 3.0;
/// How many standard deviations of the default band's fit a body mode may move in the wide
/// band's fit for the wide one to be taken ([`choose_band`]): the two-sided 1 % quantile of
/// Student's t with 7 degrees of freedom (3.50; a jackknife over 8 records), so that a wide
/// band as right as the default one is refused in about 3 % of fits (three body modes; with
/// the default band's standard deviation, an upper bound of the difference's).
pub const WIDE_BAND_MAX_SHIFT_SD: f64 = 3.5;
/// A relative shift of a body mode between the two bands' fits that is no evidence against
/// the wide band whatever the standard deviations (a third of the 3 % the body modes are
/// asked to hold; [`choose_band`]).
pub const WIDE_BAND_MAX_SHIFT_REL: f64 = 0.01;

/// The wide band of `vehicle`'s model update, Hz: `[0.45 f_min, 3 f_max]` over its body modes.
pub fn wide_band_hz(vehicle: &VehicleParams) -> Result<[f64; 2]> {
    body_band_hz(&FullCar::new(vehicle)?.modes()?, WIDE_BAND_HIGH_FACTOR)
}

/// `[BAND_LOW_FACTOR f_min, high_factor f_max]` over the body modes (heave, pitch, roll) among
/// `modes`, Hz.
fn body_band_hz(modes: &[ModeInfo], high_factor: f64) -> Result<[f64; 2]> {
    let body: Vec<f64> = modes
        .iter()
        .filter(|m| m.label.is_body_rigid())
        .map(|m| m.frequency_hz)
        .collect();
    if body.is_empty() {
        return Err(fit_error(
            "the vehicle model has no body heave, pitch or roll mode".into(),
            "check the vehicle file's masses and springs, or give the band",
        ));
    }
    let lo = body.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = body.iter().cloned().fold(0.0, f64::max);
    Ok([BAND_LOW_FACTOR * lo, high_factor * hi])
}

/// The fit of the default band or of the wide one (`wide_band_hz`, [`wide_band_hz`]; `wide`
/// its fit of the same records, or why it failed). The wide band holds more of the wheels'
/// motion (its signal grows with frequency while the sensors' noise is white), so its fit is the more precise, but above about twice
/// the body modes the body's bending, which three sprung sensors cannot tell from pitch, can
/// enter it (docs/model_update.md, "Band"). The wide band's fit is taken when every body
/// mode's frequency lies within [`WIDE_BAND_MAX_SHIFT_SD`] standard deviations (jackknife) of
/// the default band's or within [`WIDE_BAND_MAX_SHIFT_REL`] of it, and its sensors' noise was
/// taken out wherever the default band's was;
/// else the default band's, with the reason. Without the default band's standard deviations
/// (fewer than three records) or with a failed wide fit, the default band's.
pub fn choose_band(
    narrow: BodyFitResult,
    wide_band_hz: [f64; 2],
    wide: Result<BodyFitResult>,
) -> BodyFitResult {
    let bands = |w: [f64; 2]| format!("{:.2}-{:.2} Hz", w[0], w[1]);
    let keep = |mut r: BodyFitResult, wide_band_hz: [f64; 2], shift: Option<f64>, why: String| {
        r.band_choice = Some(BandChoice {
            default_band_hz: r.band_hz,
            wide_band_hz,
            wide_taken: false,
            largest_shift_sd: shift,
            reason: why,
        });
        r
    };
    let wide = match wide {
        Ok(w) => w,
        Err(e) => {
            return keep(
                narrow,
                wide_band_hz,
                None,
                format!("default band kept: the wide band's fit failed ({e})"),
            )
        }
    };
    let wb = wide_band_hz;
    if narrow.mode_sd.is_empty() {
        return keep(
            narrow,
            wb,
            None,
            format!(
                "default band kept: comparing it with the wide band {} needs three records or more",
                bands(wb)
            ),
        );
    }
    let floors = |r: &BodyFitResult| {
        r.noise_density
            .iter()
            .filter(|c| c.density_per_hz > 0.0)
            .count()
    };
    if floors(&wide) < floors(&narrow) {
        return keep(
            narrow,
            wb,
            None,
            format!(
                "default band kept: the sensors' noise could not be measured above the wide band {} (the rate is too low for it)",
                bands(wb)
            ),
        );
    }
    // Per body mode: (shift in the default band's standard deviations, label, relative shift,
    // relative standard deviation).
    let mut shifts: Vec<(f64, ModeLabel, f64, f64)> = Vec::new();
    let body: Vec<(ModeLabel, f64)> = narrow
        .body_mode_pairs()
        .iter()
        .map(|(_, u)| (u.label, u.frequency_hz))
        .collect();
    for (label, f) in body {
        let Some(w) = wide.mode(label) else {
            return keep(
                narrow,
                wb,
                None,
                format!(
                    "default band kept: the wide band {} gave no {label}",
                    bands(wb)
                ),
            );
        };
        // The default band's standard deviation; where its jackknife has none (a record left
        // out loses the mode), the wide band's, which is the smaller and so the stricter.
        let Some(sd) = narrow
            .mode_spread(label)
            .or_else(|| wide.mode_spread(label))
            .map(|m| m.frequency_hz_sd)
        else {
            return keep(
                narrow,
                wb,
                None,
                format!(
                    "default band kept: neither band's fit has a standard deviation of the {label}"
                ),
            );
        };
        shifts.push((
            (w.frequency_hz - f).abs() / sd.max(f64::MIN_POSITIVE),
            label,
            w.frequency_hz / f - 1.0,
            sd / f,
        ));
    }
    if shifts.is_empty() {
        return keep(
            narrow,
            wb,
            None,
            "default band kept: no body mode to compare".into(),
        );
    }
    shifts.sort_by(|a, b| b.0.total_cmp(&a.0));
    let shift = shifts[0].0;
    if let Some(&(s, label, rel, sd_rel)) = shifts
        .iter()
        .find(|m| m.0 > WIDE_BAND_MAX_SHIFT_SD && m.2.abs() > WIDE_BAND_MAX_SHIFT_REL)
    {
        return keep(
            narrow,
            wb,
            Some(shift),
            format!(
                "default band kept: in the wide band {} the {label} moved by {:+.1} %, {s:.1} standard deviations of the default band's fit ({:.2} %): the body is not rigid that far up for these sensors (bending)",
                bands(wb),
                100.0 * rel,
                100.0 * sd_rel
            ),
        );
    }
    let rel = shifts.iter().map(|m| m.2.abs()).fold(0.0, f64::max);
    let default_band_hz = narrow.band_hz;
    BodyFitResult {
        band_choice: Some(BandChoice {
            default_band_hz,
            wide_band_hz: wb,
            wide_taken: true,
            largest_shift_sd: Some(shift),
            reason: format!(
                "wide band {} taken: its body modes lie within {:.1} % (at most {shift:.1} standard deviations) of the default band's ({}) fit, and it holds more of the wheels' motion",
                bands(wb),
                100.0 * rel.abs(),
                bands(default_band_hz)
            ),
        }),
        ..wide
    }
}

fn fit_error(problem: String, fix: &'static str) -> VehicleError {
    VehicleError::BodyFit { problem, fix }
}

impl BodyFit {
    /// A fit of `vehicle`'s suspension (validated) with `params` (validated).
    pub fn new(vehicle: &VehicleParams, params: BodyFitParams) -> Result<Self> {
        params.validate().map_err(VehicleError::Param)?;
        let nominal_modes = FullCar::new(vehicle)?.modes()?;
        let band_hz = match params.band_hz {
            Some(b) => b,
            None => body_band_hz(&nominal_modes, BAND_HIGH_FACTOR)?,
        };
        let bars = match params.anti_roll_bars {
            AntiRollBars::Both => [true, true],
            AntiRollBars::File => [
                vehicle.front.anti_roll_stiffness_nm_per_rad > 0.0,
                vehicle.rear.anti_roll_stiffness_nm_per_rad > 0.0,
            ],
        };
        let n = N_BASE + bars.iter().filter(|&&b| b).count();
        let m = vehicle.body.mass_kg;
        Ok(BodyFit {
            vehicle: vehicle.clone(),
            params,
            band_hz,
            bars,
            row_weight: [
                (m / vehicle.body.pitch_inertia_kgm2).sqrt(),
                (m / vehicle.body.roll_inertia_kgm2).sqrt(),
            ],
            nominal_modes,
            gram: DMatrix::zeros(n + 1, n + 1),
            per_record: Vec::new(),
            noise: Vec::new(),
            equations: 0,
            records: 0,
        })
    }

    /// The band of the equations, Hz.
    pub fn band_hz(&self) -> [f64; 2] {
        self.band_hz
    }

    /// Unknowns of the fit: the pitch and roll inertias, four springs, four dampers and the
    /// anti-roll bars fitted ([`AntiRollBars`]); a [`RecordEquations`] must have as many.
    pub fn unknowns(&self) -> usize {
        self.gram.nrows() - 1
    }

    /// Records added so far.
    pub fn records(&self) -> usize {
        self.records
    }

    /// Which channel measures what: four unsprung sensors (one per corner) and three or more
    /// sprung sensors at known body positions. Channels are placed by their placement (role and
    /// corner) or, failing that, by the vehicle file's sensor of the same name; horizontal
    /// channels, and those whose placement is `None`, are left out.
    fn layout(
        &self,
        rec: &Recording,
        placement: &dyn Fn(&Channel) -> Option<Placement>,
    ) -> Result<Layout> {
        let spec = self.vehicle.effective_sensors();
        let mut wheels: [Option<usize>; 4] = [None; 4];
        let mut sprung: Vec<(usize, f64, f64)> = Vec::new();
        for (i, ch) in rec.channels.iter().enumerate() {
            let Some(pl) = placement(ch) else {
                continue;
            };
            if matches!(pl.direction, Some(Direction::X | Direction::Y)) {
                continue;
            }
            let named = spec.iter().find(|s| s.name.eq_ignore_ascii_case(&ch.name));
            let (role, corner) = match pl.role {
                Role::Sprung => (Role::Sprung, pl.corner),
                Role::Unsprung => (Role::Unsprung, pl.corner),
                Role::Other => match named {
                    Some(s) => (s.kind.role(), s.corner),
                    None => continue,
                },
            };
            match role {
                Role::Unsprung => {
                    let Some(c) = corner.or(named.and_then(|s| s.corner)) else {
                        continue;
                    };
                    let slot = &mut wheels[c.index()];
                    if let Some(j) = *slot {
                        return Err(fit_error(
                            format!(
                                "two unsprung channels at {c}: {} and {}",
                                rec.channels[j].name, ch.name
                            ),
                            "give each wheel one unsprung channel",
                        ));
                    }
                    *slot = Some(i);
                }
                Role::Sprung => {
                    let pos = match corner {
                        Some(c) => Some(self.vehicle.corner_position_m(c)),
                        None => named.and_then(|s| match (s.corner, s.x_m, s.y_m) {
                            (Some(c), _, _) => Some(self.vehicle.corner_position_m(c)),
                            (None, Some(x), Some(y)) => Some((x, y)),
                            _ => None,
                        }),
                    };
                    if let Some((x, y)) = pos {
                        sprung.push((i, x, y));
                    }
                }
                Role::Other => {}
            }
        }
        let missing: Vec<String> = Corner::ALL
            .iter()
            .filter(|c| wheels[c.index()].is_none())
            .map(|c| c.to_string())
            .collect();
        if !missing.is_empty() {
            return Err(fit_error(
                format!("no unsprung channel at {}", missing.join(", ")),
                "give each wheel's channel the role unsprung and its corner",
            ));
        }
        let wheels = wheels.map(|w| w.unwrap_or(0));
        if sprung.len() < 3 {
            return Err(fit_error(
                format!(
                    "{} sprung channel(s) at known positions, 3 needed",
                    sprung.len()
                ),
                "give three or more body channels the role sprung and a corner (or x_m, y_m in the vehicle file)",
            ));
        }
        let p = DMatrix::from_fn(sprung.len(), 3, |r, c| {
            let (_, x, y) = sprung[r];
            [1.0, x, y][c]
        });
        let ptp = p.transpose() * &p;
        // Collinear sensors leave pitch or roll unobserved.
        let eig = ptp.clone().symmetric_eigen().eigenvalues;
        let (emin, emax) = eig
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |(a, b), &v| (a.min(v), b.max(v)));
        let inv = if emin > 1e-6 * emax {
            ptp.try_inverse()
        } else {
            None
        };
        let Some(inv) = inv else {
            return Err(fit_error(
                "the sprung channels lie on one line, so pitch or roll is not observed".into(),
                "use three or more sprung sensors not on one line",
            ));
        };
        Ok(Layout {
            wheels,
            sprung: sprung.iter().map(|s| s.0).collect(),
            body: inv * p.transpose(),
        })
    }

    /// Adds one record's equations. The channels need placements (or the vehicle file's sensor
    /// names): four unsprung at FL, FR, RL, RR and three or more sprung at known positions.
    pub fn add_record(&mut self, rec: &Recording) -> Result<()> {
        self.add_record_placed(rec, |c| Some(c.placement))
    }

    /// As [`BodyFit::add_record`], with each channel's placement given by `placement` instead
    /// of its own (e.g. an analysis config's roles and corners); a channel placed `None` is left
    /// out, even when the vehicle file names a sensor like it.
    pub fn add_record_placed(
        &mut self,
        rec: &Recording,
        placement: impl Fn(&Channel) -> Option<Placement>,
    ) -> Result<()> {
        let eq = self.record_equations_placed(rec, placement)?;
        self.add_equations(&eq)
    }

    /// One record's equations, not added: what [`BodyFit::add_record`] would add, to be kept
    /// (e.g. by the fleet store, per record) and added later with [`BodyFit::add_equations`]
    /// to a fit of the same vehicle file and parameters.
    pub fn record_equations(&self, rec: &Recording) -> Result<RecordEquations> {
        self.record_equations_placed(rec, |c| Some(c.placement))
    }

    /// Adds one record's equations made by [`BodyFit::record_equations`] of a fit of the same
    /// vehicle file and parameters. An error if their number of unknowns differs from this
    /// fit's (another vehicle file's anti-roll bars) or their matrices are not square of that
    /// size or hold a non-finite value.
    pub fn add_equations(&mut self, eq: &RecordEquations) -> Result<()> {
        let size = self.gram.nrows();
        let ok_len = |v: &[f64]| v.len() == size * size && v.iter().all(|x| x.is_finite());
        if eq.unknowns + 1 != size || !ok_len(&eq.gram) || !ok_len(&eq.noise_gram) {
            return Err(fit_error(
                format!(
                    "a record's equations have {} unknowns ({} and {} matrix entries), this fit {}",
                    eq.unknowns,
                    eq.gram.len(),
                    eq.noise_gram.len(),
                    size - 1
                ),
                "make the record's equations with the same vehicle file and band",
            ));
        }
        let gram = DMatrix::from_column_slice(size, size, &eq.gram);
        let noise_gram = DMatrix::from_column_slice(size, size, &eq.noise_gram);
        self.gram += &gram;
        self.per_record.push((gram, noise_gram));
        self.noise.extend(eq.noise.iter().cloned());
        self.equations += eq.equations;
        self.records += 1;
        Ok(())
    }

    /// As [`BodyFit::record_equations`], with each channel's placement given by `placement`
    /// (see [`BodyFit::add_record_placed`]).
    pub fn record_equations_placed(
        &self,
        rec: &Recording,
        placement: impl Fn(&Channel) -> Option<Placement>,
    ) -> Result<RecordEquations> {
        self.record_equations_spectra(rec, placement, None)
    }

    /// As [`BodyFit::record_equations_placed`], a channel brought down to
    /// [`EQUATION_RATE_HZ`] from its spectrum `spectra[i]` (of `rec.channels[i]`,
    /// `vibmode_signal::ChannelSpectrum::of`) where given, so that a caller resampling the
    /// channels to another rate too transforms them once: the same equations bit for bit.
    /// `spectra` of another number of channels than `rec` is not used.
    pub fn record_equations_spectra(
        &self,
        rec: &Recording,
        placement: impl Fn(&Channel) -> Option<Placement>,
        spectra: Option<&[vibmode_signal::ChannelSpectrum]>,
    ) -> Result<RecordEquations> {
        let spectra = spectra.filter(|s| s.len() == rec.channels.len());
        let fs = rec.fs_hz;
        if !(fs.is_finite() && fs > 0.0) {
            return Err(fit_error(
                format!("sampling rate {fs} Hz"),
                "give a positive, finite rate",
            ));
        }
        if self.band_hz[1] * 1.3 >= 0.5 * fs {
            return Err(fit_error(
                format!(
                    "the band's upper edge {:.2} Hz (tapered to {:.2} Hz) is above the Nyquist frequency {:.2} Hz",
                    self.band_hz[1],
                    1.3 * self.band_hz[1],
                    0.5 * fs
                ),
                "sample faster or lower the band",
            ));
        }
        let layout = self.layout(rec, &placement)?;
        let len = rec.channels.first().map_or(0, |c| c.samples.len());
        let edge = (self.params.edge_s * fs).round() as usize;
        // At least one period of the lowest band frequency between the edges.
        let need = 2 * edge + (fs / self.band_hz[0]).ceil() as usize;
        if len < need {
            return Err(fit_error(
                format!(
                    "a record of {len} samples ({:.2} s) is shorter than {need} samples ({:.2} s): two edges of {} s and one period of {:.2} Hz",
                    len as f64 / fs,
                    need as f64 / fs,
                    self.params.edge_s,
                    self.band_hz[0]
                ),
                "use longer records",
            ));
        }
        for ch in &rec.channels {
            if ch.samples.len() != len {
                return Err(fit_error(
                    format!(
                        "channel {} has {} samples, the first channel {len}",
                        ch.name,
                        ch.samples.len()
                    ),
                    "give channels of equal length",
                ));
            }
            if let Some(k) = ch.samples.iter().position(|v| !v.is_finite()) {
                return Err(fit_error(
                    format!("channel {} sample {k} is {}", ch.name, ch.samples[k]),
                    "remove or repair non-finite samples",
                ));
            }
        }
        // A record sampled much faster than the band needs is brought down first (an integer
        // factor, ideal DFT low-pass): the equations and the noise floor are the same at
        // `EQUATION_RATE_HZ`, at a quarter of the FFTs' length for 20 kHz records.
        let factor = decimation_factor(fs);
        let fs_in = fs;
        let (fs, len, edge) = if factor > 1 {
            let fs = fs / factor as f64;
            (
                fs,
                len.div_ceil(factor),
                (self.params.edge_s * fs).round() as usize,
            )
        } else {
            (fs, len, edge)
        };
        // Equations at about 25 times the band's upper edge, away from the record ends.
        let step = ((fs / (25.0 * self.band_hz[1])).floor() as usize).max(1);
        let instants: Vec<usize> = (edge..len - edge).step_by(step).collect();
        // a, a', a'' of the used channels, band-limited, at those instants, and each channel's
        // noise density from its spectrum above the band.
        let mut deriv = Derivatives::new(len, fs, self.band_hz);
        let mut of = |i: usize| {
            let x = &rec.channels[i].samples;
            if factor > 1 {
                let spectrum = spectra.map(|s| &s[i]);
                deriv.apply(&decimate_ideal(x, spectrum, fs_in, factor)?, &instants)
            } else {
                deriv.apply(x, &instants)
            }
        };
        let wheel: Vec<([Vec<f64>; 3], f64)> = layout
            .wheels
            .iter()
            .map(|&i| of(i))
            .collect::<Result<_>>()?;
        let sprung: Vec<([Vec<f64>; 3], f64)> = layout
            .sprung
            .iter()
            .map(|&i| of(i))
            .collect::<Result<_>>()?;
        let n = self.gram.nrows() - 1;
        let mut gram = DMatrix::<f64>::zeros(n + 1, n + 1);
        let mut z = [vec![0.0; n + 1], vec![0.0; n + 1], vec![0.0; n + 1]];
        let add = |z: &[Vec<f64>; 3], w: f64, g: &mut DMatrix<f64>| {
            for zr in z {
                for (u, &zu) in zr.iter().enumerate() {
                    if zu == 0.0 {
                        continue;
                    }
                    for (v, &zv) in zr.iter().enumerate() {
                        g[(u, v)] += w * zu * zv;
                    }
                }
            }
        };
        let ns = layout.sprung.len();
        let mut equations = 0usize;
        let mut noise = Vec::with_capacity(4 + ns);
        let mut wv = [[0.0; 3]; 4];
        let mut sv = vec![[0.0; 3]; ns];
        for t in 0..instants.len() {
            for (c, d) in wheel.iter().enumerate() {
                wv[c] = [d.0[0][t], d.0[1][t], d.0[2][t]];
            }
            for (j, d) in sprung.iter().enumerate() {
                sv[j] = [d.0[0][t], d.0[1][t], d.0[2][t]];
            }
            self.rows(&layout, &wv, &sv, &mut z);
            add(&z, 1.0, &mut gram);
            equations += 3;
        }
        // The noise's expected share of the gram: the rows are linear in each channel's a, a',
        // a''; white noise of variance s^2 per sample adds s^2 times the kernels' sums
        // (`noise_cov`) to their covariances summed over the instants, so each channel's share
        // is found by putting a unit value in one of its three signals at a time.
        let cov = deriv.noise_cov(&instants)?;
        let mut noise_gram = DMatrix::<f64>::zeros(n + 1, n + 1);
        for ch in 0..4 + ns {
            let density = if ch < 4 {
                wheel[ch].1
            } else {
                sprung[ch - 4].1
            };
            let name = &rec.channels[if ch < 4 {
                layout.wheels[ch]
            } else {
                layout.sprung[ch - 4]
            }]
            .name;
            noise.push((name.clone(), density));
            if density <= 0.0 {
                continue;
            }
            // Variance per sample of white noise of this one-sided density.
            let variance = 0.5 * density * fs;
            // Rows for a unit k-th derivative of this channel: L_k.
            let mut probes: Vec<[Vec<f64>; 3]> = Vec::with_capacity(3);
            for k in 0..3 {
                let (mut w0, mut s0) = ([[0.0; 3]; 4], vec![[0.0; 3]; ns]);
                if ch < 4 {
                    w0[ch][k] = 1.0;
                } else {
                    s0[ch - 4][k] = 1.0;
                }
                let mut zk = [vec![0.0; n + 1], vec![0.0; n + 1], vec![0.0; n + 1]];
                self.rows(&layout, &w0, &s0, &mut zk);
                probes.push(zk);
            }
            for (k, pk) in probes.iter().enumerate() {
                for (l, pl) in probes.iter().enumerate() {
                    let c = cov[k][l];
                    if c == 0.0 {
                        continue;
                    }
                    for (a, b) in pk.iter().zip(pl) {
                        for u in 0..=n {
                            for v in 0..=n {
                                noise_gram[(u, v)] += variance * c * a[u] * b[v];
                            }
                        }
                    }
                }
            }
        }
        Ok(RecordEquations {
            unknowns: n,
            gram: gram.as_slice().to_vec(),
            noise_gram: noise_gram.as_slice().to_vec(),
            noise,
            equations,
        })
    }

    /// The three body rows `[x | y]` (regressors, then the right side) at one instant from the
    /// wheels' and the sprung sensors' a, a', a'' (`wheel[c][k]`, `sprung[j][k]`); linear in them.
    fn rows(
        &self,
        layout: &Layout,
        wheel: &[[f64; 3]; 4],
        sprung: &[[f64; 3]],
        z: &mut [Vec<f64>; 3],
    ) {
        let n = z[0].len() - 1;
        z.iter_mut()
            .for_each(|r| r.iter_mut().for_each(|v| *v = 0.0));
        // Body coordinates' derivatives.
        let body: [[f64; 3]; 3] = std::array::from_fn(|b| {
            std::array::from_fn(|k| {
                sprung
                    .iter()
                    .enumerate()
                    .map(|(j, d)| layout.body[(b, j)] * d[k])
                    .sum()
            })
        });
        let tracks = [
            self.vehicle.geometry.track_front_m,
            self.vehicle.geometry.track_rear_m,
        ];
        // Suspension deflection g_c (k-th derivative) = z + x theta + y phi - w.
        for (ci, corner) in Corner::ALL.iter().enumerate() {
            let (cx, cy) = self.vehicle.corner_position_m(*corner);
            let g = |k: usize| body[0][k] + cx * body[1][k] + cy * body[2][k] - wheel[ci][k];
            let (g0, g1) = (g(0), g(1));
            for (row, lever) in [(0, 1.0), (1, cx), (2, cy)] {
                z[row][2 + ci] = lever * g0;
                z[row][6 + ci] = lever * g1;
            }
        }
        z[1][0] = body[1][2];
        z[2][1] = body[2][2];
        let mut col = N_BASE;
        for (a, (l, r)) in [(0usize, (0usize, 1usize)), (1, (2, 3))] {
            if self.bars[a] {
                z[2][col] = body[2][0] - (wheel[l][0] - wheel[r][0]) / tracks[a];
                col += 1;
            }
        }
        z[0][n] = -body[0][2];
        // Pitch and roll rows in force units (moment / radius of gyration).
        for (row, w) in [(1, self.row_weight[0]), (2, self.row_weight[1])] {
            z[row].iter_mut().for_each(|v| *v *= w);
        }
    }

    /// Solves the accumulated equations and builds the updated model, with the jackknife's
    /// standard deviations over the records (three or more) and whether the records support it.
    pub fn solve(&self) -> Result<BodyFitResult> {
        if self.records == 0 {
            return Err(fit_error(
                "no record was added".into(),
                "add at least one record",
            ));
        }
        let n = self.gram.nrows() - 1;
        let zero = || DMatrix::<f64>::zeros(n + 1, n + 1);
        let (raw, noise) = self
            .per_record
            .iter()
            .fold((zero(), zero()), |(a, b), (g, q)| (a + g, b + q));
        let scale = noise_scale(&raw, &noise);
        let (th, at_zero) = self.solve_gram(&(&raw - &noise * scale))?;
        let (ata, atb, btb) = (
            self.gram.view((0, 0), (n, n)),
            self.gram.view((0, n), (n, 1)),
            self.gram[(n, n)],
        );
        let rss = btb - 2.0 * th.dot(&atb) + (ata * &th).dot(&th);
        let explained = if btb > 0.0 { 1.0 - rss / btb } else { 0.0 };
        let (v, absent) = self.vehicle_from(&th, &at_zero)?;
        let modes = FullCar::new(&v)?.modes()?;
        let values = self.values(&th);
        // Jackknife over the records: each left out in turn.
        let body = [
            ModeLabel::BodyPitch,
            ModeLabel::BodyHeave,
            ModeLabel::BodyRoll,
        ];
        let mut not_supported: Option<String> = None;
        let mut loo_values: Vec<Vec<f64>> = Vec::new();
        let mut loo_modes: Vec<Vec<Option<(f64, f64)>>> = Vec::new();
        if self.records >= 3 {
            for (r, (g, q)) in self.per_record.iter().enumerate() {
                let (raw_r, noise_r) = (&raw - g, &noise - q);
                let scale_r = noise_scale(&raw_r, &noise_r);
                let fit = self
                    .solve_gram(&(&raw_r - &noise_r * scale_r))
                    .and_then(|(t, z)| Ok((self.vehicle_from(&t, &z)?, t)))
                    .and_then(|((vv, _), t)| Ok((FullCar::new(&vv)?.modes()?, t)));
                match fit {
                    Ok((mm, t)) => {
                        loo_values.push(self.values(&t).into_iter().map(|x| x.2).collect());
                        loo_modes.push(
                            body.iter()
                                .map(|&l| {
                                    mm.iter()
                                        .find(|m| m.label == l)
                                        .map(|m| (m.frequency_hz, m.damping_ratio))
                                })
                                .collect(),
                        );
                    }
                    Err(e) => {
                        not_supported.get_or_insert(format!(
                            "without record {} of {} the fit fails ({e})",
                            r + 1,
                            self.records
                        ));
                    }
                }
            }
        }
        let jack = vibmode_core::stats::jackknife_std;
        let have_sd = not_supported.is_none() && loo_values.len() >= 3;
        let parameters: Vec<FittedParameter> = values
            .iter()
            .enumerate()
            .map(|(i, (name, unit, value))| FittedParameter {
                name: name.clone(),
                unit,
                value: *value,
                sd: have_sd.then(|| jack(&loo_values.iter().map(|l| l[i]).collect::<Vec<_>>())),
            })
            .collect();
        let mut mode_sd = Vec::new();
        for (i, &l) in body.iter().enumerate() {
            if !have_sd {
                break;
            }
            let got: Option<Vec<(f64, f64)>> = loo_modes.iter().map(|m| m[i]).collect();
            match got {
                Some(g) => {
                    let f: Vec<f64> = g.iter().map(|x| x.0).collect();
                    let z: Vec<f64> = g.iter().map(|x| x.1).collect();
                    mode_sd.push(ModeSpread {
                        label: l,
                        frequency_hz_sd: jack(&f),
                        damping_ratio_sd: jack(&z),
                    });
                }
                None => {
                    not_supported.get_or_insert(format!(
                        "leaving out a record, the updated model has no {l} mode"
                    ));
                }
            }
        }
        // Support: every body mode's frequency and every spring and damper inside its tolerance
        // at SUPPORT_CONFIDENCE together: `support_factor` standard deviations each.
        if not_supported.is_none() && !have_sd {
            not_supported = Some(format!(
                "{} record{} cannot show how well the fit is known: the support is judged from the spread over the records left out in turn, which needs 3 or more",
                self.records,
                if self.records == 1 { "" } else { "s" }
            ));
        }
        if not_supported.is_none() {
            let mut judged: Vec<(String, f64, f64)> = Vec::new();
            for sp in &mode_sd {
                if let Some(m) = modes.iter().find(|m| m.label == sp.label) {
                    let rel = sp.frequency_hz_sd / m.frequency_hz;
                    judged.push((format!("{} frequency", sp.label), rel, MODE_TOLERANCE));
                }
            }
            for p in &parameters {
                if !(p.name.starts_with("spring") || p.name.starts_with("damper")) {
                    continue;
                }
                if let Some(sd) = p.sd {
                    let rel = sd / p.value.abs().max(f64::MIN_POSITIVE);
                    judged.push((p.name.clone(), rel, PARAM_TOLERANCE));
                }
            }
            let k = support_factor(loo_values.len(), judged.len());
            if judged.is_empty() {
                // Nothing to judge supports nothing (every fit has springs and dampers today).
                not_supported = Some(
                    "no body mode frequency, spring or damper of the fit has a standard deviation to judge its support by".to_string(),
                );
            } else if let Some((name, rel, tol)) = judged.iter().find(|(_, rel, tol)| {
                // Outside, or not a number (an sd that is NaN supports nothing).
                matches!(
                    (k * rel).partial_cmp(tol),
                    Some(std::cmp::Ordering::Greater) | None
                )
            }) {
                let worst = judged
                    .iter()
                    .map(|(_, rel, tol)| rel / tol)
                    .fold(0.0, f64::max);
                let more = match records_to_support(loo_values.len(), judged.len(), worst) {
                    Some(r) => format!(
                        "; about {r} records like these would support it (the spread falls as 1/sqrt(records))"
                    ),
                    None => String::new(),
                };
                not_supported = Some(format!(
                    "the {name} is known to +-{:.1} % ({k:.2} jackknife standard deviations of {:.2} %: {:.0} % confidence over {} quantities from {} records), more than the {:.0} % a supported fit meets{more}",
                    100.0 * k * rel,
                    100.0 * rel,
                    100.0 * SUPPORT_CONFIDENCE,
                    judged.len(),
                    loo_values.len(),
                    100.0 * tol
                ));
            }
        }
        Ok(BodyFitResult {
            vehicle: v,
            modes,
            nominal_modes: self.nominal_modes.clone(),
            records: self.records,
            equations: self.equations,
            band_hz: self.band_hz,
            explained,
            absent,
            parameters,
            replicates: if have_sd { loo_values } else { Vec::new() },
            mode_sd,
            supported: not_supported.is_none(),
            not_supported,
            noise_density: self.noise_summary(),
            noise_share: scale,
            band_choice: None,
        })
    }

    /// Each used channel's noise density, the median over the records.
    fn noise_summary(&self) -> Vec<ChannelNoise> {
        let mut names: Vec<&String> = Vec::new();
        for (n, _) in &self.noise {
            if !names.contains(&n) {
                names.push(n);
            }
        }
        names
            .into_iter()
            .map(|name| {
                let mut d: Vec<f64> = self
                    .noise
                    .iter()
                    .filter(|(n, _)| n == name)
                    .map(|x| x.1)
                    .collect();
                ChannelNoise {
                    channel: name.clone(),
                    density_per_hz: vibmode_core::stats::median_high_in_place(&mut d),
                }
            })
            .collect()
    }

    /// The bounded least-squares solution of an augmented gram `[X^T X, X^T y; ., y^T y]`
    /// and which unknowns it holds at 0.
    fn solve_gram(&self, g: &DMatrix<f64>) -> Result<(DVector<f64>, Vec<bool>)> {
        let n = g.nrows() - 1;
        let ata = g.view((0, 0), (n, n)).into_owned();
        let atb = g.view((0, n), (n, 1)).column(0).into_owned();
        let Some(ch) = ata.clone().cholesky() else {
            return Err(fit_error(
                "the equations do not determine the suspension (the normal matrix, less the sensors' noise, is not positive definite)".into(),
                "check that the records contain body motion in the band above the sensors' noise and that the channels' corners are right",
            ));
        };
        // Every unknown is >= 0 (inertias, springs, dampers, bars): the unconstrained solution
        // when it is feasible, else non-negative least squares, which holds at 0 what the
        // records pull below it (an anti-roll bar the bus does not have).
        let th = ch.solve(&atb);
        if th.iter().all(|&v| v >= 0.0) {
            let z = vec![false; n];
            return Ok((th, z));
        }
        match crate::nnls::nnls_normal(&ata, &atb) {
            Some(sol) => Ok((sol.x, sol.at_bound)),
            None => Err(fit_error(
                "the bounded fit did not converge".into(),
                "check that the records contain body motion in the band",
            )),
        }
    }

    /// The fitted parameters in SI units, with their names and units.
    fn values(&self, th: &DVector<f64>) -> Vec<(String, &'static str, f64)> {
        let m = self.vehicle.body.mass_kg;
        let mut out = vec![
            ("pitch inertia".to_string(), "kg m^2", th[0] * m),
            ("roll inertia".to_string(), "kg m^2", th[1] * m),
        ];
        for c in Corner::ALL {
            out.push((format!("spring {c}"), "N/m", th[2 + c.index()] * m));
        }
        for c in Corner::ALL {
            out.push((format!("damper {c}"), "N s/m", th[6 + c.index()] * m));
        }
        let mut col = N_BASE;
        for (a, name) in [(0usize, "front"), (1, "rear")] {
            if self.bars[a] {
                out.push((format!("anti-roll bar {name}"), "N m/rad", th[col] * m));
                col += 1;
            }
        }
        out
    }

    /// The updated vehicle from the fitted unknowns, and the bars held at 0.
    fn vehicle_from(
        &self,
        th: &DVector<f64>,
        at_zero: &[bool],
    ) -> Result<(VehicleParams, Vec<String>)> {
        let m = self.vehicle.body.mass_kg;
        let mut v = self.vehicle.clone();
        let positive = |what: String, value: f64, unit: &str| -> Result<f64> {
            if value.is_finite() && value > 0.0 {
                Ok(value)
            } else {
                Err(fit_error(
                    format!("the fit put {what} at its bound {value:.4e} {unit}: the records do not support a positive value"),
                    "check the channels' roles and corners and that the records contain body motion in the band",
                ))
            }
        };
        let mut absent = Vec::new();
        v.body.pitch_inertia_kgm2 = positive("the pitch inertia".into(), th[0] * m, "kg m^2")?;
        v.body.roll_inertia_kgm2 = positive("the roll inertia".into(), th[1] * m, "kg m^2")?;
        let mut k = [0.0; 4];
        let mut c = [0.0; 4];
        for corner in Corner::ALL {
            let i = corner.index();
            k[i] = positive(format!("the {corner} spring"), th[2 + i] * m, "N/m")?;
            c[i] = positive(format!("the {corner} damper"), th[6 + i] * m, "N s/m")?;
        }
        let mut col = N_BASE;
        for (a, name) in [(0usize, "front"), (1, "rear")] {
            if self.bars[a] {
                // A bar held at 0 is one the measured bus does not have.
                let bar = th[col] * m;
                if at_zero[col] || bar <= 0.0 {
                    absent.push(format!("{name} anti-roll bar"));
                }
                let bar = bar.max(0.0);
                if a == 0 {
                    v.front.anti_roll_stiffness_nm_per_rad = bar;
                } else {
                    v.rear.anti_roll_stiffness_nm_per_rad = bar;
                }
                col += 1;
            }
        }
        // Axle means, and each corner as factors on them (the file's tyre factors kept).
        let tyre_factor = |corner: Corner| {
            self.vehicle
                .corner_condition
                .iter()
                .filter(|cc| cc.corner == corner)
                .map(|cc| cc.tyre_stiffness_factor)
                .product::<f64>()
        };
        let (kf, kr) = (0.5 * (k[0] + k[1]), 0.5 * (k[2] + k[3]));
        let (cf, cr) = (0.5 * (c[0] + c[1]), 0.5 * (c[2] + c[3]));
        v.front.spring_stiffness_n_per_m = kf;
        v.rear.spring_stiffness_n_per_m = kr;
        v.front.damper_n_s_per_m = cf;
        v.rear.damper_n_s_per_m = cr;
        v.corner_condition = Corner::ALL
            .iter()
            .map(|&corner| {
                let i = corner.index();
                let (ka, ca) = if corner.is_front() {
                    (kf, cf)
                } else {
                    (kr, cr)
                };
                CornerCondition {
                    corner,
                    damper_factor: c[i] / ca,
                    spring_factor: k[i] / ka,
                    tyre_stiffness_factor: tyre_factor(corner),
                }
            })
            .collect();
        Ok((v, absent))
    }
}

/// How much of the noise's expected share `noise` is taken out of the normal equations `raw`
/// (both augmented, `[X | y]^T [X | y]`): the smallest `lambda` at which `raw - lambda noise`
/// becomes singular (the generalized eigenvalue of the pencil, so that the corrected matrix stays
/// positive semi-definite and its regressor block positive definite), at most 1.
///
/// With `lambda` = 1 the fit is bias-compensated least squares; with the smallest eigenvalue it
/// is generalized total least squares (the maximum-likelihood fit of a linear model whose every
/// column is noisy, for independent equations whose noise covariance is known up to a factor;
/// here the band-passed equations are not independent, so it is that fit's form, not its
/// optimality). Both are consistent; with few records the eigenvalue falls below 1 by chance
/// and subtracting the whole expected share leaves a nearly singular, or indefinite, matrix
/// whose inverse scatters and biases the fit (docs/model_update.md, "Sensor noise"). An eigenvalue above 1 says the equations hold more error than the sensors'
/// noise (a model error: manoeuvres, bending, lines), which is not the noise's shape, so no more
/// than the expected share is taken out. 1 when there is no noise share (no flat floor found),
/// or when `raw` is not positive definite (then the fit says why).
pub fn noise_scale(raw: &DMatrix<f64>, noise: &DMatrix<f64>) -> f64 {
    // raw = L L^T; raw v = lambda noise v  <=>  L^-1 noise L^-T u = (1 / lambda) u.
    let Some(ch) = raw.clone().cholesky() else {
        return 1.0;
    };
    let l = ch.l();
    let Some(a) = l.solve_lower_triangular(noise) else {
        return 1.0;
    };
    let Some(b) = l.solve_lower_triangular(&a.transpose()) else {
        return 1.0;
    };
    let sym = 0.5 * (&b + b.transpose());
    let mu = sym
        .symmetric_eigenvalues()
        .iter()
        .cloned()
        .fold(0.0_f64, f64::max);
    if mu.is_finite() && mu > 1.0 {
        1.0 / mu
    } else {
        1.0
    }
}

/// Largest ratio between the periodogram medians of the two halves of the noise range (split at
/// its geometric mean) for the range to count as a white noise floor. Each median of N
/// ordinates spreads by about 1 / (ln 2 sqrt(N/2)) with the Hann window: 6 % for the 1100 of
/// the lower half of 20 s at 500 Hz; a spectrum falling as f^-2 differs by about 4 between the
/// halves of two octaves.
pub const FLAT_FLOOR: f64 = 1.5;

/// Where a channel's spectrum is taken as its noise floor, Hz: from 15 times the band's upper
/// edge (and at least 5 % of the rate) to 0.4 times the rate, below any anti-alias roll-off;
/// two octaves at least, so that a spectrum still falling there (road and wheel motion) is told
/// from a flat floor. On busgen's buses at 2 kHz the unsprung channels' road response is 300
/// times below the noise from 40 Hz on. `None` when the rate is too low (below about 60 times
/// the band's upper edge, 130 Hz on the bus): then nothing is subtracted.
pub fn noise_range_hz(band_hz: [f64; 2], fs_hz: f64) -> Option<[f64; 2]> {
    noise_range_above(band_hz, fs_hz, 15.0)
}

/// A channel's noise-floor range above a band, Hz: from `factor` times the band's upper edge
/// (and at least 5 % of the rate) to 0.4 times the rate, below any anti-alias roll-off; `None`
/// unless it spans two octaves (so that a spectrum still falling there is told from a flat
/// floor, [`FLAT_FLOOR`]). [`noise_range_hz`] is this with 15, the fleet's level ratios use 10.
pub fn noise_range_above(band_hz: [f64; 2], fs_hz: f64, factor: f64) -> Option<[f64; 2]> {
    let lo = (factor * band_hz[1]).max(0.05 * fs_hz);
    let hi = 0.4 * fs_hz;
    (hi >= 4.0 * lo).then_some([lo, hi])
}

/// The periodic Hann window of `n` samples (`0.5 - 0.5 cos(2 pi k / n)`) and the sum of its
/// squares.
pub fn hann_window(n: usize) -> (Vec<f64>, f64) {
    let w: Vec<f64> = (0..n)
        .map(|k| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * k as f64 / n as f64).cos())
        .collect();
    let wsum = w.iter().map(|v| v * v).sum();
    (w, wsum)
}

/// The one-sided density (unit^2/Hz) of the white noise floor of `x` sampled at `fs_hz`, from its
/// spectrum over `range_hz` (above the band of interest and below any anti-alias roll-off, two
/// octaves or more, as [`noise_range_hz`] gives the model update's), measured as the model
/// update measures each channel's: the Hann-windowed periodogram's median in each half of the
/// range (split at its geometric mean) divided by ln 2 (a periodogram ordinate of white noise is
/// exponentially distributed), robust to the few tones the range may hold, averaged over the
/// halves; 0 when a half holds fewer than 16 bins or the halves differ by more than
/// [`FLAT_FLOOR`] (no white floor: what is there is motion).
///
/// Errors: only an internal FFT failure ([`VehicleError::Numerical`]).
pub fn noise_floor_density(x: &[f64], fs_hz: f64, range_hz: [f64; 2]) -> Result<f64> {
    let n = x.len();
    let (window, wsum) = hann_window(n);
    let mean = x.iter().sum::<f64>() / n.max(1) as f64;
    floor_density(x, mean, fs_hz, range_hz, &window, wsum)
}

/// [`noise_floor_density`] with the record's mean and its Hann window (`window`, the sum of its
/// squares `wsum`) given.
fn floor_density(
    x: &[f64],
    mean: f64,
    fs_hz: f64,
    [lo, hi]: [f64; 2],
    window: &[f64],
    wsum: f64,
) -> Result<f64> {
    // A Hann-windowed periodogram of the record (its sidelobes fall fast, so a strong tone does
    // not spread over the range).
    let n = x.len();
    let plan = plan_forward(n);
    let mut hb = plan.make_input_vec();
    for ((b, v), w) in hb.iter_mut().zip(x).zip(window) {
        *b = w * (v - mean);
    }
    let mut spec = plan.make_output_vec();
    plan.process(&mut hb, &mut spec)
        .map_err(|e| VehicleError::Numerical(format!("FFT: {e}")))?;
    let df = fs_hz / n as f64;
    let (a, b) = ((lo / df).ceil() as usize, (hi / df).floor() as usize);
    let b = b.min(spec.len() - 1);
    // The median periodogram of each half of the range (split at the geometric mean, an octave
    // or more each): a white floor is flat across them; a spectrum still falling there (motion,
    // not noise) is not taken as noise.
    let c = ((lo * hi).sqrt() / df).round() as usize;
    let halves = [(a, c), (c, b + 1)];
    let medians: Vec<f64> = halves
        .iter()
        .filter(|&&(u, v)| v >= u + 16)
        .map(|&(u, v)| {
            let mut p: Vec<f64> = spec[u..v].iter().map(|v| v.norm_sqr()).collect();
            let mid = p.len() / 2;
            *p.select_nth_unstable_by(mid, |x, y| x.total_cmp(y)).1
        })
        .collect();
    let (mn, mx) = medians
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(a, b), &v| (a.min(v), b.max(v)));
    Ok(if medians.len() == 2 && mx <= FLAT_FLOOR * mn {
        let med = 0.5 * (medians[0] + medians[1]);
        // E|X_k|^2 = sigma^2 sum w^2 for white noise of variance sigma^2; one-sided density
        // 2 sigma^2 / fs.
        2.0 * (med / std::f64::consts::LN_2) / (wsum * fs_hz)
    } else {
        0.0
    })
}

/// The rate the body equations are formed at, at least: a record sampled at `k` times this
/// or more (`k >= 2`, e.g. 20 kHz: `k` = 4) is brought down by the integer factor `k`
/// ([`decimate_ideal`]) before its equations are formed. The band lies below 10 Hz; what sets
/// the rate is the noise floor ([`noise_range_hz`]: 250-2000 Hz at 5 kHz), which must lie above
/// the vehicle's motion: on the demo's records at 20 kHz (white sensor noise of density
/// 4.0e-8 (m/s^2)^2/Hz) the sprung channels' floor came out 0.4-3.6 % high at 5 kHz, 3-20 %
/// high at 2 kHz (100-800 Hz still holds motion) and within 0.3 % at the full rate. The cost
/// of the equations is that of the record's FFTs, `k` times shorter.
pub const EQUATION_RATE_HZ: f64 = 5000.0;

/// The integer factor a record at `fs_hz` is brought down by for its equations (1: none).
pub fn decimation_factor(fs_hz: f64) -> usize {
    ((fs_hz / EQUATION_RATE_HZ).floor() as usize).max(1)
}

/// How many of the first bins of a channel's spectrum (`vibmode_signal::ChannelSpectrum`) the
/// equations of a record of `n` samples at `fs_hz` read when it is brought down
/// ([`decimation_factor`] above 1): those up to the new Nyquist frequency's, and one beyond.
/// `None` when the record is used at its own rate (no spectrum is read).
pub fn spectrum_bins_read(n: usize, fs_hz: f64) -> Option<usize> {
    let factor = decimation_factor(fs_hz);
    (factor > 1).then(|| n / (2 * factor) + 2)
}

/// `x` at `1 / factor` of its rate by the paper's ideal DFT low-pass and decimation
/// (`vibmode_signal::resample`, cutoff at the new Nyquist frequency; when `factor` divides the
/// length, as `scipy.signal.resample(x, len / factor)`), from `x`'s spectrum where given.
///
/// Errors: only an internal FFT failure ([`VehicleError::Numerical`]).
fn decimate_ideal(
    x: &[f64],
    spectrum: Option<&vibmode_signal::ChannelSpectrum>,
    fs_hz: f64,
    factor: usize,
) -> Result<Vec<f64>> {
    let p = vibmode_signal::ResampleParams {
        fs_out_hz: fs_hz / factor as f64,
        cutoff_hz: None,
        filter: true,
    };
    let failed = |e: vibmode_signal::SignalError| {
        VehicleError::Numerical(format!("bringing a record down by {factor}: {e}"))
    };
    let mut r = vibmode_signal::Resampler::new(x.len(), fs_hz, &p).map_err(failed)?;
    let mut out = vec![0.0; r.n_out()];
    match spectrum {
        Some(s) => r.process_spectrum(x, s, &mut out),
        None => r.process(x, &mut out),
    }
    .map_err(failed)?;
    Ok(out)
}

/// The band-pass's moments `m_p = int G(f)^2 (2 pi f)^p df` for p = 0, 2, 4 (G the gain of
/// [`Derivatives`]): white noise of one-sided density S has, after the band-pass, variance
/// `S m_0`, its first derivative `S m_2`, its second `S m_4`, and the covariance of the signal
/// with its second derivative `-S m_2` (the others 0). Trapezoidal rule on 4000 steps. The fit
/// uses the exact sums of the finite record ([`Derivatives::noise_cov`]); these are their limit
/// far from the record's ends (tested).
#[cfg(test)]
fn band_moments(band_hz: [f64; 2]) -> [f64; 3] {
    let d = Derivatives::new(16, 1.0, band_hz);
    let (a, b) = (0.7 * band_hz[0], 1.3 * band_hz[1]);
    let steps = 4000;
    let h = (b - a) / steps as f64;
    let mut m = [0.0; 3];
    for i in 0..=steps {
        let f = a + h * i as f64;
        let w = if i == 0 || i == steps { 0.5 } else { 1.0 };
        let g2 = d.gain(f).powi(2);
        let om2 = (2.0 * std::f64::consts::PI * f).powi(2);
        m[0] += w * h * g2;
        m[1] += w * h * g2 * om2;
        m[2] += w * h * g2 * om2 * om2;
    }
    m
}

/// The band-limited signal and its first two time derivatives, by FFT of the zero-padded record
/// (twice its length, mean removed) under a band-pass with cosine tapers of 30 % of each edge.
struct Derivatives {
    len: usize,
    fs_hz: f64,
    band_hz: [f64; 2],
    /// The record's Hann window and the sum of its squares, made on first use and shared by
    /// the channels.
    hann: Option<(Vec<f64>, f64)>,
}

impl Derivatives {
    fn new(len: usize, fs_hz: f64, band_hz: [f64; 2]) -> Self {
        Derivatives {
            len,
            fs_hz,
            band_hz,
            hann: None,
        }
    }

    /// The Hann window of `n` samples and the sum of its squares.
    fn hann(&mut self, n: usize) -> &(Vec<f64>, f64) {
        if self.hann.as_ref().is_some_and(|(w, _)| w.len() != n) {
            self.hann = None;
        }
        self.hann.get_or_insert_with(|| hann_window(n))
    }

    /// The band-pass gain at `f` Hz.
    fn gain(&self, f: f64) -> f64 {
        let [lo, hi] = self.band_hz;
        let w = 0.3;
        if f <= lo * (1.0 - w) || f >= hi * (1.0 + w) {
            0.0
        } else if f < lo * (1.0 + w) {
            let u = (f - lo * (1.0 - w)) / (2.0 * w * lo);
            0.5 - 0.5 * (std::f64::consts::PI * u).cos()
        } else if f > hi * (1.0 - w) {
            let u = (hi * (1.0 + w) - f) / (2.0 * w * hi);
            0.5 - 0.5 * (std::f64::consts::PI * u).cos()
        } else {
            1.0
        }
    }

    /// For white noise of unit variance per sample, the sums over the samples `keep` of the
    /// covariances of its three filtered signals, `sum_t E[d_k(t) d_l(t)]` for k, l = 0..2:
    /// exact for the finite, zero-padded record (each output sample is `sum_j h_k(t - j) x_j`
    /// over the record's samples, `h_k` the circular kernel of the band-pass times `(i w)^k`),
    /// so the samples near the record's ends, whose kernels reach past it, count less.
    fn noise_cov(&mut self, keep: &[usize]) -> Result<[[f64; 3]; 3]> {
        // They depend on the record's length, rate, band and instants only, so the records of
        // a drive (equal lengths) share them: kept per thread for the last few such keys.
        type Key = (usize, u64, [u64; 2], Vec<usize>);
        thread_local! {
            static SUMS: std::cell::RefCell<Vec<(Key, [[f64; 3]; 3])>> =
                const { std::cell::RefCell::new(Vec::new()) };
        }
        let key: Key = (
            self.len,
            self.fs_hz.to_bits(),
            self.band_hz.map(f64::to_bits),
            keep.to_vec(),
        );
        if let Some(sums) =
            SUMS.with(|c| c.borrow().iter().find(|(k, _)| *k == key).map(|(_, v)| *v))
        {
            return Ok(sums);
        }
        let sums = self.noise_cov_sums(keep)?;
        SUMS.with(|c| {
            let mut c = c.borrow_mut();
            if c.len() >= 4 {
                c.remove(0);
            }
            c.push((key, sums));
        });
        Ok(sums)
    }

    fn noise_cov_sums(&mut self, keep: &[usize]) -> Result<[[f64; 3]; 3]> {
        use num_complex::Complex64;
        let (n, m) = (self.len, 2 * self.len);
        let inv = plan_inverse(m);
        let df = self.fs_hz / m as f64;
        let mut h: Vec<Vec<f64>> = Vec::with_capacity(3);
        for k in 0..3 {
            let mut spec = inv.make_input_vec();
            let last = spec.len() - 1;
            for (i, v) in spec.iter_mut().enumerate() {
                let f = i as f64 * df;
                let iw = Complex64::new(0.0, 2.0 * std::f64::consts::PI * f);
                *v = if i == 0 || i == last {
                    Complex64::new(0.0, 0.0)
                } else {
                    iw.powu(k) * (self.gain(f) / m as f64)
                };
            }
            let mut out = inv.make_output_vec();
            inv.process(&mut spec, &mut out)
                .map_err(|e| VehicleError::Numerical(format!("FFT: {e}")))?;
            h.push(out);
        }
        let mut sums = [[0.0; 3]; 3];
        for k in 0..3 {
            for l in k..3 {
                // Prefix sums of h_k h_l; the lags t - j for j in 0..n are t, t-1, ..., t-n+1
                // (mod m): [0, t] and [m + t - n + 1, m).
                let mut pre = vec![0.0; m + 1];
                for u in 0..m {
                    pre[u + 1] = pre[u] + h[k][u] * h[l][u];
                }
                let total: f64 = keep
                    .iter()
                    .map(|&t| pre[t + 1] + pre[m] - pre[m + t + 1 - n])
                    .sum();
                sums[k][l] = total;
                sums[l][k] = total;
            }
        }
        Ok(sums)
    }

    /// The three signals at the samples `keep`.
    ///
    /// Only the band's bins are non-zero, so each kept sample is summed from them directly
    /// (`y[n] = 2 Re sum_k S_k e^(2 pi i k n / m)`, the inverse real FFT at that sample) instead
    /// of three inverse FFTs of the whole padded record: the same numbers, at a small fraction of
    /// the cost when the records are long and sampled fast.
    /// With them, the noise density of `x` (one-sided, unit^2/Hz) estimated from its spectrum
    /// above the band ([`noise_range_hz`]): the Hann-windowed periodogram's median in each half
    /// of that range divided by ln 2 (a periodogram ordinate of white noise is exponentially
    /// distributed), robust to the few tones the range may hold, averaged over the halves;
    /// 0 when the rate leaves no such range or the halves differ by more than [`FLAT_FLOOR`]
    /// (no white floor: what is there is motion, and is not subtracted).
    fn apply(&mut self, x: &[f64], keep: &[usize]) -> Result<([Vec<f64>; 3], f64)> {
        use num_complex::Complex64;
        let m = 2 * self.len;
        let fwd = plan_forward(m);
        let mean = x.iter().sum::<f64>() / x.len().max(1) as f64;
        let mut buf = fwd.make_input_vec();
        buf.iter_mut().zip(x).for_each(|(b, v)| *b = v - mean);
        let mut spec = fwd.make_output_vec();
        // Lengths match by construction (plans of `m`); a failure is a bug, not bad input.
        fwd.process(&mut buf, &mut spec)
            .map_err(|e| VehicleError::Numerical(format!("FFT: {e}")))?;
        let df = self.fs_hz / m as f64;
        let density = match noise_range_hz(self.band_hz, self.fs_hz) {
            Some(range) => {
                let fs_hz = self.fs_hz;
                let (window, wsum) = self.hann(x.len());
                floor_density(x, mean, fs_hz, range, window, *wsum)?
            }
            None => 0.0,
        };
        // The band's bins (never DC or Nyquist: the band lies inside), each scaled for the
        // signal, its first and its second derivative.
        let first = ((self.band_hz[0] * 0.7 / df).floor() as usize).max(1);
        let last = ((self.band_hz[1] * 1.3 / df).ceil() as usize).min(spec.len().saturating_sub(2));
        let scaled: Vec<[Complex64; 3]> = (first..=last)
            .map(|i| {
                let f = i as f64 * df;
                let v = spec[i] * (2.0 * self.gain(f) / m as f64);
                let iw = Complex64::new(0.0, 2.0 * std::f64::consts::PI * f);
                [v, v * iw, v * iw * iw]
            })
            .collect();
        Ok((band_sums(&scaled, first, m, keep), density))
    }
}

/// Instants evaluated side by side by [`band_sums`]: independent recurrences, so that one
/// instant's multiplications overlap another's.
const INSTANTS_SIDE_BY_SIDE: usize = 4;

/// `sum_k Re(s_k[j] e^(2 pi i (first + k) n / m))` for j = 0, 1, 2 at each instant `n` of
/// `keep`: the band's bins brought back to those instants. Each instant's phase starts at
/// `e^(2 pi i first n / m)` and turns by `e^(2 pi i n / m)` per bin (phases reduced modulo `m`
/// in integers, so long records keep their precision). Four instants are summed side by side,
/// each with exactly the operations of one at a time ([`Complex64`]'s product and
/// `MulAssign`, in their order), so the sums are the same bits.
fn band_sums(
    scaled: &[[num_complex::Complex64; 3]],
    first: usize,
    m: usize,
    keep: &[usize],
) -> [Vec<f64>; 3] {
    use num_complex::Complex64;
    const L: usize = INSTANTS_SIDE_BY_SIDE;
    let phase = |k: usize, n: usize| {
        let r = ((k as u128 * n as u128) % m as u128) as f64;
        Complex64::from_polar(1.0, 2.0 * std::f64::consts::PI * r / m as f64)
    };
    let mut out: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(keep.len()));
    for group in keep.chunks(L) {
        let mut e_re = [0.0f64; L];
        let mut e_im = [0.0f64; L];
        let mut st_re = [0.0f64; L];
        let mut st_im = [0.0f64; L];
        for (l, &n) in group.iter().enumerate() {
            let (e, st) = (phase(first, n), phase(1, n));
            (e_re[l], e_im[l], st_re[l], st_im[l]) = (e.re, e.im, st.re, st.im);
        }
        let mut acc = [[0.0f64; L]; 3];
        for s in scaled {
            for (a, v) in acc.iter_mut().zip(s) {
                for l in 0..L {
                    // (v * e).re
                    a[l] += v.re * e_re[l] - v.im * e_im[l];
                }
            }
            for l in 0..L {
                // e *= step, as `MulAssign` does it
                let re = e_re[l];
                e_re[l] = e_re[l] * st_re[l] - e_im[l] * st_im[l];
                e_im[l] = e_im[l] * st_re[l] + re * st_im[l];
            }
        }
        for (o, a) in out.iter_mut().zip(&acc) {
            o.extend_from_slice(&a[..group.len()]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    /// By hand: with 2 records (1 degree of freedom) t is Cauchy, quantile tan(pi (p - 1/2)); with
    /// 3 records (2 degrees of freedom) it is (2p - 1) / sqrt(2 p (1 - p)). One quantity at 95 %:
    /// p = 0.975, tan(0.475 pi) = 12.7062, 0.95 / sqrt(0.04875) = 4.3027. Nothing is supported
    /// without records or quantities.
    #[test]
    fn support_factor_by_hand() {
        use super::support_factor;
        use std::f64::consts::PI;
        let p = 0.975_f64;
        let cauchy = (PI * (p - 0.5)).tan();
        assert!((cauchy - 12.706_204_736).abs() < 1e-6, "{cauchy}");
        assert!((support_factor(2, 1) - cauchy).abs() < 1e-7 * cauchy);
        let two = (2.0 * p - 1.0) / (2.0 * p * (1.0 - p)).sqrt();
        assert!((two - 4.302_652_73).abs() < 1e-6, "{two}");
        assert!((support_factor(3, 1) - two).abs() < 1e-8 * two);
        // Three quantities at 2 degrees of freedom: p = 1 - 0.05 / 6.
        let p3: f64 = 1.0 - 0.05 / 6.0;
        let three = (2.0 * p3 - 1.0) / (2.0 * p3 * (1.0 - p3)).sqrt();
        assert!((support_factor(3, 3) - three).abs() < 1e-8 * three);
        assert!(support_factor(1, 3).is_infinite());
        assert!(support_factor(8, 0).is_infinite());
        // More records and fewer quantities ask for fewer standard deviations.
        assert!(support_factor(16, 11) < support_factor(8, 11));
        assert!(support_factor(8, 3) < support_factor(8, 11));
    }

    /// The records that would support a fit: the fewest for which the condition holds (and one
    /// fewer does not), the same count when it holds already, more for a wider spread. By hand
    /// for many records, where t is the normal quantile z = 2.8376 (11 quantities): a spread
    /// `worst` = 1 from 8 records needs about 8 z^2 = 64.4 records; with t's quantile, 2.935 at
    /// 69 records and 2.9365 at 68 (scipy.stats.t.ppf(1 - 0.05/22, 67)), exactly 69.
    #[test]
    fn records_to_support_is_the_fewest_that_would() {
        use super::{records_to_support, support_factor};
        let holds = |r: usize, records: usize, w: f64| {
            support_factor(r, 11) * w * (records as f64 / r as f64).sqrt() <= 1.0
        };
        for (records, w) in [(8usize, 0.5), (8, 1.0), (8, 2.0), (16, 0.9), (3, 0.3)] {
            let r = records_to_support(records, 11, w).unwrap();
            assert!(holds(r, records, w), "{records}, {w}: {r}");
            if r > records {
                assert!(
                    !holds(r - 1, records, w),
                    "{records}, {w}: {r} is not the fewest"
                );
            }
        }
        let r1 = records_to_support(8, 11, 1.0).unwrap();
        assert_eq!(r1, 69);
        // Already supported: the same count.
        assert_eq!(records_to_support(8, 11, 0.2), Some(8));
        assert!(records_to_support(8, 11, 2.0).unwrap() > r1);
        assert_eq!(records_to_support(8, 11, f64::NAN), None);
        assert_eq!(records_to_support(8, 11, 1e6), None);
    }

    /// The gate's coverage: m quantities, each the mean of R standard normal draws, its jackknife
    /// standard deviation (for a mean, the standard error s / sqrt(R)); the intervals of
    /// `support_factor` standard deviations hold every true value at once in 95 % of 4000 seeds
    /// (Bonferroni over independent quantities: (1 - 0.05/m)^m = 95.1 % for m = 11), judged
    /// within 3 binomial standard deviations (0.34 %). The normal quantile in place of t would
    /// cover 76 % with 8 records and 11 quantities (87 % with 16).
    #[test]
    fn support_intervals_cover_at_the_stated_confidence_over_seeds() {
        use super::{support_factor, SUPPORT_CONFIDENCE};
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        use vibmode_core::stats::jackknife_std;
        for (records, m) in [(8usize, 11usize), (5, 3), (16, 11)] {
            let k = support_factor(records, m);
            let seeds = 4000;
            let mut held = 0usize;
            for seed in 0..seeds {
                let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed as u64 * 31 + m as u64);
                let all = (0..m).all(|_| {
                    let x: Vec<f64> = (0..records)
                        .map(|_| StandardNormal.sample(&mut rng))
                        .collect();
                    let mean = x.iter().sum::<f64>() / records as f64;
                    // Leave-one-out means: their jackknife spread is the mean's standard error.
                    let loo: Vec<f64> = x
                        .iter()
                        .map(|xi| (mean * records as f64 - xi) / (records - 1) as f64)
                        .collect();
                    mean.abs() <= k * jackknife_std(&loo)
                });
                held += usize::from(all);
            }
            let want = (1.0 - (1.0 - SUPPORT_CONFIDENCE) / m as f64).powi(m as i32);
            let rate = held as f64 / seeds as f64;
            let slack = 3.0 * (want * (1.0 - want) / seeds as f64).sqrt();
            assert!(
                (rate - want).abs() <= slack,
                "{records} records, {m} quantities: intervals held in {rate:.4} of seeds, expected {want:.4} +- {slack:.4}"
            );
        }
    }
    /// White noise of variance s^2 at fs has the one-sided density 2 s^2 / fs: measured within
    /// 10 % over 20 seeds, with a strong low-frequency motion below the range left out of it;
    /// a spectrum still falling over the range (integrated noise, f^-2) has no floor (0).
    #[test]
    fn the_noise_floor_density_of_white_noise_over_seeds() {
        use rand::{Rng, SeedableRng};
        let (fs, n, s) = (2000.0, 20480, 0.5);
        let range = [200.0, 800.0];
        for seed in 0..20u64 {
            let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let mut gauss = || {
                let (u, v): (f64, f64) = (r.gen_range(1e-12..1.0), r.gen_range(0.0..1.0));
                (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
            };
            let x: Vec<f64> = (0..n)
                .map(|k| {
                    let t = k as f64 / fs;
                    s * gauss() + 3.0 * (2.0 * std::f64::consts::PI * 9.0 * t).sin()
                })
                .collect();
            let d = noise_floor_density(&x, fs, range).expect("density");
            let want = 2.0 * s * s / fs;
            assert!((d / want - 1.0).abs() < 0.1, "seed {seed}: {d} vs {want}");
            let mut acc = 0.0;
            let walk: Vec<f64> = (0..n)
                .map(|_| {
                    acc += gauss();
                    acc
                })
                .collect();
            assert_eq!(
                noise_floor_density(&walk, fs, range).expect("walk"),
                0.0,
                "seed {seed}"
            );
        }
    }

    use super::*;

    /// The kept noise sums are those of their own key: records of other lengths, rates, bands
    /// and instants, taken in turn, each get the sums computed afresh for them, bit for bit.
    #[test]
    fn shared_noise_sums_follow_their_key() {
        let cases = [
            (400usize, 50.0, [0.5, 2.0], 20usize),
            (600, 50.0, [0.5, 2.0], 20),
            (400, 60.0, [0.5, 2.0], 20),
            (400, 50.0, [0.6, 2.0], 20),
            (400, 50.0, [0.5, 2.0], 30),
            (400, 50.0, [0.5, 2.0], 20),
        ];
        for _ in 0..2 {
            for &(n, fs, band, edge) in &cases {
                let keep: Vec<usize> = (edge..n - edge).step_by(3).collect();
                let shared = Derivatives::new(n, fs, band).noise_cov(&keep).unwrap();
                let own = Derivatives::new(n, fs, band).noise_cov_sums(&keep).unwrap();
                assert_eq!(shared, own, "n {n} fs {fs} band {band:?} edge {edge}");
            }
        }
    }

    /// By hand: x = sin(2 pi f t) at f = 1 Hz inside the flat part of the band has
    /// x' = 2 pi cos(2 pi f t) and x'' = -(2 pi)^2 sin(2 pi f t); away from the record ends the
    /// frequency-domain derivatives match to 1e-3 of their amplitude, for several rates.
    #[test]
    fn derivatives_of_a_sine() {
        for fs in [50.0, 100.0, 333.0] {
            let n = (30.0 * fs) as usize;
            let w = 2.0 * std::f64::consts::PI;
            let x: Vec<f64> = (0..n).map(|i| (w * i as f64 / fs).sin()).collect();
            let mut d = Derivatives::new(n, fs, [0.5, 2.0]);
            let keep: Vec<usize> = (0..n).collect();
            let ([a, v, acc], _) = d.apply(&x, &keep).unwrap();
            let edge = (5.0 * fs) as usize;
            for i in edge..n - edge {
                let t = i as f64 / fs;
                assert!((a[i] - (w * t).sin()).abs() < 1e-3, "fs {fs} t {t}: x");
                assert!(
                    (v[i] - w * (w * t).cos()).abs() < 1e-3 * w,
                    "fs {fs} t {t}: x'"
                );
                assert!(
                    (acc[i] + w * w * (w * t).sin()).abs() < 1e-3 * w * w,
                    "fs {fs} t {t}: x''"
                );
            }
        }
    }

    /// Outside the band the output is zero (a 5 Hz sine through the 0.5-2 Hz band).
    #[test]
    fn out_of_band_is_removed() {
        let fs = 100.0;
        let n = 3000;
        let x: Vec<f64> = (0..n)
            .map(|i| (2.0 * std::f64::consts::PI * 5.0 * i as f64 / fs).sin())
            .collect();
        let keep: Vec<usize> = (0..n).collect();
        let ([a, _, _], _) = Derivatives::new(n, fs, [0.5, 2.0])
            .apply(&x, &keep)
            .unwrap();
        let worst = a[500..2500].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(worst < 1e-3, "{worst}");
    }

    /// `band_sums` (four instants side by side) against the loop it replaced, one instant at
    /// a time with `Complex64`'s operators: the same bits, for seeded random bins, band starts,
    /// transform lengths up to 2^21 and instant lists of every length modulo 4 (a partial last
    /// group), including instants beyond `m` (the phase is reduced modulo `m`).
    #[test]
    fn band_sums_side_by_side_are_one_instant_at_a_time_bit_for_bit() {
        use num_complex::Complex64;
        use rand::{Rng, SeedableRng};
        let one_at_a_time = |scaled: &[[Complex64; 3]], first: usize, m: usize, keep: &[usize]| {
            let mut out: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::new());
            for &n in keep {
                let phase = |k: usize| {
                    let r = ((k as u128 * n as u128) % m as u128) as f64;
                    Complex64::from_polar(1.0, 2.0 * std::f64::consts::PI * r / m as f64)
                };
                let (mut e, step) = (phase(first), phase(1));
                let mut acc = [0.0f64; 3];
                for s in scaled {
                    for (a, v) in acc.iter_mut().zip(s) {
                        *a += (v * e).re;
                    }
                    e *= step;
                }
                for (o, a) in out.iter_mut().zip(acc) {
                    o.push(a);
                }
            }
            out
        };
        for seed in 0..200u64 {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let m = 2 * rng.gen_range(8..(1usize << 20));
            let first = rng.gen_range(1..m / 4);
            let bins = rng.gen_range(0..(m / 2 - first).min(300));
            let scaled: Vec<[Complex64; 3]> = (0..bins)
                .map(|_| {
                    std::array::from_fn(|_| {
                        Complex64::new(rng.gen::<f64>() - 0.5, rng.gen::<f64>() - 0.5)
                    })
                })
                .collect();
            let keep: Vec<usize> = (0..rng.gen_range(0..11))
                .map(|_| rng.gen_range(0..2 * m))
                .collect();
            let got = super::band_sums(&scaled, first, m, &keep);
            let want = one_at_a_time(&scaled, first, m, &keep);
            for j in 0..3 {
                assert_eq!(got[j].len(), keep.len());
                for (g, w) in got[j].iter().zip(&want[j]) {
                    assert_eq!(g.to_bits(), w.to_bits(), "seed {seed}, j {j}: {g} != {w}");
                }
            }
        }
    }

    /// Identity: the band's bins summed at the kept samples equal three whole inverse FFTs of
    /// the band-passed spectrum (times i w and (i w)^2), on random signals over many seeds,
    /// lengths (even, odd, prime) and rates.
    #[test]
    fn direct_sums_equal_the_inverse_fft() {
        use num_complex::Complex64;
        use rand::{Rng, SeedableRng};
        for (seed, (n, fs)) in [(1000, 50.0), (1001, 333.0), (4999, 100.0), (20011, 2000.0)]
            .into_iter()
            .enumerate()
        {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed as u64);
            let x: Vec<f64> = (0..n).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let keep: Vec<usize> = (0..n).step_by(7).collect();
            let band = [0.6, 2.2];
            let mut d = Derivatives::new(n, fs, band);
            let (got, _) = d.apply(&x, &keep).unwrap();
            // The whole inverse FFTs.
            let m = 2 * n;
            let (fwd, inv) = (vibmode_fft::forward(m), vibmode_fft::inverse(m));
            let mean = x.iter().sum::<f64>() / n as f64;
            let mut buf = fwd.make_input_vec();
            buf.iter_mut().zip(&x).for_each(|(b, v)| *b = v - mean);
            let mut spec = fwd.make_output_vec();
            fwd.process(&mut buf, &mut spec).unwrap();
            for (k, g) in got.iter().enumerate() {
                let mut sk: Vec<Complex64> = spec
                    .iter()
                    .enumerate()
                    .map(|(i, v)| {
                        let f = i as f64 * fs / m as f64;
                        let iw = Complex64::new(0.0, 2.0 * std::f64::consts::PI * f);
                        v * iw.powu(k as u32) * (d.gain(f) / m as f64)
                    })
                    .collect();
                sk[0].im = 0.0;
                if let Some(l) = sk.last_mut() {
                    l.im = 0.0;
                }
                let mut y = inv.make_output_vec();
                inv.process(&mut sk, &mut y).unwrap();
                let scale = y.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
                for (j, &t) in keep.iter().enumerate() {
                    assert!(
                        (g[j] - y[t]).abs() <= 1e-9 * scale,
                        "n {n} fs {fs} derivative {k} sample {t}: {} vs {}",
                        g[j],
                        y[t]
                    );
                }
            }
        }
    }

    /// By hand: the band-pass's power gain is 1 between the tapers and (1/2 - cos/2)^2 over each
    /// taper, whose integral is 3/8 of the taper's width; so m_0 = (1.3 - 0.7) * 2.0 ... written
    /// out: flat part 2.0 * 0.7 - 0.5 * 1.3 = 0.75 Hz, tapers 3/8 * (0.3 + 1.2) = 0.5625 Hz.
    #[test]
    fn band_moments_by_hand() {
        let m = band_moments([0.5, 2.0]);
        let want = (2.0 * 0.7 - 0.5 * 1.3) + 0.375 * (2.0 * 0.3 * 0.5 + 2.0 * 0.3 * 2.0);
        assert!((m[0] / want - 1.0).abs() < 1e-6, "{} vs {want}", m[0]);
        // m_2 of a flat band [a, b] alone is (2 pi)^2 (b^3 - a^3) / 3: the tapered band lies
        // between the flat part's and the whole support's.
        let w2 =
            |a: f64, b: f64| (2.0 * std::f64::consts::PI).powi(2) * (b.powi(3) - a.powi(3)) / 3.0;
        assert!(m[1] > w2(0.65, 1.4) && m[1] < w2(0.35, 2.6), "{}", m[1]);
    }

    fn white(n: usize, sigma: f64, seed: u64) -> Vec<f64> {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let d = Normal::new(0.0, sigma).unwrap();
        (0..n).map(|_| d.sample(&mut rng)).collect()
    }

    /// The noise density of white noise of standard deviation sigma at fs is 2 sigma^2 / fs
    /// (one-sided); found within 10 % (3 sigma of the medians of 40 s at 300 Hz) with a strong tone in the range (over seeds and rates); a
    /// spectrum falling through the range (integrated noise: motion, not a floor) gives 0.
    #[test]
    fn noise_density_of_white_noise_and_none_of_a_falling_spectrum() {
        for (seed, fs) in [(1u64, 300.0), (2, 500.0), (3, 2000.0), (4, 1000.0)] {
            let n = (40.0 * fs) as usize;
            let sigma = 0.3;
            let mut x = white(n, sigma, seed);
            for (k, v) in x.iter_mut().enumerate() {
                let t = k as f64 / fs;
                *v += 5.0 * (2.0 * std::f64::consts::PI * 0.31 * fs * t).sin();
            }
            let mut d = Derivatives::new(n, fs, [0.5, 2.0]);
            let (_, dens) = d.apply(&x, &[n / 2]).unwrap();
            let want = 2.0 * sigma * sigma / fs;
            assert!((dens / want - 1.0).abs() < 0.1, "fs {fs}: {dens} vs {want}");
            let mut acc = 0.0;
            let brown: Vec<f64> = white(n, sigma, seed + 100)
                .into_iter()
                .map(|v| {
                    acc += v;
                    acc
                })
                .collect();
            let (_, dens) = d.apply(&brown, &[n / 2]).unwrap();
            assert_eq!(dens, 0.0, "fs {fs}: integrated noise taken as a floor");
        }
    }

    /// Identity over many seeds: records of pure white noise (no motion) at all seven sensors
    /// give normal equations whose expected noise share, as subtracted, equals what they hold:
    /// over 40 seeds of 80 s each diagonal entry of `Z^T Z` averages to the subtracted share
    /// within 6 % and all of them together within 2 % (one seed's ratio spreads by about
    /// sqrt(2 / (2.4 Hz * 78 s)) = 10 %, the mean of 40 by 1.6 %, of 13 unknowns by about 0.5 %).
    #[test]
    fn noise_share_equals_pure_noise_equations() {
        let v = VehicleParams::city_bus();
        let fs = 500.0;
        let n = (80.0 * fs) as usize;
        let names: Vec<String> = v
            .effective_sensors()
            .iter()
            .map(|s| s.name.clone())
            .collect();
        let sig = [0.5, 0.5, 0.5, 0.5, 0.08, 0.08, 0.08];
        let mut ratios: Vec<Vec<f64>> = Vec::new();
        let (mut dens_ratio, mut dens_count) = (0.0, 0);
        for seed in 0..40u64 {
            let channels = names
                .iter()
                .zip(sig)
                .enumerate()
                .map(|(i, (nm, s))| Channel::new(nm, "m/s^2", white(n, s, 1000 * seed + i as u64)))
                .collect();
            let rec = Recording {
                fs_hz: fs,
                channels,
                time_axis: None,
            };
            let mut fit = BodyFit::new(&v, BodyFitParams::default()).unwrap();
            fit.add_record(&rec).unwrap();
            let corrected = &fit.per_record[0].0 - &fit.per_record[0].1;
            let raw = &fit.gram;
            let k = raw.nrows();
            ratios.push(
                (0..k)
                    .filter(|&u| raw[(u, u)] > 0.0)
                    .map(|u| raw[(u, u)] / (raw[(u, u)] - corrected[(u, u)]))
                    .collect(),
            );
            for (name, d) in &fit.noise {
                let i = names.iter().position(|x| x == name).unwrap();
                let want = 2.0 * sig[i] * sig[i] / fs;
                dens_ratio += d / want;
                dens_count += 1;
                // The median of N exponential ordinates has a relative spread of about
                // 1 / (ln 2 sqrt N), 5 % here with the Hann window's N/2: within 15 %.
                assert!(
                    (d / want - 1.0).abs() < 0.15,
                    "seed {seed} {name}: {d} vs {want}"
                );
            }
        }
        let means: Vec<f64> = (0..ratios[0].len())
            .map(|u| ratios.iter().map(|r| r[u]).sum::<f64>() / ratios.len() as f64)
            .collect();
        eprintln!(
            "raw / noise share per unknown: {means:?}; density found / true {}",
            dens_ratio / dens_count as f64
        );
        for (u, &mean) in means.iter().enumerate() {
            assert!(
                (mean - 1.0).abs() < 0.06,
                "unknown {u}: raw / noise share {mean}"
            );
        }
        let all = means.iter().sum::<f64>() / means.len() as f64;
        assert!(
            (all - 1.0).abs() < 0.02,
            "all unknowns: raw / noise share {all}"
        );
    }

    /// By hand: the share taken out is the smallest generalized eigenvalue of `raw v = l noise v`,
    /// capped at 1. raw = [[2, 1], [1, 2]] (eigenvalues 1 and 3), noise = 4 I: l = 1/4. With
    /// noise = I / 2 the eigenvalues are 2 and 6: capped at 1. No noise: 1. A raw matrix that is
    /// not positive definite: 1 (the fit then says why).
    #[test]
    fn noise_scale_by_hand() {
        let raw = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 2.0]);
        let eye = DMatrix::<f64>::identity(2, 2);
        assert!((noise_scale(&raw, &(&eye * 4.0)) - 0.25).abs() < 1e-12);
        assert_eq!(noise_scale(&raw, &(&eye * 0.5)), 1.0);
        assert_eq!(noise_scale(&raw, &DMatrix::zeros(2, 2)), 1.0);
        let indefinite = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert_eq!(noise_scale(&indefinite, &eye), 1.0);
    }

    /// Identity over seeded random pencils (a signal and a noise whose share is estimated up to
    /// 50 % off): when the share is below 1, `raw - l noise` is
    /// positive semi-definite with one eigenvalue 0 (to 1e-9 of the largest); when it is 1,
    /// `raw - noise` is positive definite.
    #[test]
    fn noise_scale_leaves_the_corrected_matrix_just_singular() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(30);
        let (mut below, mut capped) = (0, 0);
        for _ in 0..200 {
            let n = rng.gen_range(2..14);
            let x = DMatrix::from_fn(3 * n, n, |_, _| rng.gen_range(-1.0..1.0));
            let e = DMatrix::from_fn(2 * n, n, |_, _| rng.gen_range(-1.0..1.0));
            // The noise's share as estimated, off from what the equations hold by up to 50 %.
            let held = e.transpose() * &e * rng.gen_range(0.5..50.0);
            let raw = x.transpose() * &x + &held;
            let noise = &held * rng.gen_range(0.5..1.5);
            let l = noise_scale(&raw, &noise);
            let eig = (&raw - &noise * l).symmetric_eigenvalues();
            let (lo, hi) = eig
                .iter()
                .fold((f64::INFINITY, 0.0_f64), |(a, b), &v| (a.min(v), b.max(v)));
            if l < 1.0 {
                below += 1;
                assert!(
                    lo.abs() <= 1e-9 * hi,
                    "share {l}: smallest eigenvalue {lo} of {hi}"
                );
            } else {
                capped += 1;
                assert!(lo > 0.0, "share 1: smallest eigenvalue {lo}");
            }
        }
        assert!(
            below > 20 && capped > 20,
            "below 1: {below}, capped: {capped}"
        );
    }

    /// The exact noise covariances of the finite record equal the band's moments far from its
    /// ends (unit variance per sample is one-sided density 2 / fs), and are smaller near them.
    #[test]
    fn noise_covariances_are_the_band_moments_inside_the_record() {
        let band = [0.5, 2.0];
        let m = band_moments(band);
        let want = [[m[0], 0.0, -m[1]], [0.0, m[1], 0.0], [-m[1], 0.0, m[2]]];
        for fs in [50.0, 200.0] {
            let n = (120.0 * fs) as usize;
            let mut d = Derivatives::new(n, fs, band);
            let mid = d.noise_cov(&[n / 2]).unwrap();
            for k in 0..3 {
                for l in 0..3 {
                    let w = want[k][l] * 2.0 / fs;
                    let scale = (want[k][k] * want[l][l]).sqrt() * 2.0 / fs;
                    assert!(
                        (mid[k][l] - w).abs() < 1e-3 * scale,
                        "fs {fs} ({k}, {l}): {} vs {w}",
                        mid[k][l]
                    );
                }
            }
            let end = d.noise_cov(&[5]).unwrap();
            assert!(
                end[0][0] < 0.8 * mid[0][0],
                "{} vs {}",
                end[0][0],
                mid[0][0]
            );
        }
    }
}
