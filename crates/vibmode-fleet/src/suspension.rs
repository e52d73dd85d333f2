//! The suspension fitted per drive (docs/fleet.md, "The suspension fitted per drive").
//!
//! A vehicle with a registered full-car model file ([`crate::Store::register_vehicle_model`])
//! gets, at ingest, each record's body equations ([`RecordEquations`], the model update of
//! `vibmode analyze --vehicle`: generalized total least squares of the body's heave, pitch and
//! roll rows, docs/model_update.md) kept with its features. The baseline fits its nominal
//! records' equations together, a checked drive fits its own records', and per corner the
//! fitted spring and damper relative to the other three corners, `ln k_c - mean_{j != c} ln
//! k_j` (a change of load scales every corner alike and cancels), is compared with the
//! baseline's. The score divides the change by the two fits' jackknife standard deviations
//! (each record left out in turn): for a spring those of `r` itself over the replicates (the
//! corners' errors are correlated), for a damper its corners' added as independent, which is
//! what covers the dampers' drive-to-drive scatter on busgen:
//! `z = (r_drive - r_baseline) / sqrt(var_drive + var_baseline)`.
//! A spring or damper that lost stiffness lowers its corner's `r`, so only a low score is an
//! alarm. A spring's loss persists from drive to drive, so its `r` is also pooled over the
//! vehicle's last [`TREND_DRIVES`] drives against the same baseline ([`spring_trend`]): the
//! drives' spread falls by their number, the baseline's stays. The limits are one-sided and
//! share the false-alarm rate `a` (weighted Bonferroni): half of it for the drive's 8 tests (the
//! 4 corners' spring and damper), `Phi^-1(1 - a / 16)` (3.23 at 1 %), half for the trend's 4
//! (each corner's spring over the last drives), `Phi^-1(1 - a / 8)` (3.02). The trend's share
//! is the larger per test because its scores find a lost spring more often (docs/fleet.md, "The
//! spring trend"). On busgen's buses the healthy drives' scores have an rms of about 1
//! (docs/fleet.md), so the stated rate holds where the jackknife does.

use serde::{Deserialize, Serialize};
use vibmode_analysis::{AnalysisConfig, Corner};
use vibmode_core::Recording;
use vibmode_vehicle::update::{BodyFit, BodyFitResult, RecordEquations};
use vibmode_vehicle::VehicleParams;

use crate::error::{FleetError, Result};
use crate::stats::normal_quantile;

/// The corners in the order of the arrays of [`CornerFit`].
pub const CORNERS: [Corner; 4] = [Corner::FL, Corner::FR, Corner::RL, Corner::RR];

/// Fewest records a fit needs: the jackknife's standard deviations need three.
pub const MIN_FIT_RECORDS: usize = 3;

/// One-sided tests per fit: a spring and a damper at each of the four corners.
pub const TESTS_PER_FIT: usize = 8;

/// Drives whose fitted springs [`spring_trend`] pools: the drive checked and the ones before it.
pub const TREND_DRIVES: usize = 3;

/// One-sided tests of the spring trend: each corner's spring over the last [`TREND_DRIVES`]
/// drives.
pub const TESTS_PER_TREND: usize = 4;

/// A vehicle's registered full-car model.
#[derive(Clone, Debug)]
pub struct VehicleModel {
    /// SHA-256 of the file's text, which each record's equations name.
    pub sha256: String,
    /// The model.
    pub params: VehicleParams,
}

impl VehicleModel {
    /// Parses and validates a model file's text (`source` names it in errors).
    pub fn from_toml(text: &str, source: &str) -> Result<Self> {
        let params = VehicleParams::from_toml_str(text).map_err(|e| FleetError::VehicleModel {
            source_name: source.to_string(),
            reason: vibmode_core::cap_message(&e.to_string(), 240),
        })?;
        Ok(VehicleModel {
            sha256: crate::fleet::sha256_hex(text.as_bytes()),
            params,
        })
    }

    /// A fit of this model with the analysis' `[model_update]` settings.
    fn fit(&self, analysis: &AnalysisConfig) -> std::result::Result<BodyFit, String> {
        BodyFit::new(&self.params, analysis.model_update.clone()).map_err(|e| e.to_string())
    }

