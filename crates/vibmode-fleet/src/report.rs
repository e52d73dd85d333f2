//! The fleet report: one self-contained HTML page with every vehicle's status, the trend of each
//! vehicle feature of its model set over the records (nominal band drawn), and the flagged
//! records with their evidence.

use std::path::{Path, PathBuf};

use vibmode_report::panels::grid;
use vibmode_report::{HtmlReport, Marker, Panel, Rgb, Series};

use crate::error::{FleetError, Result};
use crate::model::{Classification, Group, ModelSet};
use crate::store::{Condition, Store};

/// Most transmissibility / level trend panels drawn per vehicle (the features with the largest
/// scores first); every mode's frequency and damping is drawn besides.
pub const MAX_TREND_PANELS: usize = 12;

/// A file, folder or figure of the report that could not be written.
fn cannot_write(what: impl std::fmt::Display, e: impl ToString) -> FleetError {
    FleetError::Write {
        what: what.to_string(),
        reason: e.to_string(),
    }
}

/// Writes `dir/index.html` for every vehicle of `store` and returns its path. The folder is
/// created when missing; the page is written to a temporary name and renamed, so an old report
/// is never left half-overwritten.
pub fn write_fleet_report(store: &Store, dir: &Path) -> Result<PathBuf> {
    let mut html = HtmlReport::new("vibmode fleet report");
    let vehicles = store.vehicles()?;
    html.paragraph(&format!(
        "Store {}: {} vehicle(s). Each record is classified against its vehicle's nominal model set: normal, road (excitation outside the nominal range), vehicle (transmissibility or modes of a corner moved), both, or sensor (a dead, stuck, clipped or held channel: fix the sensor first) (docs/fleet.md).",
        store.path(),
        vehicles.len()
    ));
    if vehicles.is_empty() {
        // Nothing to report is said, not left as empty tables.
        html.paragraph(
            "The store holds no vehicle yet: nothing has been ingested or checked, so there is no verdict to report. Ingest a vehicle's nominal records and build its baseline first (docs/fleet.md).",
        );
    }
    let status = store.status(usize::MAX / 2)?;
    // What a maintenance planner acts on first: per vehicle, its latest drive verdict, the
    // corner named, since when, and how sure; then the timeline of its drive verdicts.
    let verdicts: Vec<Vec<String>> = status
        .iter()
        .map(|s| match &s.latest_drive {
            Some(d) => vec![
                s.vehicle.clone(),
                d.classification.to_string(),
                d.place(),
                d.since.clone(),
                d.vehicle_z_over_limit
                    .map_or("-".into(), |z| format!("{z:.2}")),
                format!(
                    "{} ({} records; false alarms <= {} per drive)",
                    d.drive, d.n_records, d.false_alarm_rate
                ),
                // A fault found on an earlier drive against the same baseline stays in sight.
                match &s.earlier_flag {
                    Some(f) if d.summary.is_empty() => crate::text::earlier_flag_line(f),
                    Some(f) => format!("{}; {}", d.summary, crate::text::earlier_flag_line(f)),
                    None => d.summary.clone(),
                },
            ],
            // Records checked one by one only: the latest one's verdict in the evidence, so a
            // flagged record is not hidden behind "no drive checked".
            None => vec![
                s.vehicle.clone(),
                "no drive checked".into(),
                "-".into(),
                "-".into(),
                "-".into(),
                "-".into(),
                s.last_checks
                    .first()
                    .map_or(String::new(), |(file, class, summary)| {
                        format!(
                            "latest record checked: {class} ({file}){}",
                            if summary.is_empty() {
                                String::new()
                            } else {
                                format!(": {summary}")
                            }
                        )
                    }),
            ],
        })
        .collect();
    html.heading(2, "Latest drive verdict per vehicle");
    html.table(
        &[
            "vehicle",
            "verdict",
            "corner, component",
            "since",
            "|z| / limit",
            "drive",
            "evidence",
        ],
        &verdicts,
    );
    if !status.is_empty() {
        html.paragraph(&crate::text::held_out_fleet_line(&status));
    }
    let timeline: Vec<Vec<String>> = status
        .iter()
        .flat_map(|s| {
            s.drives.iter().map(|d| {
                vec![
                    s.vehicle.clone(),
                    d.when(),
                    d.drive.clone(),
                    d.classification.to_string(),
                    d.place(),
                ]
            })
        })
        .collect();
    if !timeline.is_empty() {
        html.heading(2, "Drive verdicts, newest first");
        html.table(
            &[
                "vehicle",
                "driven (or checked)",
                "drive",
                "verdict",
                "corner, component",
            ],
            &timeline,
        );
    }
    let rows: Vec<Vec<String>> = status
        .iter()
        .map(|s| {
            let count = |c: Classification| {
                s.last_checks
                    .iter()
                    .filter(|(_, k, _)| *k == c)
                    .count()
                    .to_string()
            };
            vec![
                s.vehicle.clone(),
                s.n_nominal.to_string(),
                s.n_test.to_string(),
                s.baseline_version.map_or("none".into(), |v| v.to_string()),
                count(Classification::Normal),
                count(Classification::Road),
                count(Classification::Vehicle),
                count(Classification::Both),
                count(Classification::Sensor),
                s.suspension.clone().unwrap_or_default(),
            ]
        })
        .collect();
    html.heading(2, "Records per vehicle");
    html.table(
        &[
            "vehicle",
            "nominal records",
            "test records",
            "model set",
            "normal",
            "road",
            "vehicle",
            "both",
            "sensor",
            "suspension fitted per drive",
        ],
        &rows,
    );
    for v in &vehicles {
        vehicle_section(&mut html, store, v)?;
    }
    std::fs::create_dir_all(dir).map_err(|e| cannot_write(dir.display(), e))?;
    let path = dir.join("index.html");
    let tmp = dir.join(".index.html.partial");
    html.save(&tmp)
        .map_err(|e| cannot_write(tmp.display(), e))?;
    std::fs::rename(&tmp, &path).map_err(|e| cannot_write(path.display(), e))?;
    Ok(path)
}

