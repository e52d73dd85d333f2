//! Small cases computed by hand (derivations in the comments).

use vibmode_spectra::{
    periodogram, welch, window_values, Average, Detrend, PeriodogramParams, Scaling, WelchParams,
    Window,
};

fn close(got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "{got:?} vs {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() <= tol, "{got:?} vs {want:?}");
    }
}

fn raw(scaling: Scaling) -> PeriodogramParams {
    PeriodogramParams {
        window: Window::Boxcar,
        nfft: None,
        detrend: Detrend::None,
        scaling,
    }
}

#[test]
fn periodogram_of_1_0_m1_0() {
    // X_k = sum x_n e^{-2 pi i k n / 4}: X = [0, 2, 0, 2]. Density two-sided |X|^2 / (fs N)
    // = [0, 1, 0, 1]; one-sided (even nfft: Nyquist not doubled) = [0, 2, 0].
    let x = [1.0, 0.0, -1.0, 0.0];
    let s = periodogram(&x, 1.0, &raw(Scaling::Density)).unwrap();
    close(&s.freq_hz, &[0.0, 0.25, 0.5], 1e-15);
    close(&s.psd, &[0.0, 2.0, 0.0], 1e-14);
    assert_eq!((s.nperseg, s.noverlap, s.nfft, s.n_segments), (4, 0, 4, 1));
    // Spectrum scaling 1/(sum w)^2 = 1/16: 2 * 4/16 = 0.5 = A^2/2 for the unit cosine.
    let s = periodogram(&x, 1.0, &raw(Scaling::Spectrum)).unwrap();
    close(&s.psd, &[0.0, 0.5, 0.0], 1e-14);
    // fs = 8 Hz: frequencies scale, density divides by fs.
    let s = periodogram(&x, 8.0, &raw(Scaling::Density)).unwrap();
    close(&s.freq_hz, &[0.0, 2.0, 4.0], 1e-14);
    close(&s.psd, &[0.0, 0.25, 0.0], 1e-15);
}

#[test]
fn nyquist_bin_is_not_doubled() {
    // x = (-1)^n: X_2 = 4, all else 0. Density at Nyquist = 16 / (fs N) = 16 / 8 = 2.
    let x = [1.0, -1.0, 1.0, -1.0];
    let s = periodogram(&x, 2.0, &raw(Scaling::Density)).unwrap();
    close(&s.freq_hz, &[0.0, 0.5, 1.0], 1e-15);
    close(&s.psd, &[0.0, 0.0, 2.0], 1e-14);
}

#[test]
fn odd_length_doubles_last_bin_and_detrends() {
    // [1,2,3] - mean = [-1,0,1]; X_1 = -1 + e^{-4 pi i/3}, |X_1|^2 = 1.5^2 + 3/4 = 3.
    // Density 3/3 = 1, doubled (odd nfft: no Nyquist bin) = 2.
    let x = [1.0, 2.0, 3.0];
    let mut p = raw(Scaling::Density);
    p.detrend = Detrend::Constant;
    let s = periodogram(&x, 1.0, &p).unwrap();
    close(&s.freq_hz, &[0.0, 1.0 / 3.0], 1e-15);
    close(&s.psd, &[0.0, 2.0], 1e-14);
    // A straight line is removed entirely by linear detrending.
    p.detrend = Detrend::Linear;
    let s = periodogram(&x, 1.0, &p).unwrap();
    close(&s.psd, &[0.0, 0.0], 1e-28);
    // No detrend: DC = 6^2 / 3 = 12, X_1 = 1 + 2 e^{-2pi i/3} + 3 e^{-4 pi i/3} = -1.5 + i 0.866..,
    // |X_1|^2 = 3 again (the mean only affects DC).
    p.detrend = Detrend::None;
    let s = periodogram(&x, 1.0, &p).unwrap();
    close(&s.psd, &[12.0, 2.0], 1e-13);
}

#[test]
fn nfft_zero_pads_and_truncates() {
    // x = [1] zero-padded to 4: X = [1,1,1,1]; density 1/(fs*1) = 1; one-sided [1, 2, 1].
    let mut p = raw(Scaling::Density);
    p.nfft = Some(4);
    let s = periodogram(&[1.0], 1.0, &p).unwrap();
    close(&s.psd, &[1.0, 2.0, 1.0], 1e-15);
    assert_eq!((s.nperseg, s.nfft), (1, 4));
    // nfft = 2 < N = 4: only [1, 0] is used -> X = [1, 1], one-sided [1/2, 1/2].
    p.nfft = Some(2);
    let s = periodogram(&[1.0, 0.0, 5.0, 7.0], 1.0, &p).unwrap();
    close(&s.psd, &[0.5, 0.5], 1e-15);
    assert_eq!(s.nperseg, 2);
    assert!(s.notes.iter().any(|n| n.contains("first 2 samples")));
}

