//! Segmentation: by GPS against a simulated drive's truth (three track formats, many seeds), by
//! vibration on a synthetic drive and on the Bratislava bus, hand-checkable tracks, bad input.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};
use vibmode_segment::{
    by_gps, by_vibration, read_track, write_segments, SegmentParams, SkipReason, TrackFormat,
};
use vibmode_signal::{open_stream, read_path, write_path, Channel, ReadOptions, Recording};
use vibmode_vehicle::drive::{simulate_drive, DriveParams, PhaseKind};

const L: f64 = 10.24;

/// A raw f32 recording of `n` frames of noise with a sidecar holding `start_time`.
fn recording(dir: &Path, name: &str, fs: f64, n: usize, start_time: Option<&str>) -> PathBuf {
    let mut r = ChaCha8Rng::seed_from_u64(n as u64);
    let rec = Recording {
        fs_hz: fs,
        channels: vec![Channel::new(
            "z".to_string(),
            "m/s^2".to_string(),
            (0..n).map(|_| r.gen_range(-1.0..1.0)).collect(),
        )],
        time_axis: None,
    };
    let p = dir.join(name);
    write_path(&p, &rec).unwrap();
    if let Some(s) = start_time {
        let side = dir.join(format!("{name}.json"));
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&side).unwrap()).unwrap();
        v["start_time"] = s.into();
        std::fs::write(&side, v.to_string()).unwrap();
    }
    p
}

/// Says "skipped: <why>" when `what` (`shared`: the shared data folder, `chromium`: a headless
/// browser) is absent here; fails instead where CI requires it (`VIBMODE_REQUIRE=shared,chromium`,
/// set by `.ci/run` when the resource is present).
fn skipped(what: &str, why: &str) {
    let required = std::env::var("VIBMODE_REQUIRE").unwrap_or_default();
    assert!(
        !required.split(',').any(|r| r.trim() == what),
        "{why}, but VIBMODE_REQUIRE={required} requires it here"
    );
    eprintln!("skipped: {why}");
}

#[test]
fn gps_cuts_lie_in_steady_cruising_for_every_track_format_over_seeds() {
    let dir = tempfile::tempdir().unwrap();
    let p = SegmentParams::default();
    let mut total_records = 0;
    let mut total_possible = 0.0;
    for seed in 0..8u64 {
        let drive = simulate_drive(&DriveParams::new(900.0, seed));
        let rec = recording(
            dir.path(),
            &format!("d{seed}.f32"),
            50.0,
            45_000,
            Some("2024-05-02T07:31:00Z"),
        );
        let info = open_stream(&rec, &ReadOptions::default())
            .unwrap()
            .info()
            .clone();
        // Cruising time usable for whole records (2 s margin for the speed to settle).
        let possible: f64 = drive
            .phases
            .iter()
            .filter(|ph| ph.kind == PhaseKind::Cruise)
            .map(|ph| ((ph.end_s - ph.start_s - 2.0) / L).floor().max(0.0))
            .sum();
        for (ext, text) in [
            ("gpx", drive.to_gpx()),
            ("nmea", drive.to_nmea()),
            ("csv", drive.to_csv()),
        ] {
            let tp = dir.path().join(format!("track{seed}.{ext}"));
            std::fs::write(&tp, text).unwrap();
            let track = read_track(&tp).unwrap();
            assert_eq!(track.fixes.len(), drive.fixes.len(), "{ext}");
            assert!(track.absolute);
            let seg = by_gps(&info, 45_000, &track, 0.0, L, &p).unwrap();
            for r in &seg.records {
                let (a, b) = (r.meta.start_s, r.meta.start_s + r.meta.duration_s);
                let other: f64 = drive
                    .phases_in(a, b)
                    .iter()
                    .filter(|(k, _)| *k != PhaseKind::Cruise)
                    .map(|(_, o)| o)
                    .sum();
                assert!(
                    other <= 2.5,
                    "seed {seed} {ext}: record {a:.1}-{b:.1} s has {other:.1} s of {:?}",
                    drive.phases_in(a, b)
                );
                let v = r.meta.mean_speed_kmh.unwrap();
                assert!(v > 15.0 && v < 50.0, "{v}");
                assert!(r.meta.lat_deg.is_some() && r.meta.start_time.is_some());
            }
            // Every stop is skipped as a stop.
            for ph in drive.phases.iter().filter(|ph| {
                ph.kind == PhaseKind::Stopped && ph.end_s - ph.start_s > 6.0 && ph.start_s > 1.0
            }) {
                let mid = (ph.start_s + ph.end_s) / 2.0;
                assert!(
                    seg.skipped.iter().any(|s| s.reason == SkipReason::Stop
                        && s.start_s <= mid
                        && s.end_s >= mid),
                    "seed {seed} {ext}: stop at {mid:.0} s not skipped as a stop: {:?}",
                    seg.skipped
                );
            }
            assert!(
                seg.records.len() as f64 >= 0.6 * possible,
                "seed {seed} {ext}: {} records of {possible} possible",
                seg.records.len()
            );
            total_records += seg.records.len();
            total_possible += possible;
        }
    }
    eprintln!("{total_records} records cut of {total_possible} that fit in the cruising stretches");
    assert!(total_records > 100);
}

