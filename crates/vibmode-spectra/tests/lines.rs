//! Line detection: the kurtosis of a sine and of noise by hand, the sine-plus-noise formula over
//! seeds, and lines told from modes on simulated signals over seeds.
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use std::f64::consts::PI;
use vibmode_spectra::{line_candidates, narrowband_kurtosis, LineParams, SpectraError};

fn gauss(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| StandardNormal.sample(&mut rng)).collect()
}

#[test]
fn a_sine_on_a_bin_has_kurtosis_one_and_a_half() {
    // 8 Hz at fs 64 Hz over 256 samples: exactly 32 periods, band-passing keeps it unchanged.
    let x: Vec<f64> = (0..256)
        .map(|i| 3.0 * (2.0 * PI * 8.0 * i as f64 / 64.0 + 0.3).sin())
        .collect();
    let k = narrowband_kurtosis(&x, 64.0, 8.0, 0.5).unwrap();
    assert!((k - 1.5).abs() < 1e-9, "{k}");
    // a band without power
    assert!(narrowband_kurtosis(&x, 64.0, 20.0, 0.5).unwrap().is_nan());
}

#[test]
fn gaussian_noise_has_kurtosis_three_over_seeds() {
    let mut ks = Vec::new();
    for seed in 0..20 {
        let x = gauss(8192, seed);
        // a wide band (many independent samples): close to 3
        ks.push(narrowband_kurtosis(&x, 100.0, 20.0, 10.0).unwrap());
    }
    let mean = ks.iter().sum::<f64>() / ks.len() as f64;
    assert!((mean - 3.0).abs() < 0.1, "mean kurtosis {mean}, {ks:?}");
    assert!(ks.iter().all(|k| (k - 3.0).abs() < 0.4), "{ks:?}");
}

#[test]
fn sine_plus_noise_follows_the_mixture_formula_over_seeds() {
    // Sine power S = A^2/2 = 2; white noise of variance 1 at fs 100 Hz over 8192 samples
    // band-passed to 10 +- 5 Hz keeps G = 1 * 10 / 50 = 0.2 of it.
    let (s, g): (f64, f64) = (2.0, 0.2);
    let expect = (1.5 * s * s + 6.0 * s * g + 3.0 * g * g) / (s + g).powi(2);
    let mut worst: f64 = 0.0;
    for seed in 0..10 {
        let noise = gauss(8192, 100 + seed);
        let x: Vec<f64> = noise
            .iter()
            .enumerate()
            .map(|(i, e)| 2.0 * (2.0 * PI * 10.0 * i as f64 / 100.0).sin() + e)
            .collect();
        let k = narrowband_kurtosis(&x, 100.0, 10.0, 5.0).unwrap();
        worst = worst.max((k - expect).abs());
    }
    assert!(
        worst < 0.03,
        "expected {expect:.3}, worst deviation {worst:.3}"
    );
}

/// A lightly damped mode (zeta, f0) driven by white noise, as an AR(2) process.
fn mode(n: usize, fs: f64, f0: f64, zeta: f64, seed: u64) -> Vec<f64> {
    let w = 2.0 * PI * f0 / fs;
    let r = (-zeta * w).exp();
    let (a1, a2) = (2.0 * r * (w * (1.0 - zeta * zeta).sqrt()).cos(), -r * r);
    let e = gauss(n + 500, seed);
    let mut y = vec![0.0; n + 500];
    for t in 2..y.len() {
        y[t] = a1 * y[t - 1] + a2 * y[t - 2] + e[t];
    }
    y.split_off(500)
}

