//! `vibmode fleet check` per drive: the given records of a vehicle classified together (the
//! median of every feature over them), the JSON's `drives` beside its `records`, and the drive's
//! bad input (too few records, records of another vehicle, another channel layout): one line,
//! exit code 2, nothing stored; a record stored for another vehicle is ingested with a note.

use crate::common;

use common::{fails_with, fleet_args, fleet_ingest, ok, simulate_csv};

/// `vibmode fleet check --json -` of `files` for `bus-1` in the store `db`, as one drive `drive`
/// when given.
fn check_json<S: AsRef<str>>(db: &str, drive: Option<&str>, files: &[S]) -> serde_json::Value {
    let mut args = vec!["fleet", "check", "--db", db, "--vehicle", "bus-1", "-q"];
    if let Some(id) = drive {
        args.extend(["--drive", id]);
    }
    args.extend(["--json", "-"]);
    args.extend(files.iter().map(AsRef::as_ref));
    serde_json::from_slice(&ok(&args).stdout).unwrap()
}

/// Test records the store holds for `vehicle` (from `fleet status`).
fn n_test(db: &str, vehicle: &str) -> usize {
    let o = ok(&["fleet", "status", "--db", db]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    let line = text
        .lines()
        .find(|l| l.starts_with(&format!("vehicle {vehicle}:")))
        .unwrap_or_else(|| panic!("no {vehicle} in {text}"));
    let n = line
        .split(", ")
        .find(|p| p.ends_with("test records"))
        .and_then(|p| p.split_whitespace().next())
        .and_then(|n| n.parse().ok());
    n.unwrap_or_else(|| panic!("no test count in {line}"))
}

/// A store in `dir` with vehicle `bus-1`: 6 nominal records (road B, 30 km/h, seed 11) and
/// its baseline. Returns the store's path.
fn store_with_baseline(dir: &std::path::Path) -> String {
    let db = dir.join("fleet.db").to_str().unwrap().to_string();
    ok(&["fleet", "init", "--db", &db]);
    let nominal = simulate_csv(&dir.join("nominal"), "B", "30", "11", "6");
    let mut args = vec!["fleet", "ingest", "--db", &db, "--vehicle", "bus-1", "-q"];
    args.extend(nominal.iter().map(String::as_str));
    ok(&args);
    ok(&["fleet", "baseline", "--db", &db, "--vehicle", "bus-1"]);
    db
}

#[test]
fn a_drive_is_classified_from_its_records_and_bad_drives_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let db = store_with_baseline(d.path());
    let db = db.as_str();

    // A healthy drive of 4 records: one drive, its records listed, the per-record verdicts kept.
    let test = simulate_csv(&d.path().join("test"), "B", "30", "21", "4");
    let v = check_json(db, Some("2026-11-25"), &test);
    assert_eq!(v["records"].as_array().unwrap().len(), 4, "{v}");
    let drives = v["drives"].as_array().unwrap();
    assert_eq!(drives.len(), 1, "{v}");
    let dr = &drives[0];
    assert_eq!(dr["drive"], "2026-11-25");
    assert_eq!(dr["records"].as_array().unwrap().len(), 4);
    assert_eq!(dr["false_alarm_rate"], 0.01);
    assert_eq!(dr["classification"], "normal", "{dr}");
    // No vehicle evidence: no component named.
    assert!(dr.get("component").is_none(), "{dr}");
    // No model file registered: the drive says what it could not look at (not a silent normal).
    let missing = dr["missing"].as_array().unwrap();
    assert!(
        missing
            .iter()
            .any(|m| m.as_str() == Some(vibmode_fleet::fleet::NO_MODEL_FILE)),
        "{dr}"
    );
    assert_eq!(n_test(db, "bus-1"), 4);
    let drives = || {
        vibmode_fleet::Store::open(std::path::Path::new(db))
            .unwrap()
            .drives("bus-1")
            .unwrap()
    };
    assert_eq!(
        drives(),
        vec![("2026-11-25".to_string(), "normal".to_string(), 4)]
    );

    // Without --drive: 3 or more records are a drive named by their folder; fewer, no drive.
    let folder = d.path().join("test").to_string_lossy().to_string();
    let v = check_json(db, None, &test[..3]);
    assert_eq!(v["drives"][0]["drive"], folder.as_str(), "{v}");
    let v = check_json(db, None, &test[..1]);
    assert_eq!(v["drives"].as_array().unwrap().len(), 0, "{v}");
    assert_eq!(drives().len(), 2);
    assert_eq!(drives()[1].0, folder);

    // The status leads with each vehicle's latest drive verdict and since when (the first
    // drive of the latest run of equal verdicts: both drives are normal).
    let st = vibmode_fleet::Store::open(std::path::Path::new(db))
        .unwrap()
        .status(10)
        .unwrap();
    let v1 = st.iter().find(|v| v.vehicle == "bus-1").unwrap();
    let latest = v1.latest_drive.as_ref().unwrap();
    assert_eq!(latest.drive, folder);
    assert_eq!(latest.classification.to_string(), "normal");
    assert_eq!(latest.n_records, 3);
    assert_eq!(v1.drives.len(), 2);
    assert_eq!(v1.drives[1].drive, "2026-11-25");
    assert_eq!(
        latest.since, v1.drives[1].checked,
        "since the first normal drive"
    );
    let o = ok(&["fleet", "status", "--db", db]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    let row = text.lines().nth(1).unwrap_or("");
    assert!(
        row.starts_with("bus-1") && row.contains("normal") && row.contains(&latest.since),
        "{text}"
    );
    // And that the vehicle's springs and dampers are not fitted: it has no model file.
    assert!(
        text.contains(&format!(
            "  {}\n",
            vibmode_fleet::store::NO_MODEL_FILE_STATUS
        )),
        "{text}"
    );

    // Too few records for a named drive: refused before anything is read or stored.
    let more = simulate_csv(&d.path().join("more"), "B", "30", "31", "3");
    fails_with(
        &fleet_args(
            "check",
            db,
            "bus-1",
            &["--drive", "day-2", &more[0], &more[1]],
        ),
        &["drive 'day-2'", "2 record(s)", "at least 3"],
    );
    assert_eq!(n_test(db, "bus-1"), 4);

    // A record of another vehicle in the drive.
    ok(&fleet_args("ingest", db, "bus-2", &["-q", &more[2]]));
    fails_with(
        &fleet_args(
            "check",
            db,
            "bus-1",
            &["--drive", "day-2", &more[0], &more[1], &more[2]],
        ),
        &["drive 'day-2'", "vehicle 'bus-2'", "record_"],
    );
    assert_eq!(n_test(db, "bus-1"), 4);
    // The same without a drive id: the three records are the drive of their folder.
    let folder = d.path().join("more").to_string_lossy().to_string();
    fails_with(
        &fleet_args("check", db, "bus-1", &[&more[0], &more[1], &more[2]]),
        &[&format!("drive '{folder}'"), "vehicle 'bus-2'", "record_"],
    );
    // Given from two folders, they are `all given records`.
    let elsewhere = d.path().join("elsewhere.csv").to_string_lossy().to_string();
    std::fs::copy(&more[2], &elsewhere).unwrap();
    fails_with(
        &fleet_args("check", db, "bus-1", &[&more[0], &more[1], &elsewhere]),
        &[
            "drive 'all given records'",
            "vehicle 'bus-2'",
            "elsewhere.csv",
        ],
    );
    assert_eq!(n_test(db, "bus-1"), 4);
    // Alone, it is checked (no drive).
    ok(&fleet_args("check", db, "bus-1", &["-q", &more[2]]));
    assert_eq!(n_test(db, "bus-1"), 5);
    // Stored for a third vehicle, it is stored with a note naming the two that have it.
    let o = ok(&fleet_args("ingest", db, "bus-3", &["-q", &more[2]]));
    let text = common::stderr(&o);
    assert!(
        text.contains("note: its content is stored for vehicle 'bus-1', 'bus-2' too: a record is of one vehicle"),
        "{text}"
    );
    // Given again, it is already stored: no note.
    let o = ok(&fleet_args("ingest", db, "bus-3", &["-q", &more[2]]));
    let text = String::from_utf8_lossy(&o.stdout).to_string() + &common::stderr(&o);
    assert!(!text.contains("note"), "{text}");

    // A record with another channel layout (a sprung channel missing) in the drive.
    let text = std::fs::read_to_string(&more[1]).unwrap();
    let cut: String = text
        .lines()
        .map(|l| {
            let mut cols: Vec<&str> = l.split(',').collect();
            cols.pop();
            cols.join(",") + "\n"
        })
        .collect();
    let other = d.path().join("other_layout.csv");
    std::fs::write(&other, cut).unwrap();
    fails_with(
        &fleet_args(
            "check",
            db,
            "bus-1",
            &[
                "--drive",
                "day-2",
                &more[0],
                other.to_str().unwrap(),
                &more[1],
            ],
        ),
        &[
            "other_layout.csv",
            "has channels",
            "baseline of vehicle 'bus-1'",
        ],
    );
    assert_eq!(n_test(db, "bus-1"), 5);
    assert_eq!(drives().len(), 2, "no drive stored by a refused check");
}

/// `path`'s time column (seconds from 0) rewritten as date-times from `day` `hh:mm:00` (UTC), as
/// pandas writes a `DatetimeIndex`.
fn dated(path: &str, day: &str, hh: u32, mm: u32) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("time"), "{header}");
    let mut out = format!("{header}\n");
    for l in lines {
        let (t, rest) = l.split_once(',').unwrap();
        let us = (t.parse::<f64>().unwrap() * 1e6).round() as u64;
        out.push_str(&format!(
            "{day} {hh:02}:{mm:02}:{:02}.{:06},{rest}\n",
            us / 1_000_000,
            us % 1_000_000
        ));
    }
    let p = format!("{path}.{day}.csv");
    std::fs::write(&p, out).unwrap();
    p
}

