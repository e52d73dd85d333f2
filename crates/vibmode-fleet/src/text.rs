//! The fleet commands' printed text (as the report crate prints `analyze`'s tables): each
//! function turns a result into the lines a user reads, so the binary only parses arguments and
//! prints, and any other front end can print the same.

use crate::fleet::{Checked, Ingested, Registered};
use crate::model::{Classification, Drive, ModelSet, MIN_DRIVE_RECORDS};
use crate::store::{Condition, EarlierFlag, VehicleStatus};
use std::fmt::Write as _;

/// What `fleet ingest` says of the records it was given, one line per file, each record's own
/// notes beneath it. A note that every newly stored record has (a sensor layout without a
/// partner channel, say) is printed once after the list, not under each record; a record
/// already stored keeps all its notes.
pub fn ingest_text(done: &[Ingested], vehicle: &str, condition: Condition) -> String {
    let new: Vec<&Vec<String>> = done
        .iter()
        .filter(|r| !r.already_stored)
        .map(|r| &r.notes)
        .collect();
    let common: Vec<&String> = match new.split_first() {
        Some((first, rest)) if !rest.is_empty() => first
            .iter()
            .filter(|n| rest.iter().all(|o| o.contains(n)))
            .collect(),
        _ => Vec::new(),
    };
    let n_new = new.len();
    let condition = condition.as_str();
    let mut text = String::new();
    for r in done {
        let own = r
            .notes
            .iter()
            .filter(|n| r.already_stored || !common.contains(n));
        if r.already_stored && r.notes.is_empty() {
            let _ = writeln!(
                text,
                "{}: already stored for vehicle {vehicle} (record {}), nothing to do",
                r.file, r.record_id
            );
            continue;
        }
        if r.already_stored {
            let _ = writeln!(
                text,
                "{}: already stored for vehicle {vehicle} (record {})",
                r.file, r.record_id
            );
        } else {
            let _ = writeln!(
                text,
                "{}: stored as {condition} record {} of vehicle {vehicle}",
                r.file, r.record_id
            );
        }
        for n in own {
            let _ = writeln!(text, "  note: {n}");
        }
    }
    for n in common {
        let _ = writeln!(text, "note (every one of the {n_new} records stored): {n}");
    }
    text
}

/// What `fleet register` says of a vehicle's model file.
pub fn register_text(vehicle: &str, file: &std::path::Path, done: Registered) -> String {
    let file = file.display();
    match done {
        Registered::New => format!(
            "vehicle {vehicle}: model file {file} registered; records ingested or checked from now on keep their body equations for the suspension fitted per drive (ingest nominal records, then build the baseline)\n"
        ),
        Registered::Unchanged => {
            format!("vehicle {vehicle}: model file {file} already registered (unchanged)\n")
        }
        Registered::Replaced => format!(
            "vehicle {vehicle}: model file {file} registered in place of the one before; records' body equations made with the old file no longer count: ingest nominal records and build a new baseline for the suspension fitted per drive\n"
        ),
    }
}

/// A model set as `fleet baseline` prints it: its size, the control limit of each kind of
/// feature, the fitted suspension where there is one, and its notes.
pub fn baseline_text(set: &ModelSet) -> String {
    let mut text = format!(
        "vehicle {}: model set version {} from {} nominal records, {} features, {} modes\n",
        set.vehicle,
        set.version,
        set.records.len(),
        set.features.len(),
        set.slots.len()
    );
    text.push_str("kind               features  Bonferroni  LOO max |z|  limit\n");
    for l in &set.limits {
        let _ = writeln!(
            text,
            "{:<18} {:>8}  {:>10.2}  {:>11.2}  {:>5.2}",
            l.kind.to_string(),
            l.n_features,
            l.bonferroni,
            l.loo_max_abs_z,
            l.limit
        );
    }
    if set
        .limits
        .iter()
        .any(|l| l.kind == crate::model::Kind::Level)
    {
        // One-sided, so its leave-one-out maximum is 0 on every baseline: said, not a puzzle.
        text.push_str(
            "(level: a road scored only beyond the nominal records' largest level and the road margin, so a nominal record scores 0)\n",
        );
    }
    if let Some(s) = &set.suspension {
        let _ = writeln!(
            text,
            "suspension fitted to {} nominal records: springs and dampers per corner scored per drive, and the springs over the last {} drives, one-sided limits {:.2} and {:.2} (the trend){}",
            s.fit.records,
            crate::suspension::TREND_DRIVES,
            s.limit,
            crate::suspension::trend_limit(set.config.false_alarm_rate),
            if s.fit.supported {
                ""
            } else {
                " (the fit's standard deviations exceed the model update's support limits: the scores use them as they are)"
            }
        );
        for (i, c) in crate::suspension::CORNERS.iter().enumerate() {
            let _ = writeln!(
                text,
                "  {c}: spring {:.1} kN/m (sd {:.1} %), damper {:.2} kN s/m (sd {:.1} %)",
                s.fit.spring_n_per_m[i] / 1e3,
                100.0 * s.fit.spring_rel_sd[i],
                s.fit.damper_n_s_per_m[i] / 1e3,
                100.0 * s.fit.damper_rel_sd[i]
            );
        }
    }
    held_out_text(&mut text, &set.held_out_drives);
    for n in &set.notes {
        let _ = writeln!(text, "note: {n}");
    }
    text
}

