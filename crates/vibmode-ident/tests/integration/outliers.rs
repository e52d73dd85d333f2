//! Additive outliers (issue #4): the robust AR filter-cleaner and the default robust ARMA fit on
//! data with 1 % spikes; the clean-data guard; hand-checkable cleaner cases; bad inputs.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use vibmode_ident::sim::{ar_from_modes, filter_arma, simulate_arma};
use vibmode_ident::{
    clean_additive_outliers, fit_arma, ArmaModel, ArmaParams, CleanerParams, IdentError, Mode,
    OutlierCleaning, Robust,
};

fn quadratic() -> ArmaParams {
    ArmaParams {
        robust: Robust::Off,
        ..ArmaParams::default()
    }
}

fn huber_only() -> ArmaParams {
    ArmaParams {
        outlier_cleaning: OutlierCleaning::Off,
        ..ArmaParams::default()
    }
}

fn std_of(y: &[f64]) -> f64 {
    let m = y.iter().sum::<f64>() / y.len() as f64;
    (y.iter().map(|v| (v - m).powi(2)).sum::<f64>() / y.len() as f64).sqrt()
}

/// Replaces `frac` of the samples (distinct random positions) by `+-(lo..hi) * std(y)`.
fn add_spikes(y: &[f64], frac: f64, lo: f64, hi: f64, seed: u64) -> (Vec<f64>, Vec<usize>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let sd = std_of(y);
    let n = y.len();
    let count = (frac * n as f64).round() as usize;
    let mut pos: Vec<usize> = Vec::with_capacity(count);
    while pos.len() < count {
        let i = rng.gen_range(0..n);
        if !pos.contains(&i) {
            pos.push(i);
        }
    }
    pos.sort_unstable();
    let mut out = y.to_vec();
    for &i in &pos {
        let sign = if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
        out[i] = sign * rng.gen_range(lo..hi) * sd;
    }
    (out, pos)
}

/// Relative frequency changes between the modes of `m` and `reference`, paired in ascending order;
/// None when the mode counts differ.
fn mode_changes(reference: &[Mode], m: &ArmaModel, fs: f64) -> Option<Vec<f64>> {
    let modes = m.modes(fs).modes;
    if modes.len() != reference.len() {
        return None;
    }
    Some(
        reference
            .iter()
            .zip(&modes)
            .map(|(r, e)| (e.frequency_hz / r.frequency_hz - 1.0).abs())
            .collect(),
    )
}

/// Worst relative frequency change (1.0 when the mode counts differ: a mode was lost or gained).
fn worst(reference: &[Mode], m: &ArmaModel, fs: f64) -> f64 {
    mode_changes(reference, m, fs).map_or(1.0, |v| v.into_iter().fold(0.0, f64::max))
}

struct Case {
    fs: f64,
    truth: [(f64, f64); 2],
    c: [f64; 3],
    n: usize,
}

/// A 1 Hz-ish body mode and a 7-12 Hz wheel-hop-like mode, at 50 Hz and at 200 Hz (the harder,
/// strongly low-pass case: var(y) / lambda ~ 4e6).
const CASES: [Case; 2] = [
    Case {
        fs: 50.0,
        truth: [(1.1, 0.1), (8.5, 0.05)],
        c: [1.0, -0.3, 0.2],
        n: 4096,
    },
    Case {
        fs: 200.0,
        truth: [(1.0, 0.08), (11.0, 0.04)],
        c: [1.0, -0.5, 0.3],
        n: 8192,
    },
];

