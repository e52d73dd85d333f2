//! Issue 28 on the command line: GPS values checked (dropped and counted on stderr and in
//! segments.json, through `segment` and `analyze --gps`), segmentation settings bounded with
//! the value given named, no staging folder left behind, short messages, and `simulate`'s
//! speed, minimum speed and WAV rate.

use std::path::{Path, PathBuf};

use crate::common;

use common::{fails_with, ok, stderr};
use vibmode_signal::{write_path, Channel, Recording};
use vibmode_vehicle::drive::{simulate_drive, DriveParams, PhaseKind};

/// A raw f32 recording of `seconds` at `fs` (two channels of sines and a little noise)
/// starting at 2024-05-02T07:31:00Z.
fn recording(dir: &Path, name: &str, fs: f64, seconds: f64) -> PathBuf {
    let n = (fs * seconds) as usize;
    let ch = |f: f64| -> Vec<f64> {
        (0..n)
            .map(|i| {
                let t = i as f64 / fs;
                (2.0 * std::f64::consts::PI * f * t).sin()
                    + 0.05 * (((i * 7919) % 1013) as f64 / 1013.0 - 0.5)
            })
            .collect()
    };
    let rec = Recording {
        fs_hz: fs,
        channels: vec![
            Channel::new("FL".to_string(), "m/s^2".to_string(), ch(3.0)),
            Channel::new("FR".to_string(), "m/s^2".to_string(), ch(7.0)),
        ],
        time_axis: None,
    };
    let p = dir.join(name);
    write_path(&p, &rec).unwrap();
    let side = dir.join(format!("{name}.json"));
    let text = std::fs::read_to_string(&side).unwrap();
    let text = text.replacen('{', "{\n  \"start_time\": \"2024-05-02T07:31:00Z\",", 1);
    std::fs::write(&side, text).unwrap();
    p
}

