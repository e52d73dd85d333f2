//! Sections of the analysis report beyond the analysis itself, as plain data: a title, paragraphs
//! and tables. The model update (`analyze --vehicle`) is one.

use crate::{Figure, Marker, Panel, Rgb, Scale, Series, SeriesStyle};
use vibmode_core::{InvariantMode, ModeClass};
use vibmode_vehicle::{update::BodyFitResult, VehicleParams};

/// A parameter's value: whole numbers from 1000 on, else one decimal.
fn value(v: f64) -> String {
    if v.abs() >= 1000.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.1}")
    }
}

/// A table of a [`ReportSection`]: column headers and rows of cells (numbers as text).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReportTable {
    /// Column headers, with units.
    pub headers: Vec<String>,
    /// Rows, each as many cells as there are headers.
    pub rows: Vec<Vec<String>>,
}

/// A figure of a [`ReportSection`], numbered with the report's others.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionFigure {
    /// File name stem (`figNN_<file>.svg|png`).
    pub file: String,
    /// Heading, after "Figure n: ".
    pub title: String,
    /// The figure.
    pub figure: Figure,
    /// Caption.
    pub caption: String,
}

/// A section of the report: a heading, paragraphs, tables, then figures.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReportSection {
    /// The heading.
    pub title: String,
    /// Paragraphs under the heading.
    pub paragraphs: Vec<String>,
    /// Tables after the paragraphs.
    pub tables: Vec<ReportTable>,
    /// Figures after the tables.
    pub figures: Vec<SectionFigure>,
    /// The section's numbers, added to `results.json` under this key (e.g. `model_update`).
    pub json: Option<(String, serde_json::Value)>,
}

impl ReportSection {
    /// The model update: the body modes of the vehicle file and of the updated model, then the
    /// fitted parameters beside the file's, and a figure of the body modes with the
    /// `identified` structural modes (e.g. the SSI-cov clusters) in the same band; `results.json`
    /// gets the whole result as `model_update` (as Python's `analyze` returns it).
    pub fn model_update(
        file: &VehicleParams,
        r: &BodyFitResult,
        identified: &[InvariantMode],
    ) -> ReportSection {
        Self::fit_section(file, r, identified, None)
    }

    /// A fit the records do not support (`why`): the reason first, then the fit's figures with
    /// their standard deviations (what the records gave, and how far they determine it), no
    /// vehicle file (`results.json`: `model_update` holds the figures and `not_updated`).
    pub fn model_update_unsupported(
        file: &VehicleParams,
        r: &BodyFitResult,
        identified: &[InvariantMode],
        why: &str,
    ) -> ReportSection {
        Self::fit_section(file, r, identified, Some(why))
    }

    fn fit_section(
        file: &VehicleParams,
        r: &BodyFitResult,
        identified: &[InvariantMode],
        not_used: Option<&str>,
    ) -> ReportSection {
        let files = if not_used.is_some() {
            "no updated vehicle file was written"
        } else {
            "the updated vehicle file is updated_vehicle.toml beside this page"
        };
        let intro = format!(
            "The vehicle file's suspension and body inertias were fitted to the records from the full-car model's three body equations, which carry no road input: {} records, {} equations in {:.2}-{:.2} Hz, {:.1} % of their variance explained. Each sensor's white noise, measured from its spectrum above the band, was taken out of the equations, as much of its share as leaves them positive semi-definite (generalized total least squares; noise_share in model_update.json), and the standard deviations are the jackknife's over the records. The sprung mass, unsprung masses, tyres and bending are the file's. These body modes do not depend on the road's wheelbase delay, which biases output-only heave and pitch (docs/model_update.md); {files}, every number is in model_update.json and, under model_update, in results.json.",
            r.records,
            r.equations,
            r.band_hz[0],
            r.band_hz[1],
            100.0 * r.explained
        );
        // Which band was taken, and why (the default band's fit against the wide one's).
        let intro = match &r.band_choice {
            Some(c) => format!("{intro} Band: {}.", c.reason),
            None => intro,
        };
        // What the updated vehicle file holds is said only where one is written.
        let written = not_used.is_none();
        let intro = if r.absent.is_empty() {
            intro
        } else {
            format!(
                "{intro} The records put the {} at 0 (held there by the bounded fit, every parameter >= 0): the measured vehicle has none{}.",
                r.absent.join(" and the "),
                if written { ", and the updated vehicle file has none" } else { "" }
            )
        };
        let found = r.found_bars(file);
        let intro = if found.is_empty() {
            intro
        } else {
            format!(
                "{intro} The records give a {}, which the vehicle file lacks (both axles' bars are fitted whatever the file holds: anti_roll_bars in [model_update]){}.",
                found.join(" and a "),
                if written { "; the updated vehicle file has it" } else { "" }
            )
        };
        let modes = ReportTable {
            headers: [
                "mode",
                "file [Hz]",
                "updated [Hz]",
                "change [%]",
                "sd [Hz]",
                "file damping ratio",
                "updated damping ratio",
                "sd",
            ]
            .map(String::from)
            .to_vec(),
            rows: r
                .body_mode_pairs()
                .into_iter()
                .map(|(n, u)| {
                    let sd = r.mode_spread(u.label);
                    let f = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
                    vec![
                        n.label.to_string(),
                        format!("{:.3}", n.frequency_hz),
                        format!("{:.3}", u.frequency_hz),
                        format!("{:+.1}", 100.0 * (u.frequency_hz / n.frequency_hz - 1.0)),
                        f(sd.map(|m| m.frequency_hz_sd)),
                        format!("{:.3}", n.damping_ratio),
                        format!("{:.3}", u.damping_ratio),
                        f(sd.map(|m| m.damping_ratio_sd)),
                    ]
                })
                .collect(),
        };
        let params = ReportTable {
            headers: ["parameter", "unit", "file", "fitted", "sd", "change [%]"]
                .map(String::from)
                .to_vec(),
            rows: r
                .parameter_changes(file)
                .into_iter()
                .map(|p| {
                    let change = if p.file != 0.0 {
                        format!("{:+.1}", 100.0 * (p.fitted / p.file - 1.0))
                    } else {
                        "-".into()
                    };
                    vec![
                        p.name,
                        p.unit.to_string(),
                        value(p.file),
                        value(p.fitted),
                        p.sd.map_or("-".into(), value),
                        change,
                    ]
                })
                .collect(),
        };
        let mut json = serde_json::to_value(r).ok();
        let (title, paragraphs) = match not_used {
            None => ("Full-car model updated from the records", vec![intro]),
            Some(why) => {
                if let Some(o) = json.as_mut().and_then(|v| v.as_object_mut()) {
                    o.insert("not_updated".into(), why.into());
                }
                (
                    "Full-car model not updated",
                    vec![
                        format!(
                            "The fit below was not used: {why}. Its figures are shown with their standard deviations, as what these records give and how far they determine it; the modes above are matched to the vehicle file's model as it is."
                        ),
                        intro,
                    ],
                )
            }
        };
        ReportSection {
            title: title.into(),
            paragraphs,
            tables: vec![modes, params],
            figures: vec![body_modes_figure(r, identified)],
            json: json.map(|v| ("model_update".to_string(), v)),
        }
    }