/// The baseline's leave-one-drive-out lines: one per held-out nominal drive, and a warning
/// when any of them is flagged.
fn held_out_text(text: &mut String, drives: &[crate::model::HeldOutDrive]) {
    if drives.is_empty() {
        return;
    }
    let flagged: Vec<&crate::model::HeldOutDrive> = drives
        .iter()
        .filter(|d| d.classification != Classification::Normal)
        .collect();
    let _ = writeln!(
        text,
        "leave-one-drive-out: {} nominal drive(s), each checked as a drive against a model set of the other nominal records: {} flagged",
        drives.len(),
        flagged.len()
    );
    for d in drives {
        let component = d.component.map(|c| format!(" ({c})")).unwrap_or_default();
        let _ = writeln!(
            text,
            "  {:<30} {} records, against {}: {}{component}  {}",
            d.drive,
            d.records.len(),
            d.reference_records,
            d.classification,
            or_dash(&d.summary)
        );
    }
    if !flagged.is_empty() {
        let _ = writeln!(
            text,
            "warning: {} of {} healthy nominal drives would be flagged against the other nominal records: this vehicle's healthy drives differ more than the limits allow, so checks will flag healthy drives like them; ingest nominal drives of more days, roads and loads and build the baseline again",
            flagged.len(),
            drives.len()
        );
    }
}

