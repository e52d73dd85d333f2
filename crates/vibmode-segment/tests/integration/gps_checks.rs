//! Issue 28: GPS values checked in every format (dropped and counted, or the file refused),
//! GGA-only tracks, RMC without a date, numeric sidecar start times, bounded segmentation
//! settings and short messages. Every input is built here.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};
use vibmode_segment::{
    by_gps, by_vibration, fixed_cuts, read_track, SegmentError, SegmentParams, SkipReason,
    TrackFormat,
};
use vibmode_signal::{open_stream, write_path, Channel, ReadOptions, Recording, StreamInfo};
use vibmode_vehicle::drive::{simulate_drive, DriveParams, PhaseKind};

const L: f64 = 10.24;

/// A raw f32 recording of `n` frames of noise; `start_time` written into the sidecar as given
/// (a JSON value).
fn recording(
    dir: &Path,
    name: &str,
    fs: f64,
    n: usize,
    start_time: Option<serde_json::Value>,
) -> PathBuf {
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
        v["start_time"] = s;
        std::fs::write(&side, v.to_string()).unwrap();
    }
    p
}

fn info(p: &Path) -> StreamInfo {
    open_stream(p, &ReadOptions::default())
        .unwrap()
        .info()
        .clone()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Every fix of a track is finite and in range.
fn assert_sane(t: &vibmode_segment::GpsTrack) {
    for f in &t.fixes {
        assert!(f.t_s.is_finite() && f.t_s.abs() <= vibmode_segment::GPS_TIME_ABS_MAX_S);
        assert!(f.lat_deg.is_finite() && f.lat_deg.abs() <= 90.0, "{f:?}");
        assert!(f.lon_deg.is_finite() && f.lon_deg.abs() <= 180.0, "{f:?}");
        if let Some(v) = f.speed_kmh {
            assert!(
                v.is_finite() && (0.0..=vibmode_segment::GPS_SPEED_KMH_MAX).contains(&v),
                "{f:?}"
            );
        }
    }
}

/// The issue's case: one `<speed>NaN</speed>` in a GPX track made every record's mean speed
/// NaN (null) and let stops and accelerations pass as records. Now the fix is dropped and
/// counted, and the segmentation equals the one of the track without that fix.
#[test]
fn a_nan_gpx_speed_is_dropped_and_counted_and_changes_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let drive = simulate_drive(&DriveParams::new(600.0, 5));
    let rec = recording(
        dir.path(),
        "r.f32",
        50.0,
        30_000,
        Some("2024-05-02T07:31:00Z".into()),
    );
    let info = info(&rec);
    let gpx = drive.to_gpx();
    let lines: Vec<&str> = gpx.lines().collect();
    // Point 200 (line 4 + 199) with a NaN speed; and the same track without that point.
    let k = 3 + 200;
    assert!(lines[k].contains("<speed>"));
    let mut with_nan: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    let start = with_nan[k].find("<speed>").unwrap();
    let end = with_nan[k].find("</speed>").unwrap();
    with_nan[k].replace_range(start + 7..end, "NaN");
    let mut without: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    without.remove(k);
    let a = read_track(&write(dir.path(), "nan.gpx", &with_nan.join("\n"))).unwrap();
    let b = read_track(&write(dir.path(), "without.gpx", &without.join("\n"))).unwrap();
    assert_sane(&a);
    assert_eq!(a.fixes, b.fixes);
    assert_eq!(a.n_read, drive.fixes.len());
    assert_eq!(
        a.dropped.get("speed not finite"),
        Some(&1),
        "{:?}",
        a.dropped
    );
    assert_eq!(
        a.dropped_note().unwrap(),
        format!(
            "dropped 1 of {} fixes: 1 speed not finite",
            drive.fixes.len()
        )
    );
    let p = SegmentParams::default();
    let sa = by_gps(&info, 30_000, &a, 0.0, L, &p).unwrap();
    let sb = by_gps(&info, 30_000, &b, 0.0, L, &p).unwrap();
    assert_eq!(sa.records, sb.records);
    assert!(!sa.records.is_empty());
    for r in &sa.records {
        assert!(r.meta.mean_speed_kmh.is_some_and(f64::is_finite));
    }
    assert_eq!(
        sa.gps
            .as_ref()
            .unwrap()
            .dropped_fixes
            .get("speed not finite"),
        Some(&1)
    );
}

