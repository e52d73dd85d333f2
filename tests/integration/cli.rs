//! The command line as a user meets it: outputs on small files, and one-line errors with exit
//! code 2 on bad input.

use crate::common;

use std::path::Path;

use common::{fails_with, vibmode};

fn write_csv(path: &Path, n: usize, fs: f64, bad: Option<&str>) {
    let mut s = String::from("time_s,a,b\n");
    for i in 0..n {
        let t = i as f64 / fs;
        let a =
            (2.0 * std::f64::consts::PI * 5.0 * t).sin() + 0.1 * ((i * 7919) % 101) as f64 / 101.0;
        let b = (2.0 * std::f64::consts::PI * 12.0 * t).cos()
            + 0.3 * (((i * 104729) % 1009) as f64 / 1009.0 - 0.5);
        if i == n / 2 {
            if let Some(cell) = bad {
                s.push_str(&format!("{t},{cell},{b}\n"));
                continue;
            }
        }
        s.push_str(&format!("{t},{a},{b}\n"));
    }
    std::fs::write(path, s).expect("write csv");
}

#[test]
fn psd_json_has_channels_and_the_tone_peak() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("x.csv");
    write_csv(&f, 4000, 200.0, None);
    let o = vibmode(&[
        "psd",
        f.to_str().unwrap(),
        "--nperseg",
        "400",
        "--json",
        "-",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let chans = v["channels"].as_array().unwrap();
    assert_eq!(chans.len(), 2);
    assert_eq!(chans[0]["name"], "a");
    assert_eq!(v["parameters"]["fs_hz"].as_f64(), Some(200.0));
    assert_eq!(v["parameters"]["nperseg"].as_u64(), Some(400));
    let f_hz: Vec<f64> = serde_json::from_value(chans[0]["frequency_hz"].clone()).unwrap();
    let p: Vec<f64> = serde_json::from_value(chans[0]["psd"].clone()).unwrap();
    let imax = (0..p.len()).max_by(|&i, &j| p[i].total_cmp(&p[j])).unwrap();
    assert!((f_hz[imax] - 5.0).abs() < 0.6, "peak at {}", f_hz[imax]);
    // Plot and CSV outputs.
    let svg = d.path().join("p.svg");
    let csv = d.path().join("p.csv");
    let o = vibmode(&[
        "psd",
        f.to_str().unwrap(),
        "--method",
        "both",
        "--plot",
        svg.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read_to_string(&svg)
        .unwrap()
        .contains("Frequency [Hz]"));
    assert!(std::fs::read_to_string(&csv)
        .unwrap()
        .starts_with("frequency_hz,a,b"));
}

#[test]
fn fit_finds_the_tone_and_resample_writes_a_readable_file() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("x.csv");
    write_csv(&f, 4000, 200.0, None);
    let o = vibmode(&[
        "fit",
        f.to_str().unwrap(),
        "--channel",
        "b",
        "--order",
        "4",
        "--json",
        "-",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let modes = v["channels"][0]["modes"].as_array().unwrap();
    assert!(
        modes
            .iter()
            .any(|m| (m["frequency_hz"].as_f64().unwrap() - 12.0).abs() < 0.05),
        "{modes:?}"
    );
    // A clean tone in noise: the spike cleaner replaces nothing.
    assert_eq!(v["channels"][0]["outliers_replaced"].as_u64(), Some(0));
    let out = d.path().join("r.csv");
    let o = vibmode(&[
        "resample",
        f.to_str().unwrap(),
        "--fs-out",
        "50",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = vibmode(&["psd", out.to_str().unwrap(), "--json", "-"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["parameters"]["fs_hz"].as_f64(), Some(50.0));
}

#[test]
fn bad_input_gives_one_line_and_exit_code_2() {
    let d = tempfile::tempdir().unwrap();
    let good = d.path().join("good.csv");
    write_csv(&good, 1000, 200.0, None);
    let g = good.to_str().unwrap();
    let nan = d.path().join("nan.csv");
    write_csv(&nan, 1000, 200.0, Some("NaN"));
    let text = d.path().join("text.csv");
    write_csv(&text, 1000, 200.0, Some("abc"));
    let empty = d.path().join("empty.csv");
    std::fs::write(&empty, "").unwrap();
    let header = d.path().join("header.csv");
    std::fs::write(&header, "a,b\n").unwrap();
    let notime = d.path().join("notime.csv");
    std::fs::write(&notime, "a,b\n1,2\n3,4\n5,6\n").unwrap();

    fails_with(&["psd", "no/such/file.csv"], &["no/such/file.csv"]);
    fails_with(&["psd", empty.to_str().unwrap()], &["empty"]);
    fails_with(
        &["psd", header.to_str().unwrap(), "--fs", "10"],
        &["header"],
    );
    fails_with(&["psd", nan.to_str().unwrap()], &["NaN"]);
    fails_with(&["psd", text.to_str().unwrap()], &["abc"]);
    fails_with(&["psd", notime.to_str().unwrap()], &["--fs"]);
    fails_with(&["psd", notime.to_str().unwrap(), "--fs", "0"], &["0"]);
    fails_with(&["psd", notime.to_str().unwrap(), "--fs=-5"], &["-5"]);
    fails_with(
        &["psd", g, "--nperseg", "100", "--noverlap", "100"],
        &["noverlap"],
    );
    fails_with(&["psd", g, "--window", "hanning2"], &["hanning2"]);
    fails_with(&["psd", g, "--channel", "zz"], &["zz", "available"]);
    fails_with(&["psd", g, "--nperseg", "5000"], &["5000"]);
    fails_with(&["fit", g, "--order", "900"], &["order"]);
    fails_with(&["resample", g, "--fs-out=-1", "-o", "x.csv"], &["-1"]);
    fails_with(&["fullcar", "no/such/bus.toml"], &["no/such/bus.toml"]);
    let bad_bus = d.path().join("bus.toml");
    let bus = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/city_bus.toml"
    ))
    .unwrap()
    .replacen("mass_kg", "mass_kgs", 1);
    std::fs::write(&bad_bus, bus).unwrap();
    fails_with(&["fullcar", bad_bus.to_str().unwrap()], &["mass_kgs"]);
}

#[test]
fn fullcar_and_simulate() {
    let bus = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/city_bus.toml");
    let o = vibmode(&["fullcar", bus, "--json", "-"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let modes = v["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 7);
    assert!(modes
        .iter()
        .all(|m| m["frequency_hz"].as_f64().unwrap() > 0.5));
    let d = tempfile::tempdir().unwrap();
    let run = |dir: &Path| {
        let o = vibmode(&[
            "simulate",
            bus,
            "--fs",
            "1000",
            "--duration-s",
            "2",
            "--records",
            "2",
            "--seed",
            "5",
            "--format",
            "csv",
            "-o",
            dir.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(dir.join("record_02.csv")).unwrap()
    };
    let a = run(&d.path().join("a"));
    let b = run(&d.path().join("b"));
    assert_eq!(a, b, "same seed, same bytes");
    assert!(d.path().join("a/truth.json").exists());
}

#[test]
fn a_cause_already_in_the_message_is_not_repeated() {
    let o = vibmode(&["simulate", "no_such_bus.toml", "--output", "x"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("no_such_bus.toml"), "{err}");
    assert_eq!(
        err.matches("os error 2").count(),
        1,
        "repeated cause: {err}"
    );
}

#[test]
fn unknown_channel_suggests_the_one_it_prefixes() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("phone.csv");
    let mut text = String::from("Time (s),X-Axis (m/s2),Z-Axis (m/s2)\n");
    for i in 0..400 {
        let t = i as f64 / 100.0;
        text.push_str(&format!("{t},{},{}\n", (t * 7.0).sin(), (t * 3.0).cos()));
    }
    std::fs::write(&f, text).unwrap();
    let p = f.to_str().unwrap();
    fails_with(
        &["psd", p, "--channel", "z"],
        &["no channel named 'z'", "did you mean 'Z-Axis'?"],
    );
    // Ambiguous or no prefix: the list only.
    let o = vibmode(&["psd", p, "--channel", "Q"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("X-Axis") && !err.contains("did you mean"),
        "{err}"
    );
}