/// `fleet check`'s table: one row per record (class, scores, evidence), the notes on records
/// that are not independent checks, then one line per drive with its verdict and notes.
pub fn check_text(vehicle: &str, model_version: i64, out: &[Checked], drives: &[Drive]) -> String {
    let mut text = format!(
        "vehicle {vehicle} against model set version {model_version}\nfile                            class     vehicle |z|  road score  evidence\n"
    );
    for c in out {
        let _ = writeln!(
            text,
            "{:<31} {:<9} {:>11.1}  {:>10.1}  {}",
            c.file,
            c.assessment.classification.to_string(),
            c.assessment.scores.vehicle_max_abs_z,
            c.assessment.scores.excitation_max_abs_z,
            or_dash(&c.assessment.summary)
        );
    }
    // Records that are not independent checks: the same content given twice, and a record of
    // the baseline checked against it (scored by a yardstick made from itself).
    for c in out {
        if let Some(first) = &c.same_as {
            let _ = writeln!(
                text,
                "note: {} has the content of {first}, given before it: counted once in a drive",
                c.file
            );
        }
        if let Some(twin) = &c.in_baseline {
            let _ = writeln!(
                text,
                "note: {} has the content of {twin}, a record model set version {} was built from: not an independent check",
                c.file, c.model_version
            );
        }
    }
    for d in drives {
        let _ = writeln!(
            text,
            "drive {} ({} records, median of each feature; false alarms per drive at most {} %): {}{}  {}",
            d.drive,
            d.records.len(),
            100.0 * d.false_alarm_rate,
            d.assessment.classification,
            match (d.corner, d.assessment.component) {
                (Some(c), Some(k)) => format!(" ({c} {k})"),
                (Some(c), None) => format!(" ({c})"),
                _ => String::new(),
            },
            or_dash(&d.assessment.summary)
        );
        // Why the suspension was not fitted to the drive (no model file, no fit in the model
        // set, too few records...): not a silent absence.
        for m in d
            .assessment
            .missing
            .iter()
            .filter(|m| m.starts_with("suspension fit:"))
        {
            let _ = writeln!(text, "  note: {m}");
        }
        // What the fitted suspension was scored against, once normal drives joined the baseline.
        if let Some(s) = d
            .suspension
            .as_ref()
            .filter(|s| !s.reference_drives.is_empty())
        {
            let _ = writeln!(
                text,
                "  note: suspension fit scored against the baseline's fit pooled with the vehicle's first {} normal drive(s): {}",
                s.reference_drives.len(),
                vibmode_core::cap_message(&s.reference_drives.join(", "), 120)
            );
        }
        // What the drive's fit could have shown: a normal drive is not a verdict on a smaller loss.
        if let Some(s) = &d.suspension {
            if let Some(line) = smallest_losses_line(s) {
                let _ = writeln!(text, "  note: {line}");
            }
        }
        if !d.in_baseline.is_empty() {
            let _ = writeln!(
                text,
                "  note: {} of the drive's {} records are records of the baseline ({}): its verdict leans toward normal; check records the baseline was not built from",
                d.in_baseline.len(),
                d.records.len(),
                vibmode_core::cap_message(&d.in_baseline.join(", "), 120)
            );
        }
    }
    // Records checked one by one only: say so, rather than let a per-record verdict pass for
    // a drive's (a copy given twice has its own note and counts with its first).
    let loose: Vec<&str> = out
        .iter()
        .filter(|c| c.same_as.is_none() && !drives.iter().any(|d| d.records.contains(&c.file)))
        .map(|c| c.file.as_str())
        .collect();
    if !loose.is_empty() {
        let which = match loose.as_slice() {
            [one] => format!("{one} is in no drive"),
            many => format!(
                "{} records are in no drive ({})",
                many.len(),
                vibmode_core::cap_message(&many.join(", "), 120)
            ),
        };
        let _ = writeln!(
            text,
            "note: {which}: a drive needs at least {MIN_DRIVE_RECORDS} records (of one day, where the records' starts are known); a single record's verdict flags a healthy vehicle more often than a drive's"
        );
    }
    text
}

/// `fleet status`: one row per vehicle first (its latest drive verdict, the corner, since when,
/// how sure), then each vehicle's counts, drives and latest records, newest first.
pub fn status_text(st: &[VehicleStatus]) -> String {
    if st.is_empty() {
        // An empty store is a state, said as such (not an empty table).
        return "no vehicle in the store yet: nothing ingested or checked, so no verdict; ingest a vehicle's nominal records and build its baseline first (docs/fleet.md)\n".to_string();
    }
    let mut text = String::from(
        "vehicle          latest drive verdict  corner, component  since                 |z|/limit  drive\n",
    );
    for v in st {
        match &v.latest_drive {
            Some(d) => {
                let _ = writeln!(
                    text,
                    "{:<16} {:<21} {:<18} {:<21} {:>9}  {} ({} records, false alarms <= {} per drive)",
                    v.vehicle,
                    d.classification.to_string(),
                    d.place(),
                    d.since,
                    d.vehicle_z_over_limit
                        .map_or("-".to_string(), |z| format!("{z:.2}")),
                    d.drive,
                    d.n_records,
                    d.false_alarm_rate
                );
                if let Some(f) = &v.earlier_flag {
                    let _ = writeln!(text, "{:<16} {}", "", earlier_flag_line(f));
                }
            }
            // Records checked one by one only: the latest one's verdict, so that a flagged
            // record is not hidden behind "no drive".
            None => match v.last_checks.first() {
                Some((file, class, _)) => {
                    let _ = writeln!(
                        text,
                        "{:<16} no drive checked yet; latest record checked: {class} ({file})",
                        v.vehicle
                    );
                }
                None => {
                    let _ = writeln!(text, "{:<16} no drive checked yet", v.vehicle);
                }
            },
        }
    }
    text.push_str(&held_out_fleet_line(st));
    text.push('\n');
    text.push('\n');
    for v in st {
        let _ = writeln!(
            text,
            "vehicle {}: {} nominal, {} test records, baseline {}",
            v.vehicle,
            v.n_nominal,
            v.n_test,
            v.baseline_version
                .map_or("none".to_string(), |n| format!("version {n}"))
        );
        if let Some(s) = &v.suspension {
            let _ = writeln!(text, "  {s}");
        }
        if let Some(h) = &v.held_out {
            let _ = writeln!(
                text,
                "  baseline's nominal drives, each checked against the other nominal records: {} of {} flagged",
                h.flagged, h.drives
            );
        }
        if !v.drives.is_empty() {
            text.push_str("  drives, newest first (when driven; when checked where the records' times are unknown):\n");
            text.push_str("    when                         verdict  corner, part    drive               evidence\n");
            for d in &v.drives {
                // The drive (a date, a folder or a given id) padded, then two spaces: a long
                // folder still stands apart from the evidence.
                let _ = writeln!(
                    text,
                    "    {:<28} {:<8} {:<15} {:<18}  {}",
                    d.when(),
                    d.classification.to_string(),
                    d.place(),
                    d.drive,
                    or_dash(&d.summary)
                );
            }
            text.push_str("  records, newest first:\n");
        }
        for (file, class, summary) in &v.last_checks {
            let _ = writeln!(text, "  {file:<31} {:<8} {summary}", class.to_string());
        }
    }
    text
}