    /// Checks that a fit of this model can be made with these settings (the band below the
    /// records' Nyquist frequency is checked per record).
    pub fn check(&self, analysis: &AnalysisConfig, source: &str) -> Result<()> {
        self.fit(analysis)
            .map(|_| ())
            .map_err(|reason| FleetError::VehicleModel {
                source_name: source.to_string(),
                reason: vibmode_core::cap_message(&reason, 240),
            })
    }

    /// A record's body equations, its channels placed as the analysis places them; the reason
    /// as text when the record cannot give them (it is then kept as a note of the record).
    pub fn record_equations(
        &self,
        rec: &Recording,
        analysis: &AnalysisConfig,
    ) -> std::result::Result<StoredEquations, String> {
        let fit = self.fit(analysis)?;
        let equations = fit
            .record_equations_placed(rec, |c| analysis.placement_for_update(c))
            .map_err(|e| e.to_string())?;
        Ok(StoredEquations {
            model_sha256: self.sha256.clone(),
            equations,
        })
    }

    /// The fit of records' equations together; the reason as text when it fails or has fewer
    /// than [`MIN_FIT_RECORDS`] records.
    pub fn fit_corners(
        &self,
        analysis: &AnalysisConfig,
        equations: &[&RecordEquations],
    ) -> std::result::Result<CornerFit, String> {
        if equations.len() < MIN_FIT_RECORDS {
            return Err(format!(
                "{} record(s) with body equations of this model file, {MIN_FIT_RECORDS} needed",
                equations.len()
            ));
        }
        let mut fit = self.fit(analysis)?;
        for e in equations {
            fit.add_equations(e).map_err(|e| e.to_string())?;
        }
        let r = fit.solve().map_err(|e| e.to_string())?;
        CornerFit::from_result(&r)
    }
}

/// A record's body equations with the model file they were made with.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredEquations {
    /// SHA-256 of the vehicle model file's text.
    pub model_sha256: String,
    /// The equations.
    pub equations: RecordEquations,
}

/// The springs and dampers of one fit, per corner in the order of [`CORNERS`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CornerFit {
    /// Records fitted.
    pub records: usize,
    /// Springs, N/m.
    pub spring_n_per_m: [f64; 4],
    /// Their relative standard deviations (jackknife over the records).
    pub spring_rel_sd: [f64; 4],
    /// Dampers, N s/m.
    pub damper_n_s_per_m: [f64; 4],
    /// Their relative standard deviations.
    pub damper_rel_sd: [f64; 4],
    /// Whether the model update calls the records' support of the whole fit sufficient (modes
    /// within 3 %, springs and dampers within 10 %, at 95 % together:
    /// `vibmode_vehicle::update::support_factor`); the scores use the standard deviations either
    /// way.
    pub supported: bool,
    /// Standard deviations of [`CornerFit::relative`]'s spring statistics from the jackknife's
    /// replicates of the whole fit (the corners' errors are correlated); absent in model sets
    /// stored before they were kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spring_relative_sd: Option<[f64; 4]>,
}

/// Spring or damper.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Part {
    /// The corner's spring.
    Spring,
    /// The corner's damper.
    Damper,
}

impl CornerFit {
    fn from_result(r: &BodyFitResult) -> std::result::Result<Self, String> {
        let mut out = CornerFit {
            records: r.records,
            spring_n_per_m: [0.0; 4],
            spring_rel_sd: [0.0; 4],
            damper_n_s_per_m: [0.0; 4],
            damper_rel_sd: [0.0; 4],
            supported: r.supported,
            spring_relative_sd: None,
        };
        for (i, c) in CORNERS.iter().enumerate() {
            for (p, value, sd) in [
                (
                    r.spring(*c),
                    &mut out.spring_n_per_m[i],
                    &mut out.spring_rel_sd[i],
                ),
                (
                    r.damper(*c),
                    &mut out.damper_n_s_per_m[i],
                    &mut out.damper_rel_sd[i],
                ),
            ] {
                let Some(p) = p else {
                    return Err(format!("the fit has no {c} spring or damper"));
                };
                let Some(s) = p.sd.filter(|s| s.is_finite()) else {
                    return Err(format!(
                        "the fit's {} has no standard deviation (the fit fails without one of its records)",
                        p.name
                    ));
                };
                if !(p.value.is_finite() && p.value > 0.0) {
                    return Err(format!("the fit's {} is {:.4e}", p.name, p.value));
                }
                *value = p.value;
                *sd = s / p.value;
            }
        }
        let index = |name: &str| r.parameters.iter().position(|p| p.name == name);
        // The springs' relative statistics of each replicate, and their jackknife spread.
        let cols: Option<Vec<usize>> = CORNERS
            .iter()
            .map(|c| index(&format!("spring {c}")))
            .collect();
        if let Some(cols) = cols {
            let reps: Vec<[f64; 4]> = r
                .replicates
                .iter()
                .map(|rep| std::array::from_fn(|c| rep.get(cols[c]).copied().unwrap_or(f64::NAN)))
                .collect();
            out.spring_relative_sd = jackknife_relative_sd(&reps);
        }
        Ok(out)
    }

