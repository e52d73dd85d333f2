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

// ---- swept lines: short-time spectra, ridges, kurtosis along a ridge ----

use vibmode_spectra::{
    ridges, swept_line_candidates, tracked_kurtosis, Ridge, WelchParams, WelchPlan,
};

/// A linear chirp `sin(2 pi (f0 t + rate t^2 / 2))`, instantaneous frequency `f0 + rate t`.
fn chirp(n: usize, fs: f64, f0: f64, rate: f64, amp: f64) -> Vec<f64> {
    (0..n)
        .map(|i| {
            let t = i as f64 / fs;
            amp * (2.0 * PI * (f0 * t + 0.5 * rate * t * t)).sin()
        })
        .collect()
}

#[test]
fn spectrogram_times_are_segment_centres_and_its_mean_is_welch() {
    let x = gauss(512, 7);
    let p = WelchParams {
        nperseg: Some(64),
        noverlap: Some(48),
        ..WelchParams::default()
    };
    let mut plan = WelchPlan::new(x.len(), 50.0, &p).unwrap();
    let s = plan.spectrogram(&x).unwrap();
    // (512 - 64) / 16 + 1 = 29 slices, the first centred at 32 samples = 0.64 s, 0.32 s apart.
    assert_eq!(s.psd.len(), 29);
    assert!((s.time_s[0] - 0.64).abs() < 1e-12);
    assert!((s.time_s[28] - (0.64 + 28.0 * 0.32)).abs() < 1e-12);
    let w = plan.welch(&x).unwrap();
    for (b, v) in w.psd.iter().enumerate() {
        let mean = s.psd.iter().map(|row| row[b]).sum::<f64>() / 29.0;
        assert!((mean - v).abs() <= 1e-12 * v.abs().max(1e-12), "bin {b}");
    }
    assert!(plan.spectrogram(&x[..100]).is_err());
}

#[test]
fn a_linear_chirp_has_its_ridge_at_the_instantaneous_frequency() {
    // 5 Hz + 0.4 Hz/s over 10.24 s at 50 Hz: 5.26 Hz at the first slice centre (0.64 s),
    // 0.128 Hz more every slice (0.32 s), 8.84 Hz at the last (9.6 s).
    let fs = 50.0;
    let x = chirp(512, fs, 5.0, 0.4, 1.0);
    let p = LineParams::default();
    let mut plan = WelchPlan::new(
        x.len(),
        fs,
        &WelchParams {
            nperseg: Some(64),
            noverlap: Some(48),
            nfft: Some(256),
            ..WelchParams::default()
        },
    )
    .unwrap();
    let s = plan.spectrogram(&x).unwrap();
    let r = ridges(&s, &p);
    assert_eq!(r.len(), 1, "{r:?}");
    let r = &r[0];
    assert_eq!(r.freq_hz.len(), 29);
    for (t, f) in r.time_s.iter().zip(&r.freq_hz) {
        let expect = 5.0 + 0.4 * t;
        assert!((f - expect).abs() < 0.05, "t {t}: {f} vs {expect}");
    }
    assert!((r.range_hz() - 0.4 * 28.0 * 0.32).abs() < 0.1);
    // Demodulated along its ridge the chirp is a sine: kurtosis 1.5.
    let k = tracked_kurtosis(&x, fs, r, 0.25, 0.64).unwrap();
    assert!((k - 1.5).abs() < 0.05, "{k}");
    // Along a wrong ridge (constant 7 Hz) the band holds a short burst: far from a sine.
    let wrong = Ridge {
        time_s: r.time_s.clone(),
        freq_hz: vec![7.0; r.time_s.len()],
        n_found: 29,
    };
    let k = tracked_kurtosis(&x, fs, &wrong, 0.25, 0.64).unwrap();
    assert!(k > 3.0, "{k}");
}

