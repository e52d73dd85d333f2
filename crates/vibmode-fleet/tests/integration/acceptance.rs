//! Issue 12's acceptance scenarios on the simulator, over three baseline seeds: a baseline of 8
//! healthy records (class B road, 25-35 km/h), then 20 further healthy records (new seeds,
//! 20-40 km/h), 8 on a class D road, 8 with the rear-left damper at 50 %, 8 with the front-left
//! tyre 30 % softer, 8 with the rear springs 20 % softer, 8 with 15 % and 8 with 30 % more load
//! (`VehicleParams::with_passenger_load`), and a sweep of rear-left damper losses (10, 20, 30,
//! 50 %). Prints the confusion table; the assertions are what was measured (docs/fleet.md states
//! it against the issue's targets). Measured (`cargo test --release -p vibmode-fleet --test
//! integration acceptance:: -- --nocapture`): healthy 60/60 normal; road D 24/24 road; RL damper at 50 %
//! 24/24 vehicle, RL named every time; FL tyre -30 % 24/24 vehicle, FL named in 24; rear springs
//! -20 % 24/24 vehicle, a rear corner named every time; loaded +15 % 23/24 normal, +30 % 24/24;
//! RL damper -30 % 24/24 (RL named in 24), -20 % 17/24, -10 % 3/24. `FAR=0.05` repeats it at a
//! 5 % false-alarm rate (healthy 59/60; road D 23/24 road and 1 both; loaded +15 % 22/24 normal,
//! +30 % 23/24; damper -20 % 21/24, -10 % 6/24). `LOAD_SPREAD=20` gives the baseline and the
//! healthy records 0-20 % passenger load (1 %: loads 24/24 and 24/24 normal, but rear springs
//! 18/24 and damper -30 % 20/24: 8 records of mixed loads are a wider baseline). A class C road
//! (rougher, still nominal): 22/24 road, 1 normal, 1 both at 1 %; 23 road, 1 both at 5 %;
//! `FLEET_DEBUG=1` prints the summary of every record not classed normal.

use std::collections::BTreeMap;

use crate::common;

use common::{config, record};
use vibmode_fleet::{
    build_baseline, check_recording, ingest_recording, Classification, Condition, ContentHash,
    IngestLabels, Store,
};
use vibmode_vehicle::{Corner, CornerCondition, RoadClass, VehicleParams};

/// (label, vehicle, road, speeds km/h, corners that must all be named).
type Scenario = (
    String,
    VehicleParams,
    RoadClass,
    Vec<f64>,
    &'static [&'static str],
);

fn with(bus: &VehicleParams, cc: CornerCondition) -> VehicleParams {
    let mut v = bus.clone();
    v.corner_condition.push(cc);
    v
}

/// The spread of passenger loads over the baseline and healthy records (fraction of the body
/// mass; `LOAD_SPREAD` in percent, default 0: the issue's baseline is 8 records of one bus).
fn load_spread() -> f64 {
    std::env::var("LOAD_SPREAD")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .map_or(0.0, |p| p / 100.0)
}

