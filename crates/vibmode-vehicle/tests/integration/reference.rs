//! Against tools/reference/vehicle.py (numpy 2.1.3 / scipy 1.14.1): modes and PSD to 1e-6
//! relative, bump response (scipy.signal.lsim) to 2e-3 of the channel peak; and the body-equation
//! fit against tools/reference/body_fit.py to 1e-6.
use serde_json::Value;
use vibmode_vehicle::{Corner, FullCar, LateralCoherence, RoadClass, RoadInput, VehicleParams};

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

const BODY_FIT: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/body_fit.json"
));
const BODY_FIT_INPUT: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/body_fit_input.json"
));

/// The body-equation fit against tools/reference/body_fit.py (numpy FFT derivatives, lstsq,
/// scipy eigenvalues) on records of a changed rigid bus that script simulated: parameters and
/// body modes equal to 1e-6; both within 1 % of the changed bus (its simulation's truth).
#[test]
fn body_fit_matches_numpy() {
    use vibmode_core::{Channel, Recording};
    use vibmode_vehicle::update::{BodyFit, BodyFitParams};
    let r: Value = serde_json::from_str(BODY_FIT).unwrap();
    let input: Value = serde_json::from_str(BODY_FIT_INPUT).unwrap();
    let file = VehicleParams::from_path(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/city_bus.toml"
    ))
    .unwrap();
    let fs = input["fs_hz"].as_f64().unwrap();
    let names: Vec<&str> = input["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    let mut fit = BodyFit::new(&file, BodyFitParams::default()).unwrap();
    for rec in input["records"].as_array().unwrap() {
        let channels = rec
            .as_array()
            .unwrap()
            .iter()
            .zip(&names)
            .map(|(v, n)| Channel::new(*n, "m/s^2", vec_f(v)))
            .collect();
        fit.add_record(&Recording {
            fs_hz: fs,
            channels,
            time_axis: None,
        })
        .unwrap();
    }
    let res = fit.solve().unwrap();
    let rel = |a: f64, b: f64| (a / b - 1.0).abs();
    let want = &r["fit"];
    assert_eq!(res.equations as u64, want["equations"].as_u64().unwrap());
    let band = vec_f(&want["band_hz"]);
    assert!(rel(res.band_hz[0], band[0]) < 1e-12 && rel(res.band_hz[1], band[1]) < 1e-12);
    let v = &res.vehicle;
    let got_params = [
        (
            "springs",
            Corner::ALL
                .map(|c| v.axle(c).spring_stiffness_n_per_m)
                .to_vec(),
        ),
        (
            "dampers",
            Corner::ALL.map(|c| v.axle(c).damper_n_s_per_m).to_vec(),
        ),
        (
            "bars",
            vec![
                v.front.anti_roll_stiffness_nm_per_rad,
                v.rear.anti_roll_stiffness_nm_per_rad,
            ],
        ),
        (
            "inertia",
            vec![v.body.pitch_inertia_kgm2, v.body.roll_inertia_kgm2],
        ),
    ];
    for (key, got) in &got_params {
        let numpy = vec_f(&want["params"][key]);
        let truth = vec_f(&r["truth"]["params"][key]);
        for ((g, n), t) in got.iter().zip(&numpy).zip(&truth) {
            assert!(rel(*g, *n) < 1e-6, "{key}: {g} against numpy's {n}");
            assert!(rel(*g, *t) < 0.01, "{key}: {g} against the truth {t}");
        }
    }
    let mut body: Vec<(f64, f64)> = res
        .modes
        .iter()
        .filter(|m| m.label.is_body_rigid())
        .map(|m| (m.frequency_hz, m.damping_ratio))
        .collect();
    body.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (nf, nz) = (
        vec_f(&want["body_frequency_hz"]),
        vec_f(&want["body_damping_ratio"]),
    );
    let tf = vec_f(&r["truth"]["body_frequency_hz"]);
    assert_eq!(body.len(), 3);
    for (i, (f, z)) in body.iter().enumerate() {
        assert!(
            rel(*f, nf[i]) < 1e-6,
            "mode {i}: {f} Hz against numpy's {}",
            nf[i]
        );
        assert!(
            rel(*z, nz[i]) < 1e-6,
            "mode {i}: damping {z} against numpy's {}",
            nz[i]
        );
        assert!(
            rel(*f, tf[i]) < 0.01,
            "mode {i}: {f} Hz against the truth {}",
            tf[i]
        );
    }
}

