//! The model update inside a run: every record also feeds the fit of the vehicle's suspension
//! ([`vibmode_vehicle::update::BodyFit`]), and its outcome is written beside the analysis.

use std::path::Path;

use vibmode_analysis::{AnalysisConfig, RecordInput, RecordSource};
use vibmode_vehicle::update::{BodyFit, BodyFitResult};
use vibmode_vehicle::{VehicleError, VehicleParams};

use crate::RunError;

/// The fit of the vehicle's suspension to the records, fed one record at a time.
#[derive(Debug)]
pub struct ModelUpdate {
    cfg: AnalysisConfig,
    state: UpdateState,
}

/// The vehicle, the fit of the configured (or default) band, and with the default band also
/// the wide band's (an error once a record failed in it).
type Fitting = (
    VehicleParams,
    BodyFit,
    Option<([f64; 2], Result<BodyFit, VehicleError>)>,
);

/// Where the model update stands.
#[derive(Debug)]
enum UpdateState {
    /// No vehicle: nothing to update.
    Off,
    /// Records are being added; with the default band the better of the two bands' fits is
    /// taken at the end ([`vibmode_vehicle::update::choose_band`]).
    Fitting(Box<Fitting>),
    /// A record could not be used (the reason), so the update was stopped.
    Skipped(String),
}

impl ModelUpdate {
    /// With a vehicle, a fit of its suspension with the config's `[model_update]` settings;
    /// without, nothing.
    pub fn for_vehicle(
        vehicle: Option<VehicleParams>,
        cfg: &AnalysisConfig,
    ) -> Result<Self, RunError> {
        let state = match vehicle {
            Some(v) => {
                let fit = BodyFit::new(&v, cfg.model_update.clone())?;
                // With the default band, the wide band's fit beside it.
                // (The default band's fit above fails where the wide band cannot be made.)
                let wide = match cfg.model_update.band_hz {
                    None => {
                        let b = vibmode_vehicle::update::wide_band_hz(&v)?;
                        let params = vibmode_core::BodyFitParams {
                            band_hz: Some(b),
                            ..cfg.model_update.clone()
                        };
                        Some((b, BodyFit::new(&v, params)))
                    }
                    Some(_) => None,
                };
                UpdateState::Fitting(Box::new((v, fit, wide)))
            }
            None => UpdateState::Off,
        };
        Ok(ModelUpdate {
            cfg: cfg.clone(),
            state,
        })
    }

    /// Adds one record (its channels placed as the analysis places them). A record that cannot
    /// be used stops the update, with the reason kept for the output.
    pub fn add(&mut self, r: &RecordInput) {
        if let UpdateState::Fitting(b) = &mut self.state {
            let cfg = &self.cfg;
            if let Some((_, wide)) = &mut b.2 {
                if let Ok(w) = wide {
                    if let Err(e) =
                        w.add_record_placed(&r.recording, |c| cfg.placement_for_update(c))
                    {
                        *wide = Err(e);
                    }
                }
            }
            if let Err(e) =
                b.1.add_record_placed(&r.recording, |c| cfg.placement_for_update(c))
            {
                self.state = UpdateState::Skipped(format!("{}: {e}", r.name));
            }
        }
    }

    /// Solves the fit.
    pub fn finish(&mut self) -> UpdateOutcome {
        match std::mem::replace(&mut self.state, UpdateState::Off) {
            UpdateState::Off => UpdateOutcome::Off,
            UpdateState::Skipped(why) => UpdateOutcome::Skipped(why),
            UpdateState::Fitting(b) => match (b.1.solve(), b.2) {
                (Ok(r), None) => UpdateOutcome::Done(Box::new((b.0, r))),
                (Ok(r), Some((band, wide))) => {
                    let wide = wide.and_then(|w| w.solve());
                    let r = vibmode_vehicle::update::choose_band(r, band, wide);
                    UpdateOutcome::Done(Box::new((b.0, r)))
                }
                (Err(e), _) => UpdateOutcome::Skipped(e.to_string()),
            },
        }
    }
}

/// A record source that also feeds each record to the model update.
pub struct FeedUpdate<'a, E> {
    /// The records.
    pub source: &'a mut dyn RecordSource<Error = E>,
    /// The update they feed.
    pub update: &'a mut ModelUpdate,
}

impl<E> std::fmt::Debug for FeedUpdate<'_, E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FeedUpdate")
            .field("update", &self.update)
            .finish()
    }
}

impl<E> RecordSource for FeedUpdate<'_, E> {
    type Error = E;

    fn next_record(&mut self) -> Option<Result<RecordInput, E>> {
        let r = self.source.next_record();
        if let Some(Ok(rec)) = &r {
            self.update.add(rec);
        }
        r
    }

    fn meta(&self) -> Option<vibmode_core::RecordMeta> {
        self.source.meta()
    }
}