#[test]
fn issue_scenarios_over_three_baselines() {
    let bus = VehicleParams::city_bus();
    let cfg = config();
    let rl_damper = |f: f64| {
        with(
            &bus,
            CornerCondition {
                damper_factor: f,
                ..CornerCondition::nominal(Corner::RL)
            },
        )
    };
    let fl_tyre = with(
        &bus,
        CornerCondition {
            tyre_stiffness_factor: 0.7,
            ..CornerCondition::nominal(Corner::FL)
        },
    );
    // Another load (a normal operating condition): 15 % more sprung mass and inertia (about 23
    // passengers), the air springs' rate following (`with_passenger_load`).
    let loaded = bus.with_passenger_load(0.15);
    let heavy = bus.with_passenger_load(0.30);
    let mut rear_springs = bus.clone();
    rear_springs.rear.spring_stiffness_n_per_m *= 0.8;
    // (scenario, classification) -> count; (scenario) -> records naming the expected corner.
    let mut confusion: BTreeMap<(String, Classification), usize> = BTreeMap::new();
    let mut named: BTreeMap<String, usize> = BTreeMap::new();
    // Per scenario with a fault, the component named on the records flagged with a fault
    // corner named first.
    let mut components: BTreeMap<(String, String), usize> = BTreeMap::new();
    for base in 1..=3u64 {
        let dir = tempfile::tempdir().expect("tempdir");
        let (mut store, _) = Store::init(&dir.path().join("fleet.db")).expect("init");
        let labels = IngestLabels {
            vehicle: "bus-1",
            condition: Condition::Nominal,
            road: Some("B"),
        };
        for i in 0..8u64 {
            let kmh = 25.0 + 10.0 * i as f64 / 7.0;
            // Passenger loads of 0 to LOAD_SPREAD % (default 0: one load).
            let load = load_spread() * ((i * 3) % 8) as f64 / 7.0;
            let rec = record(
                &bus.with_passenger_load(load),
                RoadClass::B,
                kmh,
                base * 1000 + i,
            );
            ingest_recording(
                &mut store,
                &labels,
                &format!("n{i}"),
                &ContentHash::Blake3.of_recording(&rec),
                &rec,
                &cfg,
            )
            .expect("ingest");
        }
        let set = build_baseline(&mut store, "bus-1", &cfg).expect("baseline");
        if std::env::var("FLEET_DEBUG").is_ok() {
            for f in &set.features {
                eprintln!(
                    "baseline {base}: {} {} centre {:.3} sigma {:.3} n {}",
                    f.meta.key,
                    f.meta.label,
                    f.centre.exp(),
                    f.sigma,
                    f.n
                );
            }
            for l in &set.limits {
                eprintln!("baseline {base}: limit {l:?}");
            }
        }
        let mut scen: Vec<Scenario> = vec![
            (
                "healthy 20-40 km/h".into(),
                bus.clone(),
                RoadClass::B,
                (0..20).map(|i| 20.0 + i as f64).collect(),
                &[],
            ),
            (
                "loaded +15 %".into(),
                loaded.clone(),
                RoadClass::B,
                (0..8).map(|i| 22.0 + 2.0 * i as f64).collect(),
                &[],
            ),
            (
                "loaded +30 %".into(),
                heavy.clone(),
                RoadClass::B,
                (0..8).map(|i| 22.0 + 2.0 * i as f64).collect(),
                &[],
            ),
            (
                "road D".into(),
                bus.clone(),
                RoadClass::D,
                vec![30.0; 8],
                &[],
            ),
            (
                "RL damper 50 %".into(),
                rl_damper(0.5),
                RoadClass::B,
                vec![30.0; 8],
                &["RL"],
            ),
            (
                "FL tyre -30 %".into(),
                fl_tyre.clone(),
                RoadClass::B,
                vec![30.0; 8],
                &["FL"],
            ),
            (
                "rear springs -20 %".into(),
                rear_springs.clone(),
                RoadClass::B,
                vec![30.0; 8],
                &["RL", "RR"],
            ),
        ];
        for loss in [0.1, 0.2, 0.3] {
            scen.push((
                format!("RL damper -{:.0} %", 100.0 * loss),
                rl_damper(1.0 - loss),
                RoadClass::B,
                vec![30.0; 8],
                &["RL"],
            ));
        }
        // A rougher road that is still nominal (class C, 22-36 km/h): road or normal, never
        // vehicle (appended last so that the other scenarios keep their seeds).
        scen.push((
            "road C".into(),
            bus.clone(),
            RoadClass::C,
            (0..8).map(|i| 22.0 + 2.0 * i as f64).collect(),
            &[],
        ));
        for (k, (label, v, road, speeds, corners)) in scen.iter().enumerate() {
            for (j, kmh) in speeds.iter().enumerate() {
                // The healthy records carry the baseline's spread of loads.
                let v = if label.starts_with("healthy") {
                    &v.with_passenger_load(load_spread() * ((j * 7) % 20) as f64 / 19.0)
                } else {
                    v
                };
                let rec = record(v, *road, *kmh, base * 100_000 + k as u64 * 100 + j as u64);
                let c = check_recording(
                    &mut store,
                    &set,
                    &format!("{label}-{j}"),
                    &ContentHash::Blake3.of_recording(&rec),
                    &rec,
                )
                .expect("check");
                let cls = c.assessment.classification;
                if std::env::var("FLEET_DEBUG").is_ok() && cls != Classification::Normal {
                    let z: Vec<String> = c
                        .assessment
                        .evidence
                        .iter()
                        .map(|e| format!("{:.1}/{:.1}", e.z, e.limit))
                        .collect();
                    eprintln!(
                        "{label}-{j} (baseline {base}): {cls:?}: {} (z/limit {})",
                        c.assessment.summary,
                        z.join(" ")
                    );
                }
                *confusion.entry((label.clone(), cls)).or_default() += 1;
                if !corners.is_empty()
                    && matches!(cls, Classification::Vehicle | Classification::Both)
                    && corners
                        .iter()
                        .any(|corner| c.assessment.summary.contains(&format!("{corner}:")))
                {
                    *named.entry(label.clone()).or_default() += 1;
                }
                let first = c
                    .assessment
                    .evidence
                    .iter()
                    .find(|e| e.meta.group == vibmode_fleet::Group::Vehicle)
                    .and_then(|e| e.meta.corner)
                    .map(|k| k.to_string());
                if first.is_some_and(|k| corners.contains(&k.as_str())) {
                    let what = c
                        .assessment
                        .component
                        .map_or("none".to_string(), |k| k.to_string());
                    *components.entry((label.clone(), what)).or_default() += 1;
                }
            }
        }
    }
    let mut table: Vec<String> = confusion
        .iter()
        .map(|((s, c), n)| format!("{s} -> {c:?}: {n}"))
        .collect();
    table.extend(named.iter().map(|(s, n)| format!("{s}: corner named {n}")));
    table.extend(
        components
            .iter()
            .map(|((s, k), n)| format!("{s}: corner first, component {k}: {n}")),
    );
    let table = table.join("\n");
    eprintln!("over 3 baselines:\n{table}");
    let count =
        |s: &str, c: Classification| confusion.get(&(s.to_string(), c)).copied().unwrap_or(0);
    let flagged = |s: &str| count(s, Classification::Vehicle) + count(s, Classification::Both);
    // Measured thresholds (see docs/fleet.md); out of 60 healthy, 24 per scenario.
    let healthy_not_normal = 60 - count("healthy 20-40 km/h", Classification::Normal);
    assert!(healthy_not_normal <= 3, "{table}");
    assert!(count("road D", Classification::Road) >= 21, "{table}");
    assert!(flagged("RL damper 50 %") >= 21, "{table}");
    assert!(
        named.get("RL damper 50 %").copied().unwrap_or(0) >= 21,
        "{table}"
    );
    // The softer front-left tyre: vehicle with FL named (measured 24 of 24).
    assert!(flagged("FL tyre -30 %") >= 21, "{table}");
    assert!(
        named.get("FL tyre -30 %").copied().unwrap_or(0) >= 21,
        "{table}"
    );
    // Rear springs 20 % softer (issue: vehicle): measured 24 of 24 at 1 % and at 5 %, both rear
    // corners named every time by the body response to wheel motion 2-4 Hz (-15 to -21 %).
    assert!(flagged("rear springs -20 %") >= 21, "{table}");
    assert!(
        named.get("rear springs -20 %").copied().unwrap_or(0) >= 21,
        "{table}"
    );
    // The component of the corner named first (docs/fleet.md, "Which component"): the tyre and
    // the strong damper loss named as such on at least 21 of 24 records like the corner, and
    // no fault ever named as another component (`suspension` says it cannot tell).
    let component = |s: &str, k: &str| {
        components
            .get(&(s.to_string(), k.to_string()))
            .copied()
            .unwrap_or(0)
    };
    assert!(component("FL tyre -30 %", "tyre") >= 21, "{table}");
    assert!(component("RL damper 50 %", "damper") >= 21, "{table}");
    for (s, wrong) in [
        ("FL tyre -30 %", ["damper", "spring"]),
        ("RL damper 50 %", ["tyre", "spring"]),
        ("RL damper -30 %", ["tyre", "spring"]),
        ("rear springs -20 %", ["damper", "tyre"]),
    ] {
        for k in wrong {
            assert_eq!(component(s, k), 0, "{s} named {k}:\n{table}");
        }
    }
    // The sweep: a 30 % loss is caught (measured 24 of 24 at 1 % and 5 %), 20 % in most records
    // (17 and 21 of 24), 10 % hardly (3 of 24 at 1 %, 6 at 5 %).
    assert!(flagged("RL damper -30 %") >= 21, "{table}");
    // (Another set of seeds gave 14 of 24 at 1 %: the count moves by about 3 with the seeds.)
    assert!(flagged("RL damper -20 %") >= 12, "{table}");
    // Another load (15 % or 30 % heavier, air springs following): a normal condition, measured
    // 23 and 24 of 24 normal at 1 %, 22 and 23 at 5 %.
    assert!(
        24 - count("loaded +15 %", Classification::Normal) <= 3,
        "{table}"
    );
    assert!(
        24 - count("loaded +30 %", Classification::Normal) <= 3,
        "{table}"
    );
    // The rougher nominal road: measured 1 of 24 `both` at 1 % and at 5 %, never `vehicle`.
    assert!(flagged("road C") <= 2, "{table}");
    let ten_pct_bound = if cfg.false_alarm_rate <= 0.01 { 5 } else { 8 };
    assert!(flagged("RL damper -10 %") <= ten_pct_bound, "{table}");
}
