//! Issue 29 item 5: every command that reads recordings reads them the same way. A text export
//! with Excel's `sep=,` line and a jittery millisecond time column (as a published FSAE car IMU
//! export) is refused by `analyze`, `segment` and `fleet ingest` with the hint
//! `--resample-nonuniform`, and read by each of them once that flag is given; a `Timestamp`
//! column in milliseconds is read with `--time-unit ms`.

use std::path::Path;

use crate::common;

use common::{fails_with, ok, stderr};

/// A small deterministic generator (no dependency): uniform in [-1, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// 100 Hz, `seconds` long, three channels named by corner and role (a sine each plus noise), the time column `time_name`
/// in milliseconds with +-0.3 ms jitter, after Excel's `sep=,` line.
fn jittery_csv(path: &Path, time_name: &str, seconds: f64) {
    let fs = 100.0;
    let n = (fs * seconds) as usize;
    let mut rng = Lcg(7);
    let mut text = format!("sep=,\n{time_name},FL_sprung,FL_unsprung,FR_unsprung\n");
    for i in 0..n {
        let t = i as f64 / fs;
        let t_ms = 1000.0 * t + 0.3 * rng.next();
        let mut row = format!("{t_ms:.3}");
        for f in [1.3, 11.0, 12.0] {
            let v = (2.0 * std::f64::consts::PI * f * t).sin() + 0.5 * rng.next();
            row.push_str(&format!(",{v:.6}"));
        }
        text.push_str(&row);
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

#[test]
fn analyze_segment_and_fleet_ingest_read_a_jittery_time_column() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("imu.csv");
    jittery_csv(&f, "Time_ms", 60.0);
    let db = d.path().join("fleet.db");
    ok(&["fleet", "init", "--db", s(&db)]);
    let report = d.path().join("report");
    let segs = d.path().join("segs");

    // Without the flag: refused, one line naming the fix each command accepts.
    for args in [
        vec!["analyze", s(&f), "-q", "-o", s(&report)],
        vec!["segment", s(&f), "-o", s(&segs)],
        vec!["fleet", "ingest", "--db", s(&db), "--vehicle", "car", s(&f)],
    ] {
        fails_with(&args, &["not uniform", "--resample-nonuniform"]);
    }

    // With it: each command reads the file at the mean rate, 100 Hz.
    ok(&[
        "analyze",
        s(&f),
        "--resample-nonuniform",
        "-q",
        "-o",
        s(&report),
    ]);
    let r = json(&report.join("results.json"));
    let records = r["records"].as_array().expect("records");
    // 60 s in records of 10.24 s.
    assert_eq!(records.len(), 5, "{records:?}");
    let fs = records[0]["fs_hz"].as_f64().unwrap();
    assert!((fs - 50.0).abs() < 1e-9 || (fs - 100.0).abs() < 0.1, "{fs}");
    let channels: Vec<&str> = r["channels"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|c| c["name"].as_str())
        .collect();
    assert_eq!(
        channels,
        ["FL_sprung", "FL_unsprung", "FR_unsprung"],
        "time column taken as a channel"
    );

    ok(&["segment", s(&f), "--resample-nonuniform", "-o", s(&segs)]);
    let sj = json(&segs.join("segments.json"));
    assert_eq!(sj["records"].as_array().map(Vec::len), Some(5), "{sj}");
    let fs = sj["fs_hz"].as_f64().unwrap();
    assert!((fs - 100.0).abs() < 0.05, "mean rate {fs}");
    assert!(
        (sj["duration_s"].as_f64().unwrap() - 60.0).abs() < 0.05,
        "{sj}"
    );

    let o = ok(&[
        "fleet",
        "ingest",
        "--db",
        s(&db),
        "--vehicle",
        "car",
        "--resample-nonuniform",
        s(&f),
    ]);
    let err = stderr(&o);
    assert!(err.contains("stored as nominal record"), "{err}");
}

/// A `Timestamp` column says no unit: seconds, unless `--time-unit ms`; a `Time_ms` column is
/// milliseconds by its name. The rate read shows which.
#[test]
fn time_column_units_by_name_and_by_option() {
    let d = tempfile::tempdir().unwrap();
    let fs_of = |args: &[&str]| -> f64 {
        let o = ok(args);
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["parameters"]["fs_hz"].as_f64().unwrap()
    };
    let ms = d.path().join("ms.csv");
    jittery_csv(&ms, "Time_ms", 20.0);
    let fs = fs_of(&["psd", s(&ms), "--resample-nonuniform", "--json", "-"]);
    assert!((fs - 100.0).abs() < 0.05, "{fs}");

    let stamp = d.path().join("stamp.csv");
    jittery_csv(&stamp, "Timestamp", 20.0);
    let fs = fs_of(&["psd", s(&stamp), "--resample-nonuniform", "--json", "-"]);
    assert!((fs - 0.1).abs() < 1e-4, "read as seconds: {fs}");
    let fs = fs_of(&[
        "psd",
        s(&stamp),
        "--resample-nonuniform",
        "--time-unit",
        "ms",
        "--json",
        "-",
    ]);
    assert!((fs - 100.0).abs() < 0.05, "{fs}");
    fails_with(
        &["psd", s(&stamp), "--time-unit", "fortnights"],
        &["time_unit", "fortnights", "ms"],
    );
}

/// A car dataset's GPS track `Timestamp,Lat_GNSS,Long_GNSS` (Unix ms, no speed column) is read
/// by `segment --gps`: the speed comes from the positions and the records are cut where the car
/// drives (the command refused the file before: "no latitude column").
#[test]
fn segment_reads_a_gps_csv_with_gnss_column_names() {
    use vibmode_signal::{write_path, Channel, Recording};
    let d = tempfile::tempdir().unwrap();
    let fs = 100.0;
    let n = 6_000;
    let mut rng = Lcg(3);
    let rec = Recording {
        fs_hz: fs,
        channels: vec![Channel::new(
            "z".to_string(),
            "m/s^2".to_string(),
            (0..n).map(|_| rng.next()).collect(),
        )],
        time_axis: None,
    };
    let r = d.path().join("r.f32");
    write_path(&r, &rec).unwrap();
    let side = d.path().join("r.f32.json");
    let text = std::fs::read_to_string(&side).unwrap();
    let text = text.replacen('{', "{\n  \"start_time\": \"2024-05-02T07:31:00Z\",", 1);
    std::fs::write(&side, text).unwrap();
    // 10 m/s due north for 38 s, then standing.
    let mut track = String::from("Timestamp,Lat_GNSS,Long_GNSS\n");
    for i in 0..=60u64 {
        let north = 10.0 * (i as f64).min(38.0);
        let ms = (1_714_635_060 + i) * 1000;
        track.push_str(&format!("{ms},{},17.0\n", 48.0 + north / 111_195.08));
    }
    let g = d.path().join("gnss.csv");
    std::fs::write(&g, track).unwrap();
    let out = d.path().join("segs");
    ok(&[
        "segment",
        s(&r),
        "--gps",
        s(&g),
        "--plan-only",
        "-o",
        s(&out),
    ]);
    let sj = json(&out.join("segments.json"));
    let records = sj["records"].as_array().expect("records");
    assert_eq!(records.len(), 3, "{sj}");
    for rec in records {
        let v = rec["mean_speed_kmh"].as_f64().expect("speed");
        assert!((v - 36.0).abs() < 1.0, "{v}");
    }
}

/// A CSV written by pandas' `DataFrame.to_csv` (its row index as an unnamed first column): the
/// index is not a channel for `psd` and `analyze`; a broken count is refused in one line.
#[test]
fn a_pandas_index_column_is_not_analysed() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("frame.csv");
    let mut rng = Lcg(11);
    let mut text = String::from(",time,acc_front,acc_rear\n");
    for i in 0..3000 {
        let t = i as f64 / 100.0;
        let a = (2.0 * std::f64::consts::PI * 1.3 * t).sin() + 0.5 * rng.next();
        let b = (2.0 * std::f64::consts::PI * 9.0 * t).sin() + 0.5 * rng.next();
        text.push_str(&format!("{i},{t:.2},{a:.6},{b:.6}\n"));
    }
    std::fs::write(&f, &text).unwrap();
    let o = ok(&["psd", s(&f)]);
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        out.contains("acc_front") && out.contains("acc_rear"),
        "{out}"
    );
    assert!(!out.contains("ch0"), "the index read as a channel: {out}");
    let r = d.path().join("report");
    ok(&["analyze", "-q", "--method", "arma", s(&f), "-o", s(&r)]);
    let names: Vec<String> = json(&r.join("results.json"))["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(names, ["acc_front", "acc_rear"]);
    std::fs::write(&f, text.replacen("\n17,", "\n18,", 1)).unwrap();
    fails_with(
        &["psd", s(&f)],
        &["pandas row index", "line 19", "index=False"],
    );
}

