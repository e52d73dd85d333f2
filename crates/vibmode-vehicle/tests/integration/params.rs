//! TOML parsing and validation: every bad input gives a one-line error naming the key.
use vibmode_vehicle::{
    Corner, LateralCoherence, RoadClass, SensorKind, VehicleError, VehicleParams,
};

const BUS: &str = include_str!("../../../../examples/city_bus.toml");

fn err_of(text: &str) -> String {
    match VehicleParams::from_toml_str(text) {
        Ok(_) => panic!("expected an error"),
        Err(e) => {
            let s = e.to_string();
            assert!(!s.contains('\n'), "error message must be one line: {s}");
            s
        }
    }
}

#[test]
fn shipped_examples_parse_and_have_the_7_default_sensors() {
    let bus = VehicleParams::from_toml_str(BUS).unwrap();
    let car = VehicleParams::passenger_car();
    let names = [
        "FL_unsprung",
        "FR_unsprung",
        "RL_unsprung",
        "RR_unsprung",
        "FR_sprung",
        "RL_sprung",
        "RR_sprung",
    ];
    for p in [&bus, &car] {
        let got: Vec<String> = p
            .effective_sensors()
            .iter()
            .map(|s| s.name.clone())
            .collect();
        assert_eq!(got, names);
    }
    assert_eq!(bus, VehicleParams::city_bus());
    assert_eq!(bus.geometry.wheelbase_m, 5.9);
    assert!((10_000.0..=13_000.0).contains(&bus.body.mass_kg));
    // corner positions: x forward, y left
    let (x, y) = bus.corner_position_m(Corner::RR);
    assert!((x - (3.65 - 5.9)).abs() < 1e-12 && (y + 0.9).abs() < 1e-12);
}

#[test]
fn toml_round_trip() {
    let bus = VehicleParams::city_bus();
    let text = bus.to_toml_string().unwrap();
    assert_eq!(VehicleParams::from_toml_str(&text).unwrap(), bus);
}

#[test]
fn negative_stiffness_names_the_key() {
    let t = BUS.replace(
        "spring_stiffness_n_per_m = 100000.0",
        "spring_stiffness_n_per_m = -1e5",
    );
    let e = err_of(&t);
    assert!(
        e.contains("front.spring_stiffness_n_per_m = -100000 must be positive"),
        "{e}"
    );
}

#[test]
fn zero_mass_negative_damping_and_geometry() {
    let e = err_of(&BUS.replace("mass_kg = 11000.0", "mass_kg = 0.0"));
    assert!(e.contains("body.mass_kg = 0"), "{e}");
    let e = err_of(&BUS.replace("damper_n_s_per_m = 12000.0", "damper_n_s_per_m = -5.0"));
    assert!(
        e.contains("rear.damper_n_s_per_m = -5 must be zero or positive"),
        "{e}"
    );
    let e = err_of(&BUS.replace("cg_to_front_axle_m = 3.65", "cg_to_front_axle_m = 7.0"));
    assert!(
        e.contains("geometry.cg_to_front_axle_m = 7") && e.contains("wheelbase_m"),
        "{e}"
    );
    let e = err_of(&BUS.replace(
        "tyre_stiffness_n_per_m = 900000.0",
        "tyre_stiffness_n_per_m = nan",
    ));
    assert!(e.contains("front.tyre_stiffness_n_per_m"), "{e}");
}

#[test]
fn unknown_and_missing_keys_are_named() {
    let e = err_of(&BUS.replace("mass_kg = 11000.0", "mass_kg = 11000.0\nmass_kgs = 3.0"));
    assert!(
        e.contains("unknown field `mass_kgs`") && e.contains("line"),
        "{e}"
    );
    let e = err_of(&BUS.replace("pitch_inertia_kgm2 = 95000.0", ""));
    assert!(e.contains("pitch_inertia_kgm2"), "{e}");
    let e = err_of(&BUS.replace("mass_kg = 11000.0", "mass_kg = \"heavy\""));
    assert!(
        e.contains("mass_kg = \"heavy\"") && e.contains("invalid type"),
        "{e}"
    );
    let e = err_of(&BUS.replace("[geometry]", "[geometri]"));
    assert!(e.contains("geometri"), "{e}");
}

#[test]
fn sensor_errors() {
    let e = err_of(&BUS.replace(
        "name = \"FR_unsprung\"\nkind = \"unsprung\"\ncorner = \"FR\"",
        "name = \"FR_unsprung\"\nkind = \"unsprung\"",
    ));
    assert!(
        e.contains("sensors[1].corner") && e.contains("unsprung"),
        "{e}"
    );
    let e = err_of(&BUS.replace("name = \"RL_sprung\"", "name = \"FR_sprung\""));
    assert!(
        e.contains("sensors[5].name = FR_sprung is used twice"),
        "{e}"
    );
    let e = err_of(&BUS.replace(
        "kind = \"unsprung\"\ncorner = \"FL\"",
        "kind = \"unsprung\"\ncorner = \"XX\"",
    ));
    assert!(e.contains("XX") || e.contains("unknown variant"), "{e}");
    let e = err_of(&BUS.replace(
        "name = \"RR_sprung\"\nkind = \"sprung\"\ncorner = \"RR\"",
        "name = \"RR_sprung\"\nkind = \"sprung\"\nx_m = 1.0",
    ));
    assert!(e.contains("sensors[6]"), "{e}");
    // a free body point is fine
    let ok = BUS.replace(
        "name = \"RR_sprung\"\nkind = \"sprung\"\ncorner = \"RR\"",
        "name = \"mid_floor\"\nkind = \"sprung\"\nx_m = 0.5\ny_m = -0.2",
    );
    let p = VehicleParams::from_toml_str(&ok).unwrap();
    assert_eq!(p.sensors[6].name, "mid_floor");
}

