//! `vibmode analyze`, `vibmode sweep` and a closed output pipe, as a user meets them: exit codes,
//! the files written, one-line errors.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::Stdio;

use crate::common;

use common::{bin, fails_with, vibmode};

/// A lightly damped 1.5 Hz resonance (zeta 0.05) driven by seeded white noise, sampled at
/// `fs` Hz: an AR(2) filter, plus 5 % measurement noise. Columns `time_s` and `z` (m/s^2).
fn write_resonance(path: &Path, seconds: f64, fs: f64, seed: u64) {
    let n = (seconds * fs) as usize;
    let (f0, zeta) = (1.5, 0.05);
    let r = (-zeta * 2.0 * std::f64::consts::PI * f0 / fs).exp();
    let th = 2.0 * std::f64::consts::PI * f0 * (1.0 - zeta * zeta).sqrt() / fs;
    let (a1, a2) = (2.0 * r * th.cos(), -r * r);
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut noise = || {
        // Sum of 4 uniforms: close enough to Gaussian for a driving noise.
        (0..4)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .sum::<f64>()
    };
    let (mut y1, mut y2) = (0.0, 0.0);
    let mut s = String::from("time_s,z [m/s^2]\n");
    for i in 0..n {
        let y = a1 * y1 + a2 * y2 + noise();
        y2 = y1;
        y1 = y;
        s.push_str(&format!("{},{}\n", i as f64 / fs, y + 0.05 * noise()));
    }
    std::fs::write(path, s).expect("write csv");
}

