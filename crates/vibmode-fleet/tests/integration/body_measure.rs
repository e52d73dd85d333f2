//! Measurement (ignored; docs/fleet.md "The body's response to the wheel motions"): the body
//! response to wheel motion, `ln(measured / predicted sprung power)` per band, with `H` fitted on 8
//! healthy records (class B, 25-35 km/h; leave-one-out values for these), in 12 further records
//! per condition: healthy class B at 20, 30 and 40 km/h, class D at 30 km/h, rear springs 20 %
//! softer. Prints mean +- standard deviation per sprung channel.
//! `cargo test --release -p vibmode-fleet --test integration body_measure:: -- --ignored --nocapture`
//! (`NBASE=12` for another baseline size).

use crate::common;

use common::{config, record};
use vibmode_fleet::body::{body_response, fit_body_model};
use vibmode_fleet::compute_features;
use vibmode_vehicle::{RoadClass, VehicleParams};

const BANDS: [[f64; 2]; 7] = [
    [0.7, 1.0],
    [1.0, 1.5],
    [1.5, 2.5],
    [2.0, 3.0],
    [2.0, 4.0],
    [3.0, 5.0],
    [4.0, 6.0],
];

#[test]
#[ignore]
fn measure_body_response() {
    let bus = VehicleParams::city_bus();
    let mut soft = bus.clone();
    soft.rear.spring_stiffness_n_per_m *= 0.8;
    let mut cfg = config();
    // Spectra kept up to 8 Hz to try bands above the default 0.4-4 Hz.
    cfg.body_band_hz = [0.4, 8.0];
    let n_base: u64 = std::env::var("NBASE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(8);
    let feats = |v: &VehicleParams, road, kmh, seed| {
        compute_features("r", &record(v, road, kmh, seed), &cfg)
            .expect("features")
            .body_spectra
            .expect("body spectra")
    };
    let base: Vec<_> = (0..n_base)
        .map(|i| {
            feats(
                &bus,
                RoadClass::B,
                25.0 + 10.0 * i as f64 / (n_base - 1) as f64,
                1000 + i,
            )
        })
        .collect();
    let refs: Vec<_> = base.iter().collect();
    let model = fit_body_model(&refs).expect("fit");
    eprintln!("sprung {:?}", model.sprung);
    eprintln!(
        "condition: {:?}",
        model
            .freq_hz
            .iter()
            .zip(&model.condition)
            .map(|(f, c)| format!("{f:.2}:{c:.1e}"))
            .collect::<Vec<_>>()
    );
    let vals = |s: &vibmode_fleet::BodySpectra, m: &vibmode_fleet::BodyModel| -> Vec<Vec<f64>> {
        BANDS
            .iter()
            .map(|b| {
                body_response(m, s, *b)
                    .expect("same layout")
                    .into_iter()
                    .map(|x| x.unwrap_or(f64::NAN))
                    .collect()
            })
            .collect()
    };
    // Leave-one-out values of the baseline.
    let mut loo = Vec::new();
    for i in 0..base.len() {
        let others: Vec<_> = base
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, s)| s)
            .collect();
        let m = fit_body_model(&others).expect("fit");
        loo.push(vals(&base[i], &m));
    }
    let n = 12u64;
    let scen: Vec<(&str, Vec<Vec<Vec<f64>>>)> = vec![
        ("baseline LOO", loo),
        (
            "healthy B 30",
            (0..n)
                .map(|j| vals(&feats(&bus, RoadClass::B, 30.0, 5000 + j), &model))
                .collect(),
        ),
        (
            "healthy B 20",
            (0..n)
                .map(|j| vals(&feats(&bus, RoadClass::B, 20.0, 6000 + j), &model))
                .collect(),
        ),
        (
            "healthy B 40",
            (0..n)
                .map(|j| vals(&feats(&bus, RoadClass::B, 40.0, 7000 + j), &model))
                .collect(),
        ),
        (
            "healthy D 30",
            (0..n)
                .map(|j| vals(&feats(&bus, RoadClass::D, 30.0, 8000 + j), &model))
                .collect(),
        ),
        (
            "rear springs -20% B 30",
            (0..n)
                .map(|j| vals(&feats(&soft, RoadClass::B, 30.0, 9000 + j), &model))
                .collect(),
        ),
    ];
    for (k, b) in BANDS.iter().enumerate() {
        eprintln!("band {b:?}");
        for (name, v) in &scen {
            let mut line = format!("  {name:24}");
            for c in 0..model.sprung.len() {
                let xs: Vec<f64> = v.iter().map(|r| r[k][c]).collect();
                let m = xs.iter().sum::<f64>() / xs.len() as f64;
                let sd = (xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (xs.len() - 1) as f64)
                    .sqrt();
                line += &format!(" {:>7.3}±{:.3}", m, sd);
            }
            eprintln!("{line}");
        }
    }
}