#[test]
fn robust_fit_resists_additive_spikes() {
    // Issue #4 item 3: 1 % of the samples replaced by spikes of +-10-20 x std(y); the default robust
    // fit's modes stay within 2 % of the clean fit's, the quadratic fit moves more.
    let (p, q) = (4, 2);
    for (ci, case) in CASES.iter().enumerate() {
        let a = ar_from_modes(&case.truth, case.fs);
        for seed in 0..3u64 {
            let y = simulate_arma(&a, &case.c, 1.0, case.n, 100 + seed).unwrap();
            let (ys, pos) = add_spikes(&y, 0.01, 10.0, 20.0, 200 + seed);
            let m_clean = fit_arma(&y, p, q, &ArmaParams::default()).unwrap();
            let m_rob = fit_arma(&ys, p, q, &ArmaParams::default()).unwrap();
            let m_huber = fit_arma(&ys, p, q, &huber_only()).unwrap();
            let m_quad = fit_arma(&ys, p, q, &quadratic()).unwrap();
            let reference = m_clean.modes(case.fs).modes;
            // The clean fit itself recovers the simulated modes (so the comparison means something).
            assert_eq!(reference.len(), 2);
            for (r, &(f, _)) in reference.iter().zip(&case.truth) {
                assert!((r.frequency_hz / f - 1.0).abs() < 0.02, "case {ci}: {r:?}");
            }
            let (w_rob, w_huber, w_quad) = (
                worst(&reference, &m_rob, case.fs),
                worst(&reference, &m_huber, case.fs),
                worst(&reference, &m_quad, case.fs),
            );
            println!(
                "case {ci} (fs {} Hz, N {}) seed {seed}: {} spikes, {} replaced; worst mode \
                 frequency change: robust {w_rob:.2e}, Huber without cleaning {w_huber:.2e}, \
                 quadratic {w_quad:.2e}",
                case.fs,
                case.n,
                pos.len(),
                m_rob.outliers_replaced
            );
            assert_eq!(m_clean.outliers_replaced, 0, "case {ci} seed {seed}");
            assert!(
                m_rob.outliers_replaced >= pos.len() * 95 / 100
                    && m_rob.outliers_replaced <= pos.len() * 105 / 100,
                "case {ci} seed {seed}: replaced {} for {} spikes",
                m_rob.outliers_replaced,
                pos.len()
            );
            assert!(
                w_rob < 0.02,
                "case {ci} seed {seed}: robust fit moved {w_rob}"
            );
            assert!(
                w_quad > 0.02 && w_quad > w_rob,
                "case {ci} seed {seed}: quadratic fit moved only {w_quad} (robust {w_rob})"
            );
            assert_eq!(m_quad.outliers_replaced, 0);
        }
    }
}

#[test]
fn cleaner_finds_the_spikes_and_restores_the_signal() {
    // Every spike is found, nothing else is replaced, and each replaced value is within a few
    // innovation standard deviations (lambda = 1) of the clean sample, i.e. the cleaned signal is
    // the clean one up to the unpredictable part.
    for (ci, case) in CASES.iter().enumerate() {
        let a = ar_from_modes(&case.truth, case.fs);
        let y = simulate_arma(&a, &case.c, 1.0, case.n, 7).unwrap();
        let (ys, pos) = add_spikes(&y, 0.01, 10.0, 20.0, 8);
        let cl = clean_additive_outliers(&ys, &CleanerParams::default()).unwrap();
        assert_eq!(cl.replaced, pos, "case {ci}");
        let worst_err =
            cl.y.iter()
                .zip(&y)
                .map(|(c, t)| (c - t).abs())
                .fold(0.0, f64::max);
        println!(
            "case {ci}: std(y) {:.1}, residual scale {:.3} (innovation std 1), passes {}, \
             max |cleaned - clean| {worst_err:.2}",
            std_of(&y),
            cl.residual_scale,
            cl.passes
        );
        assert!(
            (cl.residual_scale - 1.0).abs() < 0.1,
            "{}",
            cl.residual_scale
        );
        assert!(worst_err < 6.0, "case {ci}: {worst_err}");
    }
}

#[test]
fn clean_data_is_left_alone() {
    // Guard: without spikes the cleaner replaces (almost) nothing and the default fit's modes do
    // not move by more than 0.1 % against the Huber fit without cleaning -- for Gaussian
    // innovations and for a process with a few large genuine innovation outliers ("potholes", 0.1 %
    // of the innovations, whose impulse responses the data follow).
    let (p, q) = (4, 2);
    for (ci, case) in CASES.iter().enumerate() {
        let a = ar_from_modes(&case.truth, case.fs);
        for seed in 0..3u64 {
            let mut rng = ChaCha8Rng::seed_from_u64(300 + seed);
            let burn = 4000;
            let e: Vec<f64> = (0..case.n + burn)
                .map(|_| rng.sample::<f64, _>(rand_distr::StandardNormal))
                .collect();
            let gaussian = filter_arma(&a, &case.c, &e)[burn..].to_vec();
            // Pothole impulses in the innovations, 0.1 % of them at 4-8 std(y) of the Gaussian
            // record (hundreds to thousands of innovation standard deviations), and 3 single ones
            // at 20 std(y) whose responses stand far out of the record (beyond the pre-screen).
            let sd = std_of(&gaussian);
            let mut e_io = e.clone();
            for _ in 0..(case.n + burn) / 1000 {
                let i = rng.gen_range(burn..e_io.len());
                let sign = if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
                e_io[i] = sign * rng.gen_range(4.0..8.0) * sd;
            }
            let potholes = filter_arma(&a, &case.c, &e_io)[burn..].to_vec();
            let mut e_big = e.clone();
            for j in 1..=3 {
                e_big[burn + j * case.n / 4] = 20.0 * sd;
            }
            let big = filter_arma(&a, &case.c, &e_big)[burn..].to_vec();
            for (name, y) in [
                ("gaussian", &gaussian),
                ("potholes", &potholes),
                ("3 big potholes", &big),
            ] {
                let cl = clean_additive_outliers(y, &CleanerParams::default()).unwrap();
                let m_def = fit_arma(y, p, q, &ArmaParams::default()).unwrap();
                let m_off = fit_arma(y, p, q, &huber_only()).unwrap();
                let reference = m_off.modes(case.fs).modes;
                let w = worst(&reference, &m_def, case.fs);
                let peak = y.iter().fold(0.0f64, |m, v| m.max(v.abs())) / std_of(y);
                println!(
                    "case {ci} seed {seed} {name}: max |y| / std(y) {peak:.1}, replaced {}, worst \
                     mode change {w:.2e}",
                    cl.replaced.len()
                );
                assert_eq!(m_def.outliers_replaced, cl.replaced.len());
                assert!(
                    cl.replaced.len() <= 1,
                    "case {ci} seed {seed} {name}: {:?}",
                    cl.replaced
                );
                assert!(w <= 1e-3, "case {ci} seed {seed} {name}: modes moved {w}");
            }
        }
    }
}