/// A folder given as an input stands for its recordings (not its subfolders, not hidden files,
/// not other files), sorted by name: `analyze DIR` gives the results of `analyze` of those files
/// given one by one, and `fleet ingest DIR` stores each. A folder without recordings, or with a
/// record in two formats, is refused in one line, exit code 2, before any output is made.
#[test]
fn a_folder_stands_for_its_recordings() {
    let d = tempfile::tempdir().unwrap();
    let recs = d.path().join("recs");
    std::fs::create_dir_all(recs.join("sub")).unwrap();
    let mut rng = Lcg(23);
    let mut write = |path: &Path| {
        let mut text = String::from("time,FL_sprung,FL_unsprung\n");
        for i in 0..2000 {
            let t = i as f64 / 100.0;
            let a = (2.0 * std::f64::consts::PI * 1.3 * t).sin() + 0.5 * rng.next();
            let b = (2.0 * std::f64::consts::PI * 9.0 * t).sin() + 0.5 * rng.next();
            text.push_str(&format!("{t:.2},{a:.6},{b:.6}\n"));
        }
        std::fs::write(path, text).unwrap();
    };
    for name in [
        "rec_b.csv",
        "rec_a.csv",
        "rec_c.csv",
        ".rec_hidden.csv",
        "sub/rec_d.csv",
    ] {
        write(&recs.join(name));
    }
    std::fs::write(recs.join("notes.json"), "{}").unwrap();
    let by_folder = d.path().join("by-folder");
    let by_files = d.path().join("by-files");
    ok(&[
        "analyze",
        "-q",
        "--method",
        "arma",
        s(&recs),
        "-o",
        s(&by_folder),
    ]);
    let files: Vec<String> = ["rec_a.csv", "rec_b.csv", "rec_c.csv"]
        .iter()
        .map(|n| s(&recs.join(n)).to_string())
        .collect();
    let mut args = vec!["analyze", "-q", "--method", "arma"];
    args.extend(files.iter().map(String::as_str));
    args.extend(["-o", s(&by_files)]);
    ok(&args);
    let strip = |mut v: serde_json::Value| {
        v.as_object_mut().unwrap().remove("timing");
        v
    };
    let a = strip(json(&by_folder.join("results.json")));
    let b = strip(json(&by_files.join("results.json")));
    assert_eq!(a, b, "a folder analysed as its files");
    assert!(a.to_string().contains("rec_c.csv") && !a.to_string().contains("rec_d"));
    assert!(!a.to_string().contains("rec_hidden"));
    // The fleet stores each of them.
    let db = d.path().join("f.db");
    ok(&["fleet", "init", "--db", s(&db)]);
    ok(&[
        "fleet",
        "ingest",
        "-q",
        "--db",
        s(&db),
        "--vehicle",
        "b",
        s(&recs),
    ]);
    let names: Vec<String> = vibmode_fleet::Store::open(&db)
        .unwrap()
        .nominal_records("b")
        .unwrap()
        .into_iter()
        .map(|(r, _)| r.file_name)
        .collect();
    assert_eq!(names, files);
    // Refused: a folder without recordings, and one holding a record twice.
    let empty = d.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let out = d.path().join("never");
    fails_with(
        &["analyze", "-q", s(&empty), "-o", s(&out)],
        &[
            "holds no recording",
            ".wav, NumPy .npy",
            "give the record files",
        ],
    );
    std::fs::copy(recs.join("rec_a.csv"), recs.join("rec_a.txt")).unwrap();
    fails_with(
        &["analyze", "-q", s(&recs), "-o", s(&out)],
        &["rec_a.csv and rec_a.txt", "two formats"],
    );
    fails_with(
        &[
            "fleet",
            "ingest",
            "-q",
            "--db",
            s(&db),
            "--vehicle",
            "b",
            s(&recs),
        ],
        &["two formats"],
    );
    assert!(!out.exists(), "nothing written");
}

