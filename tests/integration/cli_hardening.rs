//! Issue 15's reproducers: each input that once gave a silent non-finite result, a hang, an
//! abort or a half-written output now ends with exit 0 and finite outputs, or exit 2 and one
//! line naming the value and the fix. The inputs are built here in a few lines (no committed
//! binaries). A run that hangs is killed after a generous limit and fails the test (a hang
//! guard, not a timing measurement).

use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::Duration;

use crate::common;

use common::{bin, fails_with, ok, vibmode};

/// A CSV of `n` rows: a time column at `fs` Hz and the given columns.
fn csv(path: &Path, fs: f64, n: usize, cols: &[(&str, &dyn Fn(usize) -> f64)]) {
    let mut s = String::from("time_s");
    for (name, _) in cols {
        s.push(',');
        s.push_str(name);
    }
    s.push('\n');
    for i in 0..n {
        s.push_str(&format!("{}", i as f64 / fs));
        for (_, f) in cols {
            s.push_str(&format!(",{}", f(i)));
        }
        s.push('\n');
    }
    std::fs::write(path, s).unwrap();
}

/// Deterministic pseudo-noise in [-0.5, 0.5).
fn noise(i: usize) -> f64 {
    ((i.wrapping_mul(2654435761) % 1_000_003) as f64 / 1_000_003.0) - 0.5
}