/// Hidden entries (staging folders of an output) left in `dir`.
fn hidden(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with('.'))
        .collect()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn example(name: &str) -> String {
    format!("{}/examples/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// A GPX `<speed>NaN</speed>` gave `mean_speed_kmh: null` and cut stops and accelerations
/// as records, through `segment` and `analyze --gps`. Now the fix is dropped, the note is one
/// line on stderr and the count is in segments.json; every record's speed is a number.
#[test]
fn a_nan_gpx_speed_is_dropped_with_a_note_in_segment_and_analyze() {
    let d = tempfile::tempdir().unwrap();
    let input = recording(d.path(), "r.f32", 100.0, 300.0);
    let drive = simulate_drive(&DriveParams::new(300.0, 7));
    let gpx = drive.to_gpx();
    let mut lines: Vec<String> = gpx.lines().map(str::to_string).collect();
    // Point 150 is line 4 + 149 (three header lines).
    let k = 3 + 150;
    let a = lines[k].find("<speed>").unwrap() + 7;
    let b = lines[k].find("</speed>").unwrap();
    lines[k].replace_range(a..b, "NaN");
    let track = d.path().join("t.gpx");
    std::fs::write(&track, lines.join("\n")).unwrap();
    let out = d.path().join("seg");
    let o = ok(&[
        "segment",
        s(&input),
        "--gps",
        s(&track),
        "--plan-only",
        "-o",
        s(&out),
    ]);
    let err = stderr(&o);
    let note = format!(
        "dropped 1 of {} fixes: 1 speed not finite",
        drive.fixes.len()
    );
    assert!(err.contains(&note), "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("segments.json")).unwrap()).unwrap();
    assert_eq!(json["gps"]["dropped_fixes"]["speed not finite"], 1);
    assert_eq!(json["gps"]["n_fixes"], drive.fixes.len() - 1);
    let recs = json["records"].as_array().unwrap();
    assert!(!recs.is_empty());
    for r in recs {
        let v = r["mean_speed_kmh"].as_f64().expect("a number");
        assert!(v > 10.0, "{v}");
    }
    let rep = d.path().join("rep");
    let o = ok(&[
        "analyze",
        s(&input),
        "--gps",
        s(&track),
        "-q",
        "-o",
        s(&rep),
    ]);
    assert!(stderr(&o).contains(&note), "{}", stderr(&o));
    let res: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(rep.join("results.json")).unwrap()).unwrap();
    let rr = res["records"].as_array().unwrap();
    assert_eq!(rr.len(), recs.len());
    for r in rr {
        assert!(r["segment"]["mean_speed_kmh"].as_f64().is_some(), "{r}");
    }
}

/// step_s = 1e-9 ran for minutes and a killed run left its hidden staging folder. Now the step
/// is bounded (refused before any work, nothing left behind), and a stale staging folder of a
/// killed run is cleared by the next run into the same output.
#[test]
fn segmentation_steps_are_bounded_and_no_staging_folder_is_left() {
    let d = tempfile::tempdir().unwrap();
    let input = recording(d.path(), "r.f32", 100.0, 120.0);
    let track = d.path().join("t.csv");
    std::fs::write(&track, simulate_drive(&DriveParams::new(120.0, 2)).to_csv()).unwrap();
    let cfg = d.path().join("seg.toml");
    let out = d.path().join("out");
    for step in ["1e-9", "1e-6"] {
        std::fs::write(&cfg, format!("step_s = {step}\n")).unwrap();
        let e = fails_with(
            &[
                "segment",
                s(&input),
                "--gps",
                s(&track),
                "--segment-config",
                s(&cfg),
                "-o",
                s(&out),
            ],
            &[&format!("step_s = {step}"), "0.01 s", "--segment-config"],
        );
        assert!(!e.contains(".vibmode-"), "{e}");
        assert!(hidden(d.path()).is_empty(), "{:?}", hidden(d.path()));
        assert!(!out.exists());
    }
    // A killed run's staging folder: the next run clears it and succeeds.
    let stale = d.path().join(".out.vibmode-new-killed");
    std::fs::create_dir(&stale).unwrap();
    std::fs::write(stale.join("record_0001.f32"), b"half").unwrap();
    std::fs::write(&cfg, "step_s = 0.5\n").unwrap();
    ok(&[
        "segment",
        s(&input),
        "--gps",
        s(&track),
        "--segment-config",
        s(&cfg),
        "-o",
        s(&out),
    ]);
    assert!(out.join("segments.json").exists());
    assert!(hidden(d.path()).is_empty(), "{:?}", hidden(d.path()));
}

/// `--record-length-s 1e-9` blamed `window_s = 1`, a setting never given; offsets of +-1e300
/// gave 1.2 kB messages.
#[test]
fn errors_name_the_value_given_in_short_numbers() {
    let d = tempfile::tempdir().unwrap();
    let input = recording(d.path(), "r.f32", 100.0, 60.0);
    let track = d.path().join("t.csv");
    std::fs::write(&track, simulate_drive(&DriveParams::new(60.0, 2)).to_csv()).unwrap();
    let out = d.path().join("out");
    for extra in [vec![], vec!["--by-vibration"], vec!["--gps", s(&track)]] {
        let mut args = vec!["segment", s(&input), "--record-length-s", "1e-9"];
        args.extend(extra);
        args.extend(["-o", s(&out)]);
        let e = fails_with(&args, &["record_length_s = 1e-9", "--record-length-s"]);
        assert!(!e.contains("window_s"), "{e}");
    }
    for off in ["1e300", "-1e300"] {
        fails_with(
            &[
                "segment",
                s(&input),
                "--gps",
                s(&track),
                "--gps-offset-s",
                off,
                "-o",
                s(&out),
            ],
            &[&format!("gps_offset_s = {off}"), "--gps-offset-s"],
        );
    }
    assert!(hidden(d.path()).is_empty());
}

/// A 2 MB GPS CSV cell gave 2 MB of stderr; terminal escapes were echoed.
#[test]
fn gps_csv_cells_are_quoted_short_and_printable() {
    let d = tempfile::tempdir().unwrap();
    let input = recording(d.path(), "r.f32", 100.0, 30.0);
    let out = d.path().join("out");
    for (name, cell) in [
        ("big.csv", "7".repeat(2_000_000)),
        ("esc.csv", "\u{1b}]0;pwned\u{7}\u{1b}[2J".to_string()),
    ] {
        let track = d.path().join(name);
        std::fs::write(
            &track,
            format!("time,lat,lon,speed_kmh\n1714635060,x{cell},17.1,30\n"),
        )
        .unwrap();
        let e = fails_with(
            &["segment", s(&input), "--gps", s(&track), "-o", s(&out)],
            &["latitude", "is not a number"],
        );
        assert!(!e.contains('\u{1b}') && !e.contains('\u{7}'), "{e:?}");
    }
}

/// `simulate --gps-track` cruised at 30 km/h whatever `--speed-kmh`; `--speed-kmh 1`, the
/// documented minimum, was refused; `--fs 200.5` failed after simulating, naming the staging
/// folder.
#[test]
fn simulate_speed_and_rate() {
    let d = tempfile::tempdir().unwrap();
    let bus = example("city_bus.toml");
    let slow = d.path().join("slow");
    ok(&[
        "simulate",
        &bus,
        "--speed-kmh",
        "1",
        "--records",
        "2",
        "--fs",
        "200",
        "-o",
        s(&slow),
    ]);
    assert!(slow.join("record_01.wav").exists() && slow.join("record_02.wav").exists());
    // The track cruises at the speed given.
    for speed in [15.0, 120.0] {
        let out = d.path().join(format!("gps{speed}"));
        let sp = format!("{speed}");
        ok(&[
            "simulate",
            &bus,
            "--speed-kmh",
            &sp,
            "--records",
            "8",
            "--duration-s",
            "40",
            "--fs",
            "100",
            "--effects",
            "none",
            "--gps-track",
            "-o",
            s(&out),
        ]);
        let drive: vibmode_vehicle::drive::Drive =
            serde_json::from_str(&std::fs::read_to_string(out.join("drive_truth.json")).unwrap())
                .unwrap();
        let cruise: Vec<f64> = drive
            .fixes
            .iter()
            .filter(|f| {
                drive
                    .phases_in(f.t_s - 0.5, f.t_s + 0.5)
                    .iter()
                    .all(|(k, _)| *k == PhaseKind::Cruise)
            })
            .map(|f| f.speed_kmh)
            .collect();
        assert!(
            cruise.len() > 30,
            "{speed}: {} cruising fixes",
            cruise.len()
        );
        let mean = cruise.iter().sum::<f64>() / cruise.len() as f64;
        assert!(
            mean > 0.6 * speed && mean < 1.4 * speed,
            "--speed-kmh {speed}: the track cruises at {mean:.1} km/h"
        );
    }
    // A WAV rate that is not a whole number: refused before any work, naming the value.
    let bad = d.path().join("bad");
    let e = fails_with(
        &["simulate", &bus, "--fs", "200.5", "-o", s(&bad)],
        &["--fs 200.5", "whole"],
    );
    assert!(!e.contains(".vibmode-"), "{e}");
    assert!(!bad.exists());
    assert!(hidden(d.path()).is_empty(), "{:?}", hidden(d.path()));
    // The same rate in CSV is fine.
    ok(&[
        "simulate",
        &bus,
        "--fs",
        "200.5",
        "--records",
        "1",
        "--format",
        "csv",
        "-o",
        s(&bad),
    ]);
}

/// The segmentation config: a 500 kB key or a terminal escape in it is not echoed; the unknown
/// key is named (short) with its line.
#[test]
fn segment_config_errors_are_short() {
    let d = tempfile::tempdir().unwrap();
    let input = recording(d.path(), "r.f32", 100.0, 30.0);
    let cfg = d.path().join("seg.toml");
    let out = d.path().join("out");
    for (text, needles) in [
        (
            "step_s = 1\nmin_sped_kmh = 20\n".to_string(),
            vec!["line 2", "min_sped_kmh"],
        ),
        (format!("{} = 1\n", "k".repeat(500_000)), vec!["line 1"]),
        ("\u{1b}[2J = 1\n".to_string(), vec!["line 1"]),
    ] {
        std::fs::write(&cfg, text).unwrap();
        let e = fails_with(
            &[
                "segment",
                s(&input),
                "--segment-config",
                s(&cfg),
                "-o",
                s(&out),
            ],
            &needles,
        );
        assert!(!e.contains('\u{1b}'), "{e:?}");
    }
}

/// `segment` writes each WAV or raw record's absolute start into its sidecar (`start_time`, the
/// recording's sidecar start plus the record's offset), and the readers give it back as the
/// record's start (`TimeAxis::start_unix_s`), which `fleet check` groups into drives by day;
/// a sidecar's `start_time` that is no time is refused in one line.
#[test]
fn segmented_records_carry_their_start_in_the_sidecar() {
    let d = tempfile::tempdir().unwrap();
    // 2024-05-02T07:31:00Z, by hand: 19845 days after 1970-01-01, plus 7 h 31 min.
    let t0 = 19845.0 * 86400.0 + 7.0 * 3600.0 + 31.0 * 60.0;
    for (name, ext) in [("r.wav", "wav"), ("r.f32", "f32")] {
        let input = recording(d.path(), name, 100.0, 60.0);
        let out = d.path().join(format!("seg-{ext}"));
        ok(&["segment", s(&input), "-o", s(&out)]);
        let third = out.join(format!("record_0003.{ext}"));
        let side: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(out.join(format!("record_0003.{ext}.json"))).unwrap(),
        )
        .unwrap();
        assert_eq!(side["start_time"], "2024-05-02T07:31:20.48Z", "{side}");
        let rec = vibmode_signal::read_path(&third, &Default::default()).unwrap();
        let start = rec.time_axis.as_ref().and_then(|t| t.start_unix_s());
        assert_eq!(start, Some(t0 + 20.48), "{ext}");
        // The input's own start is read too, as a number of seconds since 1970 as well.
        let rec = vibmode_signal::read_path(&input, &Default::default()).unwrap();
        assert_eq!(rec.time_axis.and_then(|t| t.start_unix_s()), Some(t0));
        let side_path = d.path().join(format!("{name}.json"));
        let text = std::fs::read_to_string(&side_path).unwrap();
        let numeric = text.replacen("\"2024-05-02T07:31:00Z\"", &format!("{t0}"), 1);
        std::fs::write(&side_path, &numeric).unwrap();
        let rec = vibmode_signal::read_path(&input, &Default::default()).unwrap();
        assert_eq!(rec.time_axis.and_then(|t| t.start_unix_s()), Some(t0));
        let bad = text.replacen("\"2024-05-02T07:31:00Z\"", "\"yesterday\"", 1);
        std::fs::write(&side_path, bad).unwrap();
        fails_with(
            &["psd", s(&input)],
            &["start_time \"yesterday\"", "ISO 8601", "fix or delete it"],
        );
    }
}
