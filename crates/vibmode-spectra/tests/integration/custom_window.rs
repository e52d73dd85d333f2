//! Custom window coefficients (`WindowSpec::Custom`, scipy's window arrays): equal to the named
//! windows bit for bit, Parseval's identity for arbitrary tapers, scipy's length rules, and
//! one-line errors.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use vibmode_spectra::{
    coherence, csd, periodogram, periodogram_with_window, welch, window_values, Average, Detrend,
    PeriodogramParams, Scaling, SpectraError, WelchParams, WelchPlan, Window, WindowSpec,
};

fn noise(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| rng.gen::<f64>() * 2.0 - 1.0 + 0.3).collect()
}

fn custom(w: Vec<f64>) -> WindowSpec {
    WindowSpec::custom(w).unwrap()
}

#[test]
fn boxcar_coefficients_by_hand() {
    // x = [1, 2, 3, 4], no detrend, boxcar [1, 1, 1, 1] given as coefficients, fs = 1:
    // X = [10, -2+2i, -2], |X|^2 = [100, 8, 4]; density scale 1 / (fs * sum w^2) = 1/4,
    // one-sided doubling of the middle bin: [25, 4, 1].
    let p = PeriodogramParams {
        detrend: Detrend::None,
        ..PeriodogramParams::default()
    };
    let x = [1.0, 2.0, 3.0, 4.0];
    let s = periodogram_with_window(&x, 1.0, &p, &custom(vec![1.0; 4])).unwrap();
    assert_eq!(s.psd, vec![25.0, 4.0, 1.0]);
    // Any multiple of the window gives the same spectrum (scaled by sum w^2 or (sum w)^2).
    let s3 = periodogram_with_window(&x, 1.0, &p, &custom(vec![3.0; 4])).unwrap();
    assert_eq!(s3.psd, s.psd);
}

#[test]
fn custom_coefficients_equal_the_named_windows_bit_for_bit() {
    let named = [
        Window::Boxcar,
        Window::Hann,
        Window::Hamming,
        Window::Blackman,
        Window::Flattop,
        Window::Tukey { alpha: 0.25 },
    ];
    for (seed, w) in named.into_iter().enumerate() {
        let x = noise(3001, seed as u64);
        let y = noise(3001, 100 + seed as u64);
        for (nperseg, scaling, average) in [
            (256, Scaling::Density, Average::Mean),
            (255, Scaling::Spectrum, Average::Median),
        ] {
            let p = WelchParams {
                window: w,
                nperseg: Some(nperseg),
                scaling,
                average,
                ..WelchParams::default()
            };
            let c = custom(window_values(&w, nperseg));
            let by_name = welch(&x, 10.0, &p).unwrap();
            let mut plan = WelchPlan::with_window(x.len(), 10.0, &p, &c).unwrap();
            assert_eq!(plan.welch(&x).unwrap(), by_name, "{w} {nperseg}");
            assert_eq!(plan.csd(&x, &y).unwrap(), csd(&x, &y, 10.0, &p).unwrap());
            assert_eq!(
                plan.coherence(&x, &y).unwrap(),
                coherence(&x, &y, 10.0, &p).unwrap()
            );
            // nperseg may be given when it is the window's length.
            let q = WelchParams { nperseg: None, ..p };
            let mut unset = WelchPlan::with_window(x.len(), 10.0, &q, &c).unwrap();
            assert_eq!(unset.nperseg(), nperseg);
            assert_eq!(unset.welch(&x).unwrap(), by_name);
        }
        let pp = PeriodogramParams {
            window: w,
            ..PeriodogramParams::default()
        };
        assert_eq!(
            periodogram_with_window(&x, 10.0, &pp, &custom(window_values(&w, x.len()))).unwrap(),
            periodogram(&x, 10.0, &pp).unwrap()
        );
        // nfft smaller than the record: the window covers the first nfft samples.
        let short = PeriodogramParams {
            nfft: Some(1000),
            ..pp
        };
        assert_eq!(
            periodogram_with_window(&x, 10.0, &short, &custom(window_values(&w, 1000))).unwrap(),
            periodogram(&x, 10.0, &short).unwrap()
        );
    }
}

