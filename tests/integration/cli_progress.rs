//! The progress bar of `analyze`, `fleet ingest` and `fleet check`: nothing of it on a standard
//! error that is not a terminal, nothing with `-q`, and on a terminal (a pseudo-terminal from
//! `script`) records counted with their rate.

use crate::common;

use std::path::Path;
use std::process::Command;

use common::{ok, simulate_csv};

/// Nothing a progress bar draws: no carriage return, no terminal escape, no bar or spinner
/// characters, no rate, no time left.
fn assert_no_bar(what: &str, err: &str) {
    for needle in [
        "\r",
        "\x1b[",
        "records/s",
        "files/s",
        "ETA",
        "\u{2588}",
        "\u{2591}",
        "files analysed",
    ] {
        assert!(
            !err.contains(needle),
            "{what}: {needle:?} in stderr: {err:?}"
        );
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn no_bar_when_stderr_is_not_a_terminal_and_q_accepted() {
    let d = tempfile::tempdir().unwrap();
    let db = d.path().join("fleet.db");
    ok(&["fleet", "init", "--db", s(&db)]);
    let nominal = simulate_csv(&d.path().join("nominal"), "C", "40", "3", "6");
    let mut args = vec!["fleet", "ingest", "--db", s(&db), "--vehicle", "bus-1"];
    args.extend(nominal.iter().map(String::as_str));
    // Piped stderr, no -q: the per-file lines only.
    let o = ok(&args);
    let err = common::stderr(&o);
    assert!(err.contains("stored as nominal"), "{err}");
    assert_no_bar("fleet ingest", &err);
    // -q and --quiet accepted (the files are already stored: a no-op each).
    for q in ["-q", "--quiet"] {
        let mut with_q = args.clone();
        with_q.push(q);
        assert_no_bar("fleet ingest -q", &common::stderr(&ok(&with_q)));
    }
    ok(&["fleet", "baseline", "--db", s(&db), "--vehicle", "bus-1"]);
    let test = simulate_csv(&d.path().join("test"), "C", "40", "4", "2");
    let check = |extra: &[&str]| {
        let mut a = vec!["fleet", "check", "--db", s(&db), "--vehicle", "bus-1"];
        a.extend(extra);
        a.extend(test.iter().map(String::as_str));
        ok(&a)
    };
    let o = check(&[]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("class"));
    assert_no_bar("fleet check", &common::stderr(&o));
    assert_no_bar("fleet check -q", &common::stderr(&check(&["-q"])));
    let out = d.path().join("rep");
    let mut a = vec!["analyze", "--method", "arma", "-o", s(&out)];
    a.extend(test.iter().map(String::as_str));
    assert_no_bar("analyze", &common::stderr(&ok(&a)));
    a.push("-q");
    assert_no_bar("analyze -q", &common::stderr(&ok(&a)));
}

/// `-q` is one option of the whole program: every command takes it, before or after the command's
/// name (a script that passes it everywhere must not fail on the commands without a bar).
#[test]
fn every_command_takes_q_before_or_after_its_name() {
    let d = tempfile::tempdir().unwrap();
    let rec = simulate_csv(&d.path().join("r"), "C", "40", "7", "1");
    let rec = rec[0].as_str();
    let params = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/city_bus.toml");
    // The commands, each writing its output under a name of its own per `tag`.
    let commands = |tag: &str| -> Vec<Vec<String>> {
        let out = |name: &str| s(&d.path().join(format!("{tag}-{name}"))).to_string();
        let words = |w: &[&str]| w.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        vec![
            words(&["psd", rec]),
            words(&["fit", "--order", "4", rec]),
            words(&[
                "sweep",
                "--orders",
                "2:4",
                rec,
                "--json",
                &out("sweep.json"),
            ]),
            words(&["ssi", rec, "--json", &out("ssi.json")]),
            words(&["fullcar", params]),
            words(&["resample", "--fs-out", "100", rec, "-o", &out("rs.csv")]),
            words(&["segment", rec, "-o", &out("seg")]),
            words(&[
                "simulate",
                params,
                "--records",
                "1",
                "--duration-s",
                "2",
                "--fs",
                "200",
                "-o",
                &out("sim"),
            ]),
            words(&["fleet", "init", "--db", &out("f.db")]),
        ]
    };
    for cmd in commands("after") {
        let mut args: Vec<&str> = cmd.iter().map(String::as_str).collect();
        args.push("-q");
        assert_no_bar(&args.join(" "), &common::stderr(&ok(&args)));
    }
    for cmd in commands("before") {
        let mut args: Vec<&str> = vec!["--quiet"];
        args.extend(cmd.iter().map(String::as_str));
        assert_no_bar(&args.join(" "), &common::stderr(&ok(&args)));
    }
}

/// `vibmode ARGS` on a pseudo-terminal (util-linux `script`): what the terminal received.
/// None where `script` is missing.
fn on_terminal(args: &[&str]) -> Option<String> {
    let quote = |x: &str| format!("'{}'", x.replace('\'', r"'\''"));
    let mut cmd = quote(env!("CARGO_BIN_EXE_vibmode"));
    for a in args {
        cmd.push(' ');
        cmd.push_str(&quote(a));
    }
    let o = Command::new("script")
        .args(["-q", "-e", "-c", &cmd, "/dev/null"])
        .stdin(std::process::Stdio::null())
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert_eq!(o.status.code(), Some(0), "{args:?}: {text}");
    Some(text)
}

#[test]
fn bar_counts_files_on_a_terminal_and_not_with_q() {
    let d = tempfile::tempdir().unwrap();
    let db = d.path().join("fleet.db");
    ok(&["fleet", "init", "--db", s(&db)]);
    let files = simulate_csv(&d.path().join("r"), "C", "40", "5", "3");
    let mut args = vec![
        "fleet",
        "ingest",
        "--db",
        s(&db),
        "--vehicle",
        "bus-1",
        "-q",
    ];
    args.extend(files.iter().map(String::as_str));
    let Some(quiet) = on_terminal(&args) else {
        eprintln!("util-linux `script` not found: the terminal half of this test did not run");
        return;
    };
    assert!(quiet.contains("stored as nominal"), "{quiet}");
    assert!(
        !quiet.contains("files analysed") && !quiet.contains("files/s"),
        "{quiet:?}"
    );
    // Other files (new content), without -q: the bar counts files with their rate.
    let files = simulate_csv(&d.path().join("r2"), "C", "40", "6", "3");
    let mut args = vec!["fleet", "ingest", "--db", s(&db), "--vehicle", "bus-1"];
    args.extend(files.iter().map(String::as_str));
    let shown = on_terminal(&args).unwrap_or_default();
    assert!(shown.contains("stored as nominal"), "{shown}");
    assert!(
        shown.contains("/3 files analysed") && shown.contains("files/s"),
        "{shown:?}"
    );
}