#[test]
fn a_hand_checkable_track_two_records_then_a_stop() {
    let dir = tempfile::tempdir().unwrap();
    // 10 m/s due north for 28 s, then standing; fixes every second.
    let mut csv = String::from("time_s;lat;lon;speed\n");
    for i in 0..=50 {
        let t = i as f64;
        let north = 10.0 * t.min(28.0);
        let v = if i <= 28 { 10.0 } else { 0.0 };
        csv.push_str(&format!("{t};{};17.0;{v}\n", 48.0 + north / 111_132.0));
    }
    let tp = dir.path().join("t.csv");
    std::fs::write(&tp, csv).unwrap();
    let track = read_track(&tp).unwrap();
    assert_eq!(track.format, TrackFormat::Csv);
    assert!(!track.absolute);
    let rec = recording(dir.path(), "r.f32", 100.0, 5_000, None);
    let info = open_stream(&rec, &ReadOptions::default())
        .unwrap()
        .info()
        .clone();
    let seg = by_gps(&info, 5_000, &track, 0.0, L, &SegmentParams::default()).unwrap();
    let starts: Vec<f64> = seg.records.iter().map(|r| r.meta.start_s).collect();
    assert_eq!(starts, [0.0, 10.24]);
    for r in &seg.records {
        assert!((r.meta.mean_speed_kmh.unwrap() - 36.0).abs() < 1e-9);
        assert_eq!(r.n_frames, 1024);
        assert!(
            (r.heading_deg.unwrap() - 0.0).abs() < 1.0
                || (r.heading_deg.unwrap() - 360.0).abs() < 1.0
        );
    }
    assert!(seg.skipped.iter().any(|s| s.reason == SkipReason::Stop));
    assert!(seg.records.iter().all(|r| r.meta.start_time.is_none()));
    // An offset of 25 s moves the track: the recording starts 25 s into the drive.
    let seg = by_gps(&info, 5_000, &track, -25.0, L, &SegmentParams::default()).unwrap();
    assert!(seg.records.is_empty(), "{:?}", seg.records);
}

