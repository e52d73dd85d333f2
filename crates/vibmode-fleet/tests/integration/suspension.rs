//! The suspension fitted per drive (`vibmode_fleet::suspension`) on vibmode's own simulator, over
//! seeds: per baseline seed a fit of 8 healthy records (class B, 30 km/h, in-service sensor
//! noise and engine lines), then drives of 4 records on other seeds: healthy at 20-40 km/h on
//! roads B and C and with 15 % more load, and with one corner's spring at 80 % or damper at 70 %.
//!
//! Judged against the goals and the stated false-alarm rate, not against what was
//! measured: a healthy drive flags a corner with probability at most 0.5 % (the limit, -3.23 =
//! Phi^-1(0.01 / 16): the drive's 8 tests get half the 1 %, the spring trend's 4 the other
//! half), so 2 or more flagged of the healthy drives would be improbable (< 5 %) if
//! the rate held; a fault is found with its corner and part lowest in at least 90 % of drives.

use crate::common;

use common::records;
use vibmode_fleet::suspension::{corner_scores, suspension_limit, Part, VehicleModel};
use vibmode_fleet::FleetConfig;
use vibmode_vehicle::{Corner, CornerCondition, Disturbances, RoadClass, VehicleParams};

const CITY_BUS: &str = include_str!("../../../../examples/city_bus.toml");

fn with(bus: &VehicleParams, corner: Corner, spring: f64, damper: f64) -> VehicleParams {
    let mut v = bus.clone();
    v.corner_condition.push(CornerCondition {
        corner,
        damper_factor: damper,
        spring_factor: spring,
        tyre_stiffness_factor: 1.0,
    });
    v
}

/// A checked drive: the vehicle, its road and speed, and the fault (corner and part) if any.
type DrivePlan = (VehicleParams, RoadClass, f64, Option<(Corner, Part)>);

/// P(X >= k) for X ~ Binomial(n, p).
fn tail(k: usize, n: usize, p: f64) -> f64 {
    let comb = |n: usize, k: usize| -> f64 {
        (0..k).fold(1.0, |c, i| c * (n - i) as f64 / (i + 1) as f64)
    };
    (k..=n)
        .map(|j| comb(n, j) * p.powi(j as i32) * (1.0 - p).powi((n - j) as i32))
        .sum()
}

#[test]
fn the_binomial_tail_by_hand() {
    // 1 - 0.99^24 - 24 * 0.01 * 0.99^23 = 0.0239.
    assert!((tail(2, 24, 0.01) - 0.023_9).abs() < 1e-4);
    assert!((tail(0, 5, 0.3) - 1.0).abs() < 1e-12);
}

#[test]
fn springs_and_dampers_fitted_per_drive_over_seeds() {
    let bus = VehicleParams::city_bus();
    let model = VehicleModel::from_toml(CITY_BUS, "examples/city_bus.toml").unwrap();
    let cfg = FleetConfig::default();
    let limit = suspension_limit(cfg.false_alarm_rate);
    let fit = |recs: &[vibmode_core::Recording]| {
        let eqs: Vec<_> = recs
            .iter()
            .map(|r| model.record_equations(r, &cfg.analysis).unwrap())
            .collect();
        let refs: Vec<_> = eqs.iter().map(|e| &e.equations).collect();
        model.fit_corners(&cfg.analysis, &refs).unwrap()
    };
    let (mut healthy, mut flagged) = (0usize, 0usize);
    let (mut faults, mut found) = (0usize, 0usize);
    for b in 0..4u64 {
        let base = fit(&records(
            &bus,
            RoadClass::B,
            30.0,
            100 + b,
            8,
            Disturbances::in_service(),
        ));
        let drives: Vec<DrivePlan> = vec![
            (bus.clone(), RoadClass::B, 20.0, None),
            (bus.clone(), RoadClass::C, 40.0, None),
            (bus.with_passenger_load(0.15), RoadClass::B, 30.0, None),
            (bus.clone(), RoadClass::C, 25.0, None),
            (
                with(&bus, Corner::RL, 0.8, 1.0),
                RoadClass::B,
                30.0,
                Some((Corner::RL, Part::Spring)),
            ),
            (
                with(&bus, Corner::FR, 0.8, 1.0),
                RoadClass::C,
                35.0,
                Some((Corner::FR, Part::Spring)),
            ),
            (
                with(&bus, Corner::RR, 1.0, 0.7),
                RoadClass::B,
                30.0,
                Some((Corner::RR, Part::Damper)),
            ),
            (
                with(&bus, Corner::FL, 1.0, 0.7),
                RoadClass::C,
                25.0,
                Some((Corner::FL, Part::Damper)),
            ),
        ];
        for (k, (v, road, kmh, fault)) in drives.into_iter().enumerate() {
            let drive = fit(&records(
                &v,
                road,
                kmh,
                1000 * (b + 1) + k as u64,
                4,
                Disturbances::in_service(),
            ));
            let scores = corner_scores(&[&base], &drive);
            let lowest = scores.iter().min_by(|a, c| a.z.total_cmp(&c.z)).unwrap();
            println!(
                "baseline {b} drive {k} {fault:?}: lowest {:?} {:?} z {:.2}",
                lowest.corner, lowest.part, lowest.z
            );
            match fault {
                None => {
                    healthy += 1;
                    flagged += usize::from(lowest.z < -limit);
                }
                Some((corner, part)) => {
                    faults += 1;
                    found += usize::from(
                        lowest.z < -limit && lowest.corner == corner && lowest.part == part,
                    );
                }
            }
        }
    }
    println!("healthy drives flagged {flagged}/{healthy}, faults found {found}/{faults}");
    assert!(
        tail(flagged, healthy, cfg.false_alarm_rate / 2.0) >= 0.05,
        "{flagged} of {healthy} healthy drives flagged"
    );
    // At least 90 %: missing more is improbable (< 5 %) if the goal held.
    assert!(
        tail(faults - found, faults, 0.1) >= 0.05,
        "{found} of {faults} faults found"
    );
}