/// CSV: latitude 95, longitude 400, latitude 1e300, speeds of 1e300 km/h, negative and NaN
/// were all accepted; each is dropped with its reason, the same reasons as the other formats.
#[test]
fn csv_values_out_of_range_are_dropped_by_reason() {
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("time,lat,lon,speed_kmh\n");
    for i in 0..100 {
        let (lat, lon, v) = match i {
            10 => ("95".to_string(), "17.1".to_string(), "30".to_string()),
            11 => ("48.1".to_string(), "400".to_string(), "30".to_string()),
            12 => ("1e300".to_string(), "17.1".to_string(), "30".to_string()),
            13 => ("48.1".to_string(), "17.1".to_string(), "1e300".to_string()),
            14 => ("48.1".to_string(), "17.1".to_string(), "-5".to_string()),
            15 => ("48.1".to_string(), "17.1".to_string(), "nan".to_string()),
            16 => ("nan".to_string(), "17.1".to_string(), "30".to_string()),
            17 => ("48.1".to_string(), "-inf".to_string(), "30".to_string()),
            _ => (
                format!("{:.6}", 48.1 + i as f64 * 1e-4),
                "17.1".to_string(),
                "30".to_string(),
            ),
        };
        csv.push_str(&format!("{},{lat},{lon},{v}\n", 1_714_635_060 + i));
    }
    // A NaN time too.
    csv.push_str("nan,48.2,17.1,30\n");
    let t = read_track(&write(dir.path(), "t.csv", &csv)).unwrap();
    assert_sane(&t);
    assert_eq!(t.n_read, 101);
    assert_eq!(t.fixes.len(), 92);
    let want: Vec<(&str, usize)> = vec![
        ("latitude not finite", 1),
        ("latitude out of range", 2),
        ("longitude not finite", 1),
        ("longitude out of range", 1),
        ("speed above the maximum", 1),
        ("speed negative", 1),
        ("speed not finite", 1),
        ("time not finite", 1),
    ];
    let got: Vec<(&str, usize)> = t.dropped.iter().map(|(k, v)| (k.as_str(), *v)).collect();
    assert_eq!(got, want);
    assert!(t.absolute);
}

/// NMEA: an RMC speed of 1e20 knots (1.85e20 km/h) and a latitude of 95 degrees were accepted.
#[test]
fn nmea_values_out_of_range_are_dropped_by_reason() {
    let dir = tempfile::tempdir().unwrap();
    let drive = simulate_drive(&DriveParams::new(60.0, 2));
    let mut lines: Vec<String> = drive.to_nmea().lines().map(str::to_string).collect();
    let resign = |body: &str| {
        let ck = body.bytes().fold(0u8, |a, b| a ^ b);
        format!("${body}*{ck:02X}")
    };
    let body = |l: &str| l[1..l.find('*').unwrap()].to_string();
    // Field 7 is the speed in knots, field 3 the latitude (ddmm.mmmm).
    let mut f: Vec<String> = body(&lines[20]).split(',').map(str::to_string).collect();
    f[7] = "100000000000000000000.0".into();
    lines[20] = resign(&f.join(","));
    let mut f: Vec<String> = body(&lines[21]).split(',').map(str::to_string).collect();
    f[3] = "9500.0000".into();
    lines[21] = resign(&f.join(","));
    let t = read_track(&write(dir.path(), "t.nmea", &lines.join("\n"))).unwrap();
    assert_sane(&t);
    let dropped: usize = t.dropped.values().sum();
    // The latitude may already be refused by the sentence parser (then counted as
    // unparseable); either way it is not a fix.
    assert_eq!(t.dropped.get("speed above the maximum"), Some(&1), "{t:?}");
    assert_eq!(
        t.fixes.len() + dropped + t.n_bad_sentences,
        drive.fixes.len(),
        "{:?} {}",
        t.dropped,
        t.n_bad_sentences
    );
    assert!(t.fixes.len() <= drive.fixes.len() - 2);
}