fn vehicle_section(html: &mut HtmlReport, store: &Store, vehicle: &str) -> Result<()> {
    html.heading(2, &format!("Vehicle {vehicle}"));
    let records = store.records_with_checks(vehicle)?;
    let Some(set) = store.latest_model_set(vehicle)? else {
        html.paragraph(&format!(
            "{} record(s), no model set yet: build one from at least 5 nominal records (vibmode fleet baseline).",
            records.len()
        ));
        return Ok(());
    };
    html.paragraph(&format!(
        "Model set version {} from {} nominal record(s). Trends: each vehicle feature per record in ingest order (blue circles: nominal records, green squares: test records inside the band, red triangles: flagged); the grey lines are the nominal band, centre x exp(+-limit x spread).",
        set.version,
        set.records.len()
    ));
    trend_figure(html, &set, &records)?;
    let flagged: Vec<Vec<String>> = records
        .iter()
        .filter_map(|(row, _, a)| {
            let a = a.as_ref()?;
            (a.classification != Classification::Normal).then(|| {
                let sensors = a.sensor_faults.iter().map(|f| f.to_string());
                let evidence: Vec<String> = sensors
                    .chain(a.evidence.iter().filter(|e| e.flagged).take(6).map(|e| {
                        format!(
                            "{}{} {:+.0} % (z {:.1})",
                            e.meta.corner.map_or(String::new(), |c| format!("{c}: ")),
                            e.meta.label,
                            e.change_pct,
                            e.z
                        )
                    }))
                    .collect();
                vec![
                    row.file_name.clone(),
                    row.ingested.clone(),
                    format!("{:?}", a.classification).to_lowercase(),
                    evidence.join("; "),
                ]
            })
        })
        .collect();
    if flagged.is_empty() {
        html.paragraph("No flagged record.");
    } else {
        html.heading(3, "Flagged records");
        html.table(
            &["file", "ingested", "classification", "evidence"],
            &flagged,
        );
    }
    Ok(())
}