#[test]
fn parseval_for_arbitrary_tapers() {
    // One segment, no detrend, nfft = n: the one-sided density integrates to the
    // window-weighted mean square sum(w^2 x^2) / sum(w^2), for any taper (odd and even n).
    for seed in 0..8u64 {
        let n = 500 + seed as usize * 37;
        let x = noise(n, seed);
        let mut rng = ChaCha8Rng::seed_from_u64(1000 + seed);
        let w: Vec<f64> = (0..n).map(|_| rng.gen::<f64>() * 2.0 - 0.5).collect();
        let p = PeriodogramParams {
            detrend: Detrend::None,
            ..PeriodogramParams::default()
        };
        let fs = 40.0;
        let s = periodogram_with_window(&x, fs, &p, &custom(w.clone())).unwrap();
        let df = s.freq_hz[1];
        let total: f64 = s.psd.iter().sum::<f64>() * df;
        let w2: f64 = w.iter().map(|v| v * v).sum();
        let expect: f64 = w.iter().zip(&x).map(|(a, b)| a * a * b * b).sum::<f64>() / w2;
        assert!(
            (total - expect).abs() < 1e-12 * expect,
            "seed {seed}: {total} vs {expect}"
        );
    }
}

#[test]
fn length_rules_follow_scipy() {
    let x = noise(1000, 1);
    let c = custom(window_values(&Window::Hann, 128));
    let p = WelchParams {
        nperseg: Some(100),
        ..WelchParams::default()
    };
    let e = WelchPlan::with_window(x.len(), 1.0, &p, &c).unwrap_err();
    assert_eq!(
        e,
        SpectraError::WindowLengthMismatch {
            window_len: 128,
            nperseg: 100
        }
    );
    let m = e.to_string();
    assert!(
        m.contains("100") && m.contains("128") && !m.contains('\n'),
        "{m}"
    );
    // Longer than the record: an error, never clamped.
    let e = WelchPlan::with_window(100, 1.0, &WelchParams::default(), &c).unwrap_err();
    assert!(matches!(
        e,
        SpectraError::WindowLongerThanRecord {
            window_len: 128,
            n_samples: 100
        }
    ));
    // Periodogram: one coefficient per sample used.
    let e = periodogram_with_window(&x, 1.0, &PeriodogramParams::default(), &c).unwrap_err();
    assert!(matches!(
        e,
        SpectraError::PeriodogramWindowLength {
            window_len: 128,
            n_samples: 1000
        }
    ));
    assert!(e.to_string().contains("1000"));
    // noverlap defaults to half the window's length.
    let plan = WelchPlan::with_window(x.len(), 1.0, &WelchParams::default(), &c).unwrap();
    assert_eq!((plan.nperseg(), plan.noverlap()), (128, 64));
}

#[test]
fn bad_coefficients_are_one_line_errors() {
    let cases: [(Vec<f64>, &str); 4] = [
        (vec![], "0 coefficients"),
        (vec![1.0, f64::NAN, 1.0], "window[1] = NaN"),
        (vec![1.0, 1.0, f64::INFINITY], "window[2]"),
        (vec![0.0; 16], "all 0"),
    ];
    for (w, needle) in cases {
        let e = WindowSpec::custom(w.clone()).unwrap_err();
        let m = e.to_string();
        assert!(m.contains(needle) && !m.contains('\n'), "{m}");
        // The spectral functions check an unchecked Custom too.
        let raw = WindowSpec::Custom(w.into());
        let e2 = WelchPlan::with_window(100, 1.0, &WelchParams::default(), &raw).unwrap_err();
        assert_eq!(e2.to_string(), m); // (NaN != NaN: compare the messages)
    }
    // Coefficients summing to 0 cannot give a power spectrum (scaling by 1 / sum(w)^2).
    let p = WelchParams {
        scaling: Scaling::Spectrum,
        ..WelchParams::default()
    };
    let c = custom(vec![1.0, -1.0, 1.0, -1.0]);
    let e = WelchPlan::with_window(100, 1.0, &p, &c).unwrap_err();
    assert!(e.to_string().contains("sum(w)"), "{e}");
    assert!(WelchPlan::with_window(100, 1.0, &WelchParams::default(), &c).is_ok());
}