/// RMC sentences without a date were dropped while the message said "0 unparseable and 0
/// other sentences"; now they are counted with their reason.
#[test]
fn rmc_without_a_date_is_counted_with_its_reason() {
    let dir = tempfile::tempdir().unwrap();
    let drive = simulate_drive(&DriveParams::new(30.0, 1));
    let lines: Vec<String> = drive
        .to_nmea()
        .lines()
        .map(|l| {
            let mut f: Vec<String> = l[1..l.find('*').unwrap()]
                .split(',')
                .map(str::to_string)
                .collect();
            f[9] = String::new(); // the date
            let body = f.join(",");
            let ck = body.bytes().fold(0u8, |a, b| a ^ b);
            format!("${body}*{ck:02X}")
        })
        .collect();
    let e = read_track(&write(dir.path(), "nodate.nmea", &lines.join("\n")))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("{} RMC without a date", drive.fixes.len())),
        "{e}"
    );
    assert!(!e.contains('\n') && e.len() < 400, "{e}");
}

/// More than half the fixes invalid: the file is refused with one short line naming the counts.
#[test]
fn a_track_mostly_invalid_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("time,lat,lon,speed_kmh\n");
    for i in 0..10 {
        let lat = if i < 6 { "95" } else { "48.1" };
        csv.push_str(&format!("{},{lat},17.1,30\n", 100 + i));
    }
    let e = read_track(&write(dir.path(), "bad.csv", &csv)).unwrap_err();
    assert!(matches!(
        e,
        SegmentError::TooManyBadFixes {
            n_dropped: 6,
            n_read: 10,
            ..
        }
    ));
    let m = e.to_string();
    assert!(
        m.contains("6 of 10") && m.contains("6 latitude out of range") && m.len() < 400,
        "{m}"
    );
    // Every fix invalid: no usable fix, with the reasons.
    let e = read_track(&write(
        dir.path(),
        "all.csv",
        "time,lat,lon\n1,95,17\n2,96,17\n",
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("no usable fix") && e.contains("2 latitude out of range"),
        "{e}"
    );
}

/// Segments of a track on the recording: (start_s, mean speed) of each record.
fn segments_of(
    info: &StreamInfo,
    n: u64,
    path: &Path,
) -> (
    Vec<(f64, f64)>,
    vibmode_segment::Segmentation,
    vibmode_segment::GpsTrack,
) {
    let t = read_track(path).unwrap();
    let s = by_gps(info, n, &t, 0.0, L, &SegmentParams::default()).unwrap();
    (
        s.records
            .iter()
            .map(|r| (r.meta.start_s, r.meta.mean_speed_kmh.unwrap()))
            .collect(),
        s,
        t,
    )
}

/// The simulator's own drive written as GGA sentences only (no speed) gave 0 records: the
/// speed from fix-to-fix steps was swamped by the position noise. With the speed from the
/// positions over 8 s it segments like the same drive as RMC: records in cruising only, the
/// stops skipped as stops, and most of the RMC records found.
#[test]
fn a_gga_only_track_segments_like_the_rmc_track_of_the_same_drive() {
    let dir = tempfile::tempdir().unwrap();
    let (mut n_gga, mut n_rmc, mut n_common) = (0usize, 0usize, 0usize);
    for seed in 0..6u64 {
        let drive = simulate_drive(&DriveParams::new(900.0, seed));
        let rec = recording(dir.path(), &format!("r{seed}.f32"), 20.0, 18_000, None);
        let info = info(&rec);
        let (rmc, _, _) = segments_of(
            &info,
            18_000,
            &write(dir.path(), &format!("rmc{seed}.nmea"), &drive.to_nmea()),
        );
        let (gga, seg, t) = segments_of(
            &info,
            18_000,
            &write(dir.path(), &format!("gga{seed}.nmea"), &drive.to_nmea_gga()),
        );
        assert_eq!(t.format, TrackFormat::Nmea);
        assert!(t.fixes.iter().all(|f| f.speed_kmh.is_none()));
        for &(a, v) in &gga {
            let other: f64 = drive
                .phases_in(a, a + L)
                .iter()
                .filter(|(k, _)| *k != PhaseKind::Cruise)
                .map(|(_, o)| o)
                .sum();
            assert!(
                other <= 4.0,
                "seed {seed}: GGA record at {a:.1} s has {other:.1} s of {:?}",
                drive.phases_in(a, a + L)
            );
            assert!(v > 15.0 && v < 50.0, "seed {seed}: {v} km/h");
        }
        for ph in drive.phases.iter().filter(|ph| {
            ph.kind == PhaseKind::Stopped && ph.end_s - ph.start_s > 12.0 && ph.start_s > 1.0
        }) {
            let mid = (ph.start_s + ph.end_s) / 2.0;
            assert!(
                seg.skipped
                    .iter()
                    .any(|s| s.reason == SkipReason::Stop && s.start_s <= mid && s.end_s >= mid),
                "seed {seed}: stop at {mid:.0} s not skipped as a stop"
            );
        }
        n_gga += gga.len();
        n_rmc += rmc.len();
        n_common += gga
            .iter()
            .filter(|g| rmc.iter().any(|r| (r.0 - g.0).abs() < L / 2.0))
            .count();
    }
    eprintln!("GGA {n_gga} records, RMC {n_rmc}, {n_common} within half a record");
    assert!(n_rmc > 100, "{n_rmc}");
    assert!(n_gga as f64 >= 0.8 * n_rmc as f64, "{n_gga} of {n_rmc}");
    assert!(
        n_common as f64 >= 0.7 * n_rmc as f64,
        "{n_common} of {n_rmc}"
    );
}

