//! `vibmode fleet` under bad input and concurrency (issue 28): the store is never an output,
//! settings that would give a store no later command can read are refused, check and ingest
//! are all or nothing, concurrent ingests and inits both succeed, failed sensors are classed
//! `sensor` and unfit records refused, and messages never echo long or binary input.

use crate::common;

use std::path::Path;
use std::process::Stdio;

use common::{
    bin, fails_with, fleet_args, fleet_ingest, ok, simulate_csv, stderr, vibmode, wait_or_kill,
};

/// A CSV record's header and rows.
fn read_csv(path: &str) -> (String, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    let rows = lines
        .filter(|l| !l.is_empty())
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (header, rows)
}

fn write_csv(path: &Path, header: &str, rows: &[Vec<String>]) -> String {
    let mut text = format!("{header}\n");
    for r in rows {
        text.push_str(&r.join(","));
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
    path.to_string_lossy().to_string()
}

/// The column of a channel (the first column is time).
fn column(header: &str, channel: &str) -> usize {
    header
        .split(',')
        .position(|h| h.starts_with(channel))
        .unwrap()
}

/// `fleet status` of the store.
fn status(db: &str) -> String {
    String::from_utf8_lossy(&ok(&["fleet", "status", "--db", db]).stdout).to_string()
}

fn check_json(db: &str, file: &str) -> serde_json::Value {
    let o = ok(&fleet_args("check", db, "bus-1", &["--json", "-", file]));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    v["records"][0].clone()
}

#[test]
fn store_is_safe_checks_are_all_or_nothing_and_failed_sensors_are_named() {
    let d = tempfile::tempdir().unwrap();
    let db_path = d.path().join("fleet.db");
    let db = db_path.to_str().unwrap();
    ok(&["fleet", "init", "--db", db]);
    let nominal = simulate_csv(&d.path().join("nominal"), "C", "40", "3", "6");
    fleet_ingest(db, "bus-1", &nominal);
    ok(&["fleet", "baseline", "--db", db, "--vehicle", "bus-1"]);
    let test = simulate_csv(&d.path().join("test"), "C", "40", "4", "1");
    let good = test[0].as_str();
    let before = std::fs::read(&db_path).unwrap();

    // 1. The store given as the JSON output: refused before any work, the store unchanged.
    fails_with(
        &fleet_args("check", db, "bus-1", &["--json", db, good]),
        &["fleet.db", "input"],
    );
    // Through a hard link too (same file, another name).
    let link = d.path().join("link.json");
    std::fs::hard_link(&db_path, &link).unwrap();
    fails_with(
        &fleet_args(
            "check",
            db,
            "bus-1",
            &["--json", link.to_str().unwrap(), good],
        ),
        &["link.json", "input"],
    );
    std::fs::remove_file(&link).unwrap();
    assert_eq!(
        std::fs::read(&db_path).unwrap(),
        before,
        "the store changed"
    );

    // 3. A check of a good and a missing file stores nothing (not the good one's check).
    let missing = d.path().join("missing.csv");
    let missing = missing.to_str().unwrap();
    fails_with(
        &fleet_args("check", db, "bus-1", &[good, missing]),
        &["missing.csv"],
    );
    let st = status(db);
    assert!(st.contains("6 nominal, 0 test records"), "{st}");
    // An ingest likewise, and it does not report the good file as stored.
    let e = fails_with(
        &fleet_args("ingest", db, "bus-1", &[good, missing]),
        &["missing.csv", "check the path"],
    );
    assert!(!e.contains("stored as"), "{e}");
    let st = status(db);
    assert!(st.contains("6 nominal, 0 test records"), "{st}");

    // 5. Failed sensors: built from the good test record.
    let (header, rows) = read_csv(good);
    // A dead logger: every channel 0. Classed sensor, never normal.
    let zero: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut z = vec!["0".to_string(); r.len()];
            z[0] = r[0].clone();
            z
        })
        .collect();
    let zero = write_csv(&d.path().join("zero.csv"), &header, &zero);
    let r = check_json(db, &zero);
    assert_eq!(r["classification"], "sensor", "{r}");
    assert!(r["summary"].as_str().unwrap().contains("dead"), "{r}");
    // One dead channel: classed sensor, the channel named in the JSON.
    let c = column(&header, "FR_sprung");
    let dead: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut r = r.clone();
            r[c] = "0".into();
            r
        })
        .collect();
    let dead = write_csv(&d.path().join("dead.csv"), &header, &dead);
    let r = check_json(db, &dead);
    assert_eq!(r["classification"], "sensor", "{r}");
    assert_eq!(r["sensor_faults"][0]["channel"], "FR_sprung", "{r}");
    assert_eq!(r["sensor_faults"][0]["fault"], "dead", "{r}");
    // A stuck channel (one value other than 0).
    let stuck: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut r = r.clone();
            r[c] = "9.81".into();
            r
        })
        .collect();
    let stuck = write_csv(&d.path().join("stuck.csv"), &header, &stuck);
    let r = check_json(db, &stuck);
    assert_eq!(r["classification"], "sensor", "{r}");
    assert_eq!(r["sensor_faults"][0]["fault"], "flat", "{r}");
    // A saturated channel: clipped at 60 % of its peak.
    let u = column(&header, "FL_unsprung");
    let peak = rows
        .iter()
        .map(|r| r[u].parse::<f64>().unwrap().abs())
        .fold(0.0, f64::max);
    let clipped: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut r = r.clone();
            let x: f64 = r[u].parse().unwrap();
            r[u] = x.clamp(-0.6 * peak, 0.6 * peak).to_string();
            r
        })
        .collect();
    let clipped = write_csv(&d.path().join("clipped.csv"), &header, &clipped);
    let r = check_json(db, &clipped);
    assert_eq!(r["classification"], "sensor", "{r}");
    assert_eq!(r["sensor_faults"][0]["channel"], "FL_unsprung", "{r}");
    assert_eq!(r["sensor_faults"][0]["fault"], "clipped", "{r}");
    // The terminal table names the channel too.
    let o = ok(&fleet_args("check", db, "bus-1", &[&dead]));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("sensor") && out.contains("FR_sprung"), "{out}");
    // The healthy record itself is not a sensor fault.
    let r = check_json(db, good);
    assert_ne!(r["classification"], "sensor", "{r}");
    assert!(r["sensor_faults"].as_array().unwrap().is_empty(), "{r}");
    // A nominal record with a dead channel is refused: it would spoil the next baseline.
    let before = status(db);
    let c2 = column(&header, "RL_sprung");
    let dead2: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut r = r.clone();
            r[c2] = "0".into();
            r
        })
        .collect();
    let dead2 = write_csv(&d.path().join("dead2.csv"), &header, &dead2);
    fails_with(
        &fleet_args("ingest", db, "bus-1", &[&dead2]),
        &["dead2.csv", "RL_sprung", "dead"],
    );
    assert_eq!(status(db), before);
    // A record of 1.5 s and one sampled at 20 Hz (Nyquist below the 12-20 Hz band): refused
    // with the minimum, nothing stored.
    let short = write_csv(&d.path().join("short.csv"), &header, &rows[..300]);
    fails_with(
        &fleet_args("check", db, "bus-1", &[&short]),
        &["short.csv", "1.5 s", "at least 8 s"],
    );
    let slow: Vec<Vec<String>> = rows.iter().step_by(10).cloned().collect();
    let slow = write_csv(&d.path().join("slow.csv"), &header, &slow);
    fails_with(
        &fleet_args("check", db, "bus-1", &[&slow]),
        &["slow.csv", "20 Hz", "at least 40 Hz"],
    );
    assert_eq!(status(db), before);
    // The report counts and names the sensor faults.
    let rep = d.path().join("report");
    ok(&["fleet", "report", "--db", db, "-o", rep.to_str().unwrap()]);
    let html = std::fs::read_to_string(rep.join("index.html")).unwrap();
    assert!(
        html.contains("sensor") && html.contains("FR_sprung is dead"),
        "no sensor fault in the report"
    );
}