    fn values(&self, part: Part) -> (&[f64; 4], &[f64; 4]) {
        match part {
            Part::Spring => (&self.spring_n_per_m, &self.spring_rel_sd),
            Part::Damper => (&self.damper_n_s_per_m, &self.damper_rel_sd),
        }
    }

    /// Per corner `ln v_c - mean_{j != c} ln v_j` and its variance. For the springs, where the
    /// fit kept it ([`CornerFit::spring_relative_sd`]), the square of the statistic's own
    /// jackknife spread over the fit's replicates (the corners' errors are correlated, e.g. all
    /// move with the noise share, which cancels); else, and for the dampers, from the relative
    /// standard deviations with the corners taken as independent, which on busgen is what
    /// covers the dampers' drive-to-drive scatter (docs/fleet.md).
    pub fn relative(&self, part: Part) -> [(f64, f64); 4] {
        let (v, sd) = self.values(part);
        let stat = relative_of(v);
        if let (Part::Spring, Some(rsd)) = (part, self.spring_relative_sd) {
            return std::array::from_fn(|c| (stat[c], rsd[c].powi(2)));
        }
        std::array::from_fn(|c| {
            let others = (0..4)
                .filter(|&j| j != c)
                .map(|j| sd[j].powi(2))
                .sum::<f64>();
            (stat[c], sd[c].powi(2) + others / 9.0)
        })
    }
}

/// Per corner `ln v_c - mean_{j != c} ln v_j`.
fn relative_of(v: &[f64; 4]) -> [f64; 4] {
    let ln = v.map(f64::ln);
    std::array::from_fn(|c| {
        let others: f64 = (0..4).filter(|&j| j != c).map(|j| ln[j]).sum::<f64>() / 3.0;
        ln[c] - others
    })
}

/// The jackknife standard deviation of [`relative_of`] per corner from the replicates of a fit
/// (the values with each record left out in turn; [`vibmode_core::stats::jackknife_std`]).
/// `None` with fewer than [`MIN_FIT_RECORDS`] replicates or a value that is not positive.
fn jackknife_relative_sd(replicates: &[[f64; 4]]) -> Option<[f64; 4]> {
    if replicates.len() < MIN_FIT_RECORDS
        || replicates
            .iter()
            .flatten()
            .any(|v| !(v.is_finite() && *v > 0.0))
    {
        return None;
    }
    let stats: Vec<[f64; 4]> = replicates.iter().map(relative_of).collect();
    Some(std::array::from_fn(|c| {
        vibmode_core::stats::jackknife_std(&stats.iter().map(|s| s[c]).collect::<Vec<_>>())
    }))
}

/// The baseline's fit, kept in the model set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SuspensionReference {
    /// SHA-256 of the vehicle model file the fit used.
    pub model_sha256: String,
    /// The fit of the nominal records together.
    pub fit: CornerFit,
    /// The one-sided limit of a drive's scores: [`suspension_limit`] (model sets built before the
    /// spring trend keep theirs, `Phi^-1(1 - false_alarm_rate / 8)`: build a new baseline).
    pub limit: f64,
}