/// A numeric sidecar start_time (seconds since 1970) was ignored: the track was then aligned by
/// its first fix. Now it aligns like the same time in RFC 3339; a start time of another type
/// is refused naming it.
#[test]
fn a_numeric_sidecar_start_time_is_seconds_since_1970() {
    let dir = tempfile::tempdir().unwrap();
    let drive = simulate_drive(&DriveParams::new(600.0, 4));
    let tp = write(dir.path(), "t.csv", &drive.to_csv());
    let t = read_track(&tp).unwrap();
    // The recording starts 100 s after the track.
    let text = recording(
        dir.path(),
        "a.f32",
        20.0,
        8_000,
        Some("2024-05-02T07:32:40Z".into()),
    );
    let num = recording(
        dir.path(),
        "b.f32",
        20.0,
        8_000,
        Some(serde_json::json!(1_714_635_160)),
    );
    let p = SegmentParams::default();
    let a = by_gps(&info(&text), 8_000, &t, 0.0, L, &p).unwrap();
    let b = by_gps(&info(&num), 8_000, &t, 0.0, L, &p).unwrap();
    assert_eq!(a.records, b.records);
    assert_eq!(b.start_time.as_deref(), Some("2024-05-02T07:32:40Z"));
    assert_eq!(
        b.gps.as_ref().unwrap().alignment.recording_start.as_deref(),
        Some("2024-05-02T07:32:40Z")
    );
    let bad = recording(
        dir.path(),
        "c.f32",
        20.0,
        8_000,
        Some(serde_json::json!(true)),
    );
    let e = by_gps(&info(&bad), 8_000, &t, 0.0, L, &p)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("'true'") && e.contains("seconds since 1970"),
        "{e}"
    );
}