const NNLS: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/nnls.json"
));

/// Non-negative least squares against scipy.optimize.nnls (tools/reference/nnls.py, scipy
/// 1.14.1): 20 problems of 3 to 14 unknowns scaled over five decades, 72 unknowns at their bound;
/// the same unknowns at 0 and x within 1e-8 of max |x|.
#[test]
fn nnls_matches_scipy() {
    use nalgebra::{DMatrix, DVector};
    use vibmode_vehicle::nnls::nnls_normal;
    let r: Value = serde_json::from_str(NNLS).unwrap();
    let cases = r["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 20);
    let vec_of = |v: &Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    for (k, c) in cases.iter().enumerate() {
        let (m, n) = (
            c["m"].as_u64().unwrap() as usize,
            c["n"].as_u64().unwrap() as usize,
        );
        let a = DMatrix::from_row_slice(m, n, &vec_of(&c["a"]));
        let b = DVector::from_vec(vec_of(&c["b"]));
        let want = vec_of(&c["x"]);
        let got = nnls_normal(&(a.transpose() * &a), &(a.transpose() * &b)).unwrap();
        let scale = want.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
        assert_eq!(want.len(), n);
        for (i, &w) in want.iter().enumerate() {
            assert_eq!(
                got.x[i] == 0.0,
                w == 0.0,
                "case {k}: x[{i}] = {} against scipy's {w}",
                got.x[i]
            );
            assert!(
                (got.x[i] - w).abs() <= 1e-8 * scale,
                "case {k}: x[{i}] = {} against scipy's {w}",
                got.x[i]
            );
        }
    }
}

const BODY_FIT_NOISE: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/body_fit_noise.json"
));
const BODY_FIT_NOISE_INPUT: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/body_fit_noise_input.json"
));

/// The bias-compensated fit and its jackknife against tools/reference/body_fit_noise.py (numpy,
/// scipy 1.14.1) on noisy records of the changed rigid bus at 400 Hz: each channel's noise
/// density (0 where the spectrum above the band is not flat: the unsprung channels, whose road
/// motion is there), the parameters and body modes to 1e-6, their jackknife standard
/// deviations to 1e-5 (differences of nearly equal fits).
#[test]
fn noisy_body_fit_matches_numpy() {
    use vibmode_core::{Channel, Recording};
    use vibmode_vehicle::update::{BodyFit, BodyFitParams};
    let r: Value = serde_json::from_str(BODY_FIT_NOISE).unwrap();
    let input: Value = serde_json::from_str(BODY_FIT_NOISE_INPUT).unwrap();
    let file = VehicleParams::from_path(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/city_bus.toml"
    ))
    .unwrap();
    let fs = input["fs_hz"].as_f64().unwrap();
    let names: Vec<&str> = input["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    let mut fit = BodyFit::new(&file, BodyFitParams::default()).unwrap();
    for rec in input["records"].as_array().unwrap() {
        let channels = rec
            .as_array()
            .unwrap()
            .iter()
            .zip(&names)
            .map(|(v, n)| Channel::new(*n, "m/s^2", vec_f(v)))
            .collect();
        fit.add_record(&Recording {
            fs_hz: fs,
            channels,
            time_axis: None,
        })
        .unwrap();
    }
    let res = fit.solve().unwrap();
    let want = &r["fit"];
    let close = |what: &str, got: f64, numpy: f64, tol: f64| {
        assert!(
            (got - numpy).abs() <= tol * numpy.abs().max(1e-300),
            "{what}: {got} against numpy's {numpy}"
        );
    };
    // Densities: the median over the records, per channel.
    let dens: Vec<Vec<f64>> = want["density"]
        .as_array()
        .unwrap()
        .iter()
        .map(vec_f)
        .collect();
    let mut corrected = 0;
    for (i, name) in names.iter().enumerate() {
        let mut d: Vec<f64> = dens.iter().map(|r| r[i]).collect();
        d.sort_by(|a, b| a.total_cmp(b));
        let got = res
            .noise_density
            .iter()
            .find(|c| c.channel == *name)
            .unwrap()
            .density_per_hz;
        if d[1] == 0.0 {
            assert_eq!(got, 0.0, "{name}");
        } else {
            corrected += 1;
            close(name, got, d[1], 1e-6);
        }
    }
    assert_eq!(corrected, 3, "the sprung channels' noise is taken out");
    close(
        "noise share",
        res.noise_share,
        want["noise_share"].as_f64().unwrap(),
        1e-9,
    );
    let th = vec_f(&want["theta_si"]);
    let sd = vec_f(&want["theta_sd"]);
    assert_eq!(res.parameters.len(), th.len());
    for ((p, t), s) in res.parameters.iter().zip(&th).zip(&sd) {
        close(&p.name, p.value, *t, 1e-6);
        close(&format!("sd of {}", p.name), p.sd.unwrap(), *s, 1e-5);
    }
    let mut body: Vec<_> = res
        .modes
        .iter()
        .filter(|m| m.label.is_body_rigid())
        .collect();
    body.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    let (nf, nz) = (
        vec_f(&want["body_frequency_hz"]),
        vec_f(&want["body_damping_ratio"]),
    );
    let (sf, sz) = (
        vec_f(&want["body_frequency_sd"]),
        vec_f(&want["body_damping_sd"]),
    );
    assert_eq!(body.len(), 3);
    for (i, m) in body.iter().enumerate() {
        close(&format!("{} Hz", m.label), m.frequency_hz, nf[i], 1e-6);
        close(
            &format!("{} damping", m.label),
            m.damping_ratio,
            nz[i],
            1e-6,
        );
        let spread = res.mode_spread(m.label).unwrap();
        close(
            &format!("{} sd Hz", m.label),
            spread.frequency_hz_sd,
            sf[i],
            1e-5,
        );
        close(
            &format!("{} sd damping", m.label),
            spread.damping_ratio_sd,
            sz[i],
            1e-5,
        );
    }
}

