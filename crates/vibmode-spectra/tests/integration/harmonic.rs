//! Thomson's multitaper harmonic F-test: agreement with an independent implementation (scipy's
//! dpss and numpy's FFT, tools/reference/harmonic.py -> tools/reference/data/harmonic.json,
//! numpy 2.1.3, scipy 1.14.1), and its false-alarm rate and power over many seeded records.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde_json::Value;
use vibmode_spectra::{dpss, f_test_peaks, harmonic_f_test, HarmonicPlan};

const REF: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tools/reference/data/harmonic.json"
));

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|e| e.as_f64().expect("number"))
        .collect()
}

#[test]
fn tapers_f_and_p_values_agree_with_scipy() {
    let r: Value = serde_json::from_str(REF).expect("reference JSON parses");
    let cases = r["cases"].as_array().expect("cases");
    assert_eq!(cases.len(), 4);
    for c in cases {
        let n = c["n"].as_u64().unwrap() as usize;
        let nw = c["nw"].as_f64().unwrap();
        let k = c["k"].as_u64().unwrap() as usize;
        let pad = c["pad"].as_u64().unwrap() as usize;
        let fs = c["fs"].as_f64().unwrap();
        let x = floats(&c["x"]);
        let tapers = dpss(n, nw, k).unwrap();
        for (j, (got, want)) in tapers
            .iter()
            .zip(c["tapers"].as_array().unwrap())
            .enumerate()
        {
            let want = floats(want);
            let err = got
                .iter()
                .zip(&want)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-9, "n {n} nw {nw} taper {j}: max error {err:e}");
        }
        let h = harmonic_f_test(&x, fs, nw, k, pad).unwrap();
        let f = floats(&c["f"]);
        let p = floats(&c["p"]);
        let a = floats(&c["amplitude"]);
        assert_eq!(h.f_stat.len(), f.len(), "n {n}: grid length");
        let amax = a.iter().fold(0.0f64, |m, v| m.max(*v));
        for j in 0..f.len() {
            let tol = if f[j] > 1e-3 { 1e-6 * f[j] } else { 1e-9 };
            assert!(
                (h.f_stat[j] - f[j]).abs() <= tol,
                "n {n} bin {j}: F {} vs {}",
                h.f_stat[j],
                f[j]
            );
            assert!((h.p_value(j) - p[j]).abs() <= 1e-9, "n {n} bin {j}: p");
            assert!(
                (h.amplitude[j] - a[j]).abs() <= 1e-9 * amax,
                "n {n} bin {j}: amplitude"
            );
        }
    }
}

fn noise(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    (0..n).map(|_| StandardNormal.sample(rng)).collect()
}

/// A randomly excited mode (f_n Hz, damping zeta) sampled at fs: the AR(2) with the mode's
/// discrete poles driven by white noise, after a burn-in of 20 time constants.
fn mode(rng: &mut ChaCha8Rng, n: usize, fs: f64, f_n: f64, zeta: f64) -> Vec<f64> {
    let w = 2.0 * std::f64::consts::PI * f_n;
    let r = (-zeta * w / fs).exp();
    let th = w * (1.0 - zeta * zeta).sqrt() / fs;
    let (a1, a2) = (2.0 * r * th.cos(), -r * r);
    let burn = (20.0 / (zeta * w) * fs) as usize + 100;
    let mut x = vec![0.0; n + burn];
    for t in 2..n + burn {
        let e: f64 = StandardNormal.sample(rng);
        x[t] = a1 * x[t - 1] + a2 * x[t - 2] + e;
    }
    x.split_off(burn)
}

/// Count in [mean - 4.5 sd, mean + 4.5 sd] of Binomial(trials, p): a correct test fails this
/// with probability below 1e-5.
fn within_binomial(count: usize, trials: usize, p: f64) -> bool {
    let mean = trials as f64 * p;
    let sd = (trials as f64 * p * (1.0 - p)).sqrt();
    (count as f64 - mean).abs() <= 4.5 * sd
}

const FS: f64 = 50.0;
const N: usize = 512; // 10.24 s at 50 Hz, a record of the analysis
const NW: f64 = 4.0;
const K: usize = 7;

