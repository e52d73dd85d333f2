//! Acceptance of the multichannel identification (SSI-cov, the analysis' settings: 40 block
//! rows, correlations pooled over the 8 records) on the realistic simulator over five seeds,
//! with the modes matched to the full-car model by frequency and MAC. What holds on 8 records
//! of 10.24 s (docs/ssi.md):
//! - body roll (1.33 Hz) within 5 % and MAC >= 0.85 on at least 3 of 5 seeds (measured: 3 of 5;
//!   1.313-1.324 Hz with MAC 0.89-0.92; one seed 1.394 Hz, one seed roll taken by a 1.28 Hz
//!   heave/roll mixture);
//! - the body bending mode (9.0 Hz, damping 0.03, between the axle modes at 8.7-9.9 Hz) found as
//!   its own cluster within 3 % and MAC >= 0.8 on at least 4 of 5 seeds (measured: 5 of 5,
//!   8.93-9.05 Hz, MAC 0.81-0.94); the ARMA pools merge it with wheel hop;
//! - no model mode matched to a cluster classed periodic (matching takes structural modes only)
//!   and every match one to one.
//!
//! Body heave and pitch (1.17 and 1.03 Hz, damping 0.19 and 0.17) are not separated on this
//! much data (a 1.05-1.28 Hz mixture with MAC 0.57-0.67 to heave; no pitch); printed, not
//! asserted.

use crate::common;

use vibmode_analysis::{analyze, AnalysisConfig};
use vibmode_core::IdentMethod;
use vibmode_vehicle::{FullCar, VehicleParams};

#[test]
fn ssi_finds_roll_and_bending_over_five_seeds() {
    let vehicle = VehicleParams::city_bus_flexible();
    let reference: Vec<_> = FullCar::new(&vehicle)
        .and_then(|c| c.modes())
        .expect("model modes")
        .iter()
        .map(|m| m.to_reference())
        .collect();
    let (mut roll, mut bending) = (0, 0);
    let mut table = Vec::new();
    for seed in 1..=5u64 {
        let (_, sim) = common::realistic_demo(seed);
        let records = common::inputs(&sim);
        let cfg = AnalysisConfig {
            method: IdentMethod::SsiCov.into(),
            ..AnalysisConfig::default()
        };
        let res = analyze(&records, &cfg, &reference, &|_, _| {}).expect("analysis");
        let ssi = res.ssi.expect("ssi results");
        // Every supported mode carries its jackknife standard deviations (8 records: 8 groups).
        for m in ssi.invariant_modes.iter().filter(|m| m.is_invariant()) {
            let u = m.uncertainty.as_ref().expect("jackknife uncertainty");
            assert!(
                u.replicates >= 2 && u.replicates <= u.of && u.of == 8,
                "{u:?}"
            );
            assert!(u.frequency_std_hz > 0.0 && u.frequency_std_hz < 0.1 * m.frequency_hz);
            assert!(u.damping_std > 0.0 && u.damping_std.is_finite(), "{u:?}");
        }
        let mut used = std::collections::HashSet::new();
        for m in &ssi.matches {
            let Some(k) = m.invariant else { continue };
            assert!(used.insert(k), "seed {seed}: mode {k} matched twice");
            assert_eq!(
                ssi.invariant_modes[k].class,
                vibmode_core::ModeClass::Structural
            );
            let f = ssi.invariant_modes[k].frequency_hz;
            let mac = m.mac.unwrap_or(0.0);
            table.push(format!(
                "seed {seed}: {} {:.3} Hz -> {f:.3} Hz, MAC {mac:.2}",
                m.reference.label, m.reference.frequency_hz
            ));
            let rel = (f - m.reference.frequency_hz).abs() / m.reference.frequency_hz;
            match m.reference.label.as_str() {
                "body roll" if rel <= 0.05 && mac >= 0.85 => roll += 1,
                "body bending" if rel <= 0.03 && mac >= 0.8 => bending += 1,
                _ => {}
            }
        }
    }
    let msg = format!("roll {roll}/5, bending {bending}/5\n{}", table.join("\n"));
    eprintln!("{msg}");
    assert!(roll >= 3, "{msg}");
    assert!(bending >= 4, "{msg}");
}