#[test]
fn lines_are_told_from_modes_in_ten_second_records_over_seeds() {
    // The analysis' records: 512 samples at 50 Hz. A mode at 9 Hz with damping 0.03 (a body
    // bending mode) and a wandering, amplitude-modulated 7 Hz line, in broadband noise.
    let (fs, n) = (50.0, 512);
    let p = LineParams::default();
    let (mut line_found, mut mode_called_line, mut mode_peaks) = (0, 0, 0);
    let seeds = 0..20u64;
    for seed in seeds.clone() {
        let m = mode(n, fs, 9.0, 0.03, seed);
        let rms_m = (m.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
        let noise = gauss(n, 1000 + seed);
        let am = gauss(n, 2000 + seed);
        let mut phase = 0.0;
        let x: Vec<f64> = (0..n)
            .map(|i| {
                phase += 2.0 * PI * 7.0 * (1.0 + 1e-3 * (i as f64 / 100.0).sin()) / fs;
                let a = 1.0 + 0.1 * am[i] * 0.3;
                m[i] + rms_m * (a * phase.sin() + 0.1 * noise[i])
            })
            .collect();
        let c = line_candidates(&x, fs, &p).unwrap();
        if c.iter()
            .any(|l| (l.frequency_hz - 7.0).abs() < 0.1 && l.periodic)
        {
            line_found += 1;
        }
        for l in c.iter().filter(|l| (l.frequency_hz - 9.0).abs() < 0.4) {
            mode_peaks += 1;
            if l.periodic {
                mode_called_line += 1;
            }
        }
    }
    let n_seeds = seeds.count();
    assert!(
        line_found >= n_seeds - 1,
        "7 Hz line found periodic in {line_found} of {n_seeds} seeds"
    );
    assert!(
        mode_called_line * 5 <= mode_peaks.max(1),
        "9 Hz mode (zeta 0.03) called periodic in {mode_called_line} of {mode_peaks} peaks"
    );
}

#[test]
fn bad_input_is_an_error() {
    let p = LineParams::default();
    assert!(matches!(
        line_candidates(&[], 50.0, &p),
        Err(SpectraError::EmptyInput { .. })
    ));
    assert!(matches!(
        line_candidates(&[1.0, f64::NAN], 50.0, &p),
        Err(SpectraError::NonFiniteSample { index: 1, .. })
    ));
    assert!(matches!(
        narrowband_kurtosis(&[1.0, 2.0], -1.0, 1.0, 0.1),
        Err(SpectraError::InvalidSampleRate { .. })
    ));
}

#[test]
fn pooled_moments_reveal_a_lightly_damped_mode_that_one_record_cannot() {
    // 1.5 Hz, damping 0.02: correlation time 1 / (zeta omega) = 5.3 s, half a 10 s record. In one
    // record the band looks like a sine; over records its amplitude is random, so the pooled
    // kurtosis is Gaussian-like. A sine of fixed amplitude stays at 1.5 either way.
    use vibmode_spectra::narrowband_moments;
    let (fs, n, hw) = (50.0, 512, 0.25);
    let (mut low_single, mut pooled_mode) = (0, Vec::new());
    for seed in 0..10u64 {
        let (mut s2, mut s4) = (0.0, 0.0);
        for r in 0..8u64 {
            let x = mode(n, fs, 1.5, 0.02, 100 * seed + r);
            let k = narrowband_kurtosis(&x, fs, 1.5, hw).unwrap();
            if k < 2.0 {
                low_single += 1;
            }
            let (m2, m4) = narrowband_moments(&x, fs, 1.5, hw).unwrap();
            s2 += m2;
            s4 += m4;
        }
        pooled_mode.push((s4 / 8.0) / (s2 / 8.0).powi(2));
    }
    assert!(
        low_single >= 20,
        "single records looked periodic only {low_single} of 80 times"
    );
    let below = pooled_mode.iter().filter(|k| **k < 2.0).count();
    assert!(below <= 1, "pooled kurtosis of the mode: {pooled_mode:?}");
    // the moments are those of the band-passed signal: a unit sine has m2 = 1/2, m4 = 3/8
    let x: Vec<f64> = (0..256)
        .map(|i| (2.0 * PI * 8.0 * i as f64 / 64.0).sin())
        .collect();
    let (m2, m4) = narrowband_moments(&x, 64.0, 8.0, 0.5).unwrap();
    assert!(
        (m2 - 0.5).abs() < 1e-12 && (m4 - 0.375).abs() < 1e-12,
        "{m2} {m4}"
    );
}