/// P(F > F_obs) at fixed grid frequencies (pad 1: bins 0.098 Hz apart; frequencies 2W apart are
/// nearly independent) over many seeded records; the share below alpha must be alpha within
/// binomial bounds.
fn null_rate(
    signal: impl Fn(&mut ChaCha8Rng) -> Vec<f64>,
    freqs: &[f64],
    seeds: u64,
) -> [(usize, usize); 2] {
    let plan = HarmonicPlan::new(N, NW, K, 1).unwrap();
    let mut counts = [(0, 0); 2];
    for seed in 0..seeds {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let x = signal(&mut rng);
        let h = plan.f_test(&x, FS).unwrap();
        for &f in freqs {
            let j = (f * N as f64 / FS).round() as usize;
            let p = h.p_value(j);
            for (i, alpha) in [0.05, 0.01].iter().enumerate() {
                counts[i].1 += 1;
                if p < *alpha {
                    counts[i].0 += 1;
                }
            }
        }
    }
    counts
}

#[test]
fn false_alarm_rate_on_white_noise_is_nominal() {
    let c = null_rate(
        |r| noise(r, N),
        &[3.0, 6.0, 9.0, 12.0, 15.0, 18.0, 21.0],
        1500,
    );
    for ((hits, trials), alpha) in c.iter().zip([0.05, 0.01]) {
        assert!(
            within_binomial(*hits, *trials, alpha),
            "white noise: {hits}/{trials} below {alpha}"
        );
    }
}

#[test]
fn false_alarm_rate_on_a_randomly_excited_mode_is_nominal_at_and_beside_its_peak() {
    // A wheel-hop-like mode (9 Hz, damping 0.25) and a light one (9 Hz, 0.1, half-power
    // half-width 0.9 Hz, over twice the tapers' W = 0.39 Hz), tested at the peak and beside it.
    for zeta in [0.25, 0.1] {
        let c = null_rate(|r| mode(r, N, FS, 9.0, zeta), &[7.0, 9.0, 11.0], 2000);
        for ((hits, trials), alpha) in c.iter().zip([0.05, 0.01]) {
            assert!(
                within_binomial(*hits, *trials, alpha),
                "mode zeta {zeta}: {hits}/{trials} below {alpha}"
            );
        }
    }
}

#[test]
fn peaks_in_a_band_of_noise_stay_below_the_union_bound() {
    // The search over a band: a record has a peak with p < alpha somewhere in 5-20 Hz with
    // probability at most alpha times the number of independent frequencies (B T = 154 at pad 1);
    // here alpha = 1e-3 -> at most 0.154 per record.
    let plan = HarmonicPlan::new(N, NW, K, 1).unwrap();
    let (mut any, trials) = (0usize, 1000usize);
    for seed in 0..trials as u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(10_000 + seed);
        let h = plan.f_test(&noise(&mut rng, N), FS).unwrap();
        if !f_test_peaks(&h, 1e-3, 5.0, 20.0).is_empty() {
            any += 1;
        }
    }
    let bound = 1e-3 * 15.0 * N as f64 / FS;
    let sd = (trials as f64 * bound * (1.0 - bound)).sqrt();
    assert!(
        (any as f64) <= trials as f64 * bound + 4.5 * sd,
        "{any}/{trials} records, bound {bound}"
    );
    // And not vacuous: the look-elsewhere effect is there (more than one test's alpha).
    assert!(any > 0, "{any}");
}

#[test]
fn a_line_on_the_shoulder_of_a_broad_mode_is_detected_in_nearly_every_record() {
    // 10.8 Hz line of amplitude the mode's RMS (half the mode's power) on a 9 Hz mode damped
    // 0.25, 20 % above its peak.
    let plan = HarmonicPlan::new(N, NW, K, 4).unwrap();
    let (mut found, trials) = (0usize, 300usize);
    for seed in 0..trials as u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(20_000 + seed);
        let mut x = mode(&mut rng, N, FS, 9.0, 0.25);
        let rms = (x.iter().map(|v| v * v).sum::<f64>() / N as f64).sqrt();
        for (t, v) in x.iter_mut().enumerate() {
            *v += rms * (2.0 * std::f64::consts::PI * 10.8 * t as f64 / FS + seed as f64).cos();
        }
        let h = plan.f_test(&x, FS).unwrap();
        if f_test_peaks(&h, 1e-3, 5.0, 20.0)
            .iter()
            .any(|(f, _, _)| (f - 10.8).abs() <= 0.1)
        {
            found += 1;
        }
    }
    assert!(found as f64 >= 0.95 * trials as f64, "{found}/{trials}");
}