#[test]
fn missing_file_is_an_io_error() {
    let e = VehicleParams::from_path("/nonexistent/bus.toml").unwrap_err();
    assert!(matches!(e, VehicleError::Io { .. }));
    assert!(e.to_string().contains("/nonexistent/bus.toml"));
}

#[test]
fn enums_parse_and_display() {
    assert_eq!("c".parse::<RoadClass>().unwrap(), RoadClass::C);
    assert_eq!(RoadClass::D.to_string(), "D");
    let e = "Z".parse::<RoadClass>().unwrap_err().to_string();
    assert!(e.contains("'Z'") && e.contains("A, B, C"), "{e}");
    assert_eq!("fr".parse::<Corner>().unwrap(), Corner::FR);
    assert!("XX"
        .parse::<Corner>()
        .unwrap_err()
        .to_string()
        .contains("FL, FR, RL, RR"));
    assert_eq!("sprung".parse::<SensorKind>().unwrap(), SensorKind::Sprung);
    for c in [
        LateralCoherence::FullyCorrelated,
        LateralCoherence::Independent,
        LateralCoherence::Exponential {
            cutoff_cycles_per_m: 0.35,
        },
    ] {
        assert_eq!(c.to_string().parse::<LateralCoherence>().unwrap(), c);
    }
    assert!("exponential:-1"
        .parse::<LateralCoherence>()
        .unwrap_err()
        .to_string()
        .contains("must be positive"));
    assert!("sometimes"
        .parse::<LateralCoherence>()
        .unwrap_err()
        .to_string()
        .contains("fully-correlated"));
}

#[test]
fn iso8608_class_values() {
    // Hand values: Gd(n0) = 16e-6 * 4^k m^3, and Gd(n) = Gd(n0) (n/n0)^-2.
    let expect = [
        16e-6, 64e-6, 256e-6, 1024e-6, 4096e-6, 16384e-6, 65536e-6, 262144e-6,
    ];
    for (c, e) in RoadClass::ALL.iter().zip(expect) {
        assert!((c.gd_n0_m3() - e).abs() < 1e-18);
    }
    assert!((RoadClass::C.displacement_psd_m3(0.2) - 64e-6).abs() < 1e-15);
    assert!((RoadClass::A.displacement_psd_m3(0.05) - 64e-6).abs() < 1e-15);
    assert_eq!(RoadClass::B.displacement_psd_m3(0.0), 0.0);
}

/// A passenger load scales the sprung mass, its inertias and the air springs by the same factor
/// (by hand), so heave and pitch keep their frequencies within the tyres' share (the tyres are
/// not stiffened), roll loses the anti-roll bars' share (they are not stiffened either), and their damping ratios, `c / (2 m omega)`, fall by
/// about `1 - 1/1.15` = 13 % (the dampers are not stronger): checked on the full-car model's
/// modes.
#[test]
fn passenger_load_scales_the_body_and_the_air_springs() {
    use vibmode_vehicle::{FullCar, ModeLabel};
    let bus = VehicleParams::city_bus();
    let loaded = bus.with_passenger_load(0.15);
    assert_eq!(loaded.body.mass_kg, bus.body.mass_kg * 1.15);
    assert_eq!(
        loaded.body.pitch_inertia_kgm2,
        bus.body.pitch_inertia_kgm2 * 1.15
    );
    assert_eq!(
        loaded.body.roll_inertia_kgm2,
        bus.body.roll_inertia_kgm2 * 1.15
    );
    assert_eq!(
        loaded.rear.spring_stiffness_n_per_m,
        bus.rear.spring_stiffness_n_per_m * 1.15
    );
    assert_eq!(loaded.front.damper_n_s_per_m, bus.front.damper_n_s_per_m);
    assert_eq!(loaded.front.unsprung_mass_kg, bus.front.unsprung_mass_kg);
    assert_eq!(bus.with_passenger_load(0.0), bus);
    assert_eq!(bus.with_passenger_load(f64::NAN), bus);
    let modes = |v: &VehicleParams| FullCar::new(v).and_then(|c| c.modes()).expect("modes");
    let (m0, m1) = (modes(&bus), modes(&loaded));
    // Heave and pitch stay within the tyres' share; roll drops by part of 1 - 1/sqrt(1.15) =
    // 6.7 %, the anti-roll bars' share of the roll stiffness.
    for (label, lo, hi) in [
        (ModeLabel::BodyHeave, -0.015, 0.0),
        (ModeLabel::BodyPitch, -0.015, 0.0),
        (ModeLabel::BodyRoll, -0.067, -0.02),
    ] {
        let a = m0.iter().find(|m| m.label == label).expect("nominal mode");
        let b = m1.iter().find(|m| m.label == label).expect("loaded mode");
        let df = b.frequency_hz / a.frequency_hz - 1.0;
        let dz = b.damping_ratio / a.damping_ratio - 1.0;
        eprintln!("{label:?}: frequency {df:+.4}, damping {dz:+.4}");
        assert!((lo..hi).contains(&df), "{label:?}: frequency {df:+.4}");
        assert!((-0.16..-0.10).contains(&dz), "{label:?}: damping {dz:+.4}");
    }
}
