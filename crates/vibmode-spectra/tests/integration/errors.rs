//! Bad input gives one-line errors naming the offending value and the fix.

use vibmode_spectra::{
    coherence, csd, periodogram, welch, Average, Detrend, PeriodogramParams, Scaling, ShortRecord,
    SpectraError, WelchParams, WelchPlan, Window,
};

fn one_line(e: &SpectraError) -> String {
    let m = e.to_string();
    assert!(!m.contains('\n'), "multi-line message: {m}");
    assert!(!m.is_empty());
    m
}

fn sig(n: usize) -> Vec<f64> {
    (0..n).map(|i| (i as f64 * 0.1).sin()).collect()
}

#[test]
fn bad_sampling_rate() {
    let x = sig(100);
    for fs in [0.0, -5.0, f64::NAN, f64::INFINITY] {
        let e = welch(&x, fs, &WelchParams::default()).unwrap_err();
        assert!(matches!(e, SpectraError::InvalidSampleRate { .. }), "{e:?}");
        assert!(one_line(&e).contains("fs_hz"));
        assert!(periodogram(&x, fs, &PeriodogramParams::default()).is_err());
        assert!(csd(&x, &x, fs, &WelchParams::default()).is_err());
        assert!(coherence(&x, &x, fs, &WelchParams::default()).is_err());
        assert!(WelchPlan::new(100, fs, &WelchParams::default()).is_err());
    }
    let m = one_line(&welch(&x, -5.0, &WelchParams::default()).unwrap_err());
    assert!(m.contains("-5"), "{m}");
}

#[test]
fn empty_input() {
    let e = welch(&[], 10.0, &WelchParams::default()).unwrap_err();
    assert_eq!(e, SpectraError::EmptyInput { name: "x" });
    assert!(one_line(&e).contains("empty"));
    assert!(periodogram(&[], 10.0, &PeriodogramParams::default()).is_err());
    let e = csd(&sig(10), &[], 10.0, &WelchParams::default()).unwrap_err();
    assert_eq!(e, SpectraError::EmptyInput { name: "y" });
    assert!(WelchPlan::new(0, 10.0, &WelchParams::default()).is_err());
}

#[test]
fn non_finite_sample_names_index() {
    let mut x = sig(300);
    x[123] = f64::NAN;
    let e = welch(&x, 10.0, &WelchParams::default()).unwrap_err();
    assert!(
        matches!(e, SpectraError::NonFiniteSample { index: 123, .. }),
        "{e:?}"
    );
    let m = one_line(&e);
    assert!(m.contains("x[123]") && m.contains("NaN"), "{m}");
    x[123] = 1.0;
    x[7] = f64::NEG_INFINITY;
    let e = periodogram(&x, 10.0, &PeriodogramParams::default()).unwrap_err();
    assert!(one_line(&e).contains("x[7] = -inf"), "{e}");
    let mut y = sig(300);
    y[299] = f64::INFINITY;
    let e = coherence(&sig(300), &y, 10.0, &WelchParams::default()).unwrap_err();
    assert!(one_line(&e).contains("y[299]"), "{e}");
    let mut plan = WelchPlan::new(300, 10.0, &WelchParams::default()).unwrap();
    assert!(plan.welch(&x).is_err());
}

#[test]
fn noverlap_not_smaller_than_nperseg() {
    let x = sig(1000);
    let p = WelchParams {
        nperseg: Some(256),
        noverlap: Some(256),
        ..Default::default()
    };
    let e = welch(&x, 10.0, &p).unwrap_err();
    assert_eq!(
        one_line(&e),
        "noverlap (256) must be smaller than nperseg (256); use noverlap = 128"
    );
    let p = WelchParams {
        noverlap: Some(300),
        ..p
    };
    assert!(csd(&x, &x, 10.0, &p).is_err());
    // After clamping nperseg to a 100-sample record, noverlap 128 is too large (as scipy).
    let p = WelchParams {
        nperseg: None,
        noverlap: Some(128),
        ..Default::default()
    };
    let e = welch(&sig(100), 10.0, &p).unwrap_err();
    assert!(one_line(&e).contains("nperseg (100)"), "{e}");
}