/// Issue 29 item 5: a car dataset's `Timestamp,Lat_GNSS,Long_GNSS` track (Unix time in ms, no
/// speed column: the speed comes from the positions) segments as the same track written as
/// `time,lat,lon,speed` (Unix seconds, speed in m/s); two latitude columns are refused naming
/// both; an acceleration column `Long_Acc` is not taken for the longitude.
#[test]
fn gps_csv_columns_found_by_name_patterns() {
    let dir = tempfile::tempdir().unwrap();
    // 10 m/s due north for 38 s, then standing; fixes every second from 2024-05-02T07:31:00Z.
    let t0 = 1_714_635_060.0;
    let mut plain = String::from("time,lat,lon,speed\n");
    let mut car = String::from("Timestamp,Long_Acc,Lat_GNSS,Long_GNSS\n");
    // A phone app's date-times: a space, no offset (UTC).
    let mut phone = String::from("time,lat,lon\n");
    for i in 0..=60 {
        let t = i as f64;
        let north = 10.0 * t.min(38.0);
        let v = if i <= 38 { 10.0 } else { 0.0 };
        let lat = 48.0 + north / 111_195.08;
        plain.push_str(&format!("{},{lat},17.0,{v}\n", t0 + t));
        car.push_str(&format!("{},0.1,{lat},17.0\n", (t0 + t) as u64 * 1000));
        phone.push_str(&format!(
            "2024-05-02 07:{:02}:{:02}.000,{lat},17.0\n",
            31 + i / 60,
            i % 60
        ));
    }
    let phone_p = dir.path().join("phone.csv");
    std::fs::write(&phone_p, phone).unwrap();
    let c = read_track(&phone_p).unwrap();
    assert!(c.absolute);
    let plain_p = dir.path().join("plain.csv");
    let car_p = dir.path().join("car.csv");
    std::fs::write(&plain_p, plain).unwrap();
    std::fs::write(&car_p, &car).unwrap();
    let rec = recording(
        dir.path(),
        "r.f32",
        100.0,
        6_000,
        Some("2024-05-02T07:31:00Z"),
    );
    let info = open_stream(&rec, &ReadOptions::default())
        .unwrap()
        .info()
        .clone();
    let a = read_track(&plain_p).unwrap();
    let b = read_track(&car_p).unwrap();
    assert!(a.absolute && b.absolute);
    assert_eq!(a.fixes.len(), b.fixes.len());
    assert_eq!(a.fixes.len(), c.fixes.len());
    for ((x, y), z) in a.fixes.iter().zip(&b.fixes).zip(&c.fixes) {
        assert!((x.t_s - y.t_s).abs() < 1e-6, "{} {}", x.t_s, y.t_s);
        assert!((x.t_s - z.t_s).abs() < 1e-6, "{} {}", x.t_s, z.t_s);
        assert_eq!((x.lat_deg, x.lon_deg), (y.lat_deg, y.lon_deg));
        assert_eq!((x.lat_deg, x.lon_deg), (z.lat_deg, z.lon_deg));
        assert!(y.speed_kmh.is_none());
    }
    let p = SegmentParams::default();
    let sa = by_gps(&info, 6_000, &a, 0.0, L, &p).unwrap();
    let sb = by_gps(&info, 6_000, &b, 0.0, L, &p).unwrap();
    let starts = |s: &vibmode_segment::Segmentation| -> Vec<f64> {
        s.records.iter().map(|r| r.meta.start_s).collect()
    };
    assert_eq!(starts(&sa), [0.0, 10.24, 20.48]);
    assert_eq!(starts(&sb), starts(&sa));
    for (x, y) in sa.records.iter().zip(&sb.records) {
        assert_eq!(x.n_frames, y.n_frames);
        let (vx, vy) = (
            x.meta.mean_speed_kmh.unwrap(),
            y.meta.mean_speed_kmh.unwrap(),
        );
        assert!((vx - vy).abs() < 0.1, "{vx} {vy}");
    }
    // Two latitude candidates: one line naming both.
    let two = dir.path().join("two.csv");
    std::fs::write(&two, car.replace("Long_Acc", "lat_imu")).unwrap();
    let e = read_track(&two).unwrap_err().to_string();
    assert!(
        e.contains("two latitude columns")
            && e.contains("'lat_imu'")
            && e.contains("'Lat_GNSS'")
            && !e.contains('\n'),
        "{e}"
    );
    // A time column in milliseconds by its name, relative times.
    let rel = dir.path().join("rel.csv");
    let mut text = String::from("time_ms,latitude_deg,lng\n");
    for i in 0..=60 {
        text.push_str(&format!("{},{},17.0\n", i * 1000, 48.0 + i as f64 * 1e-4));
    }
    std::fs::write(&rel, text).unwrap();
    let r = read_track(&rel).unwrap();
    assert!(!r.absolute);
    // Two latitude words but only one exact name: the exact one is taken.
    let exact = dir.path().join("exact.csv");
    std::fs::write(
        &exact,
        "time,lat,lat_err,lon\n0,48.0,5.0,17.0\n1,48.0001,5.0,17.0\n",
    )
    .unwrap();
    assert_eq!(read_track(&exact).unwrap().fixes[1].lat_deg, 48.0001);
    assert_eq!(r.fixes[60].t_s, 60.0);
    assert_eq!(r.fixes[60].lat_deg, 48.0 + 60.0 * 1e-4);
}

