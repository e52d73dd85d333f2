//! One name per parameter on the command line, the older spellings still accepted (hidden):
//! the rate to resample to is `--fs-out` (was `--to` for `resample`, `--resample-to` for the
//! other commands). Each old spelling must give the same output as the new one.

use crate::common;

use common::{fails_with, ok, simulate_csv};

fn s(p: &std::path::Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn resample_takes_fs_out_and_the_old_to_and_resample_to() {
    let d = tempfile::tempdir().unwrap();
    let files = simulate_csv(d.path(), "B", "30", "3", "1");
    let f = files[0].as_str();
    let mut outputs = Vec::new();
    for flag in ["--fs-out", "--to", "--resample-to"] {
        let out = d
            .path()
            .join(format!("r{}.csv", flag.trim_start_matches('-')));
        ok(&["resample", f, flag, "50", "-o", s(&out)]);
        outputs.push(std::fs::read_to_string(&out).unwrap());
    }
    // 10.24 s at 50 Hz: 512 rows after the header (the 200 Hz input has 2048).
    assert_eq!(outputs[0].lines().count(), 1 + 512, "not at 50 Hz");
    assert_eq!(outputs[1], outputs[0], "--to differs from --fs-out");
    assert_eq!(
        outputs[2], outputs[0],
        "--resample-to differs from --fs-out"
    );
}

#[test]
fn resample_without_a_rate_or_with_two_fails_in_one_line() {
    let d = tempfile::tempdir().unwrap();
    let files = simulate_csv(d.path(), "B", "30", "3", "1");
    let out = d.path().join("r.csv");
    fails_with(&["resample", &files[0], "-o", s(&out)], &["--fs-out"]);
    let o = common::vibmode(&[
        "resample",
        &files[0],
        "--fs-out",
        "50",
        "--to",
        "100",
        "-o",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", common::stderr(&o));
    assert!(!out.exists(), "a rate given twice still wrote output");
}

#[test]
fn analysis_commands_take_fs_out_and_the_old_resample_to() {
    let d = tempfile::tempdir().unwrap();
    let files = simulate_csv(d.path(), "B", "30", "3", "1");
    let f = files[0].as_str();
    let new = ok(&["psd", f, "--fs-out", "50", "--json", "-"]);
    let old = ok(&["psd", f, "--resample-to", "50", "--json", "-"]);
    let v: serde_json::Value = serde_json::from_slice(&new.stdout).unwrap();
    assert_eq!(
        v["parameters"]["resampled_to_hz"].as_f64(),
        Some(50.0),
        "{v}"
    );
    assert_eq!(
        old.stdout, new.stdout,
        "--resample-to differs from --fs-out"
    );
}

/// `--estimator` (fit, sweep) and `--resampler` (resample) each name one thing; `--method`,
/// their older spelling there, gives the same output.
#[test]
fn fit_and_sweep_take_estimator_and_the_old_method() {
    let d = tempfile::tempdir().unwrap();
    let files = simulate_csv(d.path(), "B", "30", "3", "1");
    let f = files[0].as_str();
    let base = [
        "fit", f, "-c", "0", "--model", "ar", "--order", "8", "--json", "-",
    ];
    let new = ok(&[&base[..], &["--estimator", "yule-walker"]].concat());
    let old = ok(&[&base[..], &["--method", "yule-walker"]].concat());
    let burg = ok(&[&base[..], &["--estimator", "burg"]].concat());
    assert_eq!(old.stdout, new.stdout, "--method differs from --estimator");
    assert_ne!(burg.stdout, new.stdout, "--estimator was not applied");
    let sweep = [
        "sweep", f, "-c", "0", "--model", "ar", "--orders", "4:8", "--json", "-",
    ];
    let new = ok(&[&sweep[..], &["--estimator", "ls"]].concat());
    let old = ok(&[&sweep[..], &["--method", "ls"]].concat());
    assert_eq!(
        old.stdout, new.stdout,
        "sweep: --method differs from --estimator"
    );
    fails_with(
        &[&base[..], &["--estimator", "pem"]].concat(),
        &["--estimator pem", "--model arma"],
    );
}

#[test]
fn resample_takes_resampler_and_the_old_method() {
    let d = tempfile::tempdir().unwrap();
    let files = simulate_csv(d.path(), "B", "30", "3", "1");
    let f = files[0].as_str();
    let mut outputs = Vec::new();
    for (flag, value) in [
        ("--resampler", "fir"),
        ("--method", "fir"),
        ("--resampler", "ideal"),
    ] {
        let out = d.path().join(format!("r{}.csv", outputs.len()));
        ok(&["resample", f, "--fs-out", "50", flag, value, "-o", s(&out)]);
        outputs.push(std::fs::read_to_string(&out).unwrap());
    }
    assert_eq!(
        outputs[1], outputs[0],
        "--method fir differs from --resampler fir"
    );
    // The FIR and the ideal filter differ in their last digits: the option reached the run.
    assert_ne!(outputs[2], outputs[0], "--resampler was not applied");
    let out = d.path().join("x.csv");
    fails_with(
        &[
            "resample",
            f,
            "--fs-out",
            "50",
            "--resampler",
            "fir",
            "--no-filter",
            "-o",
            s(&out),
        ],
        &["--resampler ideal"],
    );
}

/// `sweep --starts multi|single` (`[sweep] starts` of the analysis config): the default is
/// `multi`; an ARMA(9,9) fit (p + q = 18, one start either way) is the same with both; at the
/// first order of a sweep (no warm start) the multi-start keeps the lowest end point of the
/// single start's candidates and more, so its loss is never above; a value not in the list
/// fails in one line naming the ones that are.
#[test]
fn sweep_takes_starts() {
    let d = tempfile::tempdir().unwrap();
    let files = simulate_csv(d.path(), "B", "30", "3", "1");
    let f = files[0].as_str();
    let run = |orders: &str, starts: Option<&str>| {
        let mut args = vec!["sweep", f, "-c", "0", "--orders", orders, "--json", "-"];
        if let Some(s) = starts {
            args.extend(["--starts", s]);
        }
        let o = ok(&args);
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["channels"][0]["loss"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect::<Vec<f64>>()
    };
    let default = run("2:6", None);
    assert_eq!(run("2:6", Some("multi")), default);
    let single = run("2:6", Some("single"));
    assert!(single[0] >= default[0], "{single:?} against {default:?}");
    assert_eq!(run("9", Some("single")), run("9", Some("multi")));
    fails_with(
        &["sweep", f, "--starts", "some"],
        &["--starts", "multi", "single"],
    );
}