    /// The model update could not be made: the reason, so that its absence is not silent
    /// (`results.json`: `model_update: {"not_updated": reason}`).
    pub fn model_update_skipped(why: &str) -> ReportSection {
        ReportSection {
            title: "Full-car model not updated".into(),
            paragraphs: vec![format!(
                "The vehicle file's suspension was not fitted to the records: {why}. The modes above are matched to the vehicle file's model as it is."
            )],
            tables: Vec::new(),
            figures: Vec::new(),
            json: Some((
                "model_update".into(),
                serde_json::json!({ "not_updated": why }),
            )),
        }
    }
}

/// Frequency against damping ratio around the body modes: the vehicle file's model (red
/// diamonds), the updated model (green squares) and the identified structural modes (blue
/// circles) in the same band.
fn body_modes_figure(r: &BodyFitResult, identified: &[InvariantMode]) -> SectionFigure {
    let pairs = r.body_mode_pairs();
    let (lo, hi) = pairs
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), (n, u)| {
            (
                lo.min(n.frequency_hz).min(u.frequency_hz),
                hi.max(n.frequency_hz).max(u.frequency_hz),
            )
        });
    let (x0, x1) = if lo.is_finite() && hi > 0.0 {
        (0.7 * lo, 1.3 * hi)
    } else {
        (r.band_hz[0], r.band_hz[1])
    };
    let points = |f: Vec<(f64, f64)>, label: &str, marker: Marker, color: Rgb, size: u32| {
        let (x, y): (Vec<f64>, Vec<f64>) = f.into_iter().unzip();
        Series::points(x, y, marker)
            .with_label(label)
            .with_color(color)
            .with_style(SeriesStyle::Points { size, marker })
    };
    let ident: Vec<(f64, f64)> = identified
        .iter()
        .filter(|m| m.class == ModeClass::Structural)
        .filter(|m| (x0..=x1).contains(&m.frequency_hz) && m.damping_ratio > 0.0)
        .map(|m| (m.frequency_hz, m.damping_ratio))
        .collect();
    let n_ident = ident.len();
    let mut panel = Panel::new("Body modes", "Frequency [Hz]", "Damping ratio [-]")
        .with_scales(Scale::Linear, Scale::Log)
        .with_series(points(
            pairs
                .iter()
                .map(|(n, _)| (n.frequency_hz, n.damping_ratio))
                .collect(),
            "vehicle file's model",
            Marker::Diamond,
            Rgb::RED,
            7,
        ))
        .with_series(points(
            pairs
                .iter()
                .map(|(_, u)| (u.frequency_hz, u.damping_ratio))
                .collect(),
            "updated model",
            Marker::Square,
            Rgb::GREEN,
            6,
        ))
        .with_series(points(
            ident,
            "identified structural modes",
            Marker::Circle,
            Rgb::BLUE,
            5,
        ));
    panel.x_range = Some((x0, x1));
    panel.y_range = Some((0.01, 3.0));
    SectionFigure {
        file: "body_modes".into(),
        title: "body modes of the file, the updated model and the records".into(),
        figure: Figure::single(panel),
        caption: format!(
            "Body pitch, heave and roll of the vehicle file's model (red diamonds) and of the model updated from the records (green squares), with the {n_ident} identified structural mode(s) between {x0:.2} and {x1:.2} Hz (blue circles). Output-only heave and pitch carry the road's wheelbase delay (docs/ssi.md); the updated model's do not."
        ),
    }
}
