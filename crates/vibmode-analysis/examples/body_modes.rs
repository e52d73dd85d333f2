//! The body modes (heave, pitch, roll) of the realistic demo bus found by the analysis' SSI-cov,
//! over five seeds, for a given amount of data and first correlation lag (docs/ssi.md, "The
//! road's own correlation"):
//!
//! ```text
//! cargo run --release -p vibmode-analysis --example body_modes -- RECORDS FIRST_LAG [VMIN VMAX]
//! cargo run --release -p vibmode-analysis --example body_modes -- 128 40
//! cargo run --release -p vibmode-analysis --example body_modes -- 128 1 20 45
//! ```
//!
//! Without a speed range the records are successive segments of the demo's drive at 30 km/h;
//! with `VMIN VMAX` (km/h) each record is driven on its own at a speed spread over the range
//! (record `r` at `VMIN + (VMAX - VMIN) frac(0.618 r + 0.37 seed)`, 10 s warm-up).
//!
//! For each model mode below 2 Hz it prints the identified structural cluster within 25 % in
//! frequency with the best MAC to the model's shape at the sensors.

use std::error::Error;

use vibmode_analysis::{analyze, AnalysisConfig, RecordInput};
use vibmode_core::{IdentMethod, ModeClass};
use vibmode_vehicle::{simulate, FullCar, SimParams, VehicleParams};

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().collect();
    let records: usize = args.get(1).map_or(Ok(8), |s| s.parse())?;
    let first_lag: usize = args.get(2).map_or(Ok(1), |s| s.parse())?;
    let speeds: Option<(f64, f64)> = match (args.get(3), args.get(4)) {
        (Some(a), Some(b)) => Some((a.parse()?, b.parse()?)),
        _ => None,
    };
    let vehicle = VehicleParams::city_bus_flexible();
    let reference: Vec<_> = FullCar::new(&vehicle)?
        .modes()?
        .iter()
        .map(|m| m.to_reference())
        .collect();
    let body: Vec<_> = reference.iter().filter(|r| r.frequency_hz < 2.0).collect();
    println!("{records} records of 10.24 s, first lag {first_lag}, speeds {speeds:?} km/h");
    for seed in 1..=5u64 {
        let inputs: Vec<RecordInput> = match speeds {
            None => simulate(
                &vehicle,
                &SimParams {
                    fs_hz: 500.0,
                    ..SimParams::demo(records, seed)
                },
            )?
            .records
            .into_iter()
            .enumerate()
            .map(|(i, r)| RecordInput {
                name: format!("record {i}"),
                recording: r.recording,
            })
            .collect(),
            Some((vmin, vmax)) => (0..records)
                .map(|i| {
                    let frac = (i as f64 * 0.618_033_988_75 + seed as f64 * 0.37).fract();
                    let sim = simulate(
                        &vehicle,
                        &SimParams {
                            fs_hz: 500.0,
                            speed_kmh: vmin + (vmax - vmin) * frac,
                            warmup_s: Some(10.0),
                            ..SimParams::demo(1, seed * 1000 + i as u64)
                        },
                    )?;
                    let recording = sim
                        .records
                        .into_iter()
                        .next()
                        .ok_or("the simulation gave no record")?
                        .recording;
                    Ok(RecordInput {
                        name: format!("record {i}"),
                        recording,
                    })
                })
                .collect::<Result<_, Box<dyn Error>>>()?,
        };
        let mut cfg = AnalysisConfig {
            method: IdentMethod::SsiCov.into(),
            ..AnalysisConfig::default()
        };
        cfg.ssi.first_lag = first_lag;
        let res = analyze(&inputs, &cfg, &reference, &|_, _| {})?;
        let Some(ssi) = res.ssi else { continue };
        let mut line = format!("seed {seed}:");
        for r in &body {
            let Some(shape) = r.shape_for(&ssi.channels) else {
                continue;
            };
            let best = ssi
                .invariant_modes
                .iter()
                .filter(|m| m.class == ModeClass::Structural)
                .filter(|m| (m.frequency_hz / r.frequency_hz - 1.0).abs() <= 0.25)
                .filter_map(|m| {
                    let s = m.shape.as_ref()?;
                    Some((m, vibmode_modal::shapes::mac(&shape, s)))
                })
                .max_by(|a, b| a.1.total_cmp(&b.1));
            match best {
                Some((m, mac)) => line.push_str(&format!(
                    "  {} {:.3} Hz -> {:.3} Hz ({:+.1} %), damping {:.2}, MAC {mac:.2};",
                    r.label,
                    r.frequency_hz,
                    m.frequency_hz,
                    100.0 * (m.frequency_hz / r.frequency_hz - 1.0),
                    m.damping_ratio
                )),
                None => line.push_str(&format!("  {}: no cluster;", r.label)),
            }
        }
        println!("{line}");
    }
    Ok(())
}