fn tone(i: usize) -> f64 {
    (2.0 * std::f64::consts::PI * 3.0 * i as f64 / 50.0).sin() + noise(i)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn extreme_sample_magnitudes_are_refused_not_turned_into_nan() {
    let d = tempfile::tempdir().unwrap();
    let big = d.path().join("big.csv");
    csv(&big, 200.0, 2048, &[("a", &|i| 1e155 * tone(i))]);
    fails_with(
        &["psd", s(&big)],
        &["beyond the largest magnitude", "rescale"],
    );
    let out = d.path().join("r.csv");
    fails_with(
        &["resample", s(&big), "--fs-out", "50", "-o", s(&out)],
        &["1e60"],
    );
    assert!(!out.exists());
    let tiny = d.path().join("tiny.csv");
    csv(&tiny, 200.0, 2048, &[("a", &|i| 1e-200 * tone(i))]);
    fails_with(&["fit", s(&tiny), "--order", "4"], &["below the smallest"]);
    // Large but representable values are fine, and every number printed is finite.
    let large = d.path().join("large.csv");
    csv(&large, 200.0, 2048, &[("a", &|i| 1e50 * tone(i))]);
    let o = ok(&["psd", s(&large), "--json", "-"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let psd = v["channels"][0]["psd"].as_array().unwrap();
    assert!(psd.len() > 100);
    assert!(
        psd.iter()
            .all(|p| p.as_f64().is_some_and(|p| p.is_finite() && p >= 0.0)),
        "a PSD value is not a finite number"
    );
}

#[test]
fn resource_bombs_are_refused_in_seconds() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("a.csv");
    csv(&f, 200.0, 2048, &[("a", &tone)]);
    let out = d.path().join("x.csv");
    fails_with(
        &["resample", s(&f), "--fs-out", "1e20", "-o", s(&out)],
        &["1e20", "outside"],
    );
    fails_with(
        &["resample", s(&f), "--fs-out", "1e7", "-o", s(&out)],
        &["upsamples at most 16"],
    );
    assert!(!out.exists());
    // An analysis rate far above the record's.
    let cfg = d.path().join("fast.toml");
    std::fs::write(&cfg, "[preprocess]\nanalysis_fs_hz = 1e5\ncutoff_hz = 25\n").unwrap();
    let o = d.path().join("o1");
    fails_with(
        &["analyze", s(&f), "--config", s(&cfg), "-o", s(&o)],
        &["analysis_fs_hz", "500 times"],
    );
    // A time column in minutes over values in ms: 1/300 Hz.
    let m = d.path().join("minutes.csv");
    let mut text = String::from("time (min),a\n");
    for i in 0..2048 {
        text.push_str(&format!("{},{}\n", i * 5, tone(i)));
    }
    std::fs::write(&m, text).unwrap();
    fails_with(
        &["analyze", s(&m), "-o", s(&o)],
        &["analysis_fs_hz", "unit of the time column"],
    );
    // A sidecar rate of 1e-300 Hz.
    let raw = d.path().join("r.f32");
    std::fs::write(&raw, vec![0u8; 4 * 1000]).unwrap();
    std::fs::write(
        d.path().join("r.f32.json"),
        r#"{"fs_hz": 1e-300, "dtype": "f32", "channels": ["z"]}"#,
    )
    .unwrap();
    fails_with(&["psd", s(&raw)], &["1e-300", "outside"]);
    // A clustering tolerance that would need 10^9 grid cells per pole.
    let c = d.path().join("c.toml");
    std::fs::write(&c, "[cluster]\nfreq_tol_rel = 1e-9\n").unwrap();
    fails_with(
        &["analyze", s(&f), "--config", s(&c), "-o", s(&o)],
        &["freq_tol_rel = 1e-9", "[1e-4, 1]"],
    );
    // A header of 166 666 columns.
    let wide = d.path().join("wide.csv");
    let header: Vec<String> = (0..166_666).map(|i| format!("c{i}")).collect();
    let row: Vec<&str> = vec!["1"; 166_666];
    std::fs::write(
        &wide,
        format!(
            "{}\n{}\n{}\n",
            header.join(","),
            row.join(","),
            row.join(",")
        ),
    )
    .unwrap();
    fails_with(
        &["psd", s(&wide), "--fs", "100"],
        &["166666 channels", "1024"],
    );
    // A configuration without end.
    fails_with(
        &["analyze", s(&f), "--config", "/dev/zero", "-o", s(&o)],
        &["larger than"],
    );
    assert!(!o.exists(), "an output folder was left behind");
}

#[test]
fn outputs_are_checked_before_any_work_and_never_half_written() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("a.csv");
    csv(&f, 200.0, 2048, &[("a", &tone)]);
    let c = d.path().join("c.csv");
    fails_with(
        &["psd", s(&f), "--csv", s(&c), "--fmax=-5"],
        &["--fmax -5", "positive"],
    );
    assert!(!c.exists());
    let r = d.path().join("r.csv");
    fails_with(
        &[
            "resample",
            s(&f),
            "--fs-out",
            "50",
            "-o",
            s(&r),
            "--plot-seconds=-1",
        ],
        &["--plot-seconds -1"],
    );
    assert!(!r.exists());
    // No folder is created for a single file.
    let p = d.path().join("no/such/dir/p.svg");
    fails_with(&["psd", s(&f), "--plot", s(&p)], &["does not exist"]);
    assert!(!d.path().join("no").exists());
    fails_with(
        &["psd", s(&f), "--plot", s(&d.path().join("p.pdf"))],
        &[".svg or .png"],
    );
    // The input is never the output.
    fails_with(
        &["resample", s(&f), "--fs-out", "50", "-o", s(&f)],
        &["is an input file"],
    );
    assert!(std::fs::read_to_string(&f)
        .unwrap()
        .starts_with("time_s,a\n"));
    // A report folder must be new, empty, or an earlier output; inputs never inside it.
    let mine = d.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("thesis.tex"), "keep me").unwrap();
    fails_with(
        &["analyze", s(&f), "-o", s(&mine)],
        &["holds no earlier vibmode output"],
    );
    assert_eq!(
        std::fs::read_to_string(mine.join("thesis.tex")).unwrap(),
        "keep me"
    );
    let inside = mine.join("in.csv");
    std::fs::copy(&f, &inside).unwrap();
    std::fs::write(mine.join("results.json"), "{}").unwrap();
    fails_with(
        &["analyze", s(&inside), "-o", s(&mine)],
        &["inside the output folder"],
    );
    fails_with(
        &["analyze", s(&f), "-o", s(&d.path().join("no/report"))],
        &["does not exist"],
    );
}