#[test]
fn bad_tracks_one_line_errors_and_counted_nmea_sentences() {
    let dir = tempfile::tempdir().unwrap();
    let drive = simulate_drive(&DriveParams::new(120.0, 3));
    let rec = recording(
        dir.path(),
        "r.f32",
        50.0,
        6_000,
        Some("2024-05-02T07:31:00Z"),
    );
    let info = open_stream(&rec, &ReadOptions::default())
        .unwrap()
        .info()
        .clone();
    // NMEA with a bad checksum, garbage and another sentence type: skipped and counted.
    let mut lines: Vec<String> = drive.to_nmea().lines().map(str::to_string).collect();
    lines[10] = lines[10].replace('*', "*0");
    lines[11].truncate(20);
    lines.insert(5, "garbage line".into());
    lines.insert(
        6,
        "$GPGSV,3,1,11,03,03,111,00,04,15,270,00,06,01,010,00,13,06,292,00*74".into(),
    );
    let tp = dir.path().join("t.nmea");
    std::fs::write(&tp, lines.join("\n")).unwrap();
    let t = read_track(&tp).unwrap();
    assert_eq!(t.n_bad_sentences, 3, "{t:?}");
    assert_eq!(t.n_other_sentences, 1);
    assert_eq!(t.fixes.len(), drive.fixes.len() - 2);
    let seg = by_gps(&info, 6_000, &t, 0.0, L, &SegmentParams::default()).unwrap();
    assert_eq!(seg.gps.as_ref().unwrap().n_bad_sentences, 3);
    // Not overlapping: the recording starts a day later.
    let late = recording(
        dir.path(),
        "late.f32",
        50.0,
        6_000,
        Some("2024-05-03T07:31:00Z"),
    );
    let linfo = open_stream(&late, &ReadOptions::default())
        .unwrap()
        .info()
        .clone();
    let e = by_gps(&linfo, 6_000, &t, 0.0, L, &SegmentParams::default())
        .unwrap_err()
        .to_string();
    assert!(
        !e.contains('\n') && e.contains("do not overlap") && e.contains("-86400"),
        "{e}"
    );
    // Time going backwards names the line.
    let mut csv: Vec<String> = drive.to_csv().lines().map(str::to_string).collect();
    csv.swap(20, 21);
    let cp = dir.path().join("back.csv");
    std::fs::write(&cp, csv.join("\n")).unwrap();
    let e = read_track(&cp).unwrap_err().to_string();
    assert!(
        !e.contains('\n') && e.contains("backwards") && e.contains("line 22"),
        "{e}"
    );
    // Nothing usable.
    let np = dir.path().join("none.nmea");
    std::fs::write(&np, "$GPRMC,bad*00\nhello\n").unwrap();
    let e = read_track(&np).unwrap_err().to_string();
    assert!(
        e.contains("no usable fix") && e.contains("2 unparseable"),
        "{e}"
    );
    // A start time that is not RFC 3339.
    let bad = recording(dir.path(), "bad.f32", 50.0, 6_000, Some("yesterday"));
    let binfo = open_stream(&bad, &ReadOptions::default())
        .unwrap()
        .info()
        .clone();
    let e = by_gps(&binfo, 6_000, &t, 0.0, L, &SegmentParams::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("'yesterday'") && e.contains("RFC 3339"), "{e}");
}

