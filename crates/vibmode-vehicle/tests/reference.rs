//! Against tools/reference/vehicle.py (numpy 2.1.3 / scipy 1.14.1): modes and PSD to 1e-6
//! relative, bump response (scipy.signal.lsim) to 2e-3 of the channel peak.
use serde_json::Value;
use vibmode_vehicle::{FullCar, LateralCoherence, RoadClass, RoadInput, VehicleParams};

const REF: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/vehicle.json"
));

fn vec_f(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn modes_psd_and_bump_match_scipy() {
    let r: Value = serde_json::from_str(REF).unwrap();
    let cases = r["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 3);
    let mut worst_mode = 0.0f64;
    let mut worst_psd = 0.0f64;
    let mut worst_bump = 0.0f64;
    let mut bump_channels = 0;
    for case in cases {
        let p = VehicleParams::from_toml_str(case["toml"].as_str().unwrap()).unwrap();
        let car = FullCar::new(&p).unwrap();
        let modes = car.modes().unwrap();
        let f = vec_f(&case["frequency_hz"]);
        let z = vec_f(&case["damping_ratio"]);
        assert_eq!(modes.len(), f.len(), "{}", case["name"]);
        for ((m, f), z) in modes.iter().zip(&f).zip(&z) {
            worst_mode = worst_mode
                .max((m.frequency_hz - f).abs() / f)
                .max((m.damping_ratio - z).abs() / z);
        }
        if case["name"] == "city_bus_bending" {
            assert!(modes
                .iter()
                .any(|m| m.label == vibmode_vehicle::ModeLabel::BodyBending
                    && (m.frequency_hz - 10.876).abs() < 0.01));
        }
        let freqs = vec_f(&case["psd_freq_hz"]);
        let road = RoadInput {
            class: RoadClass::C,
            coherence: LateralCoherence::Exponential {
                cutoff_cycles_per_m: 0.2,
            },
            tyre_envelope_cycles_per_m: Some(3.0),
        };
        let psd = car
            .acceleration_psd(&road, case["psd_speed_kmh"].as_f64().unwrap(), &freqs)
            .unwrap();
        let want = case["psd_m2_s4_per_hz"].as_array().unwrap();
        for (s, w) in psd.iter().zip(want) {
            for (a, b) in s.psd_m2_s4_per_hz.iter().zip(vec_f(w)) {
                worst_psd = worst_psd.max((a - b).abs() / b.abs());
            }
        }
        if let Some(b) = case.get("bump") {
            let fs = b["fs_hz"].as_f64().unwrap();
            let road: Vec<[f64; 4]> = b["road_m"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| {
                    let v = vec_f(x);
                    [v[0], v[1], v[2], v[3]]
                })
                .collect();
            let got = car.response(&road, fs).unwrap();
            for (g, w) in got.iter().zip(b["accel_m_s2"].as_array().unwrap()) {
                let w = vec_f(w);
                let peak = w.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                let err = g
                    .iter()
                    .zip(&w)
                    .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
                worst_bump = worst_bump.max(err / peak);
                bump_channels += 1;
                assert!(
                    peak > 0.1 && err <= 2e-3 * peak,
                    "bump error {err} vs peak {peak}"
                );
            }
        }
    }
    assert_eq!(bump_channels, 7, "the bump case must be checked");
    assert!(worst_mode < 1e-6, "modes rel err {worst_mode}");
    assert!(worst_psd < 1e-6, "psd rel err {worst_psd}");
    eprintln!("worst relative error: modes {worst_mode:.2e}, psd {worst_psd:.2e}, bump {worst_bump:.2e} of peak");
}