#[test]
fn a_second_run_into_a_locked_folder_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("a.csv");
    csv(&f, 50.0, 1024, &[("a", &tone)]);
    let out = d.path().join("report");
    std::fs::create_dir(&out).unwrap();
    // Hold the folder's lock as a running vibmode would.
    let lock = std::fs::File::open(&out).unwrap();
    rustix::fs::flock(&lock, rustix::fs::FlockOperation::NonBlockingLockExclusive).unwrap();
    fails_with(
        &["analyze", s(&f), "-o", s(&out), "-q"],
        &["another vibmode run is writing"],
    );
    drop(lock);
    // A child that another test thread forks at this moment holds a copy of the lock until its
    // exec: wait for that, a few times at most.
    for _ in 0..20 {
        let o = vibmode(&["analyze", s(&f), "-o", s(&out), "-q"]);
        if !String::from_utf8_lossy(&o.stderr).contains("another vibmode run") {
            break;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    ok(&["analyze", s(&f), "-o", s(&out), "-q"]);
    assert!(out.join("results.json").exists() && out.join("index.html").exists());
}

#[test]
fn messages_are_short_and_plain() {
    let d = tempfile::tempdir().unwrap();
    // Binary garbage named .csv.
    let g = d.path().join("garbage.csv");
    let bytes: Vec<u8> = (0..3000u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
        .collect();
    std::fs::write(&g, bytes).unwrap();
    let e = fails_with(&["psd", s(&g), "--fs", "100"], &["not a text file"]);
    assert!(e.chars().all(|c| !c.is_control() || c == '\n'), "{e:?}");
    // A vehicle key without a value.
    let v = d.path().join("v.toml");
    std::fs::write(&v, "[body]\nmass_kg =\n").unwrap();
    fails_with(&["fullcar", s(&v)], &["mass_kg has no value"]);
    // Values far outside a vehicle's, and no Rust debug text.
    let base = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/city_bus.toml"),
    )
    .unwrap();
    let bad = base.replace("track_front_m = ", "track_front_m = 1e10 #");
    assert_ne!(bad, base);
    std::fs::write(&v, bad).unwrap();
    fails_with(
        &["fullcar", s(&v)],
        &["track_front_m", "1e10", "at most 20"],
    );
    let far =
        format!("{base}\n[[sensors]]\nname = \"far\"\nkind = \"sprung\"\nx_m = 1e300\ny_m = 0.0\n");
    std::fs::write(&v, far).unwrap();
    let e = vibmode(&["fullcar", s(&v)]);
    let err = String::from_utf8_lossy(&e.stderr);
    assert_eq!(e.status.code(), Some(2), "{err}");
    assert!(
        err.contains("1e300") && !err.contains("None") && err.len() < 400,
        "{err}"
    );
    let out = d.path().join("sim");
    fails_with(
        &[
            "simulate",
            "examples/city_bus.toml",
            "--speed-kmh",
            "1e100",
            "-o",
            s(&out),
        ],
        &["speed_kmh = 1e100"],
    );
    assert!(!out.exists());
    // Negative numbers as values get the one-line message, not clap's usage text.
    let f = d.path().join("a.csv");
    csv(&f, 200.0, 512, &[("a", &tone)]);
    fails_with(&["psd", s(&f), "--fs", "-1"], &["-1 Hz"]);
    // A WAV cut inside its header: the reader's sentence ends before the fix ("bytes.; check"
    // before).
    let w = d.path().join("cut.wav");
    std::fs::write(&w, b"RIFF\x24\x00\x00\x00WAVEfmt ").unwrap();
    let line = fails_with(
        &["psd", s(&w)],
        &["cut.wav", "check that it is a valid WAV file"],
    );
    assert!(!line.contains(".;"), "{line}");
}

#[test]
fn excel_separator_directive_and_trailing_commas_are_read() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("imu.csv");
    let mut text = String::from("sep=,\nPacketCounter,SampleTimeFine,Acc_X,Acc_Y,Acc_Z,\n");
    for i in 0..1024 {
        text.push_str(&format!(
            "{i},{},{},{},{},\n",
            i * 100,
            noise(i),
            noise(i + 7),
            9.81 + tone(i)
        ));
    }
    std::fs::write(&f, text).unwrap();
    let o = ok(&[
        "psd",
        s(&f),
        "--fs",
        "100",
        "--channel",
        "Acc_Z",
        "--json",
        "-",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["channels"][0]["name"], "Acc_Z");
    // semicolons named by the directive, with decimal commas
    let f2 = d.path().join("semi.csv");
    let mut text = String::from("\"sep=;\"\na;b\n");
    for i in 0..512 {
        text.push_str(&format!("{:.3};{:.3}\n", tone(i), noise(i)).replace('.', ","));
    }
    std::fs::write(&f2, text).unwrap();
    ok(&["psd", s(&f2), "--fs", "100"]);
    let f3 = d.path().join("pipe.csv");
    std::fs::write(&f3, "sep=|\na|b\n1|2\n").unwrap();
    fails_with(&["psd", s(&f3), "--fs", "100"], &["separator", "'|'"]);
}

#[test]
fn a_flat_record_is_an_error_with_the_reason() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("flat.csv");
    csv(&f, 50.0, 1024, &[("a", &|_| 1.0)]);
    let o = d.path().join("o");
    fails_with(
        &["analyze", s(&f), "-o", s(&o), "-q"],
        &["flat.csv", "channel 'a' is constant", "every sample is 1"],
    );
    assert!(!o.join("results.json").exists());
}

