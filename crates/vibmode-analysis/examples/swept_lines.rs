//! Measurement behind the swept lines (docs/analysis.md, "Periodic lines"): for five seeds of the
//! realistic demo, every record's true lines (frequency range within the record) beside the
//! ridges of the short-time spectra of each sprung channel (range, roughness, kurtosis
//! demodulated along the ridge), and the count of true swept lines found and of false ones:
//!
//! ```text
//! cargo run --release -p vibmode-analysis --example swept_lines -- [STFT_NPERSEG STFT_NOVERLAP STFT_MIN_PROMINENCE_DB]
//! ```

use std::error::Error;

use vibmode_core::{LineParams, PreprocessParams, Role};
use vibmode_spectra::swept_line_candidates;
use vibmode_vehicle::{simulate, SimParams, VehicleParams};

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().collect();
    let d = LineParams::default();
    let p = LineParams {
        stft_nperseg: args.get(1).map_or(Ok(d.stft_nperseg), |s| s.parse())?,
        stft_noverlap: args.get(2).map_or(Ok(d.stft_noverlap), |s| s.parse())?,
        stft_min_prominence_db: args
            .get(3)
            .map_or(Ok(d.stft_min_prominence_db), |s| s.parse())?,
        ..d
    };
    let vehicle = VehicleParams::city_bus_flexible();
    let (mut swept_true, mut swept_found, mut reported, mut wrong) = (0, 0, 0, 0);
    for seed in 1..=5u64 {
        let sim = simulate(
            &vehicle,
            &SimParams {
                fs_hz: 500.0,
                ..SimParams::demo(8, seed)
            },
        )?;
        for (r, rec) in sim.records.iter().enumerate() {
            let lines = &sim.truth.lines;
            let truth: Vec<String> = lines
                .iter()
                .map(|l| {
                    format!(
                        "{:.2} ({:.2}-{:.2})",
                        l.record_mean_hz[r], l.record_min_hz[r], l.record_max_hz[r]
                    )
                })
                .collect();
            println!("seed {seed} record {r}: true {}", truth.join(", "));
            let pre = vibmode_signal::preprocess(&rec.recording, &PreprocessParams::default())?;
            let mut found: Vec<(f64, f64, f64)> = Vec::new();
            for ch in &pre.recording.channels {
                if ch.placement.role != Role::Sprung {
                    continue;
                }
                for c in swept_line_candidates(&ch.samples, pre.band.fs_hz, &p)? {
                    let f = &c.ridge.freq_hz;
                    let mean = f.iter().sum::<f64>() / f.len() as f64;
                    let (lo, hi) = c.ridge.span_hz();
                    println!(
                        "  {:<12} ridge {:.2} -> {:.2} (mean {:.2}, range {:.2}, {} of {} slices, roughness {:.3}) kurtosis {:.2} (fixed {:.2}){}",
                        ch.name,
                        f[0],
                        f[f.len() - 1],
                        mean,
                        c.ridge.range_hz(),
                        c.ridge.n_found,
                        f.len(),
                        c.ridge.roughness_hz(),
                        c.kurtosis,
                        c.fixed_kurtosis,
                        if c.periodic { " LINE" } else { "" }
                    );
                    if c.periodic && !found.iter().any(|g| (g.0 - mean).abs() < 0.3) {
                        found.push((mean, lo, hi));
                    }
                }
            }
            let matches = |g: &(f64, f64, f64), l: &vibmode_vehicle::LineTruth| {
                (g.0 - l.record_mean_hz[r]).abs() < 0.3
                    && g.1 < l.record_max_hz[r]
                    && g.2 > l.record_min_hz[r]
            };
            for l in lines {
                if l.record_max_hz[r] - l.record_min_hz[r] >= p.sweep_min_range_hz {
                    swept_true += 1;
                    swept_found += usize::from(found.iter().any(|g| matches(g, l)));
                }
            }
            reported += found.len();
            wrong += found
                .iter()
                .filter(|g| !lines.iter().any(|l| matches(g, l)))
                .count();
        }
    }
    println!(
        "swept lines (range >= {} Hz) found {swept_found}/{swept_true}; reported {reported}, not a line {wrong}",
        p.sweep_min_range_hz
    );
    Ok(())
}