/// A synthetic drive at 500 Hz with x, y, z: road vibration (1-8 Hz) while driving; at stops
/// only a 25 Hz idling line and sensor noise; a braking manoeuvre (x offset 2 m/s^2).
fn vibration_drive(seed: u64, dir: &Path) -> (PathBuf, Vec<(f64, f64, &'static str)>) {
    let fs = 500.0;
    let plan: Vec<(f64, f64, &'static str)> = vec![
        (0.0, 40.0, "drive"),
        (40.0, 44.0, "brake"),
        (44.0, 64.0, "stop"),
        (64.0, 130.0, "drive"),
        (130.0, 150.0, "stop"),
        (150.0, 200.0, "drive"),
    ];
    let n = (200.0 * fs) as usize;
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let mut chans = vec![vec![0.0; n]; 3];
    // Road input: a sum of random sines in 1-8 Hz.
    let tones: Vec<(f64, f64, usize)> = (0..30)
        .map(|k| {
            (
                r.gen_range(1.0..8.0),
                r.gen_range(0.0..std::f64::consts::TAU),
                k % 3,
            )
        })
        .collect();
    for i in 0..n {
        let t = i as f64 / fs;
        let kind = plan
            .iter()
            .find(|p| t >= p.0 && t < p.1)
            .map_or("drive", |p| p.2);
        for (c, ch) in chans.iter_mut().enumerate() {
            let mut v =
                0.02 * r.gen_range(-1.0..1.0) + 0.3 * (2.0 * std::f64::consts::PI * 25.0 * t).sin();
            if kind != "stop" {
                v += tones
                    .iter()
                    .filter(|x| x.2 == c)
                    .map(|x| 0.4 * (2.0 * std::f64::consts::PI * x.0 * t + x.1).sin())
                    .sum::<f64>();
            }
            if kind == "brake" && c == 0 {
                v += 2.0;
            }
            if c == 2 {
                v += 9.81;
            }
            ch[i] = v;
        }
    }
    let rec = Recording {
        fs_hz: fs,
        channels: ["x", "y", "z"]
            .iter()
            .zip(chans)
            .map(|(nm, d)| Channel::new(nm.to_string(), "m/s^2".to_string(), d))
            .collect(),
        time_axis: None,
    };
    let p = dir.join(format!("v{seed}.f32"));
    write_path(&p, &rec).unwrap();
    (p, plan)
}

#[test]
fn vibration_state_skips_stops_and_manoeuvres_over_seeds() {
    let dir = tempfile::tempdir().unwrap();
    for seed in 0..4 {
        let (p, plan) = vibration_drive(seed, dir.path());
        let mut s = open_stream(&p, &ReadOptions::default()).unwrap();
        let (seg, windows) = by_vibration(&mut s, L, &SegmentParams::default()).unwrap();
        assert_eq!(windows.len(), 200);
        for r in &seg.records {
            let (a, b) = (r.meta.start_s, r.meta.start_s + r.meta.duration_s);
            for (s0, s1, kind) in &plan {
                if *kind != "drive" {
                    assert!(
                        b <= *s0 || a >= *s1,
                        "seed {seed}: record {a}-{b} overlaps {kind} {s0}-{s1}"
                    );
                }
            }
        }
        // 40 + 66 + 50 s of driving: at least 11 records fit after the guards.
        assert!(seg.records.len() >= 11, "{}", seg.records.len());
        let stop_s = seg
            .skipped_s_by_reason
            .get("stop-or-idle")
            .copied()
            .unwrap_or(0.0);
        assert!((36.0..=42.0).contains(&stop_s), "{stop_s}");
        assert!(
            seg.skipped
                .iter()
                .any(|s| s.reason == SkipReason::Manoeuvre && s.start_s >= 39.0 && s.end_s <= 45.0),
            "{:?}",
            seg.skipped
        );
    }
}

#[test]
fn written_records_equal_the_recording_slices_and_a_cut_off_file_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (p, _) = vibration_drive(7, dir.path());
    let mut s = open_stream(&p, &ReadOptions::default()).unwrap();
    let (mut seg, _) = by_vibration(&mut s, L, &SegmentParams::default()).unwrap();
    let out = dir.path().join("out");
    let w = write_segments(
        open_stream(&p, &ReadOptions::default()).unwrap(),
        &mut seg,
        &out,
        "f32",
    )
    .unwrap();
    assert_eq!(w.records.len(), seg.records.len());
    let whole = read_path(&p, &ReadOptions::default()).unwrap();
    for (f, r) in w.records.iter().zip(&seg.records) {
        let got = read_path(f, &ReadOptions::default()).unwrap();
        let a = r.start_frame as usize;
        for (g, c) in got.channels.iter().zip(&whole.channels) {
            assert_eq!(g.samples, c.samples[a..a + r.n_frames]);
        }
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&w.segments_json).unwrap()).unwrap();
    assert_eq!(json["records"][0]["file"], "record_0001.f32");
    assert_eq!(json["method"], "vibration");
    // The same plan on a WAV cut off mid-write: the error comes while writing, nothing stays.
    let wav = dir.path().join("cut.wav");
    write_path(&wav, &whole).unwrap();
    let bytes = std::fs::read(&wav).unwrap();
    std::fs::write(&wav, &bytes[..bytes.len() / 2]).unwrap();
    let out2 = dir.path().join("out2");
    let e = write_segments(
        open_stream(&wav, &ReadOptions::default()).unwrap(),
        &mut seg,
        &out2,
        "wav",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("cut off"), "{e}");
    let left: Vec<_> = std::fs::read_dir(&out2).unwrap().collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn bratislava_bus_stop_is_skipped() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/real/bratislava_transit/L35_1915_Borska_Zaluhy.csv");
    if !p.exists() {
        skipped("shared", &format!("{} not present", p.display()));
        return;
    }
    let opts = ReadOptions {
        fs_hz: Some(500.0),
        ..ReadOptions::default()
    };
    let mut s = open_stream(&p, &opts).unwrap();
    let (seg, _) = by_vibration(&mut s, L, &SegmentParams::default()).unwrap();
    // The bus stands at Borska from about 41 s to 59 s (x RMS 0.02 m/s^2 against 0.1-0.2 while
    // driving): skipped, and no record overlaps it.
    assert!(
        seg.skipped
            .iter()
            .any(|s| s.reason == SkipReason::StopOrIdle && s.start_s <= 45.0 && s.end_s >= 55.0),
        "{:?}",
        seg.skipped
    );
    for r in &seg.records {
        assert!(
            r.meta.start_s + r.meta.duration_s <= 41.0 || r.meta.start_s >= 59.0,
            "{r:?}"
        );
    }
    assert!(seg.records.len() >= 8);
}
