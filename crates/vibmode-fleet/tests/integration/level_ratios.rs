//! Physics check of the unsprung level ratios over seeds: on simulated city-bus records the
//! front/rear and left/right ratios of `compute_features` agree with the ratios of the model's
//! analytic PSDs (`FullCar::acceleration_psd`, docs/vehicle.md), and a front-left tyre 30 % softer
//! moves the front/rear ratio of the left side by the analytic amount. Measured (10 seeds, class C,
//! 40 km/h): mean measured - analytic -0.007 (FL/RL), -0.017 (FR/RR), +0.021 (FL/FR); the
//! softer tyre's shift of ln(U_FL / U_RL) -0.510 against the analytic -0.511.

use crate::common;

use common::config;
use vibmode_fleet::{compute_features, RecordFeatures};
use vibmode_vehicle::{
    simulate, Corner, CornerCondition, FullCar, RoadClass, RoadInput, SimParams, VehicleParams,
};

const KMH: f64 = 40.0;

/// ln(U_a / U_b) of the unsprung channels of corners `a`, `b` (ratio band RMS).
fn measured(rf: &RecordFeatures, a: &str, b: &str) -> f64 {
    let level = |c: &str| {
        rf.channels
            .iter()
            .find(|ch| ch.name == format!("{c}_unsprung"))
            .and_then(|ch| ch.ratio_band_rms)
            .unwrap_or(f64::NAN)
    };
    (level(a) / level(b)).ln()
}

/// The same ratio from the analytic PSDs over the ratio band (fine grid).
fn analytic(v: &VehicleParams, a: &str, b: &str, band: [f64; 2]) -> f64 {
    let car = FullCar::new(v).expect("model");
    let f: Vec<f64> = (0..=1200)
        .map(|i| band[0] + (band[1] - band[0]) * i as f64 / 1200.0)
        .collect();
    let road = RoadInput {
        class: RoadClass::C,
        ..RoadInput::default()
    };
    let psd = car.acceleration_psd(&road, KMH, &f).expect("psd");
    let power = |c: &str| -> f64 {
        psd.iter()
            .find(|s| s.name == format!("{c}_unsprung"))
            .map_or(f64::NAN, |s| s.psd_m2_s4_per_hz.iter().sum())
    };
    0.5 * (power(a) / power(b)).ln()
}

#[test]
fn level_ratios_match_the_analytic_psds_over_ten_seeds() {
    let cfg = config();
    let bus = VehicleParams::city_bus();
    let mut soft = bus.clone();
    soft.corner_condition.push(CornerCondition {
        tyre_stiffness_factor: 0.7,
        ..CornerCondition::nominal(Corner::FL)
    });
    let band = cfg.ratio_band_hz;
    let pairs = [("FL", "RL", 0.12), ("FR", "RR", 0.12), ("FL", "FR", 0.35)];
    let mut mean_shift = 0.0;
    let mut means = [0.0; 3];
    for seed in 0..10u64 {
        let run = |v: &VehicleParams| {
            let p = SimParams {
                road: RoadClass::C,
                speed_kmh: KMH,
                fs_hz: 200.0,
                records: 1,
                seed: 40 + seed,
                ..SimParams::default()
            };
            let rec = simulate(v, &p)
                .expect("simulate")
                .records
                .remove(0)
                .recording;
            compute_features("sim", &rec, &cfg).expect("features")
        };
        let rf = run(&bus);
        for (k, (a, b, tol)) in pairs.iter().enumerate() {
            let (m, t) = (measured(&rf, a, b), analytic(&bus, a, b, band));
            // Single records: within about 3.5 record-to-record spreads (0.035 and 0.11).
            assert!(
                (m - t).abs() < *tol,
                "seed {seed} {a}/{b}: {m:.3} vs {t:.3}"
            );
            means[k] += (m - t) / 10.0;
        }
        mean_shift += (measured(&run(&soft), "FL", "RL") - measured(&rf, "FL", "RL")) / 10.0;
    }
    // Means over 10 seeds: unbiased within 0.04 (front/rear) and 0.1 (left/right).
    assert!(means[0].abs() < 0.04 && means[1].abs() < 0.04, "{means:?}");
    assert!(means[2].abs() < 0.1, "{means:?}");
    // The softer tyre: analytic change of ln(U_FL / U_RL) (about -0.5), recovered within 0.05.
    let want = analytic(&soft, "FL", "RL", band) - analytic(&bus, "FL", "RL", band);
    eprintln!("mean measured - analytic {means:?}; FL tyre shift {mean_shift:.3} vs {want:.3}");
    assert!(want < -0.4, "{want}");
    assert!(
        (mean_shift - want).abs() < 0.05,
        "{mean_shift:.3} vs {want:.3}"
    );
}
