//! The shipped demo: the flexible city bus (`examples/city_bus_flexible.toml`) simulated by
//! vibmode's simulator, with what the report and the terminal say about it.

use vibmode_analysis::RecordInput;
use vibmode_modal::ReferenceMode;
use vibmode_vehicle::{SimParams, Simulation, VehicleParams};

use crate::RunError;

/// The demo's settings: how many records of 10.24 s, and the simulation's seed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Demo {
    /// Records simulated (at least 1).
    pub records: usize,
    /// Random seed of the simulation (the same seed gives the same records).
    pub seed: u64,
}

impl Default for Demo {
    /// 8 records, seed 1 (`vibmode demo`).
    fn default() -> Self {
        Demo {
            records: 8,
            seed: 1,
        }
    }
}

pub use vibmode_core::TruthRow;

/// A simulated demo, ready to run: its records, the modes to match, the vehicle to update and
/// the words around it.
#[derive(Debug)]
pub struct DemoRecords {
    /// The simulation (records and truth), e.g. to write the records out.
    pub simulation: Simulation,
    /// The records, named with their mean speed.
    pub records: Vec<RecordInput>,
    /// The simulated bus's true modes, the reference the clusters are matched to.
    pub reference: Vec<ReferenceMode>,
    /// The simulated bus (its suspension is fitted to the records by the model update).
    pub vehicle: VehicleParams,
    /// The report's first paragraph: what was simulated.
    pub intro: String,
    /// The true modes and engine/gear lines, by frequency, for the terminal's table.
    pub truth: Vec<TruthRow>,
}

impl Demo {
    /// One line saying what is simulated (printed before the simulation).
    pub fn description(&self) -> String {
        format!(
            "simulating {} records of 10.24 s at 20 kHz: 12 m city bus with a flexible body, ISO 8608 class B road, ~30 km/h, wandering engine/gear lines, sensor noise and misalignment, braking, a turn, tones up to 6 kHz ...",
            self.records
        )
    }

    /// Simulates the demo's records.
    pub fn simulate(&self) -> Result<DemoRecords, RunError> {
        let vehicle = VehicleParams::city_bus_flexible();
        let p = SimParams::demo(self.records, self.seed);
        p.validate()?;
        let simulation = vibmode_vehicle::simulate(&vehicle, &p)?;
        let records = simulation
            .records
            .iter()
            .enumerate()
            .map(|(i, r)| RecordInput {
                name: format!("record {:02} ({:.1} km/h)", i + 1, r.mean_speed_kmh),
                recording: r.recording.clone(),
            })
            .collect();
        let truth_of = &simulation.truth;
        let reference = truth_of.modes.iter().map(|m| m.to_reference()).collect();
        let lines: Vec<String> = truth_of
            .disturbance_lines_hz
            .iter()
            .map(|f| format!("{f} Hz"))
            .collect();
        let intro = format!(
            "Demo: {} simulated record(s) of {} s of a 12 m city bus with a flexible body (vibmode's full-car simulator, examples/city_bus_flexible.toml: a body bending mode at 9 Hz between the axle modes) on an ISO 8608 class {} road at about {} km/h (the speed varies by 3 %), seed {}, with engine/gear lines at nominally {} (their frequency wanders by 0.1 %, their amplitude by 10 %, the engine speed differs by 2 % from record to record and the 7 Hz driveline line follows the vehicle speed), sensor noise, bias and misalignment up to 3 deg, braking, acceleration and a turn, and tones at {} Hz that alias without the anti-alias filter. The true modes are the full-car model's (red diamonds in the frequency-damping figure).",
            simulation.records.len(),
            p.duration_s,
            truth_of.road_class,
            truth_of.speed_kmh,
            self.seed,
            lines.join(", "),
            truth_of
                .hf_tones_hz
                .iter()
                .map(|f| f.to_string())
                .collect::<Vec<_>>()
                .join(", "),
        );
        let mut truth: Vec<TruthRow> = truth_of
            .modes
            .iter()
            .map(|m| (m.label.to_string(), m.frequency_hz, m.damping_ratio))
            .collect();
        for line in &truth_of.lines {
            let lo = line
                .record_min_hz
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min);
            let hi = line
                .record_max_hz
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max);
            truth.push((
                format!("engine/gear line, {lo:.2}-{hi:.2} Hz over the records"),
                line.nominal_hz,
                0.0,
            ));
        }
        truth.sort_by(|x, y| x.1.total_cmp(&y.1));
        Ok(DemoRecords {
            simulation,
            records,
            reference,
            vehicle,
            intro,
            truth,
        })
    }
}
