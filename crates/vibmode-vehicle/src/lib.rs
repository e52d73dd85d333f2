//! # vibmode-vehicle
//!
//! Ground truth for vibmode: a linear 7-DOF full-car model (body heave, pitch, roll and four
//! wheel hops, optional body bending as an 8th modal DOF) with its modes, frequency responses
//! and analytic acceleration PSDs on ISO 8608 roads, and a simulator of the in-service bus
//! measurement campaign (7 vertical accelerometers, 20 kHz, 8 records of 10.24 s) with
//! manoeuvres, engine lines, sensor noise/bias and high-frequency tones.
//!
//! Units: SI, frequencies in Hz, accelerations in m/s^2, PSDs one-sided in m^2/s^4/Hz.
//! Model equations, the TOML format and the simulator options are in `docs/vehicle.md`.
//!
//! ```
//! use vibmode_vehicle::{simulate, FullCar, ModeLabel, SimParams, VehicleParams};
//!
//! let bus = VehicleParams::city_bus(); // examples/city_bus.toml
//! let car = FullCar::new(&bus)?;
//! let modes = car.modes()?;
//! let heave = modes.iter().find(|m| m.label == ModeLabel::BodyHeave).unwrap();
//! assert!((0.8..1.3).contains(&heave.frequency_hz));
//! assert!(modes.iter().all(|m| m.damping_ratio > 0.0 && m.damping_ratio < 1.0));
//!
//! // A short, low-rate simulation: 2 records of 2 s at 500 Hz.
//! let sim = SimParams { fs_hz: 500.0, duration_s: 2.0, records: 2, warmup_s: Some(1.0), ..SimParams::default() };
//! let out = simulate(&bus, &sim)?;
//! assert_eq!(out.records.len(), 2);
//! let rec = &out.records[0].recording; // a vibmode_core::Recording, ready for the analysis
//! assert_eq!(rec.channels[4].name, "FR_sprung");
//! assert_eq!(rec.channels[4].placement.role, vibmode_core::Role::Sprung);
//! assert_eq!(rec.len(), 1000);
//! # Ok::<(), vibmode_vehicle::VehicleError>(())
//! ```

#![warn(missing_docs)]

pub mod drive;
pub mod error;
pub mod lines;
pub mod model;
pub mod nnls;
pub mod params;
pub mod road;
pub mod sim;
pub mod update;

pub use error::{Result, VehicleError};
pub use lines::{EngineLine, LineTruth};
pub use model::{FullCar, ModeInfo, ModeLabel, SensorPsd};
pub use params::{
    default_sensors, Axle, Bending, Body, Corner, CornerCondition, Geometry, SensorKind,
    SensorSpec, VehicleParams,
};
pub use road::{
    LateralCoherence, RoadClass, RoadInput, RoadProfile, DEFAULT_TYRE_ENVELOPE_CYCLES_PER_M,
    N0_CYCLES_PER_M,
};
pub use sim::{simulate, Disturbances, Manoeuvre, SimParams, SimRecord, Simulation, Tone, Truth};