#[test]
fn nfft_smaller_than_nperseg_or_zero() {
    let x = sig(1000);
    let p = WelchParams {
        nperseg: Some(256),
        nfft: Some(128),
        ..Default::default()
    };
    let e = welch(&x, 10.0, &p).unwrap_err();
    assert_eq!(
        e,
        SpectraError::NfftTooSmall {
            nfft: 128,
            nperseg: 256
        }
    );
    assert!(one_line(&e).contains("nfft = 256"));
    let p = WelchParams {
        nfft: Some(0),
        ..Default::default()
    };
    assert!(welch(&x, 10.0, &p).is_err());
    let pp = PeriodogramParams {
        nfft: Some(0),
        ..Default::default()
    };
    assert_eq!(
        periodogram(&x, 10.0, &pp).unwrap_err(),
        SpectraError::ZeroNfft
    );
}

#[test]
fn zero_nperseg() {
    let p = WelchParams {
        nperseg: Some(0),
        ..Default::default()
    };
    let e = welch(&sig(100), 10.0, &p).unwrap_err();
    assert_eq!(e, SpectraError::ZeroNperseg);
    assert!(one_line(&e).contains("nperseg"));
}

#[test]
fn x_and_y_lengths_differ() {
    let e = csd(&sig(100), &sig(120), 10.0, &WelchParams::default()).unwrap_err();
    assert_eq!(
        e,
        SpectraError::LengthMismatch {
            len_x: 100,
            len_y: 120
        }
    );
    let m = one_line(&e);
    assert!(m.contains("100") && m.contains("120"), "{m}");
    assert!(coherence(&sig(100), &sig(99), 10.0, &WelchParams::default()).is_err());
    let mut plan = WelchPlan::new(100, 10.0, &WelchParams::default()).unwrap();
    assert!(plan.csd(&sig(100), &sig(120)).is_err());
}

#[test]
fn short_record_error_and_clamp() {
    let p = WelchParams {
        nperseg: Some(512),
        short_record: ShortRecord::Error,
        ..Default::default()
    };
    let e = welch(&sig(300), 10.0, &p).unwrap_err();
    assert_eq!(
        one_line(&e),
        "record has 300 samples, shorter than one segment (nperseg = 512); use nperseg <= 300"
    );
    let s = welch(
        &sig(300),
        10.0,
        &WelchParams {
            short_record: ShortRecord::Clamp,
            ..p
        },
    )
    .unwrap();
    assert_eq!((s.nperseg, s.noverlap, s.n_segments), (300, 150, 1));
    assert_eq!(s.notes.len(), 1);
    // A record exactly nperseg long is fine with Error.
    assert!(welch(&sig(512), 10.0, &p).is_ok());
}

#[test]
fn tukey_alpha_out_of_range() {
    for a in [-0.1, 1.5, f64::NAN] {
        let p = WelchParams {
            window: Window::Tukey { alpha: a },
            ..Default::default()
        };
        let e = welch(&sig(300), 10.0, &p).unwrap_err();
        assert!(matches!(e, SpectraError::InvalidTukeyAlpha { .. }), "{e:?}");
        assert!(one_line(&e).contains("[0, 1]"));
        let pp = PeriodogramParams {
            window: Window::Tukey { alpha: a },
            ..Default::default()
        };
        assert!(periodogram(&sig(300), 10.0, &pp).is_err());
    }
    let e = "tukey:1.5".parse::<Window>().unwrap_err();
    assert!(one_line(&e).contains("1.5"));
}

#[test]
fn unknown_names_list_valid_values() {
    let e = "hanning-ish".parse::<Window>().unwrap_err();
    let m = one_line(&e);
    assert!(m.contains("'hanning-ish'"), "{m}");
    for w in [
        "hann",
        "hamming",
        "blackman",
        "boxcar",
        "flattop",
        "tukey:ALPHA",
        "kaiser:BETA",
    ] {
        assert!(m.contains(w), "{m} lacks {w}");
    }
    assert!("tukey:abc".parse::<Window>().is_err());
    assert!(one_line(&"cubic".parse::<Detrend>().unwrap_err()).contains("none, constant, linear"));
    assert!(one_line(&"psd".parse::<Scaling>().unwrap_err()).contains("density, spectrum"));
    assert!(one_line(&"mode".parse::<Average>().unwrap_err()).contains("mean, median"));
    assert!(one_line(&"drop".parse::<ShortRecord>().unwrap_err()).contains("clamp, error"));
}
