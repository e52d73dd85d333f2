//! Shared by the command-line tests: the binary run with a hang guard, and the two outcomes the
//! tests assert (exit 0; exit 2 with one short line naming the value).
#![allow(dead_code)]

use std::io::Read;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The `vibmode` binary under test.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_vibmode"))
}

/// Runs vibmode; a run still going after 120 s is a hang: killed, and the test fails (a hang
/// guard, not a timing measurement).
pub fn vibmode(args: &[&str]) -> Output {
    let child = bin()
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start vibmode");
    wait_or_kill(child, args)
}

/// Waits for `child`, killing it (and failing) after 120 s. Its piped stdout and stderr are
/// read while it runs, so that a large output cannot fill a pipe and stall it.
pub fn wait_or_kill(mut child: Child, args: &[&str]) -> Output {
    fn drain<R: Read + Send + 'static>(pipe: Option<R>) -> std::thread::JoinHandle<Vec<u8>> {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_end(&mut buf);
            }
            buf
        })
    }
    let out = drain(child.stdout.take());
    let err = drain(child.stderr.take());
    let t0 = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break status;
        }
        if t0.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("vibmode {args:?} hung (killed after 120 s)");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    Output {
        status,
        stdout: out.join().unwrap_or_default(),
        stderr: err.join().unwrap_or_default(),
    }
}

/// Standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// Exit code 2, one line of less than 400 bytes on stderr holding every needle, no panic.
/// Returns the line.
pub fn fails_with(args: &[&str], needles: &[&str]) -> String {
    let o = vibmode(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "args {args:?}: stderr {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    assert!(
        err.len() < 400,
        "message too long ({} bytes): {err}",
        err.len()
    );
    for n in needles {
        assert!(err.contains(n), "'{n}' not in: {err}");
    }
    err
}

/// Exit code 0 (else the test fails with stderr).
pub fn ok(args: &[&str]) -> Output {
    let o = vibmode(args);
    assert_eq!(o.status.code(), Some(0), "args {args:?}: {}", stderr(&o));
    o
}

/// The arguments `fleet SUB --db DB --vehicle VEHICLE REST...`.
pub fn fleet_args<'a>(
    sub: &'a str,
    db: &'a str,
    vehicle: &'a str,
    rest: &[&'a str],
) -> Vec<&'a str> {
    let mut args = vec!["fleet", sub, "--db", db, "--vehicle", vehicle];
    args.extend_from_slice(rest);
    args
}

/// `vibmode fleet ingest -q` of `files` as nominal records of `vehicle` into the store `db`
/// (exit code 0, else the test fails with stderr).
pub fn fleet_ingest<S: AsRef<str>>(db: &str, vehicle: &str, files: &[S]) -> Output {
    let mut args = vec!["fleet", "ingest", "--db", db, "--vehicle", vehicle, "-q"];
    args.extend(files.iter().map(AsRef::as_ref));
    ok(&args)
}

/// Simulated bus records (CSV, 200 Hz, 10.24 s; road class, speed in km/h) from `vibmode simulate` into `dir`.
pub fn simulate_csv(
    dir: &std::path::Path,
    road: &str,
    speed: &str,
    seed: &str,
    records: &str,
) -> Vec<String> {
    let params = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/city_bus.toml");
    simulate_csv_of(params, dir, road, speed, seed, records)
}

/// As [`simulate_csv`], of the vehicle file `params`.
pub fn simulate_csv_of(
    params: &str,
    dir: &std::path::Path,
    road: &str,
    speed: &str,
    seed: &str,
    records: &str,
) -> Vec<String> {
    ok(&[
        "simulate",
        params,
        "--road",
        road,
        "--speed-kmh",
        speed,
        "--duration-s",
        "10.24",
        "--records",
        records,
        "--seed",
        seed,
        "--fs",
        "200",
        "--format",
        "csv",
        "-o",
        dir.to_str().unwrap(),
    ]);
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .map(|p| p.to_string_lossy().to_string())
        .collect();
    files.sort();
    files
}