/// The losses at which a drive's suspension fit reaches its limit per corner, one line (e.g.
/// "this drive's fit reaches its limit at a loss of about: springs FL 31 %, ...; dampers ...");
/// `None` when no score gives one ([`crate::suspension::CornerScore::smallest_flagged_loss`]).
pub fn smallest_losses_line(s: &crate::suspension::DriveSuspension) -> Option<String> {
    use crate::suspension::Part;
    let part = |p: Part| -> Option<String> {
        let losses: Vec<Option<f64>> = crate::suspension::CORNERS
            .iter()
            .map(|c| {
                s.scores
                    .iter()
                    .find(|x| x.corner == *c && x.part == p)
                    .and_then(|x| x.smallest_flagged_loss(s.limit))
            })
            .collect();
        losses.iter().any(Option::is_some).then(|| {
            crate::suspension::CORNERS
                .iter()
                .zip(&losses)
                .map(|(c, l)| match l {
                    Some(l) => format!("{c} {:.0} %", 100.0 * l),
                    None => format!("{c} -"),
                })
                .collect::<Vec<_>>()
                .join(", ")
        })
    };
    let (springs, dampers) = (part(Part::Spring)?, part(Part::Damper)?);
    Some(format!(
        "this drive's fit reaches its limit at a loss of about: springs {springs}; dampers {dampers} (a loss of that size is flagged on about half of such drives, a smaller one seldom; a spring's slow loss is also judged over the last {} drives)",
        crate::suspension::TREND_DRIVES
    ))
}

/// A vehicle fault found on an earlier drive and not on the latest, one line: which drive, how
/// many drives since, and how many of the baseline's drives were flagged.
pub fn earlier_flag_line(f: &EarlierFlag) -> String {
    let d = &f.drive;
    format!(
        "earlier drive flagged {} ({}): drive {} ({}): {}; not on the {} drive(s) after it; {} of {} drives against baseline version {} flagged (a fault near the limits is not found on every drive: it stays listed until a new baseline)",
        d.classification,
        d.place(),
        d.drive,
        match &d.driven {
            Some(t) => format!("driven {t}"),
            None => format!("checked {}", d.checked),
        },
        or_dash(&d.summary),
        f.later_drives,
        f.flagged_drives,
        f.baseline_drives,
        d.model_version
    )
}

/// The note `fleet check` adds after a drive when an earlier drive against the same baseline
/// was flagged and the vehicle's latest drive is not ([`EarlierFlag`]); empty otherwise.
pub fn earlier_flag_note(f: Option<&EarlierFlag>) -> String {
    f.map_or(String::new(), |f| {
        format!("  note: {}\n", earlier_flag_line(f))
    })
}