/// Without `--drive`, records whose time column holds date-times are grouped by their UTC day:
/// one drive per day with 3 records or more (named by the date), a day with fewer checked
/// record by record only; where a record's start is unknown, all are one drive, named by the
/// folder they lie in.
#[test]
fn records_with_dates_form_one_drive_per_day() {
    let d = tempfile::tempdir().unwrap();
    let db = store_with_baseline(d.path());
    let db = db.as_str();
    let test = simulate_csv(&d.path().join("test"), "B", "30", "21", "7");
    // Given out of order: 26th, 25th, 26th, 27th (alone), 25th, 26th, 25th (23:59 UTC).
    let days = [
        ("2026-11-26", 7),
        ("2026-11-25", 8),
        ("2026-11-26", 9),
        ("2026-11-27", 6),
        ("2026-11-25", 10),
        ("2026-11-26", 11),
        ("2026-11-25", 23),
    ];
    let files: Vec<String> = test
        .iter()
        .zip(days)
        .enumerate()
        .map(|(i, (f, (day, hh)))| dated(f, day, hh, 59 * (i as u32 % 2)))
        .collect();
    let v = check_json(db, None, &files);
    assert_eq!(v["records"].as_array().unwrap().len(), 7, "{v}");
    let drives: Vec<(String, Vec<String>)> = v["drives"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| {
            let recs = d["records"].as_array().unwrap();
            let recs = recs.iter().map(|r| r.as_str().unwrap().to_string());
            (d["drive"].as_str().unwrap().to_string(), recs.collect())
        })
        .collect();
    let names = |idx: &[usize]| idx.iter().map(|&i| files[i].clone()).collect::<Vec<_>>();
    assert_eq!(
        drives,
        vec![
            ("2026-11-25".to_string(), names(&[1, 4, 6])),
            ("2026-11-26".to_string(), names(&[0, 2, 5])),
        ]
    );
    let stored = vibmode_fleet::Store::open(std::path::Path::new(db))
        .unwrap()
        .drives("bus-1")
        .unwrap();
    let mut ids: Vec<(String, usize)> = stored.into_iter().map(|(d, _, n)| (d, n)).collect();
    ids.sort();
    assert_eq!(
        ids,
        vec![("2026-11-25".to_string(), 3), ("2026-11-26".to_string(), 3)]
    );
    // The drives are ordered by when they were driven (their earliest record's start), and
    // a drive of an earlier day checked later takes its place in the timeline: since when is
    // the day driven, not the time checked.
    let early: Vec<String> = test[..3]
        .iter()
        .enumerate()
        .map(|(i, f)| dated(f, "2026-11-20", 14 - i as u32, 30))
        .collect();
    let v = check_json(db, None, &early);
    assert_eq!(v["drives"][0]["drive"], "2026-11-20", "{v}");
    let status = || {
        let st = vibmode_fleet::Store::open(std::path::Path::new(db))
            .unwrap()
            .status(10)
            .unwrap();
        st.into_iter().find(|v| v.vehicle == "bus-1").unwrap()
    };
    let v1 = status();
    let timeline: Vec<(&str, Option<&str>)> = v1
        .drives
        .iter()
        .map(|d| (d.drive.as_str(), d.driven.as_deref()))
        .collect();
    assert_eq!(
        timeline,
        vec![
            ("2026-11-26", Some("2026-11-26T07:00:00Z")),
            ("2026-11-25", Some("2026-11-25T08:59:00Z")),
            ("2026-11-20", Some("2026-11-20T12:30:00Z")),
        ],
        "newest driven first"
    );
    for d in &v1.drives {
        assert_eq!(d.classification.to_string(), "normal", "{}", d.summary);
    }
    let latest = v1.latest_drive.as_ref().unwrap();
    assert_eq!(latest.drive, "2026-11-26");
    assert_eq!(
        latest.since, "2026-11-20T12:30:00Z",
        "normal since the 20th"
    );
    let o = ok(&["fleet", "status", "--db", db]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        text.lines()
            .nth(1)
            .unwrap_or("")
            .contains("2026-11-20T12:30:00Z"),
        "{text}"
    );

    // One record without dates among them: the start of every record is not known.
    let mut mixed: Vec<&str> = files[..3].iter().map(String::as_str).collect();
    mixed.push(&test[3]);
    let v = check_json(db, None, &mixed);
    let drives = v["drives"].as_array().unwrap();
    assert_eq!(drives.len(), 1, "{v}");
    let folder = d.path().join("test").to_string_lossy().to_string();
    assert_eq!(
        drives[0]["drive"],
        folder.as_str(),
        "named by the records' folder"
    );
    assert_eq!(drives[0]["records"].as_array().unwrap().len(), 4);
    // That drive has no time of its own: it is placed by when it was checked (now, after the
    // dated ones), and shows that time.
    let v1 = status();
    let latest = v1.latest_drive.as_ref().unwrap();
    assert_eq!(latest.drive, folder);
    assert_eq!(latest.driven, None);
    assert_eq!(latest.when(), format!("checked {}", latest.checked));
    assert_eq!(v1.drives.len(), 4);
    assert_eq!(v1.drives[1].drive, "2026-11-26");
}