/// A dead (all 0) or stuck (one value) sensor used to be analysed after resampling: the
/// pre-processing's rounding noise gave "modes" and 23 "periodic lines" with exit 0 (a stuck
/// channel at 100 Hz). Now the record and channel are named, nothing is written, and the other
/// channels are analysed when chosen.
#[test]
fn a_dead_or_stuck_sensor_is_named_not_analysed() {
    let d = tempfile::tempdir().unwrap();
    let stuck = d.path().join("stuck.csv");
    csv(&stuck, 100.0, 2048, &[("a", &tone), ("stuck", &|_| 9.81)]);
    let dead = d.path().join("dead.csv");
    csv(&dead, 100.0, 2048, &[("a", &tone), ("stuck", &|_| 0.0)]);
    let o = d.path().join("o");
    for (f, value) in [(&stuck, "9.81"), (&dead, "0")] {
        let every = format!("every sample is {value})");
        fails_with(
            &["analyze", s(f), "-o", s(&o), "-q"],
            &["channel 'stuck' is constant", &every, "--channel NAME"],
        );
        assert!(!o.exists(), "an output folder for {f:?}");
        // Among good records, and cut from a long file: the record is named.
        fails_with(
            &["analyze", s(f), "-o", s(&o), "-q", "--record-length-s", "5"],
            &["[0.00-5.00 s]", "channel 'stuck' is constant"],
        );
        fails_with(
            &["ssi", s(f), "--block-rows", "10", "--orders", "2:10:2"],
            &["channel 'stuck' is constant", &every],
        );
        assert!(!o.exists());
    }
    let good = d.path().join("good.csv");
    csv(&good, 100.0, 2048, &[("a", &tone), ("stuck", &noise)]);
    fails_with(
        &["analyze", s(&good), s(&stuck), "-o", s(&o), "-q"],
        &["stuck.csv [0.00-10.24 s]'", "channel 'stuck'"],
    );
    ok(&["analyze", s(&stuck), "-c", "a", "-o", s(&o), "-q"]);
    assert!(o.join("results.json").exists());
}

/// A dead sensor with glitches (0 but for a spike, or spikes both ways) is refused as a dead
/// one is, with the share of its samples that repeat a value; without the channel the record
/// is analysed.
#[test]
fn a_dead_sensor_with_glitches_is_named_not_analysed() {
    let d = tempfile::tempdir().unwrap();
    let spike = |i: usize| if i == 700 { 2.5 } else { 0.0 };
    let both = |i: usize| match i {
        300 => 1.0,
        1500 => -1.0,
        _ => 0.0,
    };
    let o = d.path().join("o");
    for (name, f) in [("spike", &spike as &dyn Fn(usize) -> f64), ("both", &both)] {
        let path = d.path().join(format!("{name}.csv"));
        csv(&path, 100.0, 2048, &[("a", &tone), ("dead", f)]);
        fails_with(
            &["analyze", s(&path), "-o", s(&o), "-q"],
            &[
                "channel 'dead' repeats a value over 99.9 % of its samples",
                "dead or stuck sensor with glitches",
                "--channel NAME",
            ],
        );
        assert!(!o.exists(), "an output folder for {name}");
        ok(&["analyze", s(&path), "-c", "a", "-o", s(&o), "-q"]);
        assert!(o.join("results.json").exists());
        std::fs::remove_dir_all(&o).unwrap();
    }
}

