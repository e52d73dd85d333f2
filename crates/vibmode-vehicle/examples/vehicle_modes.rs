//! Print the modes of the shipped vehicles and time one 10.24 s, 20 kHz, 7-channel record.
//! Run with `cargo run --release -p vibmode-vehicle --example vehicle_modes`.
use vibmode_vehicle::{simulate, FullCar, RoadClass, SimParams, VehicleParams};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    for (name, p) in [
        ("city bus", VehicleParams::city_bus()),
        ("passenger car", VehicleParams::passenger_car()),
    ] {
        println!("{name}:");
        for m in FullCar::new(&p)?.modes()? {
            println!(
                "  {:>7.3} Hz  zeta {:.3}  {}",
                m.frequency_hz, m.damping_ratio, m.label
            );
        }
    }
    let bus = VehicleParams::city_bus();
    for (label, sim) in [
        (
            "1 record, quiet, no warm-up",
            SimParams {
                road: RoadClass::C,
                speed_kmh: 40.0,
                seed: 0,
                records: 1,
                warmup_s: Some(0.0),
                ..SimParams::default()
            },
        ),
        (
            "1 record, quiet",
            SimParams {
                road: RoadClass::C,
                speed_kmh: 40.0,
                seed: 0,
                records: 1,
                ..SimParams::default()
            },
        ),
        (
            "1 record, in-service",
            SimParams {
                road: RoadClass::C,
                speed_kmh: 40.0,
                seed: 0,
                records: 1,
                ..SimParams::in_service()
            },
        ),
        (
            "8 records, in-service",
            SimParams {
                road: RoadClass::C,
                speed_kmh: 40.0,
                seed: 0,
                ..SimParams::in_service()
            },
        ),
    ] {
        let t = std::time::Instant::now();
        let s = simulate(&bus, &sim)?;
        let el = t.elapsed().as_secs_f64();
        let rms: Vec<f64> = s.records[0]
            .recording
            .channels
            .iter()
            .map(|c| (c.samples.iter().map(|v| v * v).sum::<f64>() / c.samples.len() as f64).sqrt())
            .collect();
        println!(
            "{label}: {el:.3} s (warm-up {:.1} s); record-0 RMS m/s^2 {:.3?}",
            s.truth.warmup_s, rms
        );
    }
    Ok(())
}