#[test]
fn single_spike_in_ar2_is_replaced_by_exactly_its_prediction() {
    // AR(2) (one 2 Hz mode, damping 0.05, fs = 50 Hz), predictor order 2: the spike at t0 = 500
    // becomes centre - a1 (y[t0-1] - centre) - a2 (y[t0-2] - centre) with the returned model, every
    // other sample is returned bit for bit, and the returned model is the simulated one.
    let a_true = ar_from_modes(&[(2.0, 0.05)], 50.0);
    let y = simulate_arma(&a_true, &[1.0], 1.0, 2000, 11).unwrap();
    let t0 = 500;
    let mut ys = y.clone();
    ys[t0] += 15.0 * std_of(&y);
    let params = CleanerParams {
        ar_order: 2,
        ..CleanerParams::default()
    };
    let cl = clean_additive_outliers(&ys, &params).unwrap();
    assert_eq!(cl.replaced, vec![t0]);
    let c = cl.centre;
    let pred = c - cl.ar[1] * (ys[t0 - 1] - c) - cl.ar[2] * (ys[t0 - 2] - c);
    assert!(
        (cl.y[t0] - pred).abs() < 1e-12 * std_of(&y),
        "{} vs {pred}",
        cl.y[t0]
    );
    for t in (0..ys.len()).filter(|&t| t != t0) {
        assert_eq!(cl.y[t].to_bits(), ys[t].to_bits(), "sample {t}");
    }
    assert!((cl.ar[1] - a_true[1]).abs() < 0.01 && (cl.ar[2] - a_true[2]).abs() < 0.01);
    // The replaced value is the clean sample up to one innovation (lambda = 1).
    assert!((cl.y[t0] - y[t0]).abs() < 4.0);
    // Same for a spike in the first m samples (caught by the backward pass) ...
    let mut head = y.clone();
    head[1] -= 15.0 * std_of(&y);
    let cl = clean_additive_outliers(&head, &params).unwrap();
    assert_eq!(cl.replaced, vec![1]);
    assert!((cl.y[1] - y[1]).abs() < 4.0);
    // ... and a genuine innovation of the same size is kept (the data follow its impulse response).
    let mut e = vec![0.0; 2000];
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    for v in e.iter_mut() {
        *v = rng.sample::<f64, _>(rand_distr::StandardNormal);
    }
    e[1000] = 15.0 * std_of(&y);
    let io = filter_arma(&a_true, &[1.0], &e);
    let cl = clean_additive_outliers(&io, &params).unwrap();
    assert!(cl.replaced.is_empty(), "{:?}", cl.replaced);
}

#[test]
fn clean_sequence_is_untouched() {
    // A clean, non-constant ARMA sequence comes back bit for bit, nothing replaced; a sequence
    // shorter than 10 samples (no room for a predictor) as well.
    let a = ar_from_modes(&[(1.1, 0.1), (8.5, 0.05)], 50.0);
    let y = simulate_arma(&a, &[1.0, -0.3, 0.2], 0.5, 3000, 21).unwrap();
    let cl = clean_additive_outliers(&y, &CleanerParams::default()).unwrap();
    assert!(cl.replaced.is_empty());
    assert!(cl.y.iter().zip(&y).all(|(u, v)| u.to_bits() == v.to_bits()));
    assert_eq!(cl.ar.len(), 21);
    let short = [1.0, 2.0, 100.0, 2.0, 1.0];
    let cl = clean_additive_outliers(&short, &CleanerParams::default()).unwrap();
    assert!(cl.replaced.is_empty() && cl.y == short && cl.ar.is_empty());
    // Robust::Off is never cleaned, even with 1 % spikes.
    let (ys, _) = add_spikes(&y, 0.01, 10.0, 20.0, 22);
    assert_eq!(
        fit_arma(&ys, 4, 2, &quadratic()).unwrap().outliers_replaced,
        0
    );
}

