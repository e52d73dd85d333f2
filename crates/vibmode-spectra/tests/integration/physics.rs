//! Identity and physics checks on seeded random inputs.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::f64::consts::PI;
use vibmode_spectra::{
    coherence, csd, periodogram, welch, Average, Detrend, PeriodogramParams, Scaling, WelchParams,
    WelchPlan, Window,
};

fn noise(seed: u64, n: usize, sd: f64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let d = Normal::new(0.0, sd).unwrap();
    (0..n).map(|_| d.sample(&mut rng)).collect()
}

fn argmax(v: &[f64]) -> (usize, f64) {
    v.iter().enumerate().fold(
        (0, f64::NEG_INFINITY),
        |a, (i, &x)| if x > a.1 { (i, x) } else { a },
    )
}

#[test]
fn parseval_periodogram_density() {
    for (seed, n) in [(1u64, 1000usize), (2, 1001), (3, 257)] {
        let x: Vec<f64> = noise(seed, n, 1.7).iter().map(|v| v + 0.8).collect();
        let fs_hz = 37.5;
        let p = PeriodogramParams {
            detrend: Detrend::None,
            ..Default::default()
        };
        let s = periodogram(&x, fs_hz, &p).unwrap();
        let df = fs_hz / n as f64;
        let total = s.psd.iter().sum::<f64>() * df;
        let ms = x.iter().map(|v| v * v).sum::<f64>() / n as f64;
        assert!(
            ((total - ms) / ms).abs() < 1e-12,
            "n={n}: {total} vs mean square {ms}"
        );
    }
}

#[test]
fn bin_sine_peak_is_half_amplitude_squared() {
    // 1000 samples at 200 Hz: df = 0.2 Hz, 12.4 Hz is bin 62.
    let (fs_hz, n, amp, f0) = (200.0, 1000, 3.0, 12.4);
    let x: Vec<f64> = (0..n)
        .map(|i| amp * (2.0 * PI * f0 * i as f64 / fs_hz + 0.3).sin())
        .collect();
    let p = PeriodogramParams {
        scaling: Scaling::Spectrum,
        ..Default::default()
    };
    let s = periodogram(&x, fs_hz, &p).unwrap();
    let (k, peak) = argmax(&s.psd);
    assert_eq!(k, 62);
    assert!((s.freq_hz[k] - f0).abs() < 1e-12);
    assert!((peak - amp * amp / 2.0).abs() < 1e-9, "peak {peak}");
    // Everything else is (numerically) zero.
    let rest: f64 = s
        .psd
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != k)
        .map(|(_, v)| v)
        .sum();
    assert!(rest < 1e-20, "leakage {rest}");
}

#[test]
fn flattop_welch_peak_of_off_bin_tone() {
    // Tone between bins (df = fs/nperseg = 0.25 Hz; 10.3 Hz is bin 41.2), amplitude 2:
    // the flattop's scalloping loss is < 0.01 dB, so the peak is A^2/2 = 2 within 1 %.
    let (fs_hz, amp) = (256.0, 2.0);
    for f0 in [10.3, 10.375, 33.1] {
        let x: Vec<f64> = (0..16384)
            .map(|i| amp * (2.0 * PI * f0 * i as f64 / fs_hz).cos())
            .collect();
        let p = WelchParams {
            window: Window::Flattop,
            nperseg: Some(1024),
            scaling: Scaling::Spectrum,
            ..Default::default()
        };
        let s = welch(&x, fs_hz, &p).unwrap();
        let (k, peak) = argmax(&s.psd);
        assert!(
            (s.freq_hz[k] - f0).abs() <= 0.25,
            "f0 {f0}: peak at {}",
            s.freq_hz[k]
        );
        let rel = (peak - amp * amp / 2.0).abs() / (amp * amp / 2.0);
        assert!(rel < 0.01, "f0 {f0}: peak {peak}, rel err {rel}");
        // A Hann window would miss by the scalloping loss (up to 1.42 dB = 28 %) at 10.375 Hz
        // (half a bin off): a check that this test can tell windows apart.
        if f0 == 10.375 {
            let h = welch(
                &x,
                fs_hz,
                &WelchParams {
                    window: Window::Hann,
                    ..p
                },
            )
            .unwrap();
            assert!(argmax(&h.psd).1 < 0.8 * amp * amp / 2.0);
        }
    }
}

#[test]
fn white_noise_density_level() {
    // Variance s^2 white noise: one-sided density 2 s^2 / fs.
    let (fs_hz, sd) = (50.0, 2.0);
    let x = noise(7, 65536, sd);
    for (avg, tol) in [(Average::Mean, 0.02), (Average::Median, 0.04)] {
        let p = WelchParams {
            average: avg,
            ..Default::default()
        };
        let s = welch(&x, fs_hz, &p).unwrap();
        let inner = &s.psd[1..s.psd.len() - 1];
        let mean = inner.iter().sum::<f64>() / inner.len() as f64;
        let want = 2.0 * sd * sd / fs_hz;
        assert!(
            ((mean - want) / want).abs() < tol,
            "{avg}: mean density {mean} vs {want}"
        );
    }
}