#[test]
fn settings_a_later_command_cannot_read_are_refused() {
    let d = tempfile::tempdir().unwrap();
    for (i, (text, needles)) in [
        (
            "false_alarm_rate = 1e-15\n",
            &["false_alarm_rate", "1e-15"][..],
        ),
        (
            "false_alarm_rate = 1e-300\n",
            &["false_alarm_rate", "1e-300"],
        ),
        (
            "transmissibility_min_hz = nan\n",
            &["transmissibility_min_hz", "NaN"],
        ),
        (
            "transmissibility_min_hz = inf\n",
            &["transmissibility_min_hz"],
        ),
        ("floor_level = 1e300\n", &["floor_level"]),
        ("min_nominal = 1000000000\n", &["min_nominal"]),
    ]
    .into_iter()
    .enumerate()
    {
        let cfg = d.path().join(format!("c{i}.toml"));
        std::fs::write(&cfg, text).unwrap();
        let db = d.path().join(format!("s{i}.db"));
        fails_with(
            &[
                "fleet",
                "init",
                "--db",
                db.to_str().unwrap(),
                "--config",
                cfg.to_str().unwrap(),
            ],
            needles,
        );
        assert!(!db.exists(), "{text}: a store was created");
    }
    // An unknown key: named, without the list of every key (484 bytes before).
    let cfg = d.path().join("unknown.toml");
    std::fs::write(&cfg, "bogus_setting = 1\n").unwrap();
    let e = fails_with(
        &[
            "fleet",
            "init",
            "--db",
            d.path().join("u.db").to_str().unwrap(),
            "--config",
            cfg.to_str().unwrap(),
        ],
        &["bogus_setting", "docs/fleet.md"],
    );
    assert!(!e.contains("expected one of"), "{e}");
    // A small valid rate gives a store whose settings read back.
    let cfg = d.path().join("ok.toml");
    std::fs::write(&cfg, "false_alarm_rate = 1e-9\n").unwrap();
    let db = d.path().join("ok.db");
    let db = db.to_str().unwrap();
    ok(&[
        "fleet",
        "init",
        "--db",
        db,
        "--config",
        cfg.to_str().unwrap(),
    ]);
    let o = vibmode(&["fleet", "status", "--db", db]);
    // No vehicle yet: said on stdout with success (a state, not an error), not an unreadable
    // store.
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("no vehicle in the store yet"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    // The report of an empty store says so too, rather than showing empty tables.
    let rep = d.path().join("rep");
    ok(&["fleet", "report", "--db", db, "-o", rep.to_str().unwrap()]);
    let html = std::fs::read_to_string(rep.join("index.html")).unwrap();
    assert!(html.contains("The store holds no vehicle yet"), "{html}");
}

#[test]
fn bad_store_paths_and_input_are_short_one_line_messages() {
    let d = tempfile::tempdir().unwrap();
    let folder = d.path().join("folder");
    std::fs::create_dir(&folder).unwrap();
    for cmd in ["init", "status"] {
        let e = fails_with(
            &["fleet", cmd, "--db", folder.to_str().unwrap()],
            &["folder", "is a folder"],
        );
        assert!(!e.contains("fleet init first"), "{e}");
        let e = fails_with(
            &["fleet", cmd, "--db", "/dev/null"],
            &["/dev/null", "special file"],
        );
        assert!(!e.contains("fleet init first"), "{e}");
        let nowhere = d.path().join("nowhere").join("f.db");
        let e = fails_with(
            &["fleet", cmd, "--db", nowhere.to_str().unwrap()],
            &["nowhere", "does not exist"],
        );
        assert!(!e.contains("unable to open"), "{e}");
    }
    let db_path = d.path().join("f.db");
    let db = db_path.to_str().unwrap();
    ok(&["fleet", "init", "--db", db]);
    // A 10 000-character vehicle id and one with a terminal escape sequence: not echoed.
    let long = "x".repeat(10_000);
    let e = fails_with(
        &["fleet", "baseline", "--db", db, "--vehicle", &long],
        &["xxx"],
    );
    assert!(!e.contains(&"x".repeat(61)), "{e}");
    let escape = "bus\u{1b}[31m-red";
    let o = vibmode(&["fleet", "baseline", "--db", db, "--vehicle", escape]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!stderr(&o).contains('\u{1b}'), "escape echoed");
    // A store whose schema version was set to -1 by another program: one short line.
    let mut bytes = std::fs::read(&db_path).unwrap();
    bytes[60..64].copy_from_slice(&(-1i32).to_be_bytes());
    std::fs::write(&db_path, &bytes).unwrap();
    fails_with(
        &["fleet", "status", "--db", db],
        &["schema version -1", "not one vibmode knows"],
    );
}

/// Two ingests of overlapping files at once both succeed, the duplicates no-ops; three inits of
/// a new store at once all succeed, one of them creating it. A few repetitions (the order in
/// which the processes meet varies); no timing is asserted.
#[test]
fn concurrent_ingests_and_inits_both_succeed() {
    let d = tempfile::tempdir().unwrap();
    let files = simulate_csv(&d.path().join("rec"), "C", "40", "5", "4");
    let spawn = |args: &[&str]| {
        bin()
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    for rep in 0..3 {
        let db = d.path().join(format!("c{rep}.db"));
        let db = db.to_str().unwrap();
        ok(&["fleet", "init", "--db", db]);
        let a: Vec<&str> = ["fleet", "ingest", "--db", db, "--vehicle", "bus-1"]
            .into_iter()
            .chain(files[..3].iter().map(String::as_str))
            .collect();
        let b: Vec<&str> = ["fleet", "ingest", "--db", db, "--vehicle", "bus-1"]
            .into_iter()
            .chain(files[1..].iter().rev().map(String::as_str))
            .collect();
        let (pa, pb) = (spawn(&a), spawn(&b));
        let (oa, ob) = (wait_or_kill(pa, &a), wait_or_kill(pb, &b));
        assert_eq!(oa.status.code(), Some(0), "{}", stderr(&oa));
        assert_eq!(ob.status.code(), Some(0), "{}", stderr(&ob));
        // Each file stored once; every line of both runs says stored or already stored.
        let st = status(db);
        assert!(st.contains("4 nominal, 0 test records"), "{st}");
        let stored = |o: &std::process::Output| stderr(o).matches(": stored as").count();
        let already = |o: &std::process::Output| stderr(o).matches("already stored").count();
        assert_eq!(
            stored(&oa) + stored(&ob),
            4,
            "{} / {}",
            stderr(&oa),
            stderr(&ob)
        );
        assert_eq!(already(&oa) + already(&ob), 2);
    }
    // 20 repetitions: two processes switching a new file to WAL at once met in about 1 of 15
    // (SQLite refuses one without waiting); 5 repetitions let that pass unseen.
    for rep in 0..20 {
        let db = d.path().join(format!("n{rep}.db"));
        let args = ["fleet", "init", "--db", db.to_str().unwrap()];
        let children: Vec<_> = (0..3).map(|_| spawn(&args)).collect();
        let outs: Vec<_> = children
            .into_iter()
            .map(|c| wait_or_kill(c, &args))
            .collect();
        for o in &outs {
            assert_eq!(o.status.code(), Some(0), "{}", stderr(o));
        }
        let created = outs
            .iter()
            .filter(|o| stderr(o).starts_with("created"))
            .count();
        assert_eq!(created, 1);
        ok(&fleet_args(
            "ingest",
            db.to_str().unwrap(),
            "v",
            &[&files[0]],
        ));
    }
}
