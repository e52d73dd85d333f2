//! Sections of the analysis report beyond the analysis itself, as plain data: a title, paragraphs
//! and tables. The model update (`analyze --vehicle`) is one.

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

/// A section of the report: a heading, paragraphs, then tables.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReportSection {
    /// The heading.
    pub title: String,
    /// Paragraphs under the heading.
    pub paragraphs: Vec<String>,
    /// Tables after the paragraphs.
    pub tables: Vec<ReportTable>,
    /// The section's numbers, added to `results.json` under this key (e.g. `model_update`).
    pub json: Option<(String, serde_json::Value)>,
}

impl ReportSection {
    /// The model update: the body modes of the vehicle file and of the updated model, then the
    /// fitted parameters beside the file's; `results.json` gets the whole result as
    /// `model_update` (as Python's `analyze` returns it).
    pub fn model_update(file: &VehicleParams, r: &BodyFitResult) -> ReportSection {
        let intro = format!(
            "The vehicle file's suspension and body inertias were fitted to the records from the full-car model's three body equations, which carry no road input: {} records, {} equations in {:.2}-{:.2} Hz, {:.1} % of their variance explained. The sprung mass, unsprung masses, tyres and bending are the file's. These body modes do not depend on the road's wheelbase delay, which biases output-only heave and pitch (docs/model_update.md); the updated vehicle file is updated_vehicle.toml beside this page, every number is in model_update.json.",
            r.records,
            r.equations,
            r.band_hz[0],
            r.band_hz[1],
            100.0 * r.explained
        );
        let modes = ReportTable {
            headers: [
                "mode",
                "file [Hz]",
                "updated [Hz]",
                "change [%]",
                "file damping ratio",
                "updated damping ratio",
            ]
            .map(String::from)
            .to_vec(),
            rows: r
                .body_mode_pairs()
                .into_iter()
                .map(|(n, u)| {
                    vec![
                        n.label.to_string(),
                        format!("{:.3}", n.frequency_hz),
                        format!("{:.3}", u.frequency_hz),
                        format!("{:+.1}", 100.0 * (u.frequency_hz / n.frequency_hz - 1.0)),
                        format!("{:.3}", n.damping_ratio),
                        format!("{:.3}", u.damping_ratio),
                    ]
                })
                .collect(),
        };
        let params = ReportTable {
            headers: ["parameter", "unit", "file", "fitted", "change [%]"]
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
                        change,
                    ]
                })
                .collect(),
        };
        ReportSection {
            title: "Full-car model updated from the records".into(),
            paragraphs: vec![intro],
            tables: vec![modes, params],
            json: serde_json::to_value(r)
                .ok()
                .map(|v| ("model_update".to_string(), v)),
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
            json: Some((
                "model_update".into(),
                serde_json::json!({ "not_updated": why }),
            )),
        }
    }

    /// Adds the section to `html`.
    pub(crate) fn render(&self, html: &mut crate::HtmlReport) {
        html.heading(2, &self.title);
        for p in &self.paragraphs {
            html.paragraph(p);
        }
        for t in &self.tables {
            let headers: Vec<&str> = t.headers.iter().map(String::as_str).collect();
            html.table(&headers, &t.rows);
        }
    }
}