#[test]
fn chirps_in_noise_are_swept_lines_over_seeds_and_lengths() {
    // Chirps sweeping 0.8-2.6 Hz over the record (0.02-0.25 Hz/s) from 4-8.5 Hz (amplitude 1,
    // power 0.5) in white noise of std 0.3 at 50 Hz (density 0.0036 /Hz, 0.002 in the +-0.25 Hz
    // band): found over 10 seeds and three record lengths with their ridge within 0.15 Hz of the
    // instantaneous frequency and a kurtosis below 2; nothing else is called a swept line.
    let fs = 50.0;
    let p = LineParams::default();
    let mut worst: f64 = 0.0;
    for seed in 0..10u64 {
        for &n in &[512usize, 1024, 2048] {
            // The sweep over the record: 0.8-2.6 Hz up or down (its ridge, from the first to the last slice centre, spans at least 0.65 Hz > sweep_min_range_hz).
            let f0 = 4.0 + 0.5 * seed as f64;
            let sweep_hz =
                (0.8 + 0.45 * (seed % 5) as f64) * if seed % 2 == 0 { 1.0 } else { -1.0 };
            let rate = sweep_hz / (n as f64 / fs);
            let noise = gauss(n, 1000 + seed * 7 + n as u64);
            let x: Vec<f64> = chirp(n, fs, f0, rate, 1.0)
                .iter()
                .zip(&noise)
                .map(|(a, b)| a + 0.3 * b)
                .collect();
            let c = swept_line_candidates(&x, fs, &p).unwrap();
            let hit = c
                .iter()
                .find(|c| {
                    c.ridge
                        .time_s
                        .iter()
                        .zip(&c.ridge.freq_hz)
                        .all(|(t, f)| (f - (f0 + rate * t)).abs() < 0.15)
                })
                .unwrap_or_else(|| panic!("seed {seed} n {n}: no ridge on the chirp: {c:?}"));
            assert!(hit.periodic, "seed {seed} n {n}: kurtosis {}", hit.kurtosis);
            worst = worst.max(hit.kurtosis);
            // Nothing else is called a line in white noise.
            assert_eq!(
                c.iter().filter(|c| c.periodic).count(),
                1,
                "seed {seed} n {n}"
            );
        }
    }
    assert!(worst < 2.0, "{worst}");
}

/// A randomly excited mode: white noise through a second-order resonator at `f_hz`, damping
/// `zeta` (exact discretisation of the impulse response), sampled at `fs`.
fn random_mode(n: usize, fs: f64, f_hz: f64, zeta: f64, seed: u64) -> Vec<f64> {
    let w = 2.0 * PI * f_hz;
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let r = (-zeta * w / fs).exp();
    let (a1, a2) = (2.0 * r * (wd / fs).cos(), -r * r);
    let e = gauss(n + 2000, seed);
    let mut y = vec![0.0; n + 2000];
    for i in 2..y.len() {
        y[i] = a1 * y[i - 1] + a2 * y[i - 2] + e[i];
    }
    y.split_off(2000)
}

#[test]
fn damped_random_modes_are_never_swept_lines() {
    // Wheel hop (10 Hz, zeta 0.2), bending (9 Hz, 0.03) and a light 4 Hz mode (0.02), each with
    // a little white noise, over 20 seeds of 10.24 s at 50 Hz: no swept line.
    let fs = 50.0;
    let p = LineParams::default();
    for seed in 0..20u64 {
        for &(f, z) in &[(10.0, 0.2), (9.0, 0.03), (4.0, 0.02)] {
            let m = random_mode(512, fs, f, z, 50 + seed);
            let sd = (m.iter().map(|v| v * v).sum::<f64>() / m.len() as f64).sqrt();
            let noise = gauss(512, 900 + seed);
            let x: Vec<f64> = m
                .iter()
                .zip(&noise)
                .map(|(a, b)| a + 0.05 * sd * b)
                .collect();
            let c = swept_line_candidates(&x, fs, &p).unwrap();
            let lines: Vec<_> = c.iter().filter(|c| c.periodic).collect();
            assert!(
                lines.is_empty(),
                "seed {seed}, mode {f} Hz zeta {z}: {lines:?}"
            );
        }
    }
}
