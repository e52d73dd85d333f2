//! Long recordings on the command line: streamed `resample`, streamed `analyze`, `segment`
//! with and without GPS, and the bad-input paths (one line, exit code 2, nothing half-written).

use std::path::{Path, PathBuf};

use crate::common;

use common::{fails_with, ok, stderr};
use vibmode_signal::{read_path, write_path, Channel, ReadOptions, Recording};
use vibmode_vehicle::drive::{simulate_drive, DriveParams};

/// Two channels: a 3 Hz and a 7 Hz resonance-like sum of sines plus a 900 Hz tone, at `fs`.
fn long_recording(dir: &Path, name: &str, fs: f64, seconds: f64, start: Option<&str>) -> PathBuf {
    let n = (fs * seconds) as usize;
    let ch = |f: f64, ph: f64| -> Vec<f64> {
        (0..n)
            .map(|i| {
                let t = i as f64 / fs;
                (2.0 * std::f64::consts::PI * f * t + ph).sin()
                    + 0.3 * (2.0 * std::f64::consts::PI * 900.0 * t).sin()
                    + 0.05 * (((i * 7919) % 1013) as f64 / 1013.0 - 0.5)
            })
            .collect()
    };
    let rec = Recording {
        fs_hz: fs,
        channels: vec![
            Channel::new("FL".to_string(), "m/s^2".to_string(), ch(3.0, 0.1)),
            Channel::new("S_FR".to_string(), "m/s^2".to_string(), ch(7.0, 0.7)),
        ],
        time_axis: None,
    };
    let p = dir.join(name);
    write_path(&p, &rec).unwrap();
    if let Some(s) = start {
        let side = dir.join(format!("{name}.json"));
        let text = std::fs::read_to_string(&side).unwrap();
        let text = text.replacen('{', &format!("{{\n  \"start_time\": \"{s}\","), 1);
        std::fs::write(&side, text).unwrap();
    }
    p
}

#[test]
fn streamed_resample_writes_every_format_and_agrees_with_the_ideal_filter() {
    let d = tempfile::tempdir().unwrap();
    let input = long_recording(d.path(), "in.f32", 2000.0, 30.0, None);
    let s = |p: &Path| p.to_str().unwrap().to_string();
    for ext in ["f32", "csv", "wav"] {
        let out = d.path().join(format!("out.{ext}"));
        let err = stderr(&ok(&[
            "resample",
            &s(&input),
            "--fs-out",
            "100",
            "--resampler",
            "fir",
            "-o",
            &s(&out),
        ]));
        assert!(
            err.contains("streamed FIR") && err.contains("-110 dB"),
            "{err}"
        );
        let r = read_path(&out, &ReadOptions::default()).unwrap();
        assert_eq!(r.len(), 3000);
        assert!((r.fs_hz - 100.0).abs() < 1e-9);
        assert_eq!(r.names(), ["FL", "S_FR"]);
        assert!(!d.path().join(format!("out.{ext}.partial")).exists());
    }
    // The same through the ideal whole-record filter (cutoff inside the FIR's 40-50 Hz
    // transition band): equal away from the ends up to the broadband noise the two treat
    // differently in the transition band (the tones are periodic in the record).
    let ideal = d.path().join("ideal.f64");
    ok(&[
        "resample",
        &s(&input),
        "--fs-out",
        "100",
        "--cutoff",
        "45",
        "--resampler",
        "ideal",
        "-o",
        &s(&ideal),
    ]);
    let a = read_path(&d.path().join("out.f32"), &ReadOptions::default()).unwrap();
    let b = read_path(&ideal, &ReadOptions::default()).unwrap();
    for (x, y) in a.channels.iter().zip(&b.channels) {
        let worst = x.samples[200..2800]
            .iter()
            .zip(&y.samples[200..2800])
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        assert!(worst < 2e-4, "{worst}");
    }
}