/// The fleet's measured false-alarm rate per drive, one line: the baselines' nominal drives held
/// out, summed over the vehicles, with the one-sided upper bound of the rate they measure
/// ([`HELD_OUT_CONFIDENCE`]), or that none was held out yet.
pub fn held_out_fleet_line(st: &[VehicleStatus]) -> String {
    let (mut drives, mut flagged, mut vehicles) = (0, 0, 0);
    for h in st.iter().filter_map(|v| v.held_out) {
        drives += h.drives;
        flagged += h.flagged;
        vehicles += 1;
    }
    match crate::stats::rate_upper_bound(flagged, drives, HELD_OUT_CONFIDENCE) {
        Some(bound) => format!(
            "false alarms per drive, measured: {flagged} of {drives} healthy nominal drives of {vehicles} vehicle(s) flagged when held out of their baseline, a rate of at most {:.1} % ({:.0} % upper bound; the stated rate, a bound, is in each drive's row)",
            100.0 * bound,
            100.0 * HELD_OUT_CONFIDENCE
        ),
        None => "false alarms per drive, measured: not yet: no baseline has nominal records of two drives (days, else folders), so the rate per drive is the stated bound only".to_string(),
    }
}

/// The confidence of the upper bound on the measured false-alarm rate per drive.
pub const HELD_OUT_CONFIDENCE: f64 = 0.95;

