//! A seeded mutation fuzz over every reader and the configuration parsers (the campaign of issue
//! 15, run on every `cargo test`): valid inputs of every kind are mutated (bytes flipped,
//! inserted, deleted, lines duplicated or cut, numbers replaced by extreme ones, the file
//! truncated) and read. Property: no panic, and a read that succeeds gives a recording inside
//! the documented limits (finite samples of bounded magnitude, a bounded rate). The base
//! inputs are built here; nothing generated is committed.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;
use vibmode_core::limits::{FS_HZ_MAX, FS_HZ_MIN, SAMPLE_ABS_MAX};
use vibmode_core::{Channel, Recording};
use vibmode_signal::ReadOptions;

const EXTREMES: &[&str] = &[
    "1e155", "-1e308", "1e-200", "NaN", "inf", "-0", "0x10", "1,5", "", "\"", "1e999", "9",
];

fn mutate(rng: &mut ChaCha8Rng, base: &[u8], text: bool) -> Vec<u8> {
    let mut b = base.to_vec();
    for _ in 0..rng.gen_range(1..4) {
        if b.is_empty() {
            break;
        }
        let i = rng.gen_range(0..b.len());
        match rng.gen_range(0..8) {
            0 => b[i] = rng.gen(),
            1 => b.insert(i, rng.gen()),
            2 => {
                b.remove(i);
            }
            3 => b.truncate(i),
            4 if text => {
                // Replace the number around i by an extreme one.
                let e = EXTREMES[rng.gen_range(0..EXTREMES.len())].as_bytes();
                let is_num = |c: u8| c.is_ascii_digit() || matches!(c, b'.' | b'-' | b'e');
                let mut a = i;
                while a > 0 && is_num(b[a - 1]) {
                    a -= 1;
                }
                let mut z = i;
                while z < b.len() && is_num(b[z]) {
                    z += 1;
                }
                b.splice(a..z, e.iter().copied());
            }
            5 if text => {
                // Duplicate or drop a line.
                let start = b[..i]
                    .iter()
                    .rposition(|&c| c == b'\n')
                    .map_or(0, |p| p + 1);
                let end = b[i..]
                    .iter()
                    .position(|&c| c == b'\n')
                    .map_or(b.len(), |p| i + p + 1);
                let line = b[start..end].to_vec();
                if rng.gen() {
                    b.splice(start..start, line);
                } else {
                    b.drain(start..end);
                }
            }
            6 => {
                let n = rng.gen_range(1..64);
                let at = rng.gen_range(0..=b.len());
                let junk: Vec<u8> = (0..n).map(|_| rng.gen()).collect();
                b.splice(at..at, junk);
            }
            _ => {
                let j = rng.gen_range(0..b.len());
                b.swap(i, j);
            }
        }
    }
    b
}

fn check_read(path: &Path, opts: &ReadOptions, what: &str) {
    let r = std::panic::catch_unwind(|| vibmode_signal::read_path(path, opts));
    let r = r.unwrap_or_else(|_| panic!("{what}: the reader panicked"));
    if let Ok(rec) = r {
        assert!(
            (FS_HZ_MIN..=FS_HZ_MAX).contains(&rec.fs_hz),
            "{what}: rate {} accepted",
            rec.fs_hz
        );
        for c in &rec.channels {
            assert!(
                c.samples
                    .iter()
                    .all(|v| v.is_finite() && v.abs() <= SAMPLE_ABS_MAX),
                "{what}: channel {} has a sample outside the limits",
                c.name
            );
        }
    }
}

fn base_recording() -> Recording {
    let a: Vec<f64> = (0..400).map(|i| (i as f64 * 0.3).sin()).collect();
    let b: Vec<f64> = (0..400).map(|i| (i as f64 * 0.11).cos() * 2.5).collect();
    Recording::new(
        200.0,
        vec![Channel::new("a", "m/s^2", a), Channel::new("b", "m/s^2", b)],
    )
    .unwrap()
}