/// A `numpy.save` file of `n` samples by 3 channels (float64, C order), as NumPy writes it.
fn npy(path: &Path, n: usize) {
    let mut h = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({n}, 3), }}");
    while (10 + h.len() + 1) % 64 != 0 {
        h.push(' ');
    }
    h.push('\n');
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    b.extend((h.len() as u16).to_le_bytes());
    b.extend(h.as_bytes());
    let mut g = Lcg(5);
    for i in 0..n {
        let t = i as f64 / 200.0;
        for f in [1.5, 4.0, 9.0] {
            b.extend(((2.0 * std::f64::consts::PI * f * t).sin() + 0.2 * g.next()).to_le_bytes());
        }
    }
    std::fs::write(path, b).unwrap();
}

/// A NumPy array file is a recording of its own: `analyze` and `psd` read it with the rate
/// given (channels `ch0`..), alone or in a folder; without a rate, or asked to write `.npy`,
/// the commands refuse with one line and exit code 2, and write nothing.
#[test]
fn numpy_arrays_are_read_with_the_rate_given() {
    let d = tempfile::tempdir().unwrap();
    let a = d.path().join("a.npy");
    npy(&a, 4000);
    let out = d.path().join("an");
    ok(&["analyze", "-q", "--fs", "200", s(&a), "-o", s(&out)]);
    let r = json(&out.join("results.json"));
    let names: Vec<&str> = r["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["ch0", "ch1", "ch2"]);
    let folder = d.path().join("dir");
    std::fs::create_dir(&folder).unwrap();
    npy(&folder.join("b.npy"), 4000);
    ok(&[
        "analyze",
        "-q",
        "--fs",
        "200",
        s(&folder),
        "-o",
        s(&d.path().join("an2")),
    ]);
    fails_with(
        &["analyze", "-q", s(&a)],
        &["a.npy", "holds no sampling rate"],
    );
    fails_with(&["psd", s(&a)], &["holds no sampling rate"]);
    let o = d.path().join("r.npy");
    fails_with(
        &[
            "resample",
            "--fs",
            "200",
            s(&a),
            "--fs-out",
            "50",
            "-o",
            s(&o),
        ],
        &[".npy is read, not written"],
    );
    assert!(!o.exists());
}

#[test]
fn info_prints_what_each_file_holds() {
    let d = tempfile::tempdir().unwrap();
    // By hand: a = 1, 2, 3, 4 (mean 2.5, std sqrt(1.25) = 1.118, rms sqrt(7.5) = 2.739), b dead.
    let csv = d.path().join("rec.csv");
    std::fs::write(
        &csv,
        "time_s,a (g),b (g)\n0,1,0\n0.01,2,0\n0.02,3,0\n0.03,4,0\n",
    )
    .unwrap();
    let o = ok(&["info", s(&csv)]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        text.contains("rec.csv: delimited text, 2 channels, 4 frames at 100 Hz (0.04 s)"),
        "{text}"
    );
    assert!(
        text.contains(
            "  a        g           1.000       4.000       2.500       1.118       2.739"
        ),
        "{text}"
    );
    assert!(text.contains("all 0: a dead sensor"), "{text}");
    // JSON: one array, the folder expanded to its recordings (the npy needs its rate).
    let dir = d.path().join("dir");
    std::fs::create_dir(&dir).unwrap();
    std::fs::copy(&csv, dir.join("a.csv")).unwrap();
    npy(&dir.join("b.npy"), 400);
    let o = ok(&["info", "--json", "--fs", "100", s(&dir)]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let files = v.as_array().unwrap();
    assert_eq!(files.len(), 2);
    assert_eq!(files[0]["channels"][0]["mean"], 2.5);
    assert_eq!(files[0]["channels"][1]["constant"], 0.0);
    assert_eq!(files[1]["format"], "Npy");
    assert_eq!(files[1]["frames"], 400);
    assert_eq!(files[1]["fs_hz"], 100.0);
    // Refusals: the reader's, one line, exit 2.
    fails_with(
        &["info", s(&dir.join("b.npy"))],
        &["b.npy", "holds no sampling rate", "--fs HZ"],
    );
    fails_with(&["info", s(&d.path().join("none.csv"))], &["none.csv"]);
    let nan = d.path().join("nan.csv");
    std::fs::write(&nan, "time_s,a\n0,1\n0.01,nan\n0.02,3\n").unwrap();
    fails_with(
        &["info", s(&csv), s(&nan)],
        &["nan.csv: channel 'a' sample 1 is NaN"],
    );
}