/// A registered model file without a front bar: the fleet fits the file's bars only (its
/// default `anti_roll_bars = "file"`), so records stored before both bars became the standalone
/// update's default and records stored now have the same unknowns, and one fit takes them all;
/// equations of the other layout (a store set up with "both") are refused with one line naming
/// the unknowns, not fitted together.
#[test]
fn the_fleet_fits_the_model_files_bars_and_refuses_a_mix() {
    use vibmode_vehicle::update::{AntiRollBars, BodyFit};
    let no_front = CITY_BUS.replace(
        "anti_roll_stiffness_nm_per_rad = 300000.0",
        "anti_roll_stiffness_nm_per_rad = 0.0",
    );
    assert_ne!(no_front, CITY_BUS, "the example's front bar was not found");
    let model = VehicleModel::from_toml(&no_front, "no front bar").unwrap();
    let cfg = FleetConfig::default();
    assert_eq!(cfg.analysis.model_update.anti_roll_bars, AntiRollBars::File);
    let recs = records(
        &VehicleParams::city_bus(),
        RoadClass::B,
        30.0,
        7,
        4,
        Disturbances::in_service(),
    );
    let stored: Vec<_> = recs
        .iter()
        .map(|r| model.record_equations(r, &cfg.analysis).unwrap().equations)
        .collect();
    assert_eq!(stored[0].unknowns, 11, "10 and the rear bar");
    let refs: Vec<_> = stored.iter().collect();
    assert!(model.fit_corners(&cfg.analysis, &refs).is_ok());
    let mut both = cfg.analysis.clone();
    both.model_update.anti_roll_bars = AntiRollBars::Both;
    let fit_both = BodyFit::new(&model.params, both.model_update.clone()).unwrap();
    let other = fit_both
        .record_equations_placed(&recs[0], |c| cfg.analysis.placement_for_update(c))
        .unwrap();
    assert_eq!(other.unknowns, 12);
    let mixed = vec![refs[0], refs[1], refs[2], &other];
    let e = model.fit_corners(&cfg.analysis, &mixed).unwrap_err();
    assert!(e.contains("unknowns") && e.lines().count() == 1, "{e}");
}

/// `record_features` (each channel transformed once for the analysis's resampling and the body
/// equations' decimation) gives what `compute_features` and `add_body_equations` give, bit for
/// bit: a record at 10 kHz (brought down by 2 for the equations) with the model file, one at
/// 200 Hz (not brought down), and one without a model.
#[test]
fn features_with_one_transform_per_channel_are_the_two_steps() {
    let model = VehicleModel::from_toml(CITY_BUS, "examples/city_bus.toml").unwrap();
    let cfg = FleetConfig::default();
    let fast = vibmode_vehicle::sim::simulate(
        &VehicleParams::city_bus(),
        &vibmode_vehicle::sim::SimParams {
            fs_hz: 10_000.0,
            records: 1,
            seed: 7,
            disturbances: Disturbances::in_service(),
            ..vibmode_vehicle::sim::SimParams::default()
        },
    )
    .unwrap()
    .records
    .remove(0)
    .recording;
    let slow = common::record(&VehicleParams::city_bus(), RoadClass::B, 30.0, 8);
    let json = |f: &vibmode_fleet::RecordFeatures| serde_json::to_string(f).unwrap();
    for (rec, model) in [(&fast, Some(&model)), (&slow, Some(&model)), (&fast, None)] {
        let mut two_steps = vibmode_fleet::compute_features("r.csv", rec, &cfg).unwrap();
        vibmode_fleet::add_body_equations(&mut two_steps, rec, model, &cfg);
        let one = vibmode_fleet::record_features("r.csv", rec, model, &cfg).unwrap();
        assert_eq!(json(&one), json(&two_steps), "{} Hz", rec.fs_hz);
        assert_eq!(
            one.suspension.is_some(),
            model.is_some(),
            "{} Hz",
            rec.fs_hz
        );
    }
}