#[test]
fn bad_cleaner_inputs_give_one_line_errors() {
    let y: Vec<f64> = (0..100).map(|i| (i as f64 * 0.3).sin()).collect();
    for (cp, name) in [
        (
            CleanerParams {
                ar_order: 0,
                ..CleanerParams::default()
            },
            "ar_order",
        ),
        (
            CleanerParams {
                threshold: f64::NAN,
                ..CleanerParams::default()
            },
            "threshold",
        ),
        (
            CleanerParams {
                threshold: -1.0,
                ..CleanerParams::default()
            },
            "threshold",
        ),
        (
            CleanerParams {
                passes: 0,
                ..CleanerParams::default()
            },
            "passes",
        ),
    ] {
        let e = clean_additive_outliers(&y, &cp).unwrap_err();
        assert!(matches!(
            e,
            IdentError::Param(vibmode_core::ParamError::OutOfRange { .. })
        ));
        let msg = e.to_string();
        assert!(msg.contains(name) && !msg.contains('\n'), "{msg}");
        let params = ArmaParams {
            outlier_cleaning: OutlierCleaning::RobustFilter(cp),
            ..ArmaParams::default()
        };
        assert_eq!(fit_arma(&y, 2, 0, &params).unwrap_err(), e);
    }
    let mut bad = y.clone();
    bad[7] = f64::NAN;
    assert!(matches!(
        clean_additive_outliers(&bad, &CleanerParams::default()),
        Err(IdentError::NonFinite { index: 7, .. })
    ));
    assert!(matches!(
        clean_additive_outliers(&[], &CleanerParams::default()),
        Err(IdentError::Empty { .. })
    ));
    assert!(matches!(
        clean_additive_outliers(&[2.0; 50], &CleanerParams::default()),
        Err(IdentError::Constant { .. })
    ));
}

#[test]
fn params_serde_defaults() {
    // Old JSON without the new fields, and with the old spellings `max_iter` and `tol`, still
    // deserialises (serde defaults and aliases).
    let p: ArmaParams = serde_json::from_str(
        r#"{"robust":{"Huber":{"factor":1.6}},"max_iter":100,"tol":1e-5,"max_halvings":10,"demean":true}"#,
    )
    .unwrap();
    assert_eq!(p, ArmaParams::default());
    let old: ArmaParams = serde_json::from_str(
        r#"{"robust":"off","max_iter":7,"tol":0.5,"max_halvings":10,"demean":true}"#,
    )
    .unwrap();
    assert_eq!((old.max_iterations, old.tolerance), (7, 0.5));
    // Written with the one name.
    let v = serde_json::to_value(ArmaParams::default()).unwrap();
    assert!(
        v.get("max_iterations").is_some() && v.get("max_iter").is_none(),
        "{v}"
    );
    let a = ar_from_modes(&[(2.0, 0.05)], 50.0);
    let y = simulate_arma(&a, &[1.0], 1.0, 500, 1).unwrap();
    let m = fit_arma(&y, 2, 0, &ArmaParams::default()).unwrap();
    let mut v = serde_json::to_value(&m).unwrap();
    v.as_object_mut().unwrap().remove("outliers_replaced");
    let back: ArmaModel = serde_json::from_value(v).unwrap();
    assert_eq!(back, m);
}

/// A bad parameter of a fit is core's `ParamError` (one shape across crates), one line naming
/// the key, the value and a valid value.
#[test]
fn bad_fit_parameters_are_core_param_errors() {
    let y: Vec<f64> = (0..400).map(|i| (0.3 * i as f64).sin()).collect();
    for (params, needle) in [
        (
            ArmaParams {
                tolerance: -1.0,
                ..ArmaParams::default()
            },
            "tolerance = -1",
        ),
        (
            ArmaParams {
                noise_floor: 0.5,
                ..ArmaParams::default()
            },
            "noise_floor = 0.5",
        ),
    ] {
        let e = vibmode_ident::fit_arma(&y, 4, 4, &params).unwrap_err();
        assert!(
            matches!(
                e,
                IdentError::Param(vibmode_core::ParamError::OutOfRange { .. })
            ),
            "{e:?}"
        );
        let msg = e.to_string();
        assert!(
            msg.contains(needle) && msg.contains("use e.g.") && !msg.contains('\n'),
            "{msg}"
        );
    }
    let e = "newton"
        .parse::<vibmode_ident::ArMethod>()
        .unwrap_err()
        .to_string();
    assert!(e.contains("'newton'") && e.contains("burg"), "{e}");
}