/// A saturated sensor (a tone cut at 0.8), or one whose logger filled dropouts, is analysed,
/// and said so: the terminal and the report name the records and the channel, `results.json`
/// lists them per record.
#[test]
fn a_clipped_or_held_channel_is_named_in_the_results() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("sat.csv");
    csv(
        &f,
        100.0,
        2048,
        &[("a", &|i| tone(i).clamp(-2.0, 0.8)), ("b", &noise)],
    );
    let o = d.path().join("o");
    let out = ok(&["analyze", s(&f), "-o", s(&o), "-q"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("Clipped: 2 of 2 records")
            && text.contains("channel 'a'")
            && !text.contains("channel 'b'"),
        "{text}"
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(o.join("results.json")).unwrap()).unwrap();
    for rec in v["records"].as_array().unwrap() {
        let c = &rec["clipped"][0];
        assert_eq!(c["channel"], "a");
        assert_eq!(c["value"], 0.8);
        let share = c["share"].as_f64().unwrap();
        assert!(share > 0.05 && share < 0.5, "{share}");
        assert_eq!(rec["clipped"].as_array().unwrap().len(), 1);
    }
    let html = std::fs::read_to_string(o.join("index.html")).unwrap();
    assert!(html.contains("Clipped: 2 of 2 records"));
    // Dropouts filled with the last value (0.4 s after sample 499: 41 equal samples) and with 0
    // (0.2 s) in the first record: 61 of its 1024 samples.
    let h = d.path().join("drop.csv");
    let held = |i: usize| match i {
        500..=539 => tone(499),
        700..=719 => 0.0,
        _ => tone(i),
    };
    csv(&h, 100.0, 2048, &[("a", &held), ("b", &noise)]);
    let oh = d.path().join("oh");
    let out = ok(&["analyze", s(&h), "-o", s(&oh), "-q"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("Held: 1 of 2 records")
            && text
                .contains("channel 'a' 6.0 % of the samples in 2 stretch(es), the longest 0.410 s")
            && !text.contains("Clipped"),
        "{text}"
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(oh.join("results.json")).unwrap()).unwrap();
    assert_eq!(v["records"][0]["held"][0]["stretches"], 2);
    assert!(v["records"][1].get("held").is_none());
    // Unclipped, nothing is said.
    let g = d.path().join("fine.csv");
    csv(&g, 100.0, 2048, &[("a", &tone), ("b", &noise)]);
    let o2 = d.path().join("o2");
    let out = ok(&["analyze", s(&g), "-o", s(&o2), "-q"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        !text.contains("Clipped") && !text.contains("Held"),
        "{text}"
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(o2.join("results.json")).unwrap()).unwrap();
    assert!(v["records"][0].get("clipped").is_none());
}

/// Sizes of the files under `dir` (for comparing whole outputs).
fn listing(dir: &Path) -> Vec<(PathBuf, u64)> {
    let mut out = Vec::new();
    if let Ok(rd) = std::fs::read_dir(dir) {
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                out.extend(listing(&p));
            } else {
                out.push((p.clone(), e.metadata().map(|m| m.len()).unwrap_or(0)));
            }
        }
    }
    out.sort();
    out
}