#[test]
fn welch_of_repeated_cosine_mean_and_median() {
    // Segments of 4 with overlap 2 of [1,0,-1,0,1,0,-1,0]: [1,0,-1,0], [-1,0,1,0], [1,0,-1,0];
    // each has the periodogram [0, 2, 0] so the mean is [0, 2, 0].
    let x = [1.0, 0.0, -1.0, 0.0, 1.0, 0.0, -1.0, 0.0];
    let mut p = WelchParams {
        window: Window::Boxcar,
        nperseg: Some(4),
        noverlap: Some(2),
        detrend: Detrend::None,
        ..Default::default()
    };
    let s = welch(&x, 1.0, &p).unwrap();
    assert_eq!(s.n_segments, 3);
    close(&s.psd, &[0.0, 2.0, 0.0], 1e-14);
    // Median of 3 equal values / bias, bias(3) = 1 + (1/3 - 1/2) = 5/6 -> 2.4.
    p.average = Average::Median;
    let s = welch(&x, 1.0, &p).unwrap();
    close(&s.psd, &[0.0, 2.4, 0.0], 1e-14);
    // 4 segments with overlap 3 of 7 samples: (7 - 4) / 1 + 1 = 4 segments; bias(4) = 5/6 too
    // ((4-1)/2 = 1 term), and the median of 4 values is the mean of the middle two.
    p.noverlap = Some(3);
    let x = [1.0, 0.0, -1.0, 0.0, 1.0, 0.0, -1.0];
    let s = welch(&x, 1.0, &p).unwrap();
    assert_eq!(s.n_segments, 4);
    // Segments [1,0,-1,0], [0,-1,0,1], [-1,0,1,0], [0,1,0,-1]: each |X_1| = 2, X_0 = X_2 = 0.
    close(&s.psd, &[0.0, 2.4, 0.0], 1e-14);
}

#[test]
fn hann_window_by_hand() {
    // Periodic Hann of 4: 0.5 - 0.5 cos(2 pi k / 4) = [0, 0.5, 1, 0.5].
    close(
        &window_values(&Window::Hann, 4),
        &[0.0, 0.5, 1.0, 0.5],
        1e-15,
    );
    // Periodic Hamming of 2: 0.54 - 0.46 cos(pi k) = [0.08, 1].
    close(&window_values(&Window::Hamming, 2), &[0.08, 1.0], 1e-15);
    close(&window_values(&Window::Boxcar, 3), &[1.0; 3], 0.0);
    assert!(window_values(&Window::Hann, 0).is_empty());
    close(&window_values(&Window::Flattop, 1), &[1.0], 0.0);
    // Tukey alpha 0 is boxcar, alpha 1 is Hann.
    close(
        &window_values(&Window::Tukey { alpha: 0.0 }, 5),
        &[1.0; 5],
        0.0,
    );
    close(
        &window_values(&Window::Tukey { alpha: 1.0 }, 4),
        &[0.0, 0.5, 1.0, 0.5],
        1e-15,
    );
}

#[test]
fn kaiser_window() {
    // beta = 0: I0(0) / I0(0) = 1 everywhere (boxcar); the window depends on |beta| only.
    close(
        &window_values(&Window::Kaiser { beta: 0.0 }, 5),
        &[1.0; 5],
        0.0,
    );
    assert_eq!(
        window_values(&Window::Kaiser { beta: -3.0 }, 6),
        window_values(&Window::Kaiser { beta: 3.0 }, 6)
    );
    // scipy.signal.get_window(('kaiser', 8.0), 8) and (('kaiser', 14.0), 5), scipy 1.17.
    close(
        &window_values(&Window::Kaiser { beta: 8.0 }, 8),
        &[
            0.00233883051273333,
            0.08273981505097754,
            0.36897272261583314,
            0.788752446605349,
            1.0,
            0.788752446605349,
            0.36897272261583314,
            0.08273981505097754,
        ],
        1e-14,
    );
    close(
        &window_values(&Window::Kaiser { beta: 14.0 }, 5),
        &[
            7.726866835270368e-06,
            6.815374319396057e-02,
            7.615093990873935e-01,
            7.615093990873935e-01,
            6.815374319396057e-02,
        ],
        1e-14,
    );
    // |beta| beyond 700 (I0 overflows) and NaN are refused.
    for beta in [701.0, f64::NAN, f64::INFINITY] {
        let e = Window::Kaiser { beta }.validate().unwrap_err();
        assert!(e.to_string().contains("kaiser beta"), "{e}");
    }
    assert!("kaiser:800".parse::<Window>().is_err());
    assert!("kaiser".parse::<Window>().is_err()); // scipy: kaiser needs its beta
    let w = window_values(&Window::Kaiser { beta: 700.0 }, 64);
    assert!(w.iter().all(|v| v.is_finite()));
}