#[test]
fn coherence_of_scaled_copy_is_one_and_of_independent_noise_small() {
    let x = noise(11, 8192, 1.0);
    let tiny = noise(12, 8192, 1e-4);
    let y: Vec<f64> = x.iter().zip(&tiny).map(|(a, t)| -2.5 * a + t).collect();
    let p = WelchParams::default();
    let c = coherence(&x, &y, 100.0, &p).unwrap();
    let min = c.coherence.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(min > 0.999, "min coherence {min}");
    assert!(c.coherence.iter().all(|&v| v <= 1.0 + 1e-12));
    let z = noise(13, 8192, 1.0);
    let c = coherence(&x, &z, 100.0, &p).unwrap();
    let mean = c.coherence.iter().sum::<f64>() / c.coherence.len() as f64;
    // Expected about 1/K for K = 63 independent-ish segments (overlap raises it a bit).
    assert!(mean < 0.05, "mean coherence of independent noise {mean}");
}

#[test]
fn csd_with_itself_is_welch_and_scaled_copy() {
    let x = noise(21, 3001, 1.3);
    for avg in [Average::Mean, Average::Median] {
        let p = WelchParams {
            nperseg: Some(300),
            noverlap: Some(100),
            nfft: Some(512),
            detrend: Detrend::Linear,
            average: avg,
            window: Window::Blackman,
            ..Default::default()
        };
        let w = welch(&x, 10.0, &p).unwrap();
        let c = csd(&x, &x, 10.0, &p).unwrap();
        for (a, b) in w.psd.iter().zip(&c.csd) {
            assert!((a - b.re).abs() <= 1e-13 * a.abs().max(1e-300));
            assert_eq!(b.im, 0.0);
        }
        // Pxy of (x, a x) = a Pxx; Pxx of a x = a^2 Pxx.
        let y: Vec<f64> = x.iter().map(|v| -3.0 * v).collect();
        let c = csd(&x, &y, 10.0, &p).unwrap();
        let wy = welch(&y, 10.0, &p).unwrap();
        for ((a, b), d) in w.psd.iter().zip(&c.csd).zip(&wy.psd) {
            assert!((b.re + 3.0 * a).abs() <= 1e-12 * a.abs().max(1e-300));
            assert!((d - 9.0 * a).abs() <= 1e-12 * a.abs().max(1e-300));
        }
    }
}

#[test]
fn csd_phase_of_delayed_signal() {
    // y = x delayed by d samples: Pxy = conj(X) X e^{-i 2 pi f d / fs}, so the phase is
    // -2 pi f d / fs (scipy's conj(X) Y convention) where the delay is well inside a segment.
    let x = noise(31, 20000, 1.0);
    let d = 3usize;
    let y: Vec<f64> = (0..x.len())
        .map(|i| if i >= d { x[i - d] } else { 0.0 })
        .collect();
    let fs_hz = 100.0;
    let c = csd(&x, &y, fs_hz, &WelchParams::default()).unwrap();
    for (f, v) in c.freq_hz.iter().zip(&c.csd).skip(1).take(40) {
        let want = -2.0 * PI * f * d as f64 / fs_hz;
        assert!(
            (v.arg() - want).abs() < 0.05,
            "f {f}: phase {} vs {want}",
            v.arg()
        );
    }
}

#[test]
fn nonoverlapping_welch_is_mean_of_segment_periodograms() {
    let x = noise(41, 1200, 0.7);
    let p = WelchParams {
        window: Window::Hamming,
        nperseg: Some(300),
        noverlap: Some(0),
        ..Default::default()
    };
    let w = welch(&x, 4.0, &p).unwrap();
    assert_eq!(w.n_segments, 4);
    let pp = PeriodogramParams {
        window: Window::Hamming,
        ..Default::default()
    };
    let mut mean = vec![0.0; w.psd.len()];
    for seg in x.chunks(300) {
        let s = periodogram(seg, 4.0, &pp).unwrap();
        for (m, v) in mean.iter_mut().zip(&s.psd) {
            *m += v / 4.0;
        }
    }
    for (a, b) in w.psd.iter().zip(&mean) {
        assert!((a - b).abs() <= 1e-12 * b.abs());
    }
}

#[test]
fn spectrum_over_density_is_equivalent_noise_bandwidth() {
    // spectrum = density * fs * sum(w^2) / (sum w)^2 = density * ENBW_hz; Hann ENBW = 1.5 bins.
    let x = noise(51, 4096, 1.0);
    let fs_hz = 1000.0;
    let d = welch(&x, fs_hz, &WelchParams::default()).unwrap();
    let s = welch(
        &x,
        fs_hz,
        &WelchParams {
            scaling: Scaling::Spectrum,
            ..Default::default()
        },
    )
    .unwrap();
    let enbw_hz = 1.5 * fs_hz / 256.0;
    for (a, b) in d.psd.iter().zip(&s.psd) {
        assert!((b - a * enbw_hz).abs() <= 1e-12 * b.abs());
    }
}