/// step_s = 1e-9 ran for minutes; record_length_s = 1e-9 blamed window_s; offsets of 1e300
/// gave 300-digit messages. Each is refused before any work, naming the value given.
#[test]
fn segmentation_settings_are_bounded_against_the_recording() {
    let dir = tempfile::tempdir().unwrap();
    let drive = simulate_drive(&DriveParams::new(300.0, 1));
    let t = read_track(&write(dir.path(), "t.csv", &drive.to_csv())).unwrap();
    let rec = recording(dir.path(), "r.f32", 100.0, 30_000, None);
    let info = info(&rec);
    let step = SegmentParams {
        step_s: 1e-9,
        ..SegmentParams::default()
    };
    let e = by_gps(&info, 30_000, &t, 0.0, L, &step).unwrap_err();
    assert!(
        matches!(
            e,
            SegmentError::Param(vibmode_core::ParamError::OutOfRangeHere { name: "step_s", .. })
        ),
        "{e}"
    );
    let m = e.to_string();
    assert!(m.contains("step_s = 1e-9") && m.contains("0.01 s"), "{m}");
    // One sample is enough.
    let one = SegmentParams {
        step_s: 0.01,
        ..SegmentParams::default()
    };
    by_gps(&info, 30_000, &t, 0.0, L, &one).unwrap();
    for e in [
        fixed_cuts(&info, 30_000, 1e-9, &SegmentParams::default()).map(|_| ()),
        by_gps(&info, 30_000, &t, 0.0, 1e-9, &SegmentParams::default()).map(|_| ()),
    ] {
        let e = e.unwrap_err().to_string();
        assert!(
            e.contains("record_length_s = 1e-9") && !e.contains("window_s"),
            "{e}"
        );
    }
    let mut s = open_stream(&rec, &ReadOptions::default()).unwrap();
    let e = by_vibration(&mut s, 1e-9, &SegmentParams::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("record_length_s = 1e-9") && !e.contains("window_s ="),
        "{e}"
    );
    // A record of fewer than 16 samples is refused, 16 accepted.
    assert!(fixed_cuts(&info, 30_000, 0.15, &SegmentParams::default()).is_err());
    fixed_cuts(&info, 30_000, 0.16, &SegmentParams::default()).unwrap();
    // Offsets: bounded, and the message stays short.
    for off in [1e300, -1e300, 1.5e6, f64::NAN] {
        let e = by_gps(&info, 30_000, &t, off, L, &SegmentParams::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("gps_offset_s") && e.len() < 300, "{e}");
    }
    // Within the bound but far off: no overlap, and the numbers stay short.
    let e = by_gps(&info, 30_000, &t, -9e5, L, &SegmentParams::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("do not overlap") && e.len() < 400, "{e}");
}

/// A guard of 1e300 s took O(windows^2) work; it is clamped to the recording and every window
/// is then a transition or a stop.
#[test]
fn a_huge_guard_skips_everything_next_to_a_stop() {
    let dir = tempfile::tempdir().unwrap();
    let fs = 100.0;
    let n = 6000;
    let mut r = ChaCha8Rng::seed_from_u64(3);
    // 60 s of vibration with a quiet second in the middle.
    let z: Vec<f64> = (0..n)
        .map(|i| {
            let a = if (3000..3100).contains(&i) { 0.01 } else { 1.0 };
            a * r.gen_range(-1.0..1.0) + a * (i as f64 * 0.2).sin()
        })
        .collect();
    let rec = Recording {
        fs_hz: fs,
        channels: vec![Channel::new("z".to_string(), "m/s^2".to_string(), z)],
        time_axis: None,
    };
    let p = dir.path().join("v.f32");
    write_path(&p, &rec).unwrap();
    let mut s = open_stream(&p, &ReadOptions::default()).unwrap();
    let params = SegmentParams {
        guard_s: 1e300,
        ..SegmentParams::default()
    };
    let (seg, windows) = by_vibration(&mut s, L, &params).unwrap();
    assert!(seg.records.is_empty());
    assert!(windows.iter().all(|w| w.skip.is_some()));
    assert!(windows
        .iter()
        .any(|w| w.skip == Some(SkipReason::StopOrIdle)));
}

/// A 2 MB cell, binary bytes and terminal escapes were echoed into the message.
#[test]
fn messages_quote_at_most_a_short_printable_piece_of_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let big = "9".repeat(10).to_string() + &"x".repeat(2_000_000);
    for (name, text) in [
        ("big.csv", format!("time,lat,lon\n1,{big},17\n")),
        (
            "esc.csv",
            "time,lat,lon\n1,\u{1b}[31mred\u{7},17\n".to_string(),
        ),
        (
            "esct.csv",
            "time,lat,lon\n\u{1b}]0;title\u{7},48,17\n".to_string(),
        ),
        ("hdr.csv", format!("time,{big},lon\n1,48,17\n")),
    ] {
        let e = read_track(&write(dir.path(), name, &text))
            .unwrap_err()
            .to_string();
        assert!(e.len() < 400, "{name}: {} bytes", e.len());
        assert!(!e.chars().any(char::is_control), "{name}: {e:?}");
    }
    // Invalid UTF-8 in a CSV.
    let p = dir.path().join("bin.csv");
    std::fs::write(&p, b"time,lat,lon\n1,\xff\xfe\x1b[2J,17\n").unwrap();
    if let Err(e) = read_track(&p) {
        let e = e.to_string();
        assert!(e.len() < 400 && !e.chars().any(char::is_control), "{e:?}");
    }
}