/// A record the baseline was built from, checked again (here a copy under another name), is
/// named as such, on its row and on its drive: its check is not independent of the baseline.
/// A nominal record stored after the baseline was built is not.
#[test]
fn records_of_the_baseline_in_a_checked_drive_are_named() {
    let d = tempfile::tempdir().unwrap();
    let db = store_with_baseline(d.path());
    let db = db.as_str();
    let nominal = simulate_csv(&d.path().join("nominal"), "B", "30", "11", "6");
    // Stored after the baseline: nominal, but not in model set version 1.
    let later = simulate_csv(&d.path().join("later"), "B", "30", "31", "1");
    fleet_ingest(db, "bus-1", &later);
    let again = d.path().join("again");
    std::fs::create_dir(&again).unwrap();
    let copies: Vec<String> = nominal[..2]
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let to = again.join(format!("copy{i}.csv"));
            std::fs::copy(f, &to).unwrap();
            to.to_string_lossy().to_string()
        })
        .collect();
    let test = simulate_csv(&d.path().join("test"), "B", "30", "41", "2");
    let files: Vec<String> = copies.iter().chain(&later).chain(&test).cloned().collect();
    let json = d.path().join("check.json");
    let mut args = vec!["fleet", "check", "--db", db, "--vehicle", "bus-1", "-q"];
    args.extend(["--json", json.to_str().unwrap()]);
    args.extend(files.iter().map(String::as_str));
    let text = String::from_utf8_lossy(&ok(&args).stdout).to_string();
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let records = v["records"].as_array().unwrap();
    assert_eq!(records.len(), 5, "{v}");
    for (r, f) in records.iter().zip(&files) {
        assert_eq!(r["file"], f.as_str());
        match copies.iter().position(|c| c == f) {
            Some(i) => {
                assert_eq!(r["in_baseline"], nominal[i].as_str(), "{r}");
                assert!(
                    text.contains(&format!(
                        "note: {f} has the content of {}, a record model set version 1 was built from",
                        nominal[i]
                    )),
                    "{text}"
                );
            }
            None => {
                assert!(r.get("in_baseline").is_none(), "{f}: {r}");
                assert!(!text.contains(&format!("note: {f} ")), "{text}");
            }
        }
    }
    let drives = v["drives"].as_array().unwrap();
    assert_eq!(drives.len(), 1, "{v}");
    assert_eq!(drives[0]["in_baseline"], serde_json::json!(copies), "{v}");
    assert!(
        text.contains("note: 2 of the drive's 5 records are records of the baseline"),
        "{text}"
    );
}

