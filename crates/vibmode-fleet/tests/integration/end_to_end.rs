//! End to end over seeds: simulated city-bus runs through the store, a baseline from nominal
//! runs (class B and C roads, 30-50 km/h, two records each), then (a) a nominal run at another speed, (b) a
//! class D (one road class above the baseline's roughest: normal) and a class E road (road), (c) the rear dampers weakened by 45 %, (d) both.

use std::collections::BTreeMap;

use crate::common;

use common::{config, records};
use vibmode_fleet::{
    build_baseline, check_recording, ingest_recording, Classification, Condition, ContentHash,
    IngestLabels, Store,
};
use vibmode_vehicle::{Disturbances, RoadClass, VehicleParams};

#[test]
fn classification_over_seeds() {
    let bus = VehicleParams::city_bus();
    let mut weak = bus.clone();
    weak.rear.damper_n_s_per_m *= 0.55;
    let cfg = config();
    // confusion[(scenario, classification)] = count
    let mut confusion: BTreeMap<(&str, Classification), usize> = BTreeMap::new();
    let mut rear_named = 0;
    let mut n_vehicle_flags = 0;
    for seed in 1..=5u64 {
        let dir = tempfile::tempdir().expect("tempdir");
        let (mut store, created) = Store::init(&dir.path().join("fleet.db")).expect("init");
        assert!(created);
        let nominal = IngestLabels {
            vehicle: "bus-1",
            condition: Condition::Nominal,
            road: None,
        };
        let conditions = [
            (RoadClass::B, 30.0),
            (RoadClass::C, 40.0),
            (RoadClass::B, 50.0),
            (RoadClass::C, 30.0),
            (RoadClass::B, 40.0),
            (RoadClass::C, 50.0),
        ];
        for (i, (road, kmh)) in conditions.into_iter().enumerate() {
            for (j, rec) in records(
                &bus,
                road,
                kmh,
                seed * 100 + i as u64,
                2,
                Disturbances::default(),
            )
            .iter()
            .enumerate()
            {
                let name = format!("nominal-{i}-{j}");
                ingest_recording(
                    &mut store,
                    &nominal,
                    &name,
                    &ContentHash::Blake3.of_recording(rec),
                    rec,
                    &cfg,
                )
                .expect("ingest");
            }
        }
        let set = build_baseline(&mut store, "bus-1", &cfg).expect("baseline");
        let scenarios: [(&str, &VehicleParams, RoadClass, f64); 5] = [
            ("a normal 35 km/h C", &bus, RoadClass::C, 35.0),
            ("b road D", &bus, RoadClass::D, 40.0),
            ("b road E", &bus, RoadClass::E, 40.0),
            ("c vehicle", &weak, RoadClass::C, 40.0),
            ("d both", &weak, RoadClass::E, 40.0),
        ];
        for (k, (label, v, road, kmh)) in scenarios.into_iter().enumerate() {
            for (j, rec) in records(
                v,
                road,
                kmh,
                seed * 1000 + k as u64,
                2,
                Disturbances::default(),
            )
            .iter()
            .enumerate()
            {
                let c = check_recording(
                    &mut store,
                    &set,
                    &format!("{label}-{j}"),
                    &ContentHash::Blake3.of_recording(rec),
                    rec,
                )
                .expect("check");
                *confusion
                    .entry((label, c.assessment.classification))
                    .or_default() += 1;
                if matches!(
                    c.assessment.classification,
                    Classification::Vehicle | Classification::Both
                ) && v.rear.damper_n_s_per_m < bus.rear.damper_n_s_per_m
                {
                    n_vehicle_flags += 1;
                    if c.assessment.summary.contains("RL:") || c.assessment.summary.contains("RR:")
                    {
                        rear_named += 1;
                    }
                }
            }
        }
    }
    let table: Vec<String> = confusion
        .iter()
        .map(|((s, c), n)| format!("{s} -> {c}: {n}"))
        .collect();
    let table = table.join("; ");
    eprintln!("confusion over 5 seeds x 2 records: {table}");
    let count = |s: &str, c: Classification| confusion.get(&(s, c)).copied().unwrap_or(0);
    // 10 records per scenario.
    assert!(
        count("a normal 35 km/h C", Classification::Normal) >= 9,
        "{table}"
    );
    // The baseline's roughest road is class C; class D is one road class (a factor 2 in
    // amplitude) above it, inside `road_margin` (docs/fleet.md): normal. Class E is two.
    assert!(count("b road D", Classification::Normal) >= 8, "{table}");
    assert_eq!(count("b road E", Classification::Road), 10, "{table}");
    assert!(count("c vehicle", Classification::Vehicle) >= 9, "{table}");
    assert!(count("d both", Classification::Both) >= 9, "{table}");
    // Healthy runs called a vehicle fault: at most 2 of 30 (the limits aim at 1 % per record).
    let false_vehicle: usize = ["a normal 35 km/h C", "b road D", "b road E"]
        .iter()
        .map(|s| count(s, Classification::Vehicle) + count(s, Classification::Both))
        .sum();
    assert!(
        false_vehicle <= 2,
        "{false_vehicle} false vehicle alarms: {table}"
    );
    assert_eq!(
        rear_named, n_vehicle_flags,
        "every vehicle flag of the weak rear dampers names RL or RR: {table}"
    );
}