#[test]
fn streamed_analyze_cuts_records_and_reports_their_start() {
    let d = tempfile::tempdir().unwrap();
    let input = long_recording(d.path(), "drive.f32", 1000.0, 35.0, None);
    let out = d.path().join("rep");
    ok(&[
        "analyze",
        input.to_str().unwrap(),
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    let recs = json["records"].as_array().unwrap();
    assert_eq!(recs.len(), 3);
    assert_eq!(recs[1]["segment"]["start_s"], 10.24);
    // Named by the path as given, with the record's time range.
    assert_eq!(
        recs[2]["name"].as_str().unwrap(),
        format!("{} [20.48-30.72 s]", input.display())
    );
    assert_eq!(recs[0]["n_samples"], 10240);
}

fn gps_csv(dir: &Path, seconds: f64, seed: u64) -> PathBuf {
    let drive = simulate_drive(&DriveParams::new(seconds, seed));
    let p = dir.join("track.csv");
    std::fs::write(&p, drive.to_csv()).unwrap();
    p
}

#[test]
fn segment_and_analyze_by_gps_carry_speed_and_position() {
    let d = tempfile::tempdir().unwrap();
    let input = long_recording(
        d.path(),
        "bus.f32",
        500.0,
        200.0,
        Some("2024-05-02T07:31:00Z"),
    );
    let track = gps_csv(d.path(), 200.0, 4);
    let (i, t) = (input.to_str().unwrap(), track.to_str().unwrap());
    let seg_dir = d.path().join("seg");
    let err = stderr(&ok(&[
        "segment",
        i,
        "--gps",
        t,
        "-o",
        seg_dir.to_str().unwrap(),
    ]));
    assert!(err.contains("cut by GPS"), "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(seg_dir.join("segments.json")).unwrap())
            .unwrap();
    let recs = json["records"].as_array().unwrap();
    assert!(!recs.is_empty());
    for r in recs {
        assert!(r["mean_speed_kmh"].as_f64().unwrap() > 10.0);
        assert!(r["start_time"]
            .as_str()
            .unwrap()
            .starts_with("2024-05-02T07:"));
        let f = seg_dir.join(r["file"].as_str().unwrap());
        assert_eq!(read_path(&f, &ReadOptions::default()).unwrap().len(), 5120);
    }
    assert!(json["skipped"]
        .as_array()
        .unwrap()
        .iter()
        .any(|s| s["reason"] == "stop"));
    // Tolerances from a TOML file: no record can reach 200 km/h.
    let cfg = d.path().join("seg.toml");
    std::fs::write(&cfg, "min_speed_kmh = 200\n").unwrap();
    let strict = d.path().join("strict");
    let c = cfg.to_str().unwrap();
    ok(&[
        "segment",
        i,
        "--gps",
        t,
        "--segment-config",
        c,
        "--plan-only",
        "-o",
        strict.to_str().unwrap(),
    ]);
    let json2: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(strict.join("segments.json")).unwrap())
            .unwrap();
    assert_eq!(json2["records"].as_array().unwrap().len(), 0);
    assert_eq!(json2["params"]["min_speed_kmh"], 200.0);
    std::fs::write(&cfg, "min_sped_kmh = 20\n").unwrap();
    fails_with(
        &[
            "segment",
            i,
            "--gps",
            t,
            "--segment-config",
            c,
            "-o",
            strict.to_str().unwrap(),
        ],
        &["min_sped_kmh"],
    );
    let rep = d.path().join("rep");
    ok(&["analyze", i, "--gps", t, "-q", "-o", rep.to_str().unwrap()]);
    let res: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(rep.join("results.json")).unwrap()).unwrap();
    let rr = res["records"].as_array().unwrap();
    assert_eq!(rr.len(), recs.len());
    for (a, b) in rr.iter().zip(recs) {
        assert_eq!(a["segment"]["mean_speed_kmh"], b["mean_speed_kmh"]);
        assert_eq!(a["segment"]["lat_deg"], b["lat_deg"]);
    }
    assert!(rep.join("segments.json").exists());
    // The GPS speed over the recording is carried for the report's figure: within the
    // recording, increasing in time, the records' mean speeds inside its range.
    let trace = res["drive_speed_trace"]
        .as_array()
        .expect("drive_speed_trace");
    assert!(trace.len() > 10, "{} points", trace.len());
    let pts: Vec<(f64, f64)> = trace
        .iter()
        .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect();
    assert!(pts.windows(2).all(|w| w[1].0 > w[0].0));
    let vmax = pts.iter().map(|p| p.1).fold(0.0, f64::max);
    for r in rr {
        let v = r["segment"]["mean_speed_kmh"].as_f64().unwrap();
        assert!(
            v > 0.0 && v <= vmax + 1e-9,
            "record speed {v}, trace max {vmax}"
        );
    }
    let html = std::fs::read_to_string(rep.join("index.html")).unwrap();
    assert!(html.contains("speed over the drive"));
}

#[test]
fn bad_input_is_one_line_with_exit_code_2_and_nothing_half_written() {
    let d = tempfile::tempdir().unwrap();
    let input = long_recording(d.path(), "r.f32", 500.0, 60.0, Some("2024-05-02T07:31:00Z"));
    let i = input.to_str().unwrap();
    let out = d.path().join("o");
    let o = out.to_str().unwrap();
    // A track of another day.
    let drive = simulate_drive(&DriveParams {
        start_unix_s: 1_714_635_060.0 + 86_400.0,
        ..DriveParams::new(60.0, 1)
    });
    let other_day = d.path().join("late.gpx");
    std::fs::write(&other_day, drive.to_gpx()).unwrap();
    fails_with(
        &["segment", i, "--gps", other_day.to_str().unwrap(), "-o", o],
        &["do not overlap", "late.gpx"],
    );
    assert!(!out.join("segments.json").exists());
    fails_with(
        &["analyze", i, "--gps", other_day.to_str().unwrap(), "-o", o],
        &["do not overlap"],
    );
    assert!(!out.join("results.json").exists());
    // Unparseable NMEA sentences are skipped and counted.
    let day = simulate_drive(&DriveParams::new(60.0, 1));
    let mut nmea = day.to_nmea();
    nmea.push_str("$GPRMC,broken*11\nnoise\n");
    let np = d.path().join("t.nmea");
    std::fs::write(&np, nmea).unwrap();
    let err = stderr(&ok(&[
        "segment",
        i,
        "--gps",
        np.to_str().unwrap(),
        "--plan-only",
        "-o",
        o,
    ]));
    assert!(err.contains("2 unparseable sentences skipped"), "{err}");
    // Timestamps going backwards.
    let mut csv: Vec<String> = day.to_csv().lines().map(str::to_string).collect();
    csv.swap(5, 6);
    let cp = d.path().join("back.csv");
    std::fs::write(&cp, csv.join("\n")).unwrap();
    fails_with(
        &["segment", i, "--gps", cp.to_str().unwrap(), "-o", o],
        &["backwards", "line 7"],
    );
    // A raw file that is not a whole number of frames (cut off mid-write).
    let bytes = std::fs::read(&input).unwrap();
    let cut = d.path().join("cut.f32");
    std::fs::write(&cut, &bytes[..bytes.len() - 3]).unwrap();
    std::fs::copy(d.path().join("r.f32.json"), d.path().join("cut.f32.json")).unwrap();
    let c = cut.to_str().unwrap();
    for args in [
        vec!["analyze", c, "-o", o],
        vec!["segment", c, "-o", o],
        vec![
            "resample",
            c,
            "--fs-out",
            "50",
            "--resampler",
            "fir",
            "-o",
            d.path().join("x.f32").to_str().unwrap(),
        ],
    ] {
        fails_with(&args, &["not a whole number", "truncate -s 239992"]);
    }
    assert!(!d.path().join("x.f32").exists() && !d.path().join("x.f32.partial").exists());
    // A WAV cut off mid-write: found while streaming; the output is removed.
    let rec = read_path(&input, &ReadOptions::default()).unwrap();
    let wav = d.path().join("cut.wav");
    write_path(&wav, &rec).unwrap();
    let wb = std::fs::read(&wav).unwrap();
    std::fs::write(&wav, &wb[..wb.len() / 2]).unwrap();
    let w = wav.to_str().unwrap();
    let res = d.path().join("res.csv");
    fails_with(
        &[
            "resample",
            w,
            "--fs-out",
            "50",
            "--resampler",
            "fir",
            "-o",
            res.to_str().unwrap(),
        ],
        &["cut off"],
    );
    assert!(!res.exists() && !d.path().join("res.csv.partial").exists());
    let seg = d.path().join("seg");
    fails_with(
        &["segment", w, "--by-vibration", "-o", seg.to_str().unwrap()],
        &["cut off"],
    );
    assert!(!seg.join("segments.json").exists());
    fails_with(&["analyze", w, "-o", o], &["cut off"]);
}