#[test]
fn analyze_writes_the_report_and_finds_the_resonance() {
    let d = tempfile::tempdir().unwrap();
    let a = d.path().join("a.csv");
    let b = d.path().join("b.csv");
    write_resonance(&a, 60.0, 50.0, 1);
    write_resonance(&b, 60.0, 50.0, 2);
    let out = d.path().join("report");
    let cfg = d.path().join("quick.toml");
    std::fs::write(&cfg, "[sweep]\norder_max = 10\n").unwrap();
    let o = vibmode(&[
        "analyze",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--config",
        cfg.to_str().unwrap(),
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "index.html",
        "results.json",
        "modes.csv",
        "figures/fig01_time_records.svg",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    // 2 x 60 s files -> 2 x 5 records of 10.24 s; the resonance is a structural mode.
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(v["schema_version"], 3);
    assert_eq!(v["records"].as_array().map(Vec::len), Some(10));
    let csv = std::fs::read_to_string(out.join("modes.csv")).unwrap();
    let found = csv.lines().skip(1).any(|l| {
        let c: Vec<&str> = l.split(',').collect();
        c[10] == "structural" && c[2].parse::<f64>().is_ok_and(|f| (f - 1.5).abs() < 0.1)
    });
    assert!(found, "no 1.5 Hz structural mode in\n{csv}\n{stdout}");
}

#[test]
fn analyze_and_sweep_errors_are_one_line_with_exit_code_2() {
    let d = tempfile::tempdir().unwrap();
    let a = d.path().join("a.csv");
    write_resonance(&a, 20.0, 50.0, 3);
    let b = d.path().join("b.csv");
    write_resonance(&b, 20.0, 100.0, 4);
    let out = d.path().join("r");
    let (a, b, out) = (
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        out.to_str().unwrap(),
    );
    fails_with(&["analyze", "/no/such.csv", "-o", out], &["/no/such.csv"]);
    fails_with(
        &["analyze", a, "--channel", "q", "-o", out],
        &["'q'", "--channel"],
    );
    fails_with(
        &["analyze", a, "--preset", "nope", "-o", out],
        &["nope", "vibmode, paper"],
    );
    let cfg = d.path().join("bad.toml");
    std::fs::write(&cfg, "[sweep]\nordermax = 3\n").unwrap();
    fails_with(
        &["analyze", a, "--config", cfg.to_str().unwrap(), "-o", out],
        &["ordermax"],
    );
    fails_with(&["analyze", a, b, "-o", out], &["100 Hz", "50 Hz"]);
    assert!(
        !Path::new(out).join("index.html").exists(),
        "nothing written on error"
    );
    fails_with(&["sweep", a, "--orders", "5:2"], &["--orders", "5:2"]);
    fails_with(&["sweep", a, "--orders", "x"], &["--orders"]);
    fails_with(&["sweep", a, "--robust", "-2"], &["robust", "-2"]);
    // Resampling onto its own input is refused and leaves the input whole.
    let before = std::fs::read(a).unwrap();
    fails_with(
        &["resample", a, "--fs-out", "25", "-o", a],
        &["is an input file"],
    );
    assert_eq!(std::fs::read(a).unwrap(), before);
    // Used to panic (exit 101) in the ARMA search.
    fails_with(
        &["fit", a, "--order", "4", "--ma-order", "5"],
        &["q = 5", "p = 4"],
    );
}

#[test]
fn sweep_json_lists_every_order_and_the_filtered_poles() {
    let d = tempfile::tempdir().unwrap();
    let a = d.path().join("a.csv");
    write_resonance(&a, 20.0, 50.0, 5);
    let o = vibmode(&[
        "sweep",
        a.to_str().unwrap(),
        "--orders",
        "2:8",
        "--json",
        "-",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let ch = &v["channels"][0];
    assert_eq!(ch["orders"].as_array().map(Vec::len), Some(7));
    assert!(ch["filtered_out"].is_array());
    let near = ch["modes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| (m["frequency_hz"].as_f64().unwrap() - 1.5).abs() < 0.1)
        .count();
    assert!(near >= 5, "the 1.5 Hz resonance at most orders: {near}");
}

#[test]
fn a_closed_pipe_ends_quietly() {
    let d = tempfile::tempdir().unwrap();
    let a = d.path().join("a.csv");
    write_resonance(&a, 60.0, 50.0, 6);
    let mut child = bin()
        .args([
            "psd",
            a.to_str().unwrap(),
            "--method",
            "periodogram",
            "--json",
            "-",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    let mut first = String::new();
    {
        let stdout = child.stdout.take().expect("stdout");
        BufReader::new(stdout).read_line(&mut first).expect("read");
    } // the reader closes the pipe, as `| head -1` does
    let o = child.wait_with_output().expect("wait");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(first.trim(), "{");
    assert!(o.status.success(), "exit {:?}: {err}", o.status);
    assert!(!err.contains("error") && !err.contains("panicked"), "{err}");
}

#[test]
fn channels_without_a_role_are_analysed_alone_and_roles_can_be_given() {
    let d = tempfile::tempdir().unwrap();
    let a = d.path().join("a.csv");
    write_resonance(&a, 30.0, 50.0, 7);
    let cfg = d.path().join("quick.toml");
    std::fs::write(&cfg, "[sweep]\norder_max = 8\n").unwrap();
    let out = d.path().join("r");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "analyze",
            a.to_str().unwrap(),
            "--config",
            cfg.to_str().unwrap(),
            "-q",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = vibmode(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).to_string()
    };
    let alone = run(&[]);
    assert!(
        alone.contains("channel z (no role: analysed alone, not pooled)"),
        "{alone}"
    );
    let sprung = run(&["--role", "z=sprung", "--corner", "z=FR"]);
    assert!(sprung.contains("sprung channels (z)"), "{sprung}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(v["channels"][0]["placement"]["corner"], "FR");
    let a = a.to_str().unwrap();
    fails_with(
        &["analyze", a, "--role", "z=up"],
        &["'up'", "sprung, unsprung, other"],
    );
    fails_with(&["analyze", a, "--role", "z"], &["--role", "NAME=VALUE"]);
    fails_with(
        &["analyze", a, "--corner", "z=XX"],
        &["'XX'", "FL, FR, RL, RR"],
    );
}

/// `vibmode ssi` on a simulated bus record (written by `vibmode simulate`, names kept by the WAV
/// sidecar): the table lists modes with their shapes, the JSON holds every order, the plot is
/// written; errors are one line with exit code 2.
#[test]
fn ssi_identifies_a_simulated_record_and_reports_errors() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path().join("sim");
    let o = vibmode(&[
        "simulate",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/examples/city_bus_flexible.toml"
        ),
        "--records",
        "1",
        "--duration-s",
        "60",
        "--fs",
        "100",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let wav = dir.join("record_01.wav");
    let wav = wav.to_str().unwrap();
    let plot = d.path().join("stab.svg");
    // The record at 50 Hz with 30 block rows, as every successful call below.
    let base = ["ssi", wav, "--fs-out", "50", "--block-rows", "30"];
    let o = vibmode(&[&base[..], &["--plot", plot.to_str().unwrap()]].concat());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("SSI-cov of 7 channels"), "{out}");
    assert!(out.contains("30 block rows (lags 1..59)"), "{out}");
    assert!(out.contains("shape: FL_unsprung"), "{out}");
    assert!(plot.is_file());
    // The bending mode (9.0 Hz, damping 0.03) is among the modes that stay over the orders.
    let j = vibmode(&[&base[..], &["--json", "-"]].concat());
    let v: serde_json::Value = serde_json::from_slice(&j.stdout).unwrap();
    let modes = v["modes"].as_array().unwrap();
    assert!(
        modes.iter().any(|m| m["class"] == "structural"
            && (m["frequency_hz"].as_f64().unwrap() - 9.0).abs() < 0.2),
        "{out}"
    );
    assert_eq!(v["channels"].as_array().map(Vec::len), Some(7));
    // First-order standard deviations from 20 blocks: in the table and the JSON (the bending
    // mode's, from 60 s, between 0.001 and 0.5 Hz); one pole_std row per identified order.
    let u = vibmode(&[&base[..], &["--uncertainty-blocks", "20", "--json", "-"]].concat());
    assert!(u.status.success(), "{}", String::from_utf8_lossy(&u.stderr));
    let uv: serde_json::Value = serde_json::from_slice(&u.stdout).unwrap();
    assert_eq!(uv["uncertainty_blocks"], 20);
    assert_eq!(
        uv["pole_std"].as_array().map(Vec::len),
        uv["result"]["orders"].as_array().map(Vec::len)
    );
    let bending = uv["modes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| {
            m["class"] == "structural" && (m["frequency_hz"].as_f64().unwrap() - 9.0).abs() < 0.2
        })
        .expect("bending mode");
    assert_eq!(bending["uncertainty"]["method"], "first-order");
    let sd = bending["uncertainty"]["frequency_std_hz"].as_f64().unwrap();
    assert!(sd > 0.001 && sd < 0.5, "{sd}");
    fails_with(
        &["ssi", wav, "--uncertainty-blocks", "1"],
        &["1 data block", "at least 2 blocks"],
    );
    fails_with(
        &[&base[..], &["--uncertainty-blocks", "100"]].concat(),
        &["100 blocks", "at most 50 blocks"],
    );
    // A later first lag: reported, and in the JSON's parameters.
    let later = vibmode(&[&base[..], &["--first-lag", "37"]].concat());
    let text = String::from_utf8_lossy(&later.stdout);
    assert!(text.contains("(lags 37..95)"), "{text}");
    assert_eq!(v["params"]["first_lag"], 1);
    fails_with(
        &["ssi", wav, "--first-lag", "0"],
        &["first_lag = 0", ">= 1"],
    );
    fails_with(&["ssi", wav, "--block-rows", "0"], &["block_rows"]);
    fails_with(&["ssi", wav, "--references", "0,9"], &["9"]);
    fails_with(
        &[
            "analyze",
            wav,
            "--method",
            "fdd",
            "-o",
            d.path().join("r").to_str().unwrap(),
        ],
        &["fdd", "arma, ssi-cov, both"],
    );
}

/// `analyze --vehicle` on records of a bus that differs from the vehicle file (rear springs
/// 20 % softer, 15 % more pitch inertia): the model update prints the body modes and writes
/// `model_update.json` and `updated_vehicle.toml`, whose body modes are the measured bus's
/// within 3 % where the file's are not; without sensor placements it says why it did not update.
#[test]
fn analyze_with_a_vehicle_updates_the_model() {
    use vibmode_vehicle::{FullCar, ModeLabel, VehicleParams};
    let d = tempfile::tempdir().unwrap();
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/city_bus_flexible.toml"
    );
    let mut bus = VehicleParams::from_path(file).unwrap();
    bus.rear.spring_stiffness_n_per_m *= 0.8;
    bus.body.pitch_inertia_kgm2 *= 1.15;
    let changed = d.path().join("changed.toml");
    std::fs::write(&changed, bus.to_toml_string().unwrap()).unwrap();
    let dir = d.path().join("sim");
    let o = vibmode(&[
        "simulate",
        changed.to_str().unwrap(),
        "--records",
        "4",
        "--duration-s",
        "20",
        "--fs",
        "100",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let wavs: Vec<String> = (1..=4)
        .map(|i| dir.join(format!("record_{i:02}.wav")).display().to_string())
        .collect();
    let out = d.path().join("report");
    let mut args: Vec<&str> = vec!["analyze", "-q", "--method", "ssi-cov", "--vehicle", file];
    args.extend(wavs.iter().map(String::as_str));
    args.extend(["-o", out.to_str().unwrap()]);
    let o = vibmode(&args);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        text.contains("Full-car model updated from the body's equations (4 records"),
        "{text}"
    );
    let updated = VehicleParams::from_path(out.join("updated_vehicle.toml")).unwrap();
    let truth = FullCar::new(&bus).unwrap().modes().unwrap();
    let got = FullCar::new(&updated).unwrap().modes().unwrap();
    let nominal = FullCar::new(&VehicleParams::from_path(file).unwrap())
        .unwrap()
        .modes()
        .unwrap();
    let f = |m: &[vibmode_vehicle::ModeInfo], l: ModeLabel| {
        m.iter().find(|x| x.label == l).unwrap().frequency_hz
    };
    for l in [
        ModeLabel::BodyHeave,
        ModeLabel::BodyPitch,
        ModeLabel::BodyRoll,
    ] {
        let err = f(&got, l) / f(&truth, l) - 1.0;
        assert!(err.abs() < 0.03, "{l}: {:+.2} %\n{text}", 100.0 * err);
    }
    assert!(
        (f(&nominal, ModeLabel::BodyPitch) / f(&truth, ModeLabel::BodyPitch) - 1.0).abs() > 0.03
    );
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("model_update.json")).unwrap())
            .unwrap();
    assert_eq!(j["records"], 4);
    // results.json holds it too, as Python's analyze returns it.
    let rj: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(rj["model_update"], j);
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(
        html.contains("<h2>Full-car model updated from the records</h2>"),
        "report section"
    );
    // Two records cannot show how well the fit is known: not supported, no vehicle file; the
    // terminal says why, and the report shows the reason and the fit's figures beneath it.
    let out6 = d.path().join("report6");
    let mut args: Vec<&str> = vec!["analyze", "-q", "--method", "ssi-cov", "--vehicle", file];
    args.extend(wavs[..2].iter().map(String::as_str));
    args.extend(["-o", out6.to_str().unwrap()]);
    let o = vibmode(&args);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        text.contains("Full-car model not updated: the records do not support the fit: 2 records cannot show how well the fit is known"),
        "{text}"
    );
    assert!(!out6.join("updated_vehicle.toml").exists());
    let rj: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out6.join("results.json")).unwrap()).unwrap();
    assert_eq!(rj["model_update"]["records"], 2, "{rj}");
    assert_eq!(rj["model_update"]["supported"], false, "{rj}");
    let html = std::fs::read_to_string(out6.join("index.html")).unwrap();
    let section = html
        .split("<h2>Full-car model not updated</h2>")
        .nth(1)
        .unwrap_or_else(|| panic!("no section for the fit not supported"));
    assert!(
        section.contains(
            "The fit below was not used: the records do not support the fit: 2 records cannot show"
        ) && section.contains("updated [Hz]")
            && section.contains("no updated vehicle file was written"),
        "report section of the fit not supported"
    );
    // The fit's band from the analysis config's [model_update]; a bad band is a one-line error.
    let cfg = d.path().join("band.toml");
    std::fs::write(&cfg, "[model_update]\nband_hz = [0.5, 2.0]\nedge_s = 0.5\n").unwrap();
    let out3 = d.path().join("report3");
    let mut args: Vec<&str> = vec!["analyze", "-q", "--method", "ssi-cov", "--vehicle", file];
    args.extend(wavs.iter().map(String::as_str));
    args.extend([
        "--config",
        cfg.to_str().unwrap(),
        "-o",
        out3.to_str().unwrap(),
    ]);
    let o = vibmode(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out3.join("model_update.json")).unwrap())
            .unwrap();
    assert_eq!(j["band_hz"], serde_json::json!([0.5, 2.0]));
    std::fs::write(&cfg, "[model_update]\nband_hz = [2.0, 0.5]\n").unwrap();
    let out4 = d.path().join("report4");
    args.pop();
    args.push(out4.to_str().unwrap());
    let o = vibmode(&args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("band_hz = [2, 0.5]") && err.lines().count() == 1,
        "{err}"
    );
    assert!(!out4.exists());
    // Which anti-roll bars are fitted: a name of the setting's two, else one line naming both.
    std::fs::write(&cfg, "[model_update]\nanti_roll_bars = \"sometimes\"\n").unwrap();
    let o = vibmode(&args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("sometimes")
            && err.contains("both")
            && err.contains("file")
            && err.lines().count() == 1,
        "{err}"
    );
    assert!(!out4.exists());
    // A number where a name belongs: said in words, with the key.
    std::fs::write(&cfg, "[model_update]\nanti_roll_bars = 3\n").unwrap();
    let o = vibmode(&args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("expected a name in quotes (key = \"name\") in `model_update.anti_roll_bars`"),
        "{err}"
    );
    assert!(!out4.exists());
    // A wheel's channel left out: the analysis runs, the update says why it did not.
    let out2 = d.path().join("report2");
    let mut args: Vec<&str> = vec!["analyze", "-q", "--method", "ssi-cov", "--vehicle", file];
    args.extend(wavs.iter().map(String::as_str));
    for c in [
        "FL_unsprung",
        "FR_unsprung",
        "RR_unsprung",
        "FR_sprung",
        "RL_sprung",
        "RR_sprung",
    ] {
        args.extend(["-c", c]);
    }
    args.extend(["-o", out2.to_str().unwrap()]);
    let o = vibmode(&args);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        text.contains(&format!("Full-car model not updated: {}", wavs[0]))
            && text.contains("no unsprung channel at RL"),
        "{text}"
    );
    assert!(!out2.join("updated_vehicle.toml").exists());
    let rj: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out2.join("results.json")).unwrap()).unwrap();
    let why = rj["model_update"]["not_updated"].as_str().unwrap_or("");
    assert!(why.contains("no unsprung channel at RL"), "{rj}");
    let html = std::fs::read_to_string(out2.join("index.html")).unwrap();
    assert!(
        html.contains("<h2>Full-car model not updated</h2>")
            && html.contains("no unsprung channel at RL"),
        "report section"
    );
    // A channel given the role other on the command line is left out of the fit too.
    let out5 = d.path().join("report5");
    let mut args: Vec<&str> = vec!["analyze", "-q", "--method", "ssi-cov", "--vehicle", file];
    args.extend(wavs.iter().map(String::as_str));
    args.extend(["--role", "RL_unsprung=other", "-o", out5.to_str().unwrap()]);
    let o = vibmode(&args);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(text.contains("no unsprung channel at RL"), "{text}");
}
