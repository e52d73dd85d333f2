//! Shared by the acceptance tests: simulated records as analysis inputs.
#![allow(dead_code)]

use vibmode_analysis::RecordInput;
use vibmode_vehicle::{simulate, SimParams, Simulation, VehicleParams};

/// The records of a simulation, named `record i`.
pub fn inputs(sim: &Simulation) -> Vec<RecordInput> {
    sim.records
        .iter()
        .enumerate()
        .map(|(i, r)| RecordInput {
            name: format!("record {i}"),
            recording: r.recording.clone(),
        })
        .collect()
}

/// The realistic demo (`SimParams::demo`, 8 records) of the flexible bus for `seed`, simulated
/// at 500 Hz (the modes and lines lie below 15 Hz).
pub fn realistic_demo(seed: u64) -> (VehicleParams, Simulation) {
    let vehicle = VehicleParams::city_bus_flexible();
    let sim = simulate(
        &vehicle,
        &SimParams {
            fs_hz: 500.0,
            ..SimParams::demo(8, seed)
        },
    )
    .expect("simulation");
    (vehicle, sim)
}