/// A file given twice in one check (here a copy under another name) is scored alike and
/// counted once in its drive: a named drive of two distinct records is refused, and the
/// default drive's median is over distinct records.
#[test]
fn a_file_given_twice_counts_once_in_its_drive() {
    let d = tempfile::tempdir().unwrap();
    let db = store_with_baseline(d.path());
    let db = db.as_str();
    let test = simulate_csv(&d.path().join("test"), "B", "30", "51", "3");
    let copy = d.path().join("copy.csv").to_string_lossy().to_string();
    std::fs::copy(&test[0], &copy).unwrap();

    // Three files, two contents: too few for a named drive; nothing stored.
    fails_with(
        &fleet_args(
            "check",
            db,
            "bus-1",
            &["--drive", "day-3", &test[0], &copy, &test[1]],
        ),
        &[
            "drive 'day-3'",
            "2 record(s) of distinct content",
            "at least 3",
        ],
    );
    assert_eq!(n_test(db, "bus-1"), 0);

    // Four files, three contents: the drive holds the three, the copy is named.
    let files = [&test[0], &copy, &test[1], &test[2]];
    let v = check_json(db, None, &files);
    let records = v["records"].as_array().unwrap();
    assert_eq!(records.len(), 4, "{v}");
    assert_eq!(records[1]["file"], copy.as_str());
    assert_eq!(records[1]["same_as"], test[0].as_str(), "{v}");
    for i in [0, 2, 3] {
        assert!(records[i].get("same_as").is_none(), "{}", records[i]);
    }
    assert_eq!(records[1]["classification"], records[0]["classification"]);
    let drives = v["drives"].as_array().unwrap();
    assert_eq!(drives.len(), 1, "{v}");
    assert_eq!(
        drives[0]["records"],
        serde_json::json!([&test[0], &test[1], &test[2]]),
        "{v}"
    );
    // The same files again, all stored now: the copy is still found.
    let v = check_json(db, None, &files);
    assert_eq!(v["records"][1]["same_as"], test[0].as_str(), "{v}");
    assert_eq!(
        v["drives"][0]["records"].as_array().unwrap().len(),
        3,
        "{v}"
    );
}

