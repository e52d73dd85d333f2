//! Records are named by the path as the user gave it (relative stays relative), not by the
//! file's base name: two runs' `record_01` files stay apart in `fleet check` (table, JSON,
//! status) and in `analyze`'s results.json, also for records cut from a long recording.

use crate::common;

use std::path::Path;
use std::process::{Output, Stdio};

use common::wait_or_kill;

/// vibmode run in `dir` (so that relative paths are relative to it); exit 0 required.
fn ok_in(dir: &Path, args: &[&str]) -> Output {
    let child = common::bin()
        .current_dir(dir)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start vibmode");
    let o = wait_or_kill(child, args);
    assert_eq!(
        o.status.code(),
        Some(0),
        "args {args:?}: {}",
        common::stderr(&o)
    );
    o
}

/// `vibmode simulate` of `records` CSV records (200 Hz) of `duration` s into `dir/sub`.
fn simulate(dir: &Path, sub: &str, seed: &str, records: &str, duration: &str) {
    let params = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/city_bus.toml");
    ok_in(
        dir,
        &[
            "simulate",
            params,
            "--road",
            "C",
            "--speed-kmh",
            "40",
            "--duration-s",
            duration,
            "--records",
            records,
            "--seed",
            seed,
            "--fs",
            "200",
            "--format",
            "csv",
            "-o",
            sub,
        ],
    );
}

#[test]
fn fleet_check_names_records_by_the_path_given() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    ok_in(dir, &["fleet", "init", "--db", "fleet.db"]);
    simulate(dir, "nominal", "3", "6", "10.24");
    let mut args = vec!["fleet", "ingest", "--db", "fleet.db", "--vehicle", "bus-1"];
    let nominal: Vec<String> = (1..=6)
        .map(|i| format!("nominal/record_{i:02}.csv"))
        .collect();
    args.extend(nominal.iter().map(String::as_str));
    let o = ok_in(dir, &args);
    let err = common::stderr(&o);
    assert!(err.contains("nominal/record_01.csv: stored"), "{err}");
    ok_in(
        dir,
        &[
            "fleet",
            "baseline",
            "--db",
            "fleet.db",
            "--vehicle",
            "bus-1",
        ],
    );
    // Two runs, one base name.
    simulate(dir, "a", "4", "1", "10.24");
    simulate(dir, "b", "5", "1", "10.24");
    let o = ok_in(
        dir,
        &[
            "fleet",
            "check",
            "--db",
            "fleet.db",
            "--vehicle",
            "bus-1",
            "--json",
            "check.json",
            "a/record_01.csv",
            "b/record_01.csv",
        ],
    );
    let table = String::from_utf8_lossy(&o.stdout).to_string();
    let rows: Vec<&str> = table
        .lines()
        .filter(|l| l.contains("record_01.csv") && !l.starts_with("note: "))
        .collect();
    assert_eq!(rows.len(), 2, "{table}");
    assert!(rows[0].starts_with("a/record_01.csv "), "{table}");
    assert!(rows[1].starts_with("b/record_01.csv "), "{table}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("check.json")).unwrap()).unwrap();
    let files: Vec<&str> = v["records"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["file"].as_str().unwrap())
        .collect();
    assert_eq!(files, ["a/record_01.csv", "b/record_01.csv"]);
    // The store keeps the names: status lists both.
    let o = ok_in(dir, &["fleet", "status", "--db", "fleet.db"]);
    let st = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        st.contains("  a/record_01.csv ") && st.contains("  b/record_01.csv "),
        "{st}"
    );
}

#[test]
fn analyze_names_records_by_the_path_given() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    simulate(dir, "a", "4", "1", "10.24");
    simulate(dir, "b", "5", "1", "10.24");
    // A long recording cut into records: the range is appended to the full path.
    simulate(dir, "long", "6", "1", "30.72");
    ok_in(
        dir,
        &[
            "analyze",
            "a/record_01.csv",
            "b/record_01.csv",
            "long/record_01.csv",
            "--method",
            "arma",
            "-o",
            "out",
        ],
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/results.json")).unwrap())
            .unwrap();
    let names: Vec<&str> = v["records"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["name"].as_str().unwrap())
        .collect();
    assert_eq!(names.len(), 5, "{names:?}");
    assert_eq!(names[0], "a/record_01.csv");
    assert_eq!(names[1], "b/record_01.csv");
    assert_eq!(names[2], "long/record_01.csv [0.00-10.24 s]");
    assert!(
        names[3..]
            .iter()
            .all(|n| n.starts_with("long/record_01.csv [")),
        "{names:?}"
    );
}
