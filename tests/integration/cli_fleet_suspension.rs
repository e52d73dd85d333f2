//! `vibmode fleet register`: a vehicle's model file, and the suspension fitted per drive from it
//! (docs/fleet.md, "The suspension fitted per drive"): the baseline fits its nominal records
//! together, each drive its own, and a corner's spring lowered against the other corners is
//! named; bad model files are refused in one line with exit code 2, nothing stored.

use crate::common;

use common::{fails_with, fleet_ingest, ok, simulate_csv, simulate_csv_of};

const CITY_BUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/city_bus.toml");

fn stdout(args: &[&str]) -> String {
    String::from_utf8_lossy(&ok(args).stdout).to_string()
}

/// `fleet register` of `model` for bus-1: its standard output.
fn register(db: &str, model: &str) -> String {
    stdout(&["fleet", "register", "--db", db, "--vehicle", "bus-1", model])
}

/// `fleet check --drive ID --json -` of `files` for bus-1: the drive's verdict.
fn check_drive(db: &str, id: &str, files: &[String]) -> serde_json::Value {
    let mut args = vec![
        "fleet",
        "check",
        "--db",
        db,
        "--vehicle",
        "bus-1",
        "-q",
        "--drive",
        id,
        "--json",
        "-",
    ];
    args.extend(files.iter().map(String::as_str));
    let o = ok(&args);
    // The text (on stderr beside the JSON) says at which losses the drive's fit reaches its
    // limit, per corner, each in 10-100 %.
    let text = String::from_utf8_lossy(&o.stderr);
    let line = text
        .lines()
        .find(|l| l.contains("this drive's fit reaches its limit at a loss of about: springs FL "))
        .unwrap_or_else(|| panic!("no losses line: {text}"));
    let percents: Vec<f64> = line
        .split(" %")
        .filter_map(|p| p.rsplit(' ').next()?.parse().ok())
        .collect();
    assert_eq!(percents.len(), 8, "{line}");
    assert!(
        percents.iter().all(|p| (10.0..=100.0).contains(p)),
        "{line}"
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    v["drives"][0].clone()
}

/// The fit's evidence of a drive: (kind, corner, z).
fn fit_evidence(drive: &serde_json::Value) -> Vec<(String, String, f64)> {
    drive["evidence"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| {
            e["kind"]
                .as_str()
                .is_some_and(|k| k == "spring-fit" || k == "damper-fit")
        })
        .map(|e| {
            (
                e["kind"].as_str().unwrap().to_string(),
                e["corner"].as_str().unwrap_or("").to_string(),
                e["z"].as_f64().unwrap(),
            )
        })
        .collect()
}

/// vibmode's own simulator (city bus, class B at 30 km/h, 200 Hz): 6 nominal records with the
/// model file registered; a healthy drive of 4 records on other seeds gives no fit evidence, a
/// drive of the same bus with the RL spring at 80 % (a `[[corner_condition]]` the registered file
/// does not have) is `vehicle`, RL named first, the spring.
#[test]
fn a_spring_at_80_percent_is_named_by_the_fit_per_drive() {
    let d = tempfile::tempdir().unwrap();
    let db = d.path().join("fleet.db");
    let db = db.to_str().unwrap();
    ok(&["fleet", "init", "--db", db]);
    let out = register(db, CITY_BUS);
    assert!(out.contains("registered"), "{out}");
    let again = register(db, CITY_BUS);
    assert!(again.contains("unchanged"), "{again}");
    let status = stdout(&["fleet", "status", "--db", db]);
    assert!(
        status.contains("model file registered; no baseline yet"),
        "{status}"
    );

    let nominal = simulate_csv(&d.path().join("nominal"), "B", "30", "11", "6");
    fleet_ingest(db, "bus-1", &nominal);
    let base = stdout(&["fleet", "baseline", "--db", db, "--vehicle", "bus-1"]);
    assert!(
        base.contains("suspension fitted to 6 nominal records"),
        "{base}"
    );
    // The limits: Phi^-1(1 - 0.01 / 16) for the drive's 8 tests, Phi^-1(1 - 0.01 / 8) for the trend's 4.
    assert!(
        base.contains(
            "and the springs over the last 3 drives, one-sided limits 3.23 and 3.02 (the trend)"
        ),
        "{base}"
    );
    let status = stdout(&["fleet", "status", "--db", db]);
    assert!(
        status.contains("baseline version 1 fits the suspension (6 nominal records): springs and dampers scored per drive, springs also over the last 3 drives"),
        "{status}"
    );

    let healthy = simulate_csv(&d.path().join("healthy"), "B", "30", "21", "4");
    let dr = check_drive(db, "d", &healthy);
    assert!(fit_evidence(&dr).is_empty(), "{dr}");
    // Every corner's spring and damper score is kept, flagged or not.
    let scores = dr["suspension"]["scores"].as_array().unwrap();
    assert_eq!(scores.len(), 8, "{dr}");
    assert!(
        scores
            .iter()
            .all(|x| x["z"].as_f64().unwrap() > -dr["suspension"]["limit"].as_f64().unwrap()),
        "{dr}"
    );
    assert_eq!(dr["suspension"]["fit"]["records"], 4, "{dr}");
    // Each score's ratio t has Welch-Satterthwaite's degrees of freedom of the drive's variance
    // (4 records: 3; a spring's read as one scale over the corners, 3 to 9) and the baseline's
    // (6: 5), between the smaller and their sum, and its normal score z, of the same tail
    // probability, is nearer 0 with the same sign.
    for x in scores {
        let (t, df, z) = (
            x["t"].as_f64().unwrap(),
            x["df"].as_f64().unwrap(),
            x["z"].as_f64().unwrap(),
        );
        let most = if x["part"] == "spring" { 14.0 } else { 8.0 };
        assert!((3.0..=most).contains(&df), "{x}");
        assert!(z.abs() <= t.abs() + 1e-12 && z * t >= 0.0, "{x}");
    }
    // The bound per drive: the features' 1 % and the fit's own 1 %.
    assert_eq!(dr["false_alarm_rate"], 0.02, "{dr}");
    let missing: Vec<&str> = dr["missing"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|m| m.as_str())
        .collect();
    // The first drive after the baseline has no earlier ones to pool its springs with: said,
    // and nothing else is missing of the suspension.
    assert!(dr["suspension"].get("trend").is_none(), "{dr}");
    let of_suspension: Vec<&&str> = missing
        .iter()
        .filter(|m| m.contains("suspension"))
        .collect();
    assert_eq!(
        of_suspension,
        [&"suspension fit: no spring trend over the last 3 drives yet: 0 of the 2 earlier drives it needs fitted against baseline version 1 (a spring's slow loss is judged on this drive alone)"],
        "{dr}"
    );

    let soft = d.path().join("soft_rl.toml");
    let text = std::fs::read_to_string(CITY_BUS).unwrap()
        + "\n[[corner_condition]]\ncorner = \"RL\"\nspring_factor = 0.8\n";
    std::fs::write(&soft, text).unwrap();
    let files = simulate_csv_of(
        soft.to_str().unwrap(),
        &d.path().join("soft"),
        "B",
        "30",
        "31",
        "4",
    );
    let dr = check_drive(db, "d", &files);
    assert!(
        dr["classification"] == "vehicle" || dr["classification"] == "both",
        "{dr}"
    );
    assert_eq!(dr["corner"], "RL", "{dr}");
    assert_eq!(dr["component"], "spring", "{dr}");
    let fit = fit_evidence(&dr);
    assert!(
        fit.iter()
            .any(|(k, c, z)| k == "spring-fit" && c == "RL" && *z < -3.1),
        "{fit:?}"
    );
    // The second drive had one earlier drive; the third pools its springs with the two before
    // it, newest first, and scores every corner's.
    assert!(dr["suspension"].get("trend").is_none(), "{dr}");
    let files = simulate_csv_of(
        soft.to_str().unwrap(),
        &d.path().join("soft2"),
        "B",
        "30",
        "41",
        "4",
    );
    let dr = check_drive(db, "third", &files);
    let trend = &dr["suspension"]["trend"];
    assert_eq!(
        trend["drives"],
        serde_json::json!(["third", "d", "d"]),
        "{dr}"
    );
    let scores = trend["scores"].as_array().unwrap();
    assert_eq!(scores.len(), 4, "{dr}");
    assert!(scores.iter().all(|x| x["part"] == "spring"), "{dr}");
    // Two drives of the spring at 80 % and one healthy: RL the lowest of the four.
    let lowest = scores
        .iter()
        .min_by(|a, b| {
            a["z"]
                .as_f64()
                .unwrap()
                .total_cmp(&b["z"].as_f64().unwrap())
        })
        .unwrap();
    assert_eq!(lowest["corner"], "RL", "{dr}");
    // How sure, in the status: each flagged vehicle feature's |z| over its own limit (the
    // drive's fit and the trend have different ones), the largest.
    let want = dr["evidence"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["group"] == "vehicle")
        .map(|e| e["z"].as_f64().unwrap().abs() / e["limit"].as_f64().unwrap())
        .reduce(f64::max);
    let st = vibmode_fleet::Store::open(std::path::Path::new(db))
        .unwrap()
        .status(10)
        .unwrap();
    let latest = st[0].latest_drive.as_ref().unwrap();
    assert_eq!(latest.drive, "third");
    match (latest.vehicle_z_over_limit, want) {
        (Some(got), Some(want)) => assert!((got - want).abs() < 1e-12, "{got} vs {want}"),
        (got, want) => assert_eq!(got, want, "{dr}"),
    }
}

/// A model file that is not one, or that gives no fit, is refused before anything is stored;
/// without a registered file a baseline has no fitted suspension and says nothing of it.
#[test]
fn bad_model_files_are_refused_and_nothing_is_stored() {
    let d = tempfile::tempdir().unwrap();
    let db = d.path().join("fleet.db");
    let db = db.to_str().unwrap();
    ok(&["fleet", "init", "--db", db]);
    let junk = d.path().join("junk.toml");
    std::fs::write(&junk, "this is = not [ a vehicle").unwrap();
    fails_with(
        &[
            "fleet",
            "register",
            "--db",
            db,
            "--vehicle",
            "bus-1",
            junk.to_str().unwrap(),
        ],
        &["vehicle model", "junk.toml"],
    );
    let binary = d.path().join("binary.toml");
    std::fs::write(&binary, [0u8, 159, 146, 150, 0, 1]).unwrap();
    fails_with(
        &[
            "fleet",
            "register",
            "--db",
            db,
            "--vehicle",
            "bus-1",
            binary.to_str().unwrap(),
        ],
        &["binary.toml"],
    );
    let missing = d.path().join("missing.toml");
    fails_with(
        &[
            "fleet",
            "register",
            "--db",
            db,
            "--vehicle",
            "bus-1",
            missing.to_str().unwrap(),
        ],
        &["missing.toml"],
    );
    // A body-fit band above what a bus's body modes allow still parses; a vehicle id with a
    // space is refused.
    fails_with(
        &[
            "fleet",
            "register",
            "--db",
            db,
            "--vehicle",
            "bus 1",
            CITY_BUS,
        ],
        &["bus 1"],
    );
    let store = vibmode_fleet::Store::open(std::path::Path::new(db)).unwrap();
    assert!(store.vehicles().unwrap().is_empty());
    assert!(store.vehicle_model("bus-1").unwrap().is_none());
}

/// Records ingested before the model file was registered carry no body equations; ingesting the
/// same files again after registering adds them (the features are updated, no record is added),
/// and the baseline then fits the suspension.
#[test]
fn records_stored_before_registering_get_their_equations_when_ingested_again() {
    let d = tempfile::tempdir().unwrap();
    let db = d.path().join("fleet.db");
    let db = db.to_str().unwrap();
    ok(&["fleet", "init", "--db", db]);
    let nominal = simulate_csv(&d.path().join("nominal"), "B", "30", "12", "5");
    let mut args = vec!["fleet", "ingest", "--db", db, "--vehicle", "bus-1", "-q"];
    args.extend(nominal.iter().map(String::as_str));
    ok(&args);
    register(db, CITY_BUS);
    let base = stdout(&["fleet", "baseline", "--db", db, "--vehicle", "bus-1"]);
    assert!(
        base.contains("no suspension fit per drive") && base.contains("0 record(s)"),
        "{base}"
    );
    let again = common::vibmode(&args);
    let err = String::from_utf8_lossy(&again.stderr).to_string();
    assert_eq!(again.status.code(), Some(0), "{err}");
    assert_eq!(err.matches("body equations added").count(), 5, "{err}");
    let base = stdout(&["fleet", "baseline", "--db", db, "--vehicle", "bus-1"]);
    assert!(
        base.contains("suspension fitted to 5 nominal records"),
        "{base}"
    );
    // A third time: nothing to do.
    let third = common::vibmode(&args);
    let err = String::from_utf8_lossy(&third.stderr).to_string();
    assert_eq!(err.matches("nothing to do").count(), 5, "{err}");
    let status = stdout(&["fleet", "status", "--db", db]);
    assert!(status.contains("5 nominal, 0 test records"), "{status}");
}