/// The limit of a drive's own suspension scores at this false-alarm rate per drive: half the
/// rate over its [`TESTS_PER_FIT`] tests, `Phi^-1(1 - false_alarm_rate / 16)`.
pub fn suspension_limit(false_alarm_rate: f64) -> f64 {
    -normal_quantile(false_alarm_rate / (2 * TESTS_PER_FIT) as f64)
}

/// The limit of the spring trend's scores at this false-alarm rate per drive: the other half of
/// the rate over its [`TESTS_PER_TREND`] tests, `Phi^-1(1 - false_alarm_rate / 8)`.
pub fn trend_limit(false_alarm_rate: f64) -> f64 {
    -normal_quantile(false_alarm_rate / (2 * TESTS_PER_TREND) as f64)
}

/// One corner's score of a drive's fit against the reference.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CornerScore {
    /// The corner.
    pub corner: Corner,
    /// Spring or damper.
    pub part: Part,
    /// The drive's value relative to the other corners, `exp(r)`.
    pub value: f64,
    /// The baseline's.
    pub centre: f64,
    /// The score (negative: lower than at the baseline).
    pub z: f64,
}

/// The smallest loss a fitted spring or damper must show against the other corners to be
/// flagged, as a fraction (0.10: 10 %). Below it a score past the limit is not evidence: a drive
/// of a few records of a nearly noise-free bus (vibmode's own simulator, 3 records) has
/// jackknife spreads of 0.01-0.1 % and put a damper's -0.2 % at z -4.9; the faults this test is
/// for are losses of 20 % and more (a found spring at 80 % comes out -17 to -30 %, a damper at
/// 70 % -26 to -34 %, docs/fleet.md).
pub const MIN_FLAGGED_LOSS: f64 = 0.10;

impl CornerScore {
    /// The drive's value against the baseline's, minus 1 (-0.2: 20 % lower).
    pub fn change(&self) -> f64 {
        self.value / self.centre - 1.0
    }

    /// Whether this score is vehicle evidence: below `-limit` and a loss of at least
    /// [`MIN_FLAGGED_LOSS`].
    pub fn flagged(&self, limit: f64) -> bool {
        self.z < -limit && self.change() <= -MIN_FLAGGED_LOSS
    }
}

/// A drive's fitted suspension and every corner's score (kept with the drive's verdict).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DriveSuspension {
    /// The fit of the drive's records.
    pub fit: CornerFit,
    /// Every corner's spring and damper score against the model set's fit.
    pub scores: Vec<CornerScore>,
    /// The limit the scores are compared with (flagged below minus it).
    pub limit: f64,
    /// The springs pooled over this drive and the ones before it ([`spring_trend`]), when the
    /// vehicle has [`TREND_DRIVES`] - 1 earlier drives fitted against the same baseline; else
    /// absent and the drive's `missing` says why.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trend: Option<SpringTrend>,
}

/// The springs of a vehicle's last drives pooled (kept with the drive's verdict).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpringTrend {
    /// The drives pooled, the one checked first, then back in time.
    pub drives: Vec<String>,
    /// Every corner's spring score of the pooled statistic against the baseline's.
    pub scores: Vec<CornerScore>,
    /// The limit these scores are compared with ([`trend_limit`]; flagged below minus it).
    pub limit: f64,
}

/// Every corner's spring score of `fits` (a vehicle's last drives' fits against one baseline)
/// pooled, against `reference`. Per corner the drives' `r_c` are averaged with weights
/// `1 / var_i`, whose mean has the variance `1 / sum(1 / var_i)` (the drives' records are
/// independent); the score is `z = (r_pooled - r_baseline) / sqrt(var_pooled +
/// var_baseline)`: the baseline's variance stays, which is why pooling more drives gains less
/// and less. Where a drive's variance is not positive (a noise-free fit) the plain mean is
/// taken, with the variance `sum(var_i) / n^2`. Empty without fits.
pub fn spring_trend(reference: &CornerFit, fits: &[&CornerFit]) -> Vec<CornerScore> {
    if fits.is_empty() {
        return Vec::new();
    }
    let r = reference.relative(Part::Spring);
    let drives: Vec<[(f64, f64); 4]> = fits.iter().map(|f| f.relative(Part::Spring)).collect();
    let n = drives.len() as f64;
    CORNERS
        .iter()
        .enumerate()
        .map(|(i, corner)| {
            let weighted = drives.iter().all(|d| d[i].1 > 0.0 && d[i].1.is_finite());
            let (mean, var) = if weighted {
                let w: f64 = drives.iter().map(|d| 1.0 / d[i].1).sum();
                let m = drives.iter().map(|d| d[i].0 / d[i].1).sum::<f64>() / w;
                (m, 1.0 / w)
            } else {
                let m = drives.iter().map(|d| d[i].0).sum::<f64>() / n;
                (m, drives.iter().map(|d| d[i].1).sum::<f64>() / (n * n))
            };
            let total = var + r[i].1;
            CornerScore {
                corner: *corner,
                part: Part::Spring,
                value: mean.exp(),
                centre: r[i].0.exp(),
                z: if total > 0.0 {
                    (mean - r[i].0) / total.sqrt()
                } else {
                    0.0
                },
            }
        })
        .collect()
}