/// The model update's outcome.
#[derive(Debug)]
#[non_exhaustive]
pub enum UpdateOutcome {
    /// No vehicle.
    Off,
    /// Not possible, and why.
    Skipped(String),
    /// The vehicle and the fit.
    Done(Box<(VehicleParams, BodyFitResult)>),
}

impl UpdateOutcome {
    /// `results.json`'s `model_update`: the fit, or `{"not_updated": reason}`; None without a
    /// vehicle.
    pub fn to_json(&self) -> Option<serde_json::Value> {
        match self {
            UpdateOutcome::Off => None,
            UpdateOutcome::Skipped(why) => Some(serde_json::json!({ "not_updated": why })),
            UpdateOutcome::Done(b) => {
                let mut v = serde_json::to_value(&b.1)
                    .unwrap_or_else(|e| serde_json::json!({ "not_updated": e.to_string() }));
                // A fit the records do not support: its figures, and why it was not used.
                if let (Some(why), Some(o)) = (unsupported(&b.1), v.as_object_mut()) {
                    o.insert("not_updated".into(), why.into());
                }
                Some(v)
            }
        }
    }

    /// The report's section on the model update (none without a vehicle), with the analysis'
    /// SSI-cov modes in its figure.
    #[cfg(feature = "report")]
    pub fn sections(
        &self,
        results: &vibmode_analysis::AnalysisResults,
    ) -> Vec<vibmode_report::ReportSection> {
        use vibmode_report::ReportSection;
        let identified = results
            .ssi
            .as_ref()
            .map_or(&[][..], |s| &s.invariant_modes[..]);
        match self {
            UpdateOutcome::Off => Vec::new(),
            UpdateOutcome::Skipped(why) => vec![ReportSection::model_update_skipped(why)],
            UpdateOutcome::Done(b) => match unsupported(&b.1) {
                Some(why) => vec![ReportSection::model_update_unsupported(
                    &b.0, &b.1, identified, &why,
                )],
                None => vec![ReportSection::model_update(&b.0, &b.1, identified)],
            },
        }
    }

    /// Writes `model_update.json` and `updated_vehicle.toml` into `dir` (nothing without a fit).
    pub fn write(&self, dir: &Path) -> Result<(), RunError> {
        let UpdateOutcome::Done(b) = self else {
            return Ok(());
        };
        let (file, r) = (&b.0, &b.1);
        let write = |name: &str, text: String| {
            let path = dir.join(name);
            std::fs::write(&path, text).map_err(|e| RunError::Write {
                path: path.display().to_string(),
                message: e.to_string(),
            })
        };
        let json = serde_json::to_string_pretty(r).map_err(|e| RunError::Write {
            path: dir.join("model_update.json").display().to_string(),
            message: e.to_string(),
        })?;
        write("model_update.json", json + "\n")?;
        // A fit the records do not support is not written as a vehicle file; its figures stay
        // in model_update.json.
        if !r.supported {
            return Ok(());
        }
        let mut v = r.vehicle.clone();
        v.name = format!("{} (updated from the records)", file.name);
        // The fit's standard deviations as comments (jackknife over the records).
        let mut head = format!(
            "# Fitted to {} records by vibmode's model update (docs/model_update.md).\n",
            r.records
        );
        for p in r.parameters.iter() {
            if let Some(sd) = p.sd {
                head.push_str(&format!(
                    "# {}: {:.6e} {}, standard deviation {sd:.2e}\n",
                    p.name, p.value, p.unit
                ));
            }
        }
        write("updated_vehicle.toml", head + &v.to_toml_string()?)?;
        Ok(())
    }

    /// The text for the terminal: the fit's summary and where the updated vehicle file is
    /// (`shown`: the output folder as the user named it), or the one-line reason it was not
    /// fitted; None without a vehicle.
    pub fn summary_text(&self, shown: &Path) -> Option<String> {
        match self {
            UpdateOutcome::Off => None,
            UpdateOutcome::Skipped(why) => Some(format!("Full-car model not updated: {why}\n")),
            UpdateOutcome::Done(b) if !b.1.supported => Some(format!(
                "Full-car model not updated: {} (the fit's figures: {})\n",
                unsupported(&b.1).unwrap_or_default(),
                shown.join("model_update.json").display()
            )),
            UpdateOutcome::Done(b) => Some(format!(
                "{}  the updated vehicle file: {}\n",
                b.1.summary_text(&b.0),
                shown.join("updated_vehicle.toml").display()
            )),
        }
    }
}

/// Why the records do not support a model update's fit, as the one line the terminal and the
/// report give; `None` when they do.
fn unsupported(r: &BodyFitResult) -> Option<String> {
    (!r.supported).then(|| {
        format!(
            "the records do not support the fit: {}",
            r.not_supported.as_deref().unwrap_or("no reason recorded")
        )
    })
}