/// GPX alone checked coordinate ranges (its reader refuses such a file as a whole); the
/// message now names the value in a short number (1e300 gave 300 digits) and stays one line.
#[test]
fn a_gpx_coordinate_out_of_range_is_refused_naming_the_value() {
    let dir = tempfile::tempdir().unwrap();
    let gpx = simulate_drive(&DriveParams::new(30.0, 1)).to_gpx();
    for (attr, v) in [("lat", "95"), ("lat", "1e300"), ("lon", "-400")] {
        let mut lines: Vec<String> = gpx.lines().map(str::to_string).collect();
        let l = &mut lines[10];
        let a = l.find(&format!("{attr}=\"")).unwrap() + attr.len() + 2;
        let b = a + l[a..].find('"').unwrap();
        l.replace_range(a..b, v);
        let e = read_track(&write(dir.path(), "c.gpx", &lines.join("\n")))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!(" {v} is outside")) && e.len() < 300 && !e.contains('\n'),
            "{e}"
        );
    }
}

/// GPX 1.1 with a namespace prefix, route points when there is no track, a point without a
/// time skipped, and the times read to the millisecond (by hand: 07:31:00Z is 1714635060 s).
#[test]
fn gpx_route_points_with_a_prefix_are_read_and_untimed_points_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let text = r#"<?xml version="1.0"?>
<g:gpx xmlns:g="http://www.topografix.com/GPX/1/1" version="1.1" creator="hand">
  <g:rte>
    <g:rtept lat="45.5" lon="9.25"><g:time>2024-05-02T07:31:00Z</g:time></g:rtept>
    <g:rtept lat="45.6" lon="9.35"></g:rtept>
    <g:rtept lat="-45.75" lon="-9.5"><g:time>2024-05-02T09:31:01.25+02:00</g:time></g:rtept>
  </g:rte>
</g:gpx>"#;
    let t = read_track(&write(dir.path(), "r.gpx", text)).unwrap();
    let got: Vec<(f64, f64, f64)> = t
        .fixes
        .iter()
        .map(|f| (f.t_s, f.lat_deg, f.lon_deg))
        .collect();
    assert_eq!(
        got,
        vec![(1714635060.0, 45.5, 9.25), (1714635061.25, -45.75, -9.5)]
    );
    assert!(t.fixes.iter().all(|f| f.speed_kmh.is_none()));
}

/// A time, a coordinate or a speed that is not what GPX allows refuses the file in one line
/// naming the point and the value.
#[test]
fn a_gpx_point_with_a_malformed_value_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    for (point, want) in [
        (
            r#"<trkpt lat="45" lon="9"><time>yesterday</time></trkpt>"#,
            "time yesterday is not an RFC 3339 time",
        ),
        (
            r#"<trkpt lat="north" lon="9"><time>2024-05-02T07:31:00Z</time></trkpt>"#,
            "lat north is not a number",
        ),
        (
            r#"<trkpt lon="9"><time>2024-05-02T07:31:00Z</time></trkpt>"#,
            "has no lat attribute",
        ),
        (
            r#"<trkpt lat="45" lon="9"><time>2024-05-02T07:31:00Z</time><speed>fast</speed></trkpt>"#,
            "speed fast is not a number",
        ),
    ] {
        let text = format!(r#"<gpx version="1.0"><trk><trkseg>{point}</trkseg></trk></gpx>"#);
        let e = read_track(&write(dir.path(), "m.gpx", &text))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("point 1") && e.contains(want) && !e.contains('\n'),
            "{e}"
        );
    }
    let text = r#"<gpx><trk><trkseg><trkpt lat="45" lon="9"/><trkpt lat="95" lon="9"/></trkseg></trk></gpx>"#;
    let e = read_track(&write(dir.path(), "r.gpx", text)).unwrap_err();
    assert!(
        matches!(
            &e,
            vibmode_segment::SegmentError::Track {
                problem: vibmode_segment::TrackProblem::CoordinateOutOfRange {
                    point: 2,
                    name: "lat",
                    value,
                    limit_deg,
                },
                ..
            } if *value == 95.0 && *limit_deg == 90.0
        ),
        "{e:?}"
    );
    let e = read_track(&write(dir.path(), "k.gpx", "<kml></kml>"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("<kml>, not <gpx>"), "{e}");
}
