//! The single-record commands as libraries (`vibmode_run::{psd, fit, sweep, ssi}`): what each
//! passes through and reports, on signals whose answer is known by hand or by construction.
//! The numerics themselves are tested against scipy, statsmodels and pyOMA2 in their crates.

use std::f64::consts::PI;

use vibmode_core::{BandLimit, SsiParams, SweepModel};
use vibmode_ident::{ArMethod, ArmaParams};
use vibmode_run::fit::FitModel;
use vibmode_run::psd::PsdMethod;
use vibmode_run::RunError;
use vibmode_signal::{Channel, Recording};
use vibmode_spectra::{PeriodogramParams, WelchParams};

/// Seeded standard normal numbers (xorshift64* and Box-Muller; no dependency).
struct Gauss(u64);
impl Gauss {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (2.0 * PI * v).cos()
    }
}

/// An AR(2) signal with its pole pair at `f_hz` and damping `zeta` (sampled at `fs_hz`).
fn ar2(n: usize, fs_hz: f64, f_hz: f64, zeta: f64, seed: u64) -> Vec<f64> {
    let w = 2.0 * PI * f_hz;
    let r = (-zeta * w / fs_hz).exp();
    let theta = w * (1.0 - zeta * zeta).sqrt() / fs_hz;
    let (a1, a2) = (2.0 * r * theta.cos(), -r * r);
    let mut g = Gauss(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let mut y = vec![0.0; n + 500];
    for t in 2..y.len() {
        y[t] = a1 * y[t - 1] + a2 * y[t - 2] + g.normal();
    }
    y.split_off(500)
}

/// psd: a 5 Hz sine of amplitude 1 at 100 Hz, 1024 samples, nperseg 256: the peak is the bin
/// nearest 5 Hz, the density integrates to the sine's variance 1/2 (Parseval), the Welch
/// segments are (1024 - 256) / 128 + 1 = 7, the unit is the channel's squared per hertz, and
/// `Both` adds the periodogram of the whole record (513 bins).
#[test]
fn psd_of_a_sine_by_hand() {
    let fs = 100.0;
    let y: Vec<f64> = (0..1024)
        .map(|t| (2.0 * PI * 5.0 * t as f64 / fs).sin())
        .collect();
    let rec = Recording::new(fs, vec![Channel::new("a", "m/s^2", y)]).unwrap();
    let welch = WelchParams {
        nperseg: Some(256),
        ..WelchParams::default()
    };
    let out = vibmode_run::psd::psd(
        &rec,
        "sine.csv",
        PsdMethod::Both,
        &welch,
        &PeriodogramParams::default(),
        None,
    )
    .unwrap();
    let ch = &out.channels[0];
    let df = ch.frequency_hz[1] - ch.frequency_hz[0];
    assert!((df - fs / 256.0).abs() < 1e-12);
    let peak = (0..ch.psd.len())
        .max_by(|&i, &j| ch.psd[i].total_cmp(&ch.psd[j]))
        .unwrap();
    assert!((ch.frequency_hz[peak] - 5.0).abs() <= df / 2.0);
    let power: f64 = ch.psd.iter().sum::<f64>() * df;
    assert!((power - 0.5).abs() < 0.5 * 0.03, "{power}");
    assert_eq!(out.parameters.nperseg, Some(256));
    assert_eq!(out.parameters.n_segments, Some(7));
    assert_eq!(ch.psd_unit, "(m/s^2)^2/Hz");
    assert_eq!(ch.periodogram.as_ref().map(|p| p.psd.len()), Some(513));
    assert_eq!(out.source, "sine.csv");
}

/// fit and sweep: AR(2) signals with the pole pair at 4 Hz, damping 0.05 (fs 50 Hz, 8192
/// samples), 10 seeds: Burg's AR(2) and the ARMA(2,2) fit give the mode within 2 % in
/// frequency and 0.02 in damping on every seed; the sweep over orders 2, 4, 6 has a mode within
/// 2 % of 4 Hz at each order.
#[test]
fn fit_and_sweep_recover_a_known_pole_over_seeds() {
    let (fs, f0, z0) = (50.0, 4.0, 0.05);
    let band = BandLimit::full(fs);
    let params = ArmaParams::default();
    for seed in 0..10 {
        let rec = Recording::new(
            fs,
            vec![Channel::new("y", "m/s^2", ar2(8192, fs, f0, z0, seed))],
        )
        .unwrap();
        for model in [
            FitModel::Ar {
                method: ArMethod::Burg,
            },
            FitModel::Arma { q: 2 },
        ] {
            let out = vibmode_run::fit::fit(&rec, "y.csv", model, 2, &params, &band).unwrap();
            assert_eq!(out.channels.len(), 1);
            let m = &out.channels[0].modes[0];
            assert!(
                (m.frequency_hz / f0 - 1.0).abs() < 0.02 && (m.damping_ratio - z0).abs() < 0.02,
                "seed {seed} {model:?}: {} Hz, damping {}",
                m.frequency_hz,
                m.damping_ratio
            );
        }
        let sw = vibmode_run::sweep::sweep(
            &rec,
            "y.csv",
            SweepModel::Ar,
            ArMethod::Burg,
            &[2, 4, 6],
            &params,
            &band,
        )
        .unwrap();
        let ch = &sw.channels[0];
        assert_eq!(ch.orders, vec![2, 4, 6]);
        for o in [2, 4, 6] {
            assert!(
                ch.modes
                    .iter()
                    .any(|m| m.order == o && (m.frequency_hz / f0 - 1.0).abs() < 0.02),
                "seed {seed} order {o}"
            );
        }
    }
}

/// The sweep's clusters: AR(2) signals with the pole pair at 4 Hz, damping 0.05 (fs 50 Hz,
/// 8192 samples), swept over ARMA orders 2..20 step 2, 10 seeds: one cluster that stays over
/// the orders lies within 2 % of 4 Hz and 0.02 in damping, structural, found at 80 % of the
/// orders or more, and the summary lists it; every cluster that stays lies at 4 Hz (the signal
/// has no other mode; a spurious cluster of the high orders' extra poles is not listed).
#[test]
fn the_sweep_clusters_the_orders_into_the_known_mode() {
    let (fs, f0, z0) = (50.0, 4.0, 0.05);
    let band = BandLimit::full(fs);
    let orders: Vec<usize> = (1..=10).map(|k| 2 * k).collect();
    for seed in 0..10 {
        let rec = Recording::new(
            fs,
            vec![Channel::new(
                "y",
                "m/s^2",
                ar2(8192, fs, f0, z0, 100 + seed),
            )],
        )
        .unwrap();
        let sw = vibmode_run::sweep::sweep(
            &rec,
            "y.csv",
            SweepModel::Arma,
            ArMethod::Burg,
            &orders,
            &ArmaParams::default(),
            &band,
        )
        .unwrap();
        let stay: Vec<_> = sw.channels[0]
            .clusters
            .iter()
            .filter(|m| m.class != vibmode_core::ModeClass::Spurious)
            .collect();
        assert_eq!(stay.len(), 1, "seed {seed}: {stay:?}");
        let m = stay[0];
        assert_eq!(m.class, vibmode_core::ModeClass::Structural, "seed {seed}");
        assert!(
            (m.frequency_hz / f0 - 1.0).abs() < 0.02
                && (m.damping_ratio - z0).abs() < 0.02
                && m.order_share >= 0.8,
            "seed {seed}: {m:?}"
        );
        let text = sw.summary_text();
        let line = format!(
            "  {:>8.3} Hz  damping {:.4}  in {:.0} % of orders\n",
            m.frequency_hz,
            m.damping_ratio,
            100.0 * m.order_share
        );
        assert!(text.contains(&line), "seed {seed}: {text}");
    }
}

/// A channel no fit can use (constant) is an error naming it, in fit and in sweep.
#[test]
fn a_constant_channel_is_named() {
    let fs = 50.0;
    let rec = Recording::new(
        fs,
        vec![
            Channel::new("good", "m/s^2", ar2(2048, fs, 4.0, 0.05, 1)),
            Channel::new("flat", "m/s^2", vec![0.25; 2048]),
        ],
    )
    .unwrap();
    let band = BandLimit::full(fs);
    let params = ArmaParams::default();
    let e = vibmode_run::fit::fit(&rec, "r.csv", FitModel::Arma { q: 2 }, 2, &params, &band)
        .unwrap_err();
    assert!(
        matches!(&e, RunError::FitFailed { channel, .. } if channel == "flat"),
        "{e}"
    );
    let e = vibmode_run::sweep::sweep(
        &rec,
        "r.csv",
        SweepModel::Arma,
        ArMethod::Burg,
        &[2, 4],
        &params,
        &band,
    )
    .unwrap_err();
    assert!(
        matches!(&e, RunError::SweepFailed { channel, .. } if channel == "flat"),
        "{e}"
    );
}

/// ssi: two channels seeing one AR(2) mode (4 Hz, damping 0.05) in the ratio 1 : -0.5, plus 5 %
/// independent noise: at order 2 the one mode is found within 2 % with the shape's ratio.
#[test]
fn ssi_finds_a_known_mode_and_its_shape() {
    let fs = 50.0;
    let x = ar2(8192, fs, 4.0, 0.05, 7);
    let sd = (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
    let mut g = Gauss(99);
    let a: Vec<f64> = x.iter().map(|v| v + 0.05 * sd * g.normal()).collect();
    let b: Vec<f64> = x
        .iter()
        .map(|v| -0.5 * v + 0.05 * sd * g.normal())
        .collect();
    let rec = Recording::new(
        fs,
        vec![Channel::new("a", "m/s^2", a), Channel::new("b", "m/s^2", b)],
    )
    .unwrap();
    let params = SsiParams {
        block_rows: 10,
        order_min: 2,
        order_max: 2,
        ..SsiParams::default()
    };
    let out = vibmode_run::ssi::ssi(&rec, "r.csv", &params, &Default::default()).unwrap();
    assert_eq!(out.channels, vec!["a".to_string(), "b".to_string()]);
    let modes = &out.found.result.orders[0].modes;
    assert_eq!(modes.len(), 1);
    assert!((modes[0].frequency_hz / 4.0 - 1.0).abs() < 0.02);
    let [re_a, _] = modes[0].shape[0];
    let [re_b, _] = modes[0].shape[1];
    assert!((re_b / re_a + 0.5).abs() < 0.05, "{:?}", modes[0].shape);
}
