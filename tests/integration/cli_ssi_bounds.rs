//! Issue 28's `ssi` bounds and command-line parsing: each input that once panicked, ran for
//! minutes, answered silently wrong or printed clap's usage block now ends with exit 0 and the
//! right output, or exit 2 and one line (under 400 bytes) naming the value and the fix. The
//! inputs are built here (`vibmode simulate`, a few CSV files).

use std::path::{Path, PathBuf};

use crate::common;

use common::{fails_with, ok, stderr, vibmode};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// One simulated bus record: 7 channels, 2048 samples at 200 Hz.
fn bus_record(dir: &Path) -> PathBuf {
    let bus = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/city_bus.toml");
    let out = dir.join("sim");
    ok(&[
        "simulate",
        bus,
        "--fs",
        "200",
        "--duration-s",
        "10.24",
        "--records",
        "1",
        "--seed",
        "3",
        "-o",
        s(&out),
    ]);
    out.join("record_01.wav")
}

/// A CSV of `n` rows at 50 Hz: a time column and two channels (a 3 Hz mode in noise).
fn csv(path: &Path, n: usize) {
    let mut text = String::from("time_s,a,b\n");
    for i in 0..n {
        let noise =
            |k: usize| ((k.wrapping_mul(2654435761) % 1_000_003) as f64 / 1_000_003.0) - 0.5;
        let t = i as f64 / 50.0;
        let a = (2.0 * std::f64::consts::PI * 3.0 * t).sin() + noise(i);
        text.push_str(&format!("{t},{a},{}\n", noise(i + 77)));
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn huge_first_lag_and_block_rows_are_refused_in_one_line() {
    let d = tempfile::tempdir().unwrap();
    let rec = bus_record(d.path());
    let r = s(&rec);
    // Panicked (exit 101, a range start out of range in cov.rs).
    fails_with(
        &["ssi", r, "--first-lag", "18446744073709551615"],
        &["first_lag = 18446744073709551615", "2^30", "--first-lag"],
    );
    // Reported wrapped numbers.
    fails_with(
        &["ssi", r, "--block-rows", "18446744073709551615"],
        &[
            "block_rows = 18446744073709551615",
            "at most 1024",
            "--block-rows",
        ],
    );
    // Within the bound, beyond the record: the samples it would need are named.
    fails_with(
        &["ssi", r, "--first-lag", "5000"],
        &["2048 samples", "first_lag = 5000", "at least 5077"],
    );
    // One past what clap's integer holds: the value and the allowed range.
    fails_with(
        &["ssi", r, "--first-lag", "18446744073709551616"],
        &[
            "--first-lag",
            "18446744073709551616",
            "0 to 18446744073709551615",
        ],
    );
}

#[test]
fn block_rows_are_bounded_by_the_record_and_the_matrix_size() {
    let d = tempfile::tempdir().unwrap();
    let rec = bus_record(d.path());
    let r = s(&rec);
    // Ran past 30 s: 7000 rows of Toeplitz matrix for 2048 samples.
    fails_with(
        &["ssi", r, "--block-rows", "1000"],
        &[
            "block_rows = 1000 with 7 channels",
            "1024 rows",
            "block_rows = 146",
        ],
    );
    fails_with(
        &["ssi", r, "--block-rows", "147"],
        &["block_rows = 147", "block_rows = 146"],
    );
    // One channel: 1000 rows would fit, but 2048 samples do not carry 1999 lags.
    fails_with(
        &["ssi", r, "-c", "0", "--block-rows", "1000"],
        &["2048 samples", "block_rows = 1000", "at least 3998"],
    );
    fails_with(
        &["ssi", r, "-c", "0", "--block-rows", "513"],
        &["block_rows = 513", "at least 2050"],
    );
    // The uncertainty blocks are bounded by the SVD work.
    fails_with(
        &["ssi", r, "--uncertainty-blocks", "100000"],
        &["100000 uncertainty blocks", "--uncertainty-blocks"],
    );
    // Orders above the bound, and reference channels repeated or missing.
    fails_with(
        &["ssi", r, "--orders", "2:2000:2"],
        &["--orders", "1 to 1024"],
    );
    fails_with(
        &["ssi", r, "--references", "0,0"],
        &["reference_channels = [0, 0]", "--references"],
    );
    fails_with(
        &["ssi", r, "--references", "0,7"],
        &["reference channel 7", "--references"],
    );
    // A bound that leaves the usual run alone.
    let o = ok(&[
        "ssi",
        r,
        "--block-rows",
        "10",
        "--orders",
        "2:20:2",
        "--json",
        "-",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["params"]["block_rows"], 10);
    assert_eq!(v["result"]["orders"].as_array().map(Vec::len), Some(10));
}

#[test]
fn a_channel_given_twice_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("a.csv");
    csv(&f, 2048);
    // Analysed the same channel twice without a word.
    fails_with(
        &["ssi", s(&f), "-c", "0", "-c", "0"],
        &["channel 'a' (index 0) is selected twice", "--channel once"],
    );
    fails_with(
        &["ssi", s(&f), "-c", "b", "-c", "1"],
        &["channel 'b' (index 1) is selected twice"],
    );
    fails_with(&["psd", s(&f), "-c", "a", "-c", "A"], &["selected twice"]);
    ok(&[
        "ssi",
        s(&f),
        "-c",
        "1",
        "-c",
        "0",
        "--block-rows",
        "8",
        "--orders",
        "2:8:2",
    ]);
}

#[test]
fn order_lists_are_taken_as_listed_and_ranges_on_their_grid() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("a.csv");
    csv(&f, 2048);
    let orders = |spec: &str| -> Vec<u64> {
        let o = ok(&["ssi", s(&f), "--orders", spec, "--json", "-"]);
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["result"]["orders"]
            .as_array()
            .unwrap()
            .iter()
            .map(|o| o["order"].as_u64().unwrap())
            .collect()
    };
    // Silently ran 10, 20, 30.
    assert_eq!(orders("10,20,35"), [10, 20, 35]);
    assert_eq!(orders("4:12:4"), [4, 8, 12]);
    assert_eq!(orders("2:5"), [2, 3, 4, 5]);
    // A stop off the step's grid is refused, naming the grids on either side.
    for cmd in ["ssi", "sweep"] {
        fails_with(
            &[cmd, s(&f), "--orders", "2:35:2"],
            &["--orders: 2:35:2", "2:34:2", "2:36:2"],
        );
        // Would have allocated 2^64 orders.
        fails_with(
            &[cmd, s(&f), "--orders", "1:18446744073709551615"],
            &["--orders", "1 to 1024"],
        );
    }
    fails_with(
        &["ssi", s(&f), "--orders", "20,10"],
        &["--orders: 20,10", "increasing"],
    );
    // The help says so.
    let help = String::from_utf8_lossy(&ok(&["ssi", "--help"]).stdout).to_string();
    assert!(
        help.contains("identified as listed") && help.contains("step's grid"),
        "{help}"
    );
}

#[test]
fn clap_errors_are_one_line_naming_the_value_and_the_fix() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("a.csv");
    csv(&f, 256);
    let bus = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/city_bus.toml");
    let out = d.path().join("o");
    let o = s(&out);
    for (args, needles) in [
        (
            vec!["simulate", bus, "-o", o, "--seed", "-1"],
            vec![
                "invalid value for --seed: '-1'",
                "0 to 18446744073709551615",
            ],
        ),
        (
            vec!["simulate", bus, "-o", o, "--records", "-1"],
            vec!["--records: '-1'", "whole number from 0"],
        ),
        (
            vec!["simulate", bus, "-o", o, "--seed", "99999999999999999999"],
            vec![
                "'99999999999999999999'",
                "too large",
                "0 to 18446744073709551615",
            ],
        ),
        (
            vec!["analyze", s(&f), "-o", o, "--vehicle", "-bus"],
            vec!["unexpected argument: '-b'", "--vehicle=-bus"],
        ),
        (
            vec!["simulate", bus, "-o", ""],
            vec!["empty value for --output", "vibmode simulate --help"],
        ),
        (
            vec!["ssi", s(&f), "--json", ""],
            vec!["empty value for --json"],
        ),
        (vec!["psd", ""], vec!["empty value for <INPUT>"]),
        (
            vec!["simulate", bus, "-o", o, "--effects", "x"],
            vec!["--effects: 'x'", "none, in-service"],
        ),
        (
            vec!["ssi", s(&f), "--blok-rows", "3"],
            vec!["'--blok-rows'", "did you mean --block-rows"],
        ),
        (vec!["sssi"], vec!["unknown command: 'sssi'", "ssi"]),
        (vec!["ssi"], vec!["missing required argument", "<INPUT>"]),
        (
            vec!["psd", s(&f), "--fs", "fast"],
            vec!["--fs: 'fast'", "decimal number"],
        ),
    ] {
        let line = fails_with(&args, &needles);
        assert!(line.starts_with("vibmode: error: "), "{line}");
        assert!(!line.contains("Usage:"), "{line}");
    }
    assert!(!out.exists());
    // Help and version still print as clap prints them, with exit 0.
    let h = ok(&["ssi", "--help"]);
    assert!(String::from_utf8_lossy(&h.stdout).contains("Usage: vibmode ssi"));
    let v = ok(&["--version"]);
    assert!(String::from_utf8_lossy(&v.stdout).starts_with("vibmode "));
}