/// The timeline rows of `fleet status` (the drives, newest first) naming drive `id`.
fn timeline_rows(db: &str, id: &str) -> usize {
    let o = ok(&["fleet", "status", "--db", db]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    text.lines()
        .skip_while(|l| !l.trim_start().starts_with("drives, newest first"))
        .skip(1)
        .take_while(|l| l.starts_with("    "))
        .filter(|l| l.split_whitespace().any(|w| w == id))
        .count()
}

/// The same drive (its name and its records) checked again replaces its stored verdict, so the
/// timeline holds it once (a nightly job run twice); the same records under another name, or
/// another drive between, are other drives.
#[test]
fn the_same_drive_checked_again_is_stored_once() {
    let d = tempfile::tempdir().unwrap();
    let db = store_with_baseline(d.path());
    let db = db.as_str();
    let mon = simulate_csv(&d.path().join("mon"), "B", "30", "61", "3");
    let tue = simulate_csv(&d.path().join("tue"), "B", "30", "62", "3");
    check_json(db, Some("mon"), &mon);
    check_json(db, Some("tue"), &tue);
    let again = check_json(db, Some("mon"), &mon);
    assert_eq!(again["drives"][0]["drive"], "mon", "{again}");
    assert_eq!((timeline_rows(db, "mon"), timeline_rows(db, "tue")), (1, 1));
    check_json(db, Some("mon-2"), &mon);
    assert_eq!(
        (timeline_rows(db, "mon"), timeline_rows(db, "mon-2")),
        (1, 1)
    );
}

/// `fleet baseline` holds each nominal drive out (its folder, as given: the records' starts are
/// not known) and checks it as a drive against a model set of the other nominal records. Two
/// healthy drives of one road and speed: neither is flagged. A drive on a class D road ingested
/// as nominal by mistake is flagged `road` against the others, and the output warns that healthy
/// drives like it will be flagged. One folder: no drive to hold out, and the note says so.
#[test]
fn baseline_drives_are_each_checked_against_the_other_nominal_records() {
    let d = tempfile::tempdir().unwrap();
    let db = d.path().join("fleet.db").to_str().unwrap().to_string();
    ok(&["fleet", "init", "--db", &db]);
    let mon = simulate_csv(&d.path().join("mon"), "B", "30", "71", "5");
    let tue = simulate_csv(&d.path().join("tue"), "B", "30", "72", "5");
    let mut args = vec!["fleet", "ingest", "--db", &db, "--vehicle", "bus-1", "-q"];
    args.extend(mon.iter().chain(&tue).map(String::as_str));
    ok(&args);
    let o = ok(&["fleet", "baseline", "--db", &db, "--vehicle", "bus-1"]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        text.contains("leave-one-drive-out: 2 nominal drive(s), each checked as a drive against a model set of the other nominal records: 0 flagged"),
        "{text}"
    );
    let held: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("  ") && l.contains("records, against 5: "))
        .collect();
    assert_eq!(held.len(), 2, "{text}");
    assert!(
        held[0]
            .trim_start()
            .starts_with(&format!("{}", d.path().join("mon").display())),
        "{text}"
    );
    assert!(held.iter().all(|l| l.contains(": normal")), "{text}");
    assert!(!text.contains("warning:"), "{text}");
    let o = ok(&["fleet", "status", "--db", &db]);
    let status = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        status.contains("false alarms per drive, measured: 0 of 2 healthy nominal drives of 1 vehicle(s) flagged when held out of their baseline, a rate of at most 77.6 % (95 % upper bound"),
        "{status}"
    );

    // A rough-road drive among the nominal ones.
    let rough = simulate_csv(&d.path().join("rough"), "D", "30", "73", "5");
    let mut args = vec!["fleet", "ingest", "--db", &db, "--vehicle", "bus-1", "-q"];
    args.extend(rough.iter().map(String::as_str));
    ok(&args);
    let o = ok(&["fleet", "baseline", "--db", &db, "--vehicle", "bus-1"]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    let line = text
        .lines()
        .find(|l| {
            l.trim_start()
                .starts_with(&format!("{}", d.path().join("rough").display()))
        })
        .unwrap_or_else(|| panic!("no held-out line of the rough drive in {text}"));
    assert!(line.contains("5 records, against 10: road"), "{line}");
    assert!(
        text.contains("healthy nominal drives would be flagged against the other nominal records"),
        "{text}"
    );

    // All nominal records in one folder.
    let d1 = tempfile::tempdir().unwrap();
    let db1 = store_with_baseline(d1.path());
    let o = ok(&["fleet", "baseline", "--db", &db1, "--vehicle", "bus-1"]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        text.contains("note: leave-one-drive-out: not made: the 6 nominal records form one drive"),
        "{text}"
    );
    assert!(!text.contains("leave-one-drive-out: 2"), "{text}");
}

