//! Shared by the fleet's simulated end-to-end tests.
#![allow(dead_code)]

use vibmode_fleet::FleetConfig;
use vibmode_vehicle::{simulate, Disturbances, RoadClass, SimParams, VehicleParams};

/// `n` simulated 10.24 s records at 200 Hz of `v` on `road` at `kmh`, with `disturbances`
/// (sensor noise, engine lines, ...; `Disturbances::default()`: none).
pub fn records(
    v: &VehicleParams,
    road: RoadClass,
    kmh: f64,
    seed: u64,
    n: usize,
    disturbances: Disturbances,
) -> Vec<vibmode_core::Recording> {
    let p = SimParams {
        road,
        speed_kmh: kmh,
        fs_hz: 200.0,
        records: n,
        seed,
        disturbances,
        ..SimParams::default()
    };
    simulate(v, &p)
        .expect("simulate")
        .records
        .into_iter()
        .map(|r| r.recording)
        .collect()
}

/// One simulated 10.24 s record at 200 Hz of `v` on `road` at `kmh`.
pub fn record(v: &VehicleParams, road: RoadClass, kmh: f64, seed: u64) -> vibmode_core::Recording {
    records(v, road, kmh, seed, 1, Disturbances::default()).remove(0)
}

/// A faster analysis than the default (AR sweep to order 16) so several seeds run in seconds.
/// `FAR=0.05 cargo test ...` repeats a run at another false-alarm rate (docs/fleet.md);
/// `NO_BODY=1` leaves out the body response to wheel motion (to measure what it adds).
pub fn config() -> FleetConfig {
    let mut c = FleetConfig::default();
    // AR(16) by Burg for speed; `FLEET_ARMA=1` keeps the fleet's own sweep (ARMA, orders
    // 2..FLEET_SWEEP_ORDER_MAX from one start each; `FLEET_OM=N` sets its highest order), as
    // measured in docs/fleet.md, "The fleet's order sweep".
    if std::env::var("FLEET_ARMA").is_err() {
        c.analysis.sweep.model = vibmode_analysis::SweepModel::Ar;
        c.analysis.sweep.order_max = 16;
    } else if let Some(om) = std::env::var("FLEET_OM").ok().and_then(|v| v.parse().ok()) {
        c.analysis.sweep.order_max = om;
    }
    // `FLEET_STARTS=multi` searches the small models from every candidate (the standalone
    // analysis's default) instead of the fleet's single start.
    if std::env::var("FLEET_STARTS").is_ok_and(|v| v == "multi") {
        c.analysis.sweep.starts = vibmode_core::SearchStarts::Multi;
    }
    if let Some(v) = std::env::var("FAR").ok().and_then(|v| v.parse().ok()) {
        c.false_alarm_rate = v;
    }
    if std::env::var("NO_BODY").is_ok() {
        c.body_response_bands_hz.clear();
    }
    c
}