#[test]
fn echoed_input_is_quoted_short_and_printable() {
    let d = tempfile::tempdir().unwrap();
    // A 2 MB cell.
    let big = d.path().join("big.csv");
    let mut text = String::from("time_s,a\n0,1\n0.02,");
    text.push_str(&"7x".repeat(1_000_000));
    text.push_str("\n0.04,1\n");
    std::fs::write(&big, text).unwrap();
    fails_with(&["psd", s(&big)], &["is not a number", "7x7x"]);
    // Terminal escape sequences in a cell and in a channel name.
    let esc = d.path().join("esc.csv");
    std::fs::write(
        &esc,
        "time_s,a\u{1b}]0;owned\u{7}\n0,1\n0.02,\u{1b}[2J\n0.04,1\n",
    )
    .unwrap();
    let o = vibmode(&["psd", s(&esc)]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        !err.chars().any(|c| c.is_control() && c != '\n'),
        "control characters echoed: {err:?}"
    );
    // A 10 000-character channel asked for.
    let f = d.path().join("a.csv");
    csv(&f, 256);
    let name = "n".repeat(10_000);
    let line = fails_with(&["psd", s(&f), "-c", &name], &["no channel named", "..."]);
    assert!(line.len() < 300, "{line}");
    // A binary file passed as a recording is never echoed.
    let bin = d.path().join("rec.csv");
    let bytes: Vec<u8> = (0..200_000u32).map(|i| (i * 7 % 256) as u8).collect();
    std::fs::write(&bin, bytes).unwrap();
    fails_with(&["psd", s(&bin)], &["not a text file"]);
}

/// Issue 29 item 5: a hint names a flag the command accepts. Every command that reads files
/// shares the input options, so `analyze` and `segment` give the `--resample-nonuniform` hint as
/// `psd` does.
#[test]
fn hints_name_only_flags_the_command_accepts() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("jitter.csv");
    let mut text = String::from("time_s,a\n");
    let mut t = 0.0;
    for i in 0..4096 {
        text.push_str(&format!("{t:.6},{}\n", (i as f64 * 0.3).sin()));
        t += if i % 2 == 0 { 0.009 } else { 0.005 };
    }
    std::fs::write(&f, text).unwrap();
    let out = d.path().join("o");
    for args in [
        vec!["analyze", s(&f), "-o", s(&out)],
        vec!["segment", s(&f), "--by-vibration", "-o", s(&out)],
    ] {
        fails_with(&args, &["not uniform", "--resample-nonuniform"]);
    }
    fails_with(&["psd", s(&f)], &["not uniform", "--resample-nonuniform"]);
}