/// Every corner's spring and damper score of `drive` against `reference`.
pub fn corner_scores(reference: &CornerFit, drive: &CornerFit) -> Vec<CornerScore> {
    let mut out = Vec::with_capacity(TESTS_PER_FIT);
    for part in [Part::Spring, Part::Damper] {
        let (r, d) = (reference.relative(part), drive.relative(part));
        for (i, corner) in CORNERS.iter().enumerate() {
            let var = r[i].1 + d[i].1;
            let z = if var > 0.0 {
                (d[i].0 - r[i].0) / var.sqrt()
            } else {
                0.0
            };
            out.push(CornerScore {
                corner: *corner,
                part,
                value: d[i].0.exp(),
                centre: r[i].0.exp(),
                z,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fit(springs: [f64; 4], sd: f64) -> CornerFit {
        CornerFit {
            records: 8,
            spring_n_per_m: springs,
            spring_rel_sd: [sd; 4],
            damper_n_s_per_m: [1.0e4; 4],
            damper_rel_sd: [sd; 4],
            supported: true,
            spring_relative_sd: None,
        }
    }

    #[test]
    fn a_spring_at_80_percent_moves_its_corner_by_ln_08_and_the_others_by_a_third_less() {
        // By hand: ln 0.8 = -0.2231 at RL; each other corner's mean of the others includes RL's
        // -0.2231 / 3 = -0.0744, so theirs rises by 0.0744.
        let base = fit([2.0e5; 4], 0.02);
        let drive = fit([2.0e5, 2.0e5, 1.6e5, 2.0e5], 0.02);
        let s = corner_scores(&base, &drive);
        let rl = s
            .iter()
            .find(|x| x.corner == Corner::RL && x.part == Part::Spring)
            .map(|x| x.value.ln());
        assert!((rl.unwrap_or(0.0) - 0.8f64.ln()).abs() < 1e-12);
        let fl = s
            .iter()
            .find(|x| x.corner == Corner::FL && x.part == Part::Spring)
            .map(|x| x.value.ln());
        assert!((fl.unwrap_or(0.0) + 0.8f64.ln() / 3.0).abs() < 1e-12);
        // The variance: 0.02^2 (1 + 3/9) per fit, two fits: z = -0.2231 / sqrt(2 * 0.000533).
        let z = s
            .iter()
            .find(|x| x.corner == Corner::RL && x.part == Part::Spring)
            .map_or(0.0, |x| x.z);
        let expect = 0.8f64.ln() / (2.0f64 * 0.0004 * (1.0 + 3.0 / 9.0)).sqrt();
        assert!((z - expect).abs() < 1e-9, "{z} vs {expect}");
        // A load change (every spring alike) moves no score.
        let loaded = fit([2.3e5; 4], 0.02);
        assert!(corner_scores(&base, &loaded)
            .iter()
            .all(|x| x.z.abs() < 1e-9));
    }

    #[test]
    fn the_limits_share_the_rate_half_and_half() {
        // The drive's 8 tests at 0.01 / 16 and the trend's 4 at 0.01 / 8 (scipy 1.14.1:
        // scipy.stats.norm.isf(0.01 / 16) = 3.227_218_4, isf(0.01 / 8) = 3.023_341_4); together
        // 8 / 16 + 4 / 8 of the rate.
        assert!((suspension_limit(0.01) - 3.227_218_4).abs() < 1e-6);
        assert!((trend_limit(0.01) - 3.023_341_4).abs() < 1e-6);
        assert_eq!(
            TESTS_PER_FIT as f64 / 16.0 + TESTS_PER_TREND as f64 / 8.0,
            1.0
        );
    }

    fn relative_fit(springs: [f64; 4], rsd: [f64; 4]) -> CornerFit {
        let mut f = fit(springs, 0.02);
        f.spring_relative_sd = Some(rsd);
        f
    }

    /// By hand: three drives of equal variance pool to their mean with a third of it; unequal
    /// variances weigh by their inverses; a variance that is not positive takes the plain mean;
    /// a load change moves nothing; no fits, no scores.
    #[test]
    fn spring_trend_by_hand() {
        let base = relative_fit([2.0e5; 4], [0.04; 4]);
        // RL's statistic with the other three springs equal at 2e5: r_RL = ln(k_RL / 2e5) = ln s;
        // the baseline's is 0.
        let drive = |s: f64, sd: f64| relative_fit([2.0e5, 2.0e5, 2.0e5 * s, 2.0e5], [sd; 4]);
        let (a, b, c) = (drive(0.8, 0.06), drive(0.9, 0.06), drive(0.7, 0.06));
        let t = spring_trend(&base, &[&a, &b, &c]);
        assert_eq!(t.len(), 4);
        assert!(t.iter().all(|x| x.part == Part::Spring));
        let rl = &t[2];
        assert_eq!(rl.corner, Corner::RL);
        let mean = (0.8f64.ln() + 0.9f64.ln() + 0.7f64.ln()) / 3.0;
        assert!((rl.value.ln() - mean).abs() < 1e-12);
        let z = mean / (0.06f64.powi(2) / 3.0 + 0.04f64.powi(2)).sqrt();
        assert!((rl.z - z).abs() < 1e-9, "{} vs {z}", rl.z);
        // Weights 1/0.03^2 and 1/0.09^2 (9 : 1).
        let (p, q) = (drive(0.8, 0.03), drive(1.0, 0.09));
        let rl = spring_trend(&base, &[&p, &q])[2].clone();
        let mean = 0.9 * 0.8f64.ln();
        let var: f64 = 1.0 / (1.0 / 0.0009 + 1.0 / 0.0081);
        assert!((rl.value.ln() - mean).abs() < 1e-12);
        assert!((rl.z - mean / (var + 0.0016).sqrt()).abs() < 1e-9);
        // A noise-free fit (variance 0): the plain mean, variance (0 + 0.03^2) / 4.
        let zero = drive(0.8, 0.0);
        let rl = spring_trend(&base, &[&zero, &q])[2].clone();
        let mean = 0.8f64.ln() / 2.0;
        assert!((rl.value.ln() - mean).abs() < 1e-12);
        assert!((rl.z - mean / (0.0081_f64 / 4.0 + 0.0016).sqrt()).abs() < 1e-9);
        // A load that scales every spring alike moves no corner.
        let loaded = relative_fit([2.4e5; 4], [0.05; 4]);
        assert!(spring_trend(&base, &[&loaded, &loaded, &loaded])
            .iter()
            .all(|x| x.z.abs() < 1e-9));
        assert!(spring_trend(&base, &[]).is_empty());
    }

    /// Seeded random drives: a drive's `r_c` drawn from N(mu, sd_i^2), independent; the trend's
    /// score over many draws has mean `mu / sqrt(var + var_base)` and unit spread when the
    /// baseline sits at 0 with its variance taken as known (the baseline's own error is then
    /// one draw per trial too).
    #[test]
    fn spring_trend_scores_are_standard_normal_under_the_null_over_seeds() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut normal = || {
            let (u, v) = (uniform().max(1e-300), uniform());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        };
        let (sd_base, sds) = (0.046, [0.05, 0.063, 0.09]);
        let n = 4000;
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n {
            let b = sd_base * normal();
            let base = relative_fit([2.0e5, 2.0e5, 2.0e5 * b.exp(), 2.0e5], [sd_base; 4]);
            let drives: Vec<CornerFit> = sds
                .iter()
                .map(|sd| {
                    relative_fit(
                        [2.0e5, 2.0e5, 2.0e5 * (sd * normal()).exp(), 2.0e5],
                        [*sd; 4],
                    )
                })
                .collect();
            // RL's r with the others equal is ln(k_RL / 2e5), so its variance is the one given
            // only for RL; the test reads RL alone.
            let refs: Vec<&CornerFit> = drives.iter().collect();
            let z = spring_trend(&base, &refs)[2].z;
            sum += z;
            sum2 += z * z;
        }
        let mean = sum / n as f64;
        let sd = (sum2 / n as f64 - mean * mean).sqrt();
        // Standard errors: 1/sqrt(4000) = 0.016 for the mean, about 0.011 for the sd.
        assert!(mean.abs() < 0.06, "mean {mean}");
        assert!((sd - 1.0).abs() < 0.05, "sd {sd}");
    }

    /// By hand: replicates whose four values move together (a common factor, e.g. the noise
    /// share or the sprung mass) leave every corner's relative statistic unchanged, so its
    /// jackknife spread is 0, where corners taken as independent would add their spreads.
    /// Replicates moving corner FL alone by ln -a, 0, +a: FL's statistic spreads by
    /// sqrt(2/3 * 2 a^2), each other corner's by a third of it. Fewer than three replicates, or a
    /// value that is not positive: none.
    #[test]
    fn relative_spread_from_the_replicates_by_hand() {
        let common: Vec<[f64; 4]> = [0.9, 1.0, 1.2, 0.95]
            .iter()
            .map(|s| [1.4e5 * s, 1.3e5 * s, 2.5e5 * s, 2.6e5 * s])
            .collect();
        let sd = jackknife_relative_sd(&common).unwrap();
        assert!(sd.iter().all(|v| v.abs() < 1e-12), "{sd:?}");
        let a = 0.05_f64;
        let one: Vec<[f64; 4]> = [-a, 0.0, a]
            .iter()
            .map(|x| [2.0 * x.exp(), 2.0, 2.0, 2.0])
            .collect();
        let sd = jackknife_relative_sd(&one).unwrap();
        let want = (2.0 / 3.0 * 2.0 * a * a).sqrt();
        assert!((sd[0] - want).abs() < 1e-12, "{} vs {want}", sd[0]);
        for (c, v) in sd.iter().enumerate().skip(1) {
            assert!((v - want / 3.0).abs() < 1e-12, "{c}: {v}");
        }
        assert!(jackknife_relative_sd(&one[..2]).is_none());
        let mut bad = one.clone();
        bad[1][2] = 0.0;
        assert!(jackknife_relative_sd(&bad).is_none());
        // The springs' variance is then the square of that spread, not the independent sum.
        // The dampers keep the corners' spreads added as independent: 0.03^2 (1 + 3 / 9).
        let mut f = fit([1.0e5; 4], 0.03);
        f.spring_relative_sd = Some(sd);
        let rel = f.relative(Part::Spring);
        assert!((rel[0].1 - want * want).abs() < 1e-15);
        let damper = f.relative(Part::Damper)[3].1;
        assert!(
            (damper - 0.03_f64.powi(2) * (4.0 / 3.0)).abs() < 1e-15,
            "{damper}"
        );
    }

    /// By hand: a score past the limit is evidence only with a loss of 10 % or more; a loss
    /// without the score is none.
    #[test]
    fn flagged_needs_the_limit_and_a_loss_of_ten_percent() {
        let score = |value: f64, z: f64| CornerScore {
            corner: Corner::RR,
            part: Part::Damper,
            value,
            centre: 1.0,
            z,
        };
        assert!(!score(0.998, -4.9).flagged(3.02), "-0.2 % at z -4.9");
        assert!(!score(0.91, -6.0).flagged(3.02), "-9 %");
        assert!(score(0.899, -3.1).flagged(3.02), "-10.1 % at z -3.1");
        assert!(score(0.7, -8.0).flagged(3.02), "-30 %");
        assert!(!score(0.7, -2.9).flagged(3.02), "-30 % at z -2.9");
        assert!(!score(1.2, -4.0).flagged(3.02), "+20 %");
        assert!((score(0.75, -5.0).change() + 0.25).abs() < 1e-15);
    }
}