type RecordEntry = (
    crate::store::RecordRow,
    crate::features::RecordFeatures,
    Option<crate::model::Assessment>,
);

/// Which records a trend panel's points are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum RecordPoints {
    /// The model set's nominal records.
    Nominal,
    /// Test records inside the nominal band.
    Test,
    /// Records whose feature is flagged.
    Flagged,
}

/// A trend panel's points of one kind of record. Red is kept for what is flagged: a test record
/// inside the band is not an alarm, and a planner reads red as one.
fn record_points(kind: RecordPoints, x: Vec<f64>, y: Vec<f64>) -> Series {
    let (marker, label, color) = match kind {
        RecordPoints::Nominal => (Marker::Circle, "nominal", Rgb::BLUE),
        RecordPoints::Test => (Marker::Square, "test", Rgb::GREEN),
        RecordPoints::Flagged => (Marker::Triangle, "flagged", Rgb::RED),
    };
    Series::points(x, y, marker)
        .with_label(label)
        .with_color(color)
}

fn trend_figure(html: &mut HtmlReport, set: &ModelSet, records: &[RecordEntry]) -> Result<()> {
    // ln of each feature per record (as the model set keeps them).
    let values: Vec<Vec<(String, f64)>> = records
        .iter()
        .map(|(_, f, _)| {
            set.record_features(f)
                .into_iter()
                .map(|(m, v)| (m.key, v))
                .collect()
        })
        .collect();
    // Vehicle features, most-moved first (largest |z| seen in any record).
    let mut feats: Vec<(&crate::model::FeatureStat, f64)> = set
        .features
        .iter()
        .filter(|f| f.meta.group == Group::Vehicle)
        .map(|f| {
            let worst = values
                .iter()
                .filter_map(|vs| vs.iter().find(|(k, _)| *k == f.meta.key))
                .map(|(_, v)| (v - f.centre).abs() / f.sigma)
                .fold(0.0, f64::max);
            (f, worst)
        })
        .collect();
    // Every mode's frequency and damping, then the most-moved other features up to
    // MAX_TREND_PANELS more.
    feats.sort_by(|a, b| b.1.total_cmp(&a.1));
    let is_mode = |f: &crate::model::FeatureStat| {
        matches!(
            f.meta.kind,
            crate::model::Kind::ModeFrequency | crate::model::Kind::ModeDamping
        )
    };
    let mut chosen: Vec<&(&crate::model::FeatureStat, f64)> = feats
        .iter()
        .filter(|(f, _)| !is_mode(f))
        .take(MAX_TREND_PANELS)
        .collect();
    chosen.extend(feats.iter().filter(|(f, _)| is_mode(f)));
    let panels: Vec<Panel> = chosen
        .into_iter()
        .map(|(f, _)| {
            let limit = set
                .limits
                .iter()
                .find(|l| l.kind == f.meta.kind)
                .map_or(3.0, |l| l.limit);
            let (mut nx, mut ny, mut tx, mut ty, mut fx, mut fy) =
                (vec![], vec![], vec![], vec![], vec![], vec![]);
            for (i, ((row, _, a), vs)) in records.iter().zip(&values).enumerate() {
                let Some((_, v)) = vs.iter().find(|(k, _)| *k == f.meta.key) else {
                    continue;
                };
                let x = (i + 1) as f64;
                let flagged = a.as_ref().is_some_and(|a| {
                    a.evidence
                        .iter()
                        .any(|e| e.flagged && e.meta.key == f.meta.key)
                });
                // The features are kept as logarithms; drawn in their units.
                let y = v.exp();
                if flagged {
                    fx.push(x);
                    fy.push(y);
                } else if row.condition == Condition::Nominal {
                    nx.push(x);
                    ny.push(y);
                } else {
                    tx.push(x);
                    ty.push(y);
                }
            }
            let n = records.len().max(1) as f64;
            let band = |k: f64| {
                Series::line(
                    vec![0.5, n + 0.5],
                    vec![(f.centre + k * limit * f.sigma).exp(); 2],
                )
                .with_label(if k > 0.0 { "nominal band" } else { "" })
                .with_color(Rgb::GREY)
            };
            let title = match f.meta.corner {
                Some(c) => format!("{c}: {}", f.meta.label),
                None => format!("{}: {}", f.meta.channel, f.meta.label),
            };
            let unit = match f.meta.kind {
                crate::model::Kind::ModeFrequency => "Hz",
                crate::model::Kind::ModeDamping => "damping ratio",
                crate::model::Kind::Transmissibility => "sprung / unsprung RMS vs other corners",
                crate::model::Kind::Level => "m/s^2",
                crate::model::Kind::SideRatio => "left / right unsprung RMS",
                crate::model::Kind::TrackRatio => "front / rear unsprung RMS",
                crate::model::Kind::BodyResponse => "measured / predicted sprung power",
                crate::model::Kind::SpringFit => "fitted spring / other corners'",
                crate::model::Kind::DamperFit => "fitted damper / other corners'",
            };
            Panel::new(title, "record (ingest order)", unit)
                .with_series(band(1.0))
                .with_series(band(-1.0))
                .with_series(record_points(RecordPoints::Nominal, nx, ny))
                .with_series(record_points(RecordPoints::Test, tx, ty))
                .with_series(record_points(RecordPoints::Flagged, fx, fy))
                .without_legend()
        })
        .collect();
    if panels.is_empty() {
        html.paragraph("The model set has no vehicle feature to draw.");
        return Ok(());
    }
    let fig = grid(panels, 3, 420, 300);
    html.figure(&fig, "Vehicle features per record with the nominal band")
        .map_err(|e| cannot_write("the trend figure", e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use vibmode_report::SeriesStyle;

    /// A report that cannot be written says so (not "cannot read"), naming the path and the
    /// fix: here its folder would be made inside a file.
    #[test]
    fn a_report_that_cannot_be_written_says_write() {
        let dir = tempfile::tempdir().expect("temp dir");
        let file = dir.path().join("f");
        std::fs::write(&file, b"x").expect("write");
        let (store, _) = Store::init(&dir.path().join("s.db")).expect("store");
        let err = write_fleet_report(&store, &file.join("report"))
            .expect_err("a folder inside a file")
            .to_string();
        assert!(err.starts_with("cannot write "), "{err}");
        assert!(
            err.contains("report") && err.contains("folder you can write to"),
            "{err}"
        );
    }

    #[test]
    fn only_flagged_records_are_drawn_red_and_each_kind_apart() {
        let kinds = [
            RecordPoints::Nominal,
            RecordPoints::Test,
            RecordPoints::Flagged,
        ];
        let series: Vec<Series> = kinds
            .iter()
            .map(|&k| record_points(k, vec![1.0], vec![2.0]))
            .collect();
        let colors: Vec<Option<Rgb>> = series.iter().map(|s| s.color).collect();
        assert_eq!(colors[2], Some(Rgb::RED));
        assert!(colors[..2]
            .iter()
            .all(|c| c.is_some() && *c != Some(Rgb::RED)));
        assert_ne!(colors[0], colors[1]);
        let markers: Vec<&SeriesStyle> = series.iter().map(|s| &s.style).collect();
        assert!(markers[0] != markers[1] && markers[1] != markers[2] && markers[0] != markers[2]);
        assert_eq!(series[0].x, vec![1.0]);
        assert_eq!(series[0].y, vec![2.0]);
    }
}
