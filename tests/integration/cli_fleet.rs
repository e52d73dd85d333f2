//! `vibmode fleet` as a user meets it: init, ingest (twice), baseline, check, status, and the
//! one-line errors with exit code 2.

use crate::common;

use std::path::Path;

use common::{bin, fails_with, fleet_args, fleet_ingest, ok, simulate_csv};

#[test]
fn fleet_workflow_and_errors() {
    let d = tempfile::tempdir().unwrap();
    let db = d.path().join("fleet.db");
    let db = db.to_str().unwrap();
    let o = ok(&["fleet", "init", "--db", db]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("created"));
    let nominal = simulate_csv(&d.path().join("nominal"), "C", "40", "3", "6");
    assert_eq!(nominal.len(), 6, "{nominal:?}");
    let o = fleet_ingest(db, "bus-1", &nominal);
    assert!(!String::from_utf8_lossy(&o.stderr).contains("already stored"));
    let o = fleet_ingest(db, "bus-1", &nominal);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.matches("already stored").count(), 6, "{err}");
    // No baseline yet.
    fails_with(
        &fleet_args("check", db, "bus-1", &[&nominal[0]]),
        &["no baseline", "bus-1"],
    );
    let o = ok(&["fleet", "baseline", "--db", db, "--vehicle", "bus-1"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("version 1"));
    let test = simulate_csv(&d.path().join("test"), "C", "40", "4", "1");
    let o = ok(&fleet_args(
        "check",
        db,
        "bus-1",
        &["--json", "-", &test[0]],
    ));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let recs = v["records"].as_array().unwrap();
    assert_eq!(recs.len(), 1);
    let class = recs[0]["classification"].as_str().unwrap();
    assert!(
        ["normal", "road", "vehicle", "both"].contains(&class),
        "{class}"
    );
    assert!(recs[0]["scores"].is_object() && recs[0]["evidence"].is_array());
    // The file as given, not its base name: records of two runs are often both record_01.
    assert_eq!(recs[0]["file"].as_str().unwrap(), test[0].as_str());
    let o = ok(&["fleet", "status", "--db", db]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("bus-1") && out.contains("6 nominal") && out.contains("version 1"),
        "{out}"
    );
    // A record with another channel layout is refused before anything is stored.
    let odd = d.path().join("odd.csv");
    let text = std::fs::read_to_string(&test[0])
        .unwrap()
        .replacen("FL_unsprung", "FL_wheel", 1);
    std::fs::write(&odd, text).unwrap();
    fails_with(
        &fleet_args("check", db, "bus-1", &[odd.to_str().unwrap()]),
        &["odd.csv", "FL_wheel", "new baseline"],
    );
    let after = ok(&["fleet", "status", "--db", db]);
    assert_eq!(
        String::from_utf8_lossy(&after.stdout),
        out,
        "nothing stored"
    );
    // The HTML report: the vehicle's section, its trend figure and the status table.
    let rep = d.path().join("fleet-report");
    ok(&["fleet", "report", "--db", db, "-o", rep.to_str().unwrap()]);
    let page = std::fs::read_to_string(rep.join("index.html")).unwrap();
    assert!(
        page.contains("Vehicle bus-1") && page.contains("<svg"),
        "{page}"
    );
    assert!(page.contains("Model set version 1 from 6 nominal record(s)"));
    assert!(!rep.join(".index.html.partial").exists());
    // Errors.
    fails_with(
        &fleet_args("check", db, "bus-9", &[&test[0]]),
        &["bus-9", "not in the store"],
    );
    fails_with(
        &fleet_args("ingest", db, "bus-1", &["no-such-file.csv"]),
        &["no-such-file.csv"],
    );
    let junk = d.path().join("junk.db");
    std::fs::write(
        &junk,
        b"this is not sqlite at all, just some text bytes........",
    )
    .unwrap();
    fails_with(
        &["fleet", "status", "--db", junk.to_str().unwrap()],
        &["not a vibmode fleet store"],
    );
    fails_with(
        &[
            "fleet",
            "status",
            "--db",
            d.path().join("none.db").to_str().unwrap(),
        ],
        &["no fleet store", "init"],
    );
}