#[test]
#[ignore = "acceptance tier (about 10 s, eight killed runs): cargo test --workspace -- --ignored"]
fn kill_9_leaves_the_old_or_the_new_output_never_a_mix() {
    let d = tempfile::tempdir().unwrap();
    // resample: a single file.
    let f = d.path().join("long.csv");
    csv(&f, 400.0, 200_000, &[("a", &tone), ("b", &noise)]);
    let out = d.path().join("r");
    std::fs::create_dir(&out).unwrap();
    let target = out.join("x.csv");
    ok(&["resample", s(&f), "--fs-out", "100", "-o", s(&target)]);
    let fresh = d.path().join("fresh");
    std::fs::create_dir(&fresh).unwrap();
    ok(&[
        "resample",
        s(&f),
        "--fs-out",
        "200",
        "-o",
        s(&fresh.join("x.csv")),
    ]);
    let new: Vec<(PathBuf, u64)> = listing(&fresh)
        .into_iter()
        .map(|(p, n)| (out.join(p.file_name().unwrap()), n))
        .collect();
    // The output files (a killed write leaves its temporary `<name>.partial` beside them).
    let visible = |dir: &Path| -> Vec<(PathBuf, u64)> {
        listing(dir)
            .into_iter()
            .filter(|(p, _)| {
                let n = p.file_name().unwrap().to_string_lossy().into_owned();
                !n.starts_with('.') && !n.ends_with(".partial")
            })
            .collect()
    };
    for delay_ms in [0u64, 10, 30, 60, 100, 200, 350, 600] {
        let before = visible(&out);
        let mut child = bin()
            .args(["resample", s(&f), "--fs-out", "200", "-o", s(&target)])
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = child.kill();
        let _ = child.wait();
        let now = visible(&out);
        assert!(
            now == before || now == new,
            "resample killed at {delay_ms} ms left {now:?} (before {before:?}, complete {new:?})"
        );
    }

    // analyze over an earlier report: results.json and index.html always from one run.
    let a = d.path().join("a.csv");
    let b = d.path().join("b.csv");
    csv(&a, 50.0, 2048, &[("a_channel", &tone)]);
    csv(
        &b,
        50.0,
        2048,
        &[("b_channel", &|i| tone(i + 3) + noise(i + 11))],
    );
    let rep = d.path().join("report");
    ok(&["analyze", s(&a), "-o", s(&rep), "-q"]);
    for delay_ms in [0u64, 20, 60, 120, 250, 400, 700, 1000, 1500] {
        let mut child = bin()
            .args(["analyze", s(&b), "-o", s(&rep), "-q"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = child.kill();
        let _ = child.wait();
        let results = std::fs::read_to_string(rep.join("results.json")).unwrap();
        let html = std::fs::read_to_string(rep.join("index.html")).unwrap();
        let v: serde_json::Value = serde_json::from_str(&results)
            .unwrap_or_else(|e| panic!("results.json broken after kill at {delay_ms} ms: {e}"));
        let name = v["channels"][0]["name"].as_str().unwrap().to_string();
        assert!(
            html.contains(&name)
                && !html.contains(if name == "a_channel" {
                    "b_channel"
                } else {
                    "a_channel"
                }),
            "kill at {delay_ms} ms: results.json is for {name}, index.html is not"
        );
    }
    // simulate over an earlier simulation: records and truth.json always from one run.
    let sim = d.path().join("sim");
    // The old run: seed 1, 5 records; the new one: seed 2, 2 records.
    let sim_args = |records: &'static str, seed: &'static str| -> Vec<String> {
        [
            "simulate",
            "examples/city_bus.toml",
            "--records",
            records,
            "--seed",
            seed,
            "--duration-s",
            "10",
            "--fs",
            "4000",
            "--format",
            "csv",
            "-o",
            s(&sim),
        ]
        .map(String::from)
        .to_vec()
    };
    let old_run = sim_args("5", "1");
    ok(&old_run.iter().map(String::as_str).collect::<Vec<_>>());
    for delay_ms in [0u64, 20, 60, 150, 300, 500, 800, 1200] {
        let mut child = bin()
            .args(sim_args("2", "2"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = child.kill();
        let _ = child.wait();
        let truth: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(sim.join("truth.json")).unwrap())
                .unwrap();
        // The old run (seed 1) wrote 5 records, the new one (seed 2) writes 2.
        let n_truth = if truth["seed"] == 2 { 2 } else { 5 };
        let n_files = std::fs::read_dir(&sim)
            .unwrap()
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().starts_with("record_"))
            .count();
        assert_eq!(
            n_truth, n_files,
            "kill at {delay_ms} ms: stale or missing records"
        );
    }
    // Completed: 2 records, none stale.
    let new_run = sim_args("2", "2");
    ok(&new_run.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        !sim.join("record_03.csv").exists(),
        "stale records beside the new truth.json"
    );
}