/// A fault found on one drive and not on the next stays in the status' row of the vehicle
/// (a fault near the limits is not found on every drive): the latest `normal` is followed by the
/// earlier flagged drive, until a new baseline; the Python and JSON side get it as
/// `earlier_flag`.
#[test]
fn a_drive_flagged_earlier_stays_in_the_status_until_a_new_baseline() {
    let d = tempfile::tempdir().unwrap();
    let db = store_with_baseline(d.path());
    let db = db.as_str();
    let worn = d.path().join("worn_rl.toml");
    let bus = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/city_bus.toml");
    std::fs::write(
        &worn,
        std::fs::read_to_string(bus).unwrap()
            + "\n[[corner_condition]]\ncorner = \"RL\"\ndamper_factor = 0.5\n",
    )
    .unwrap();
    let files = common::simulate_csv_of(
        worn.to_str().unwrap(),
        &d.path().join("worn"),
        "B",
        "30",
        "21",
        "4",
    );
    let v = check_json(db, Some("day-1"), &files);
    assert_eq!(v["drives"][0]["classification"], "vehicle", "{v}");
    assert_eq!(v["drives"][0]["corner"], "RL", "{v}");
    assert!(v.get("earlier_flag").is_none(), "{v}");
    let status =
        || String::from_utf8_lossy(&ok(&["fleet", "status", "--db", db]).stdout).to_string();
    assert!(!status().contains("earlier drive flagged"), "{}", status());

    let healthy = simulate_csv(&d.path().join("healthy"), "B", "30", "22", "4");
    let v = check_json(db, Some("day-2"), &healthy);
    assert_eq!(v["drives"][0]["classification"], "normal", "{v}");
    // The check says it too, beneath its drive (and its JSON keeps it).
    assert_eq!(v["earlier_flag"]["drive"]["drive"], "day-1", "{v}");
    assert_eq!(v["earlier_flag"]["later_drives"], 1, "{v}");
    let text = status();
    let row = text.lines().nth(1).unwrap_or("");
    let next = text.lines().nth(2).unwrap_or("");
    assert!(row.starts_with("bus-1") && row.contains("normal"), "{text}");
    assert!(
        next.trim_start()
            .starts_with("earlier drive flagged vehicle (RL")
            && next.contains("drive day-1 (checked ")
            && next.contains(
                "not on the 1 drive(s) after it; 1 of 2 drives against baseline version 1 flagged"
            ),
        "{text}"
    );
    let st = vibmode_fleet::Store::open(std::path::Path::new(db))
        .unwrap()
        .status(10)
        .unwrap();
    let f = st[0].earlier_flag.as_ref().expect("earlier_flag");
    assert_eq!((f.drive.drive.as_str(), f.later_drives), ("day-1", 1));
    // The report's verdict row says the same.
    let rep = d.path().join("report");
    ok(&["fleet", "report", "--db", db, "-o", rep.to_str().unwrap()]);
    let page = std::fs::read_to_string(rep.join("index.html")).unwrap();
    assert!(
        page.contains("earlier drive flagged vehicle (RL"),
        "no earlier flag in the report"
    );

    // A new baseline (after a repair): the drives against it only.
    ok(&["fleet", "baseline", "--db", db, "--vehicle", "bus-1"]);
    let again = simulate_csv(&d.path().join("again"), "B", "30", "23", "4");
    let json = d.path().join("day3.json");
    let mut args = common::fleet_args(
        "check",
        db,
        "bus-1",
        &["-q", "--drive", "day-3", "--json", json.to_str().unwrap()],
    );
    args.extend(again.iter().map(String::as_str));
    let o = ok(&args);
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["drives"][0]["classification"], "normal", "{v}");
    assert!(v.get("earlier_flag").is_none(), "{v}");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("day-3") && !text.contains("earlier drive flagged"),
        "{text}"
    );
    assert!(!status().contains("earlier drive flagged"), "{}", status());
}
