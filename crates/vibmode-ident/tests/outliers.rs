//! Additive outliers (issue #4): the robust AR filter-cleaner and the default robust ARMA fit on
//! data with 1 % spikes; the clean-data guard; hand-checkable cleaner cases; bad parameters.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use vibmode_ident::sim::{ar_from_modes, simulate_arma};
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

/// Largest relative frequency change of `m`'s modes against each reference mode (nearest mode);
/// 1.0 when a reference mode has no counterpart.
fn worst_freq_change(reference: &[Mode], m: &ArmaModel, fs: f64) -> f64 {
    let modes = m.modes(fs).modes;
    reference
        .iter()
        .map(|r| {
            modes
                .iter()
                .map(|e| (e.frequency_hz / r.frequency_hz - 1.0).abs())
                .fold(1.0f64, f64::min)
        })
        .fold(0.0f64, f64::max)
}

struct Case {
    fs: f64,
    truth: Vec<(f64, f64)>,
    c: Vec<f64>,
    n: usize,
    p: usize,
    q: usize,
}

#[test]
fn explore() {
    let cases = [
        Case {
            fs: 50.0,
            truth: vec![(1.1, 0.1), (8.5, 0.05)],
            c: vec![1.0, -0.3, 0.2],
            n: 4096,
            p: 4,
            q: 2,
        },
        Case {
            fs: 200.0,
            truth: vec![(1.0, 0.08), (11.0, 0.04)],
            c: vec![1.0, -0.5, 0.3],
            n: 8192,
            p: 4,
            q: 2,
        },
    ];
    for (ci, case) in cases.iter().enumerate() {
        let a = ar_from_modes(&case.truth, case.fs);
        for seed in 0..4u64 {
            let t0 = std::time::Instant::now();
            let y = simulate_arma(&a, &case.c, 1.0, case.n, 100 + seed).unwrap();
            let (ys, pos) = add_spikes(&y, 0.01, 10.0, 20.0, 200 + seed);
            let m_clean = fit_arma(&y, case.p, case.q, &ArmaParams::default()).unwrap();
            let m_clean_h = fit_arma(&y, case.p, case.q, &huber_only()).unwrap();
            let m_rob = fit_arma(&ys, case.p, case.q, &ArmaParams::default()).unwrap();
            let m_h = fit_arma(&ys, case.p, case.q, &huber_only()).unwrap();
            let m_q = fit_arma(&ys, case.p, case.q, &quadratic()).unwrap();
            let cl = clean_additive_outliers(&ys, &CleanerParams::default()).unwrap();
            let hits = cl.replaced.iter().filter(|i| pos.contains(i)).count();
            let reference = m_clean.modes(case.fs).modes;
            println!(
                "case {ci} seed {seed}: clean replaced {} (guard {:.2e}), spiky: replaced {} of {} spikes ({hits} hits, passes {}), robust {:.2e}, huber-only {:.2e}, quad {:.2e}, {:?}",
                m_clean.outliers_replaced,
                worst_freq_change(&m_clean_h.modes(case.fs).modes, &m_clean, case.fs),
                m_rob.outliers_replaced,
                pos.len(),
                cl.passes,
                worst_freq_change(&reference, &m_rob, case.fs),
                worst_freq_change(&reference, &m_h, case.fs),
                worst_freq_change(&reference, &m_q, case.fs),
                t0.elapsed()
            );
        }
    }
}

#[test]
fn bad_cleaner_params_give_one_line_errors() {
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
        assert!(matches!(e, IdentError::InvalidParam { .. }));
        let msg = e.to_string();
        assert!(msg.contains(name) && !msg.contains('\n'), "{msg}");
        let params = ArmaParams {
            outlier_cleaning: OutlierCleaning::RobustFilter(cp),
            ..ArmaParams::default()
        };
        assert_eq!(fit_arma(&y, 2, 0, &params).unwrap_err(), e);
    }
}

#[test]
fn debug_case1() {
    let fs = 200.0;
    let a = ar_from_modes(&[(1.0, 0.08), (11.0, 0.04)], fs);
    for seed in 0..4u64 {
        let y = simulate_arma(&a, &[1.0, -0.5, 0.3], 1.0, 8192, 100 + seed).unwrap();
        let (ys, pos) = add_spikes(&y, 0.01, 10.0, 20.0, 200 + seed);
        let cl = clean_additive_outliers(&ys, &CleanerParams::default()).unwrap();
        let missed: Vec<usize> = pos.iter().copied().filter(|i| !cl.replaced.contains(i)).collect();
        let false_: Vec<usize> = cl.replaced.iter().copied().filter(|i| !pos.contains(i)).collect();
        println!("seed {seed} std {:.3} scale {:.3e} missed {:?} false {:?} ar {:?}", std_of(&y), cl.residual_scale, missed, false_, &cl.ar[..4]);
        for &i in missed.iter().chain(&false_) {
            let near: Vec<usize> = pos.iter().copied().filter(|&j| j.abs_diff(i) <= 25).collect();
            println!("  {i}: y {:.3} ys {:.3} cleaned {:.3} spikes near {:?}", y[i], ys[i], cl.y[i], near);
        }
        let err: f64 = cl.y.iter().zip(&y).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        println!("  max |cleaned - clean| {err:.3e}");
    }
}

#[test]
fn debug_burg() {
    let fs = 200.0;
    let a = ar_from_modes(&[(1.0, 0.08), (11.0, 0.04)], fs);
    let y = simulate_arma(&a, &[1.0, -0.5, 0.3], 1.0, 8192, 100).unwrap();
    for p in [2, 4, 6, 10, 20] {
        for meth in [vibmode_ident::ArMethod::Burg, vibmode_ident::ArMethod::LeastSquares] {
            let m = vibmode_ident::fit_ar(&y, p, meth).unwrap();
            println!("p {p} {meth}: lambda {:.3e} a {:?}", m.noise_variance, &m.a[..3]);
        }
    }
    let cl = clean_additive_outliers(&y, &CleanerParams::default()).unwrap();
    println!("clean: scale {}", cl.residual_scale);
}