const NOISE_SCALE: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/noise_scale.json"
));

/// The share of the noise taken out of the normal equations (generalized total least squares,
/// capped at 1) against scipy.linalg.eigh's generalized eigenvalues (tools/reference/noise_scale.py,
/// scipy 1.14.1): 24 seeded pencils 4-13 wide, 12 of them below 1, to 1e-8.
#[test]
fn noise_scale_matches_scipy() {
    use nalgebra::DMatrix;
    use vibmode_vehicle::update::noise_scale;
    let r: Value = serde_json::from_str(NOISE_SCALE).unwrap();
    let mut below = 0;
    for (k, c) in r["cases"].as_array().unwrap().iter().enumerate() {
        let n = c["n"].as_u64().unwrap() as usize;
        let raw = DMatrix::from_row_slice(n, n, &vec_f(&c["raw"]));
        let noise = DMatrix::from_row_slice(n, n, &vec_f(&c["noise"]));
        let want = c["share"].as_f64().unwrap();
        let got = noise_scale(&raw, &noise);
        assert!(
            (got - want).abs() <= 1e-8 * want,
            "case {k}: share {got} against scipy's {want}"
        );
        below += usize::from(want < 1.0);
    }
    assert!(below >= 5, "only {below} cases below 1");
}

const SUPPORT_FACTOR: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/support_factor.json"
));

/// The model update's support factor (Student t quantile, Bonferroni over the quantities) against
/// scipy.stats.t.ppf (tools/reference/support_factor.py, scipy 1.14.1): 3-40 records, 1-20
/// quantities, to 1e-9.
#[test]
fn support_factor_matches_scipy() {
    use vibmode_vehicle::update::support_factor;
    let r: Value = serde_json::from_str(SUPPORT_FACTOR).unwrap();
    let cases = r["cases"].as_array().unwrap();
    assert!(cases.len() >= 100);
    for c in cases {
        let records = c["records"].as_u64().unwrap() as usize;
        let m = c["quantities"].as_u64().unwrap() as usize;
        let want = c["factor"].as_f64().unwrap();
        let got = support_factor(records, m);
        assert!(
            (got - want).abs() <= 1e-9 * want,
            "{records} records, {m} quantities: {got} against scipy's {want}"
        );
    }
}
