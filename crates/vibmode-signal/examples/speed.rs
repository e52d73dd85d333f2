//! Timing of the two hot paths at the paper's size (7 channels x 204 800 samples at 20 kHz):
//! reading a CSV and resampling to 200 Hz with the ideal filter.
//!
//! `cargo run --release -p vibmode-signal --example speed [-- DIR]` writes `big.csv` into DIR
//! (default: a temporary directory) and prints the timings (best of 5).
//! `... --example speed -- --read FILE` reads FILE once (for CPU-time comparisons with `perf stat`).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use vibmode_signal::ResampleRecording;
use vibmode_signal::{read_path, write_path, Channel, ReadOptions, Recording, ResampleParams};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // `--read FILE`: read one file once (for `perf stat` CPU-time comparisons).
    let args: Vec<String> = std::env::args().collect();
    if args.len() == 3 && args[1] == "--read" {
        let rec = read_path(std::path::Path::new(&args[2]), &ReadOptions::default())?;
        println!(
            "{} channels x {} samples at {} Hz",
            rec.channels.len(),
            rec.len(),
            rec.fs_hz
        );
        return Ok(());
    }
    let mut r = ChaCha8Rng::seed_from_u64(1);
    let chans = (0..7)
        .map(|c| Channel {
            name: format!("ch{c}"),
            unit: "m/s^2".into(),
            samples: (0..204_800).map(|_| r.gen_range(-30.0..30.0)).collect(),
            placement: Default::default(),
        })
        .collect();
    let rec = Recording::new(20_000.0, chans)?;
    let tmp = tempfile::tempdir()?;
    let dir = std::env::args()
        .nth(1)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| tmp.path().to_path_buf());
    let p = dir.join("big.csv");
    write_path(&p, &rec)?;
    let best = |f: &mut dyn FnMut()| {
        (0..5)
            .map(|_| {
                let t = std::time::Instant::now();
                f();
                t.elapsed().as_secs_f64() * 1e3
            })
            .fold(f64::INFINITY, f64::min)
    };
    let read_ms = best(&mut || {
        let back = read_path(&p, &ReadOptions::default()).expect("read");
        assert_eq!(back.len(), 204_800);
    });
    let p200 = ResampleParams {
        fs_out_hz: 200.0,
        cutoff_hz: Some(25.0),
        filter: true,
    };
    let res_ms = best(&mut || {
        let out = rec.resample(&p200).expect("resample");
        assert_eq!(out.len(), 2048);
    });
    println!(
        "read {} ({} bytes): {read_ms:.1} ms; resample 7 x 204800 20 kHz -> 200 Hz: {res_ms:.1} ms",
        p.display(),
        std::fs::metadata(&p)?.len()
    );
    Ok(())
}