#[test]
fn plan_reuse_matches_fresh_computation() {
    let chans: Vec<Vec<f64>> = (0..4)
        .map(|s| noise(60 + s, 5000, 1.0 + s as f64))
        .collect();
    for avg in [Average::Mean, Average::Median] {
        let p = WelchParams {
            nperseg: Some(512),
            nfft: Some(1000),
            average: avg,
            ..Default::default()
        };
        let mut plan = WelchPlan::new(5000, 200.0, &p).unwrap();
        assert_eq!(plan.n_segments(), (5000 - 512) / 256 + 1);
        for (i, ch) in chans.iter().enumerate() {
            let a = plan.welch(ch).unwrap();
            let b = welch(ch, 200.0, &p).unwrap();
            assert_eq!(a, b, "channel {i}");
            // Interleave a cross-spectrum (shares scratch buffers) and check again.
            let c = plan.csd(ch, &chans[0]).unwrap();
            assert_eq!(c, csd(ch, &chans[0], 200.0, &p).unwrap());
            let coh = plan.coherence(ch, &chans[0]).unwrap();
            assert_eq!(
                coh.coherence,
                coherence(ch, &chans[0], 200.0, &p).unwrap().coherence
            );
            assert_eq!(plan.welch(ch).unwrap(), b);
        }
        assert!(plan.welch(&chans[0][..4000]).is_err());
    }
}

#[test]
fn median_is_robust_to_a_burst() {
    // One segment with a huge burst barely moves the median, but moves the mean a lot.
    let mut x = noise(71, 256 * 21, 1.0);
    for v in &mut x[256 * 10..256 * 10 + 50] {
        *v *= 100.0;
    }
    let base = WelchParams {
        noverlap: Some(0),
        ..Default::default()
    };
    let mean = welch(&x, 100.0, &base).unwrap();
    let med = welch(
        &x,
        100.0,
        &WelchParams {
            average: Average::Median,
            ..base
        },
    )
    .unwrap();
    let level = 2.0 / 100.0;
    let m_med = med.psd[1..128].iter().sum::<f64>() / 127.0;
    let m_mean = mean.psd[1..128].iter().sum::<f64>() / 127.0;
    assert!((m_med / level - 1.0).abs() < 0.15, "median level {m_med}");
    assert!(m_mean > 5.0 * level, "mean level {m_mean}");
}

#[test]
fn coherence_ignores_median_like_scipy() {
    let x = noise(81, 3000, 1.0);
    let y: Vec<f64> = x
        .iter()
        .zip(noise(82, 3000, 1.0))
        .map(|(a, b)| a + b)
        .collect();
    let mean = coherence(&x, &y, 10.0, &WelchParams::default()).unwrap();
    let med = coherence(
        &x,
        &y,
        10.0,
        &WelchParams {
            average: Average::Median,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(mean.coherence, med.coherence);
    assert!(mean.notes.is_empty());
    assert!(med.notes.iter().any(|n| n.contains("median")));
    // Half the power of y is coherent with x: coherence about 0.5 on average.
    let avg = mean.coherence.iter().sum::<f64>() / mean.coherence.len() as f64;
    assert!((avg - 0.5).abs() < 0.1, "{avg}");
}

/// Parseval through `rms`: the boxcar periodogram (density, mean removed) of any signal
/// integrates to its variance, over many seeds, odd and even lengths and rates.
#[test]
fn rms_of_the_periodogram_is_the_standard_deviation() {
    use rand::{Rng, SeedableRng};
    for seed in 0..20u64 {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let n = 64 + (seed as usize * 37) % 500;
        let fs = 10.0 + seed as f64 * 7.5;
        let x: Vec<f64> = (0..n).map(|_| rng.gen_range(-3.0..3.0) + 1.5).collect();
        let mean = x.iter().sum::<f64>() / n as f64;
        let std = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
        let p = vibmode_spectra::periodogram(
            &x,
            fs,
            &vibmode_spectra::PeriodogramParams {
                window: vibmode_spectra::Window::Boxcar,
                ..Default::default()
            },
        )
        .unwrap();
        let r = vibmode_spectra::rms(&p.freq_hz, &p.psd, vibmode_spectra::Scaling::Density);
        assert!(
            (r / std - 1.0).abs() < 1e-12,
            "seed {seed}, n {n}: {r} vs {std}"
        );
        // Every bin (the last one, fs/2, may round a hair above fs / 2).
        let b = vibmode_spectra::band_rms(&p.freq_hz, &p.psd, 0.0, fs);
        assert!(
            (b / std - 1.0).abs() < 1e-12,
            "seed {seed}: band {b} vs {std}"
        );
    }
}