#[test]
fn window_names_round_trip() {
    for w in [
        Window::Hann,
        Window::Hamming,
        Window::Blackman,
        Window::Boxcar,
        Window::Flattop,
        Window::Tukey { alpha: 0.25 },
        Window::Kaiser { beta: 8.6 },
    ] {
        assert_eq!(w.to_string().parse::<Window>().unwrap(), w);
    }
    assert_eq!("RECT".parse::<Window>().unwrap(), Window::Boxcar);
    assert_eq!(
        "tukey".parse::<Window>().unwrap(),
        Window::Tukey { alpha: 0.5 }
    );
    assert_eq!("linear".parse::<Detrend>().unwrap(), Detrend::Linear);
    assert_eq!("none".parse::<Detrend>().unwrap(), Detrend::None);
    assert_eq!("spectrum".parse::<Scaling>().unwrap(), Scaling::Spectrum);
    assert_eq!("median".parse::<Average>().unwrap(), Average::Median);
    assert_eq!(Average::Median.to_string(), "median");
    assert_eq!(Detrend::Constant.to_string(), "constant");
    assert_eq!(Scaling::Density.to_string(), "density");
}

#[test]
fn defaults_are_scipys() {
    let p = WelchParams::default();
    assert_eq!(p.window, Window::Hann);
    assert_eq!((p.nperseg, p.noverlap, p.nfft), (None, None, None));
    assert_eq!(p.detrend, Detrend::Constant);
    assert_eq!(p.scaling, Scaling::Density);
    assert_eq!(p.average, Average::Mean);
    assert_eq!(p.short_record, vibmode_spectra::ShortRecord::Clamp);
    let q = PeriodogramParams::default();
    assert_eq!(q.window, Window::Boxcar);
    assert_eq!(q.nfft, None);
    assert_eq!(q.detrend, Detrend::Constant);
    assert_eq!(q.scaling, Scaling::Density);
    // Resolved Welch sizes for 1000 samples: nperseg 256, noverlap 128, (1000-256)/128+1 = 6.
    let s = welch(&vec![0.5; 1000], 10.0, &p).unwrap();
    assert_eq!(
        (s.nperseg, s.noverlap, s.nfft, s.n_segments),
        (256, 128, 256, 6)
    );
    assert!(s.notes.is_empty());
    // A constant signal has nothing left after the constant detrend.
    assert!(s.psd.iter().all(|v| v.abs() < 1e-28));
}

#[test]
fn results_serialize_to_json_and_back() {
    let x = [1.0, 0.0, -1.0, 0.0, 2.0, 0.5];
    let s = periodogram(&x, 2.0, &PeriodogramParams::default()).unwrap();
    let j = serde_json::to_string(&s).unwrap();
    assert!(j.contains("\"freq_hz\"") && j.contains("\"psd\""));
    // serde_json (without its float_roundtrip feature) may be off by one ulp on parsing.
    let back: vibmode_spectra::Spectrum = serde_json::from_str(&j).unwrap();
    close(&back.psd, &s.psd, 1e-15);
    close(&back.freq_hz, &s.freq_hz, 1e-15);
    assert_eq!((back.nperseg, back.nfft, back.n_segments), (6, 6, 1));
    let p = WelchParams {
        nperseg: Some(4),
        ..Default::default()
    };
    let c = vibmode_spectra::csd(
        &x,
        &x[..].iter().rev().copied().collect::<Vec<_>>(),
        2.0,
        &p,
    )
    .unwrap();
    let back: vibmode_spectra::CrossSpectrum =
        serde_json::from_str(&serde_json::to_string(&c).unwrap()).unwrap();
    assert_eq!(back.csd.len(), c.csd.len());
    for (a, b) in back.csd.iter().zip(&c.csd) {
        assert!((a - b).norm() <= 1e-15 * b.norm().max(1e-300));
    }
    let pj = serde_json::to_string(&WelchParams::default()).unwrap();
    assert!(
        pj.contains("\"hann\"") && pj.contains("\"constant\""),
        "{pj}"
    );
}