/// Two ingests into one store at the same time (two processes): both succeed (the second waits
/// for the first's transaction) and both records are stored.
#[test]
fn concurrent_ingests_both_succeed() {
    let d = tempfile::tempdir().unwrap();
    let files = simulate_csv(&d.path().join("sim"), "B", "30", "3", "2");
    let db = d.path().join("fleet.db");
    let db = db.to_str().unwrap();
    ok(&["fleet", "init", "--db", db]);
    let spawn = |file: &str| {
        bin()
            .args(["fleet", "ingest", "--db", db, "--vehicle", "bus-2", file])
            .output()
    };
    let (a, b) = std::thread::scope(|s| {
        let ta = s.spawn(|| spawn(&files[0]));
        let tb = s.spawn(|| spawn(&files[1]));
        (ta.join().unwrap().unwrap(), tb.join().unwrap().unwrap())
    });
    for o in [&a, &b] {
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let o = ok(&["fleet", "status", "--db", db]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("bus-2") && out.contains("2 nominal"), "{out}");
}

/// An ingest killed (SIGKILL) part-way leaves a store that opens, holds only whole records, and
/// takes the rest on the next ingest (the committed ones are reported as already stored).
#[test]
fn killed_ingest_leaves_a_consistent_store() {
    let d = tempfile::tempdir().unwrap();
    let files = simulate_csv(&d.path().join("sim"), "B", "30", "4", "6");
    let db = d.path().join("fleet.db");
    let db = db.to_str().unwrap();
    ok(&["fleet", "init", "--db", db]);
    let mut args = vec!["fleet", "ingest", "--db", db, "--vehicle", "bus-3"];
    args.extend(files.iter().map(String::as_str));
    let mut child = bin()
        .args(&args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Let it store a few records, then kill it (SIGKILL: no cleanup at all).
    std::thread::sleep(std::time::Duration::from_millis(1500));
    child.kill().unwrap();
    child.wait().unwrap();
    let o = ok(&args);
    let err = String::from_utf8_lossy(&o.stderr);
    let again = err.matches("already stored").count();
    let stored = err.matches("stored as").count();
    assert_eq!(again + stored, files.len(), "{err}");
    let o = ok(&["fleet", "status", "--db", db]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("6 nominal"), "{out}");
}

/// `fleet init --config` fixes the settings for every later ingest and baseline: a baseline
/// built from a store initialised with other bands has exactly those bands' level features.
#[test]
fn init_config_sets_the_fleet_settings() {
    let d = tempfile::tempdir().unwrap();
    let db = d.path().join("fleet.db");
    let db = db.to_str().unwrap();
    let cfg = d.path().join("fleet.toml");
    std::fs::write(
        &cfg,
        "false_alarm_rate = 0.05\nmin_nominal = 3\nbands_hz = [[1.0, 3.0], [8.0, 12.0]]\n[analysis.sweep]\norder_max = 8\n",
    )
    .unwrap();
    // A bad settings file is refused before any store exists.
    let bad = d.path().join("bad.toml");
    std::fs::write(&bad, "false_alarm_rate = 2\n").unwrap();
    fails_with(
        &[
            "fleet",
            "init",
            "--db",
            db,
            "--config",
            bad.to_str().unwrap(),
        ],
        &["false_alarm_rate = 2", "[1e-9, 0.5)"],
    );
    assert!(!Path::new(db).exists());
    ok(&[
        "fleet",
        "init",
        "--db",
        db,
        "--config",
        cfg.to_str().unwrap(),
    ]);
    let files = simulate_csv(&d.path().join("n"), "A", "30", "7", "3");
    fleet_ingest(db, "bus1", &files);
    let o = ok(&["fleet", "baseline", "--db", db, "--vehicle", "bus1"]);
    let text = String::from_utf8_lossy(&o.stdout);
    // Two level bands (not the default five), and the Bonferroni limit of a 5 % family-wise
    // false-alarm rate over them: z(1 - 0.05 / (2 x 2)) = 2.24 (at the default 1 %: 2.81).
    let level = text
        .lines()
        .find(|l| l.starts_with("level "))
        .unwrap_or_else(|| panic!("no level row in:\n{text}"));
    let cols: Vec<&str> = level.split_whitespace().collect();
    assert_eq!(cols[1], "2", "{level}");
    assert_eq!(cols[2], "2.24", "{level}");
    // Its zero leave-one-out maximum is explained under the table.
    assert!(
        text.contains("(level: a road scored only beyond the nominal records' largest level"),
        "{text}"
    );
    let status = ok(&["fleet", "status", "--db", db]);
    assert!(status.status.success());
    // Other settings once records are stored: refused, the store unchanged.
    std::fs::write(&cfg, "false_alarm_rate = 0.02\n").unwrap();
    fails_with(
        &[
            "fleet",
            "init",
            "--db",
            db,
            "--config",
            cfg.to_str().unwrap(),
        ],
        &["already holds 3 record(s)", "new store"],
    );
}

/// A note every record stored by one `fleet ingest` has (here: the FL corner has no sprung
/// sensor, so no transmissibility) is printed once after the list, not under each record; a
/// record's own notes stay under it.
#[test]
fn a_note_of_every_record_is_printed_once() {
    let d = tempfile::tempdir().unwrap();
    let db = d.path().join("fleet.db");
    let db = db.to_str().unwrap();
    ok(&["fleet", "init", "--db", db]);
    let files = simulate_csv(&d.path().join("sim"), "B", "30", "5", "3");
    let o = fleet_ingest(db, "bus-1", &files);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    let once: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("note (every one of the 3 records stored): "))
        .collect();
    assert!(
        once.iter()
            .any(|l| l.contains("corner FL") && l.contains("no sprung partner")),
        "{err}"
    );
    assert_eq!(err.matches("no sprung partner").count(), 1, "{err}");
    assert_eq!(
        err.matches(": stored as nominal record").count(),
        3,
        "{err}"
    );
    // One record alone: its note under it.
    let more = simulate_csv(&d.path().join("more"), "B", "30", "6", "1");
    let o = ok(&fleet_args("ingest", db, "bus-1", &["-q", &more[0]]));
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(
        err.lines()
            .any(|l| l.starts_with("  note: corner FL") && l.contains("no sprung partner")),
        "{err}"
    );
}