#[test]
fn mutated_files_of_every_format_never_panic_or_give_out_of_range_data() {
    let d = tempfile::tempdir().unwrap();
    let rec = base_recording();
    let mut bases: Vec<(&str, Vec<u8>, bool)> = Vec::new();
    for ext in ["csv", "tsv", "wav", "f32", "f64"] {
        let p = d.path().join(format!("base.{ext}"));
        vibmode_signal::write_path(&p, &rec).unwrap();
        bases.push((
            ext,
            std::fs::read(&p).unwrap(),
            matches!(ext, "csv" | "tsv"),
        ));
    }
    // Dialects the writer does not produce: semicolons with decimal commas, whitespace, a
    // header in ms, Excel's directive.
    let mut semi = String::from("Time (ms);X (g);Y (g)\n");
    let mut ws = String::from("t a b\n");
    let mut excel = String::from("sep=,\nPacketCounter,Acc_X,Acc_Z,\n");
    for i in 0..300 {
        semi.push_str(&format!("{};{:.4};{:.4}\n", i * 5, (i as f64).sin(), 0.5).replace('.', ","));
        ws.push_str(&format!(
            "  {}  {:.5}\t{}\n",
            i as f64 / 100.0,
            (i as f64).cos(),
            i % 7
        ));
        excel.push_str(&format!("{i},{:.3},{:.3},\n", (i as f64 * 0.2).sin(), 9.81));
    }
    // A NumPy array (vibmode does not write one): numpy.save's header, then the samples by
    // channels in C order.
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    let mut h = String::from("{'descr': '<f8', 'fortran_order': False, 'shape': (400, 2), }");
    while (10 + h.len() + 1) % 64 != 0 {
        h.push(' ');
    }
    h.push('\n');
    npy.extend((h.len() as u16).to_le_bytes());
    npy.extend(h.as_bytes());
    for i in 0..400 {
        for c in &rec.channels {
            npy.extend(c.samples[i].to_le_bytes());
        }
    }
    bases.push(("npy", npy, false));
    bases.push(("csv", semi.into_bytes(), true));
    bases.push(("txt", ws.into_bytes(), true));
    bases.push(("csv", excel.into_bytes(), true));
    let f32_sidecar = std::fs::read(d.path().join("base.f32.json")).unwrap();
    let opts = ReadOptions::default();
    let mut rng = ChaCha8Rng::seed_from_u64(15);
    let mut n_ok = 0;
    let mut n_err = 0;
    for round in 0..150 {
        for (k, (ext, base, text)) in bases.iter().enumerate() {
            let bytes = mutate(&mut rng, base, *text);
            let p = d.path().join(format!("m{k}.{ext}"));
            std::fs::write(&p, &bytes).unwrap();
            match *ext {
                "wav" => {
                    // Keep the names sidecar sometimes, mutate it sometimes.
                    let side = d.path().join(format!("m{k}.wav.json"));
                    let _ = std::fs::remove_file(&side);
                    if rng.gen_bool(0.3) {
                        let s = br#"{"channels": ["a", "b"], "units": ["m/s^2", "m/s^2"]}"#;
                        std::fs::write(&side, mutate(&mut rng, s, true)).unwrap();
                    }
                }
                "npy" => {
                    // Mutate the header more often than the samples: the header is the parser.
                    let mut b = base.clone();
                    for _ in 0..rng.gen_range(1..3) {
                        let i = rng.gen_range(0..128);
                        b[i] = rng.gen();
                    }
                    let b = if rng.gen_bool(0.5) { b } else { bytes.clone() };
                    std::fs::write(&p, &b).unwrap();
                }
                "f32" | "f64" => {
                    let side = d.path().join(format!("m{k}.{ext}.json"));
                    let base_side = if *ext == "f32" {
                        f32_sidecar.clone()
                    } else {
                        std::fs::read(d.path().join("base.f64.json")).unwrap()
                    };
                    let s = if rng.gen_bool(0.5) {
                        mutate(&mut rng, &base_side, true)
                    } else {
                        base_side
                    };
                    std::fs::write(&side, s).unwrap();
                }
                _ => {}
            }
            let what = format!("round {round}, base {k} (.{ext})");
            for o in [
                opts.clone(),
                ReadOptions {
                    fs_hz: Some(100.0),
                    ..opts.clone()
                },
            ] {
                check_read(&p, &o, &what);
            }
            match vibmode_signal::read_path(&p, &opts) {
                Ok(_) => n_ok += 1,
                Err(e) => {
                    let msg = e.to_string();
                    assert!(!msg.contains('\n'), "{what}: multi-line message {msg}");
                    assert!(
                        msg.chars().all(|c| !c.is_control()),
                        "{what}: control characters in the message {msg:?}"
                    );
                    assert!(msg.len() < 600, "{what}: message of {} bytes", msg.len());
                    n_err += 1;
                }
            }
        }
    }
    // Both outcomes occur: the mutations are neither all harmless nor all fatal.
    assert!(n_ok > 50 && n_err > 50, "ok {n_ok}, errors {n_err}");
}

#[test]
fn mutated_configurations_never_panic() {
    // Every key with its default, as docs/analysis.md documents them.
    let analysis = toml::to_string(&vibmode_analysis::AnalysisConfig::default()).unwrap();
    let vehicle = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/city_bus.toml"),
    )
    .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(1515);
    for round in 0..400 {
        let a = mutate(&mut rng, analysis.as_bytes(), true);
        let a = String::from_utf8_lossy(&a).into_owned();
        let r = std::panic::catch_unwind(|| vibmode_analysis::AnalysisConfig::from_toml_str(&a));
        match r {
            Err(_) => panic!("round {round}: the analysis config parser panicked on:\n{a}"),
            Ok(Err(e)) => assert!(!e.to_string().contains('\n'), "round {round}: {e}"),
            Ok(Ok(cfg)) => assert!(cfg.validate().is_ok(), "round {round}: accepted invalid"),
        }
        let v = mutate(&mut rng, vehicle.as_bytes(), true);
        let v = String::from_utf8_lossy(&v).into_owned();
        let r = std::panic::catch_unwind(|| vibmode_vehicle::VehicleParams::from_toml_str(&v));
        match r {
            Err(_) => panic!("round {round}: the vehicle parser panicked on:\n{v}"),
            Ok(Err(e)) => {
                let m = e.to_string();
                assert!(!m.contains('\n') && m.len() < 600, "round {round}: {m}");
            }
            Ok(Ok(p)) => {
                // Accepted parameters give a model whose modes are finite.
                if let Ok(car) = vibmode_vehicle::FullCar::new(&p) {
                    if let Ok(modes) = car.modes() {
                        assert!(
                            modes
                                .iter()
                                .all(|m| m.frequency_hz.is_finite() && m.damping_ratio.is_finite()),
                            "round {round}: non-finite modes"
                        );
                    }
                }
            }
        }
    }
}