fn or_dash(s: &str) -> &str {
    if s.is_empty() {
        "-"
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(file: &str, id: i64, already: bool, notes: &[&str]) -> Ingested {
        Ingested {
            file: file.into(),
            record_id: id,
            already_stored: already,
            notes: notes.iter().map(|n| n.to_string()).collect(),
        }
    }

    #[test]
    fn a_note_every_new_record_has_is_printed_once_after_the_list() {
        let done = [
            rec("a.csv", 1, false, &["layout", "a's own"]),
            rec("b.csv", 2, false, &["layout"]),
            rec("c.csv", 3, true, &["layout"]),
            rec("d.csv", 4, true, &[]),
        ];
        let t = ingest_text(&done, "bus1", Condition::Nominal);
        assert_eq!(
            t,
            "a.csv: stored as nominal record 1 of vehicle bus1\n  note: a's own\n\
             b.csv: stored as nominal record 2 of vehicle bus1\n\
             c.csv: already stored for vehicle bus1 (record 3)\n  note: layout\n\
             d.csv: already stored for vehicle bus1 (record 4), nothing to do\n\
             note (every one of the 2 records stored): layout\n"
        );
    }

    #[test]
    fn a_single_new_record_keeps_its_notes_under_it() {
        let done = [rec("a.csv", 7, false, &["layout"])];
        let t = ingest_text(&done, "bus1", Condition::Test);
        assert_eq!(
            t,
            "a.csv: stored as test record 7 of vehicle bus1\n  note: layout\n"
        );
    }

    /// `fleet check`: a drive scored against a reference of normal drives names them under its
    /// verdict; one scored against the baseline alone (or without a fit) has no such note.
    #[test]
    fn the_reference_drives_are_named_under_the_drive() {
        use crate::model::Assessment;
        let fit = crate::suspension::CornerFit::even_for_tests();
        let drive = |reference: &[&str]| Drive {
            drive: "d9".into(),
            model_version: 1,
            records: vec!["a.csv".into(), "b.csv".into(), "c.csv".into()],
            start_unix_s: None,
            corner: None,
            false_alarm_rate: 0.02,
            assessment: Assessment::normal_for_tests(),
            suspension: Some(crate::suspension::DriveSuspension {
                fit: fit.clone(),
                scores: vec![],
                limit: 3.23,
                trend: None,
                reference_drives: reference.iter().map(|d| d.to_string()).collect(),
            }),
            in_baseline: vec![],
        };
        let note = |d: Drive| -> Option<String> {
            check_text("bus1", 1, &[], &[d])
                .lines()
                .find(|l| l.contains("pooled with"))
                .map(String::from)
        };
        assert_eq!(
            note(drive(&["d1", "d2"])).as_deref(),
            Some("  note: suspension fit scored against the baseline's fit pooled with the vehicle's first 2 normal drive(s): d1, d2")
        );
        assert_eq!(note(drive(&[])), None);
    }

    /// `fleet check`: a drive with a suspension fit says at which loss per corner its fit
    /// reaches the limit; a corner whose score gives none shows a dash, and scores without `t`
    /// and `df` (stored before them) give no line.
    #[test]
    fn a_drive_says_which_losses_its_fit_would_flag() {
        use crate::suspension::{CornerScore, DriveSuspension, Part, CORNERS};
        // ln(0.95) over t = -1: a standard deviation of 0.0513; at limit 3 with df 1e6 the
        // loss is 1 - exp(-3.0000075 * 0.0513) = 14.26 % (scipy 1.14.1, stats.t.ppf).
        let score = |corner, part, t: Option<f64>| CornerScore {
            corner,
            part,
            value: 0.95,
            centre: 1.0,
            z: -1.0,
            t,
            df: t.map(|_| 1e6),
        };
        let mut scores: Vec<CornerScore> = CORNERS
            .iter()
            .flat_map(|&c| {
                [
                    score(c, Part::Spring, Some(-1.0)),
                    score(c, Part::Damper, Some(-1.0)),
                ]
            })
            .collect();
        scores[7] = score(CORNERS[3], Part::Damper, None);
        let s = DriveSuspension {
            fit: crate::suspension::CornerFit::even_for_tests(),
            scores,
            limit: 3.0,
            trend: None,
            reference_drives: vec![],
        };
        assert_eq!(
            smallest_losses_line(&s).as_deref(),
            Some("this drive's fit reaches its limit at a loss of about: springs FL 14 %, FR 14 %, RL 14 %, RR 14 %; dampers FL 14 %, FR 14 %, RL 14 %, RR - (a loss of that size is flagged on about half of such drives, a smaller one seldom; a spring's slow loss is also judged over the last 3 drives)")
        );
        let old = DriveSuspension {
            scores: s
                .scores
                .iter()
                .map(|x| CornerScore {
                    t: None,
                    df: None,
                    ..x.clone()
                })
                .collect(),
            ..s
        };
        assert_eq!(smallest_losses_line(&old), None);
    }

    /// `fleet check`: records that form no drive (too few, or a day of too few) are named in a
    /// note, so that their per-record verdicts do not pass for a drive's; records in a drive
    /// and a copy given twice are not.
    #[test]
    fn records_in_no_drive_are_named() {
        use crate::model::Assessment;
        let mut assessment = Assessment::normal_for_tests();
        assessment.scores.vehicle_max_abs_z = 1.0;
        assessment.scores.n_vehicle = 4;
        assessment.scores.n_excitation = 1;
        let checked = |file: &str, same_as: Option<&str>| Checked {
            file: file.into(),
            record_id: 1,
            model_version: 1,
            assessment: assessment.clone(),
            in_baseline: None,
            same_as: same_as.map(String::from),
        };
        let drive = |records: &[&str]| Drive {
            drive: "2026-11-27".into(),
            model_version: 1,
            records: records.iter().map(|r| r.to_string()).collect(),
            start_unix_s: None,
            corner: None,
            false_alarm_rate: 0.01,
            assessment: assessment.clone(),
            suspension: None,
            in_baseline: vec![],
        };
        let note = |out: &[Checked], drives: &[Drive]| -> Option<String> {
            check_text("bus1", 1, out, drives)
                .lines()
                .find(|l| l.contains("in no drive"))
                .map(String::from)
        };
        // One record alone.
        let one = [checked("today/a.csv", None)];
        assert_eq!(
            note(&one, &[]).as_deref(),
            Some(
                "note: today/a.csv is in no drive: a drive needs at least 3 records (of one day, \
                 where the records' starts are known); a single record's verdict flags a healthy \
                 vehicle more often than a drive's"
            )
        );
        // A day of three records forms a drive; the next day's two records do not; a copy of
        // a record of the drive is no loose record.
        let out = [
            checked("d1/a.csv", None),
            checked("d1/b.csv", None),
            checked("d1/c.csv", None),
            checked("d1/c2.csv", Some("d1/c.csv")),
            checked("d2/a.csv", None),
            checked("d2/b.csv", None),
        ];
        let drives = [drive(&["d1/a.csv", "d1/b.csv", "d1/c.csv"])];
        let n = note(&out, &drives).unwrap_or_default();
        assert!(
            n.starts_with("note: 2 records are in no drive (d2/a.csv, d2/b.csv): "),
            "{n}"
        );
        // Every record in a drive: no note.
        assert_eq!(note(&out[..4], &drives), None);
        // A drive whose vehicle has no model file: its verdict line is followed by why its
        // suspension was not fitted.
        let mut bare = drive(&["d1/a.csv", "d1/b.csv", "d1/c.csv"]);
        bare.assessment.missing = vec![crate::fleet::NO_MODEL_FILE.to_string()];
        let t = check_text("bus1", 1, &out[..4], &[bare]);
        let at = t.lines().position(|l| l.starts_with("drive 2026-11-27"));
        assert_eq!(
            at.and_then(|i| t.lines().nth(i + 1)),
            Some(format!("  note: {}", crate::fleet::NO_MODEL_FILE).as_str()),
            "{t}"
        );
    }

    /// `fleet status` of a vehicle whose records were checked one by one only: its row says
    /// so and gives the latest record's verdict; without any check, only that no drive was.
    #[test]
    fn a_vehicle_without_drives_shows_its_latest_record_check() {
        let v = |last_checks: Vec<(String, Classification, String)>| VehicleStatus {
            vehicle: "bus-017".into(),
            n_nominal: 16,
            n_test: last_checks.len(),
            baseline_version: Some(1),
            last_checks,
            latest_drive: None,
            drives: vec![],
            suspension: None,
            held_out: None,
            earlier_flag: None,
        };
        let checked = v(vec![
            (
                "today/rec02.csv".into(),
                Classification::Vehicle,
                "RL: level vs FL 8-20 Hz +33 %".into(),
            ),
            (
                "today/rec01.csv".into(),
                Classification::Normal,
                String::new(),
            ),
        ]);
        let text = status_text(&[checked]);
        assert_eq!(
            text.lines().nth(1),
            Some("bus-017          no drive checked yet; latest record checked: vehicle (today/rec02.csv)"),
            "{text}"
        );
        assert!(status_text(&[]).starts_with("no vehicle in the store yet"));
        let text = status_text(&[v(vec![])]);
        assert_eq!(
            text.lines().nth(1),
            Some("bus-017          no drive checked yet"),
            "{text}"
        );
    }

    /// The status' drive timeline: a drive named by a long folder stays apart from its
    /// evidence, and a drive without evidence shows a dash.
    #[test]
    fn the_drive_timeline_keeps_the_drive_apart_from_its_evidence() {
        use crate::store::DriveStatus;
        let drive = |name: &str, class: Classification, summary: &str| DriveStatus {
            drive: name.into(),
            checked: "2026-11-28T02:30:12Z".into(),
            classification: class,
            corner: None,
            component: None,
            summary: summary.into(),
            vehicle_z_over_limit: None,
            false_alarm_rate: 0.01,
            n_records: 8,
            driven: None,
            since: "2026-11-28T02:30:12Z".into(),
            model_version: 1,
        };
        let long = "/data/fleet/bus-017/2026-11-26";
        let v = VehicleStatus {
            vehicle: "bus-017".into(),
            n_nominal: 16,
            n_test: 16,
            baseline_version: Some(1),
            last_checks: vec![],
            latest_drive: None,
            drives: vec![
                drive(
                    long,
                    Classification::Vehicle,
                    "FR: level vs RR 8-20 Hz +35 %",
                ),
                drive("today", Classification::Normal, ""),
            ],
            suspension: None,
            held_out: None,
            earlier_flag: None,
        };
        let text = status_text(&[v]);
        let lines: Vec<&str> = text.lines().collect();
        let at = |needle: &str| {
            lines
                .iter()
                .find(|l| l.contains(needle))
                .copied()
                .unwrap_or_else(|| panic!("no line with {needle}: {text}"))
        };
        assert!(
            at(long).ends_with(&format!("{long}  FR: level vs RR 8-20 Hz +35 %")),
            "{text}"
        );
        let today = at(" today ");
        assert!(today.ends_with("today               -"), "{text}");
        // The header's columns stand over the rows'.
        let header = at("evidence");
        assert_eq!(header.find("drive"), today.find("today"), "{text}");
        assert_eq!(header.find("verdict"), today.find("normal"), "{text}");
    }

    /// `fleet status` sums the baselines' held-out nominal drives over the fleet and bounds the
    /// false-alarm rate per drive they measure; without any, it says the rate is only stated.
    #[test]
    fn the_fleets_held_out_drives_bound_its_false_alarm_rate() {
        let v = |name: &str, held_out| VehicleStatus {
            vehicle: name.into(),
            n_nominal: 16,
            n_test: 0,
            baseline_version: Some(1),
            last_checks: vec![],
            latest_drive: None,
            drives: vec![],
            suspension: None,
            held_out,
            earlier_flag: None,
        };
        let count = |drives, flagged| Some(crate::store::HeldOutCount { drives, flagged });
        let text = status_text(&[v("a", count(2, 0)), v("b", count(3, 1)), v("c", None)]);
        // 1 of 5: scipy.stats.beta.ppf(0.95, 2, 4) = 0.6574.
        assert!(
            text.contains("false alarms per drive, measured: 1 of 5 healthy nominal drives of 2 vehicle(s) flagged when held out of their baseline, a rate of at most 65.7 % (95 % upper bound; the stated rate, a bound, is in each drive's row)"),
            "{text}"
        );
        assert!(
            text.contains("vehicle b: 16 nominal, 0 test records, baseline version 1\n  baseline's nominal drives, each checked against the other nominal records: 1 of 3 flagged"),
            "{text}"
        );
        let text = status_text(&[v("c", None)]);
        assert!(
            text.contains("false alarms per drive, measured: not yet"),
            "{text}"
        );
    }

    /// A fault found on an earlier drive and not on the latest stays in sight: the newest
    /// flagged drive against the latest drive's baseline, the drives after it, and how many of
    /// that baseline's drives were flagged; none when the latest is flagged itself or the
    /// flagged drive was against an earlier baseline (a new one after a repair clears it).
    #[test]
    fn an_earlier_flagged_drive_stays_in_the_status() {
        use crate::store::{DriveStatus, EarlierFlag};
        let drive = |name: &str, class: Classification, version: i64| DriveStatus {
            drive: name.into(),
            checked: format!("2026-11-2{}T08:00:00Z", name.len()),
            classification: class,
            corner: (class == Classification::Vehicle).then(|| "FR".to_string()),
            component: (class == Classification::Vehicle)
                .then_some(crate::model::Component::Spring),
            summary: if class == Classification::Vehicle {
                "FR: spring (fitted) vs the other corners -29 %".into()
            } else {
                String::new()
            },
            vehicle_z_over_limit: None,
            false_alarm_rate: 0.01,
            n_records: 8,
            driven: None,
            since: "2026-11-28T02:30:12Z".into(),
            model_version: version,
        };
        use Classification::{Both, Normal, Road, Vehicle};
        // Newest first.
        let drives = [
            drive("d4", Normal, 2),
            drive("d33", Road, 2),
            drive("d222", Vehicle, 2),
            drive("d1111", Normal, 2),
            drive("d0", Vehicle, 1),
        ];
        let f = EarlierFlag::of(&drives).expect("an earlier flag");
        assert_eq!(f.drive.drive, "d222");
        assert_eq!(
            (f.later_drives, f.flagged_drives, f.baseline_drives),
            (2, 1, 4)
        );
        assert!(
            EarlierFlag::of(&drives[3..]).is_none(),
            "d0 was against baseline 1"
        );
        assert!(
            EarlierFlag::of(&drives[2..]).is_none(),
            "the latest is flagged"
        );
        assert!(EarlierFlag::of(&[]).is_none());
        let both = [drive("a", Normal, 1), drive("b", Both, 1)];
        assert_eq!(EarlierFlag::of(&both).map(|f| f.later_drives), Some(1));
        let v = VehicleStatus {
            vehicle: "bus-017".into(),
            n_nominal: 16,
            n_test: 40,
            baseline_version: Some(2),
            last_checks: vec![],
            latest_drive: Some(drives[0].clone()),
            drives: drives.to_vec(),
            suspension: None,
            held_out: None,
            earlier_flag: Some(f),
        };
        let text = status_text(&[v]);
        assert_eq!(
            text.lines().nth(2),
            Some("                 earlier drive flagged vehicle (FR spring): drive d222 (checked 2026-11-24T08:00:00Z): FR: spring (fitted) vs the other corners -29 %; not on the 2 drive(s) after it; 1 of 4 drives against baseline version 2 flagged (a fault near the limits is not found on every drive: it stays listed until a new baseline)"),
            "{text}"
        );
    }
}
