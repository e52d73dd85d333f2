//! Identity over many seeds: a simulated linear system with known modes and mode shapes,
//! identified by SSI-cov at an order of twice the number of modes.
//!
//! The simulator is written here: three modes (1.2 Hz / 0.05, 4.5 Hz / 0.02, 9.0 Hz / 0.1) in
//! real modal form, each the exact discretisation `exp(A_c / fs)` of its continuous block
//! `[[sigma, -omega_d], [omega_d, sigma]]` (poles `s = sigma +- i omega_d`), driven by seeded
//! white noise; five channels `y = C x + v`, where `C` puts the real mode shape of each mode on
//! the first state of its block and `v` is white measurement noise of 10 % of each channel's
//! standard deviation.

use std::f64::consts::PI;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use vibmode_ssi::{mac, ssi_cov, stabilisation, SsiParams, Stability, StabilityParams};

const FS: f64 = 50.0;
const MODES: [(f64, f64); 3] = [(1.2, 0.05), (4.5, 0.02), (9.0, 0.1)];
const SHAPES: [[f64; 5]; 3] = [
    [1.0, 0.8, 0.5, 0.2, -0.1],
    [0.3, -0.6, 1.0, 0.2, -0.8],
    [-0.5, 1.0, 0.1, -0.9, 0.4],
];

fn simulate(n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let blocks: Vec<[f64; 5]> = MODES
        .iter()
        .map(|&(f, z)| {
            let w = 2.0 * PI * f;
            let (sigma, wd) = (-z * w, w * (1.0 - z * z).sqrt());
            let r = (sigma / FS).exp();
            let (c, s) = ((wd / FS).cos(), (wd / FS).sin());
            // Input standard deviation sqrt(1 - r^2): every mode has unit stationary variance.
            [r * c, -r * s, r * s, r * c, (1.0 - r * r).sqrt()]
        })
        .collect();
    let burn = 2000;
    let mut x = vec![[0.0f64; 2]; MODES.len()];
    let mut y: Vec<Vec<f64>> = (0..5).map(|_| Vec::with_capacity(n)).collect();
    for t in 0..n + burn {
        if t >= burn {
            for (ch, out) in y.iter_mut().enumerate() {
                out.push(
                    (0..MODES.len())
                        .map(|m| SHAPES[m][ch] * x[m][0])
                        .sum::<f64>(),
                );
            }
        }
        for (m, b) in blocks.iter().enumerate() {
            let w0: f64 = b[4] * Distribution::<f64>::sample(&StandardNormal, &mut rng);
            let w1: f64 = b[4] * Distribution::<f64>::sample(&StandardNormal, &mut rng);
            let [x0, x1] = x[m];
            x[m] = [b[0] * x0 + b[1] * x1 + w0, b[2] * x0 + b[3] * x1 + w1];
        }
    }
    for ch in y.iter_mut() {
        let sd = (ch.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
        for v in ch.iter_mut() {
            let e: f64 = StandardNormal.sample(&mut rng);
            *v += 0.1 * sd * e;
        }
    }
    y
}

fn real_shape(s: &[f64]) -> Vec<[f64; 2]> {
    s.iter().map(|&v| [v, 0.0]).collect()
}

/// Every seed 0..12, every mode: frequency within 1 %, damping within 0.02 absolute, MAC > 0.99
/// at order 6 (block rows 20, 40 000 samples at 50 Hz). Measured (printed summary, recall
/// 36/36): worst relative frequency errors 0.71 % (1.2 Hz), 0.23 % (4.5 Hz), 0.84 % (9 Hz);
/// worst damping errors 0.0049, 0.0029, 0.0077; worst MAC 0.99993. The errors scatter around
/// zero (no bias) with a standard deviation of about 0.35 % for 1.2 and 9 Hz. With the 9 Hz mode
/// at damping 0.2 and 20 000 samples its frequency scatters by 1-1.5 % (pyOMA2 1.4.3's SSI-cov
/// scatters alike on the same system), beyond a 1 % bound, hence 0.1 and 40 000 samples.
#[test]
fn three_modes_recovered_over_seeds() {
    let params = SsiParams {
        block_rows: 20,
        order_min: 6,
        order_max: 6,
        ..SsiParams::default()
    };
    recall_over_seeds(&params);
}

/// The same with channels 0 and 2 as the references (reference-based SSI-cov: a 100 x 40
/// Toeplitz matrix). Measured: recall 36/36; worst relative frequency errors 0.73 %, 0.22 %,
/// 0.84 %; worst damping errors 0.0051, 0.0028, 0.0077; worst MAC 0.99993.
#[test]
fn three_modes_recovered_over_seeds_with_two_references() {
    let params = SsiParams {
        block_rows: 20,
        order_min: 6,
        order_max: 6,
        reference_channels: Some(vec![0, 2]),
        ..SsiParams::default()
    };
    recall_over_seeds(&params);
}

fn recall_over_seeds(params: &SsiParams) {
    let n = 40_000;
    let seeds: Vec<u64> = (0..12).collect();
    let mut recovered = 0;
    let mut failures = Vec::new();
    // Per mode: worst relative frequency error, worst absolute damping error, worst MAC.
    let mut worst = [(0.0f64, 0.0f64, 1.0f64); 3];
    for &seed in &seeds {
        let y = simulate(n, seed);
        let ch: Vec<&[f64]> = y.iter().map(Vec::as_slice).collect();
        let r = ssi_cov(&ch, FS, params).unwrap();
        let modes = &r.orders[0].modes;
        for (m, &(f, z)) in MODES.iter().enumerate() {
            let best = modes.iter().min_by(|a, b| {
                (a.frequency_hz - f)
                    .abs()
                    .total_cmp(&(b.frequency_hz - f).abs())
            });
            let Some(best) = best else {
                failures.push(format!("seed {seed} mode {f} Hz: no mode identified"));
                continue;
            };
            let ef = (best.frequency_hz - f).abs() / f;
            let ez = (best.damping_ratio - z).abs();
            let mc = mac(&best.shape, &real_shape(&SHAPES[m]));
            worst[m] = (worst[m].0.max(ef), worst[m].1.max(ez), worst[m].2.min(mc));
            if ef <= 0.01 && ez <= 0.02 && mc > 0.99 {
                recovered += 1;
            } else {
                failures.push(format!(
                    "seed {seed} mode {f} Hz: {:.4} Hz, damping {:.4} (true {z}), MAC {mc:.5}",
                    best.frequency_hz, best.damping_ratio
                ));
            }
        }
    }
    let total = seeds.len() * MODES.len();
    eprintln!(
        "references {:?}: recall {recovered}/{total}",
        params.reference_channels
    );
    for (m, w) in worst.iter().enumerate() {
        eprintln!(
            "{} Hz: worst relative frequency error {:.2e}, damping error {:.2e}, MAC {:.6}",
            MODES[m].0, w.0, w.1, w.2
        );
    }
    assert_eq!(
        recovered, total,
        "recall {recovered}/{total} over seeds {seeds:?}: {failures:?}"
    );
}

/// The lightly damped true modes (1.2 Hz / 0.05, 4.5 Hz / 0.02) are stable through the orders
/// 6..=30 of one simulated record: from order 8 on, each has a mode labelled `Stable` at (at
/// least) 80 % of the orders. (The 9 Hz / 0.1 mode is left out: from order to order its damping
/// estimate moves by more than the 5 % relative tolerance: 0.09-0.12 on seed 100 with 20 000
/// samples, where a `Stable` mode within 1 % of 9 Hz was found at 4 of the 12 orders.)
#[test]
fn true_modes_stabilise() {
    let y = simulate(40_000, 100);
    let ch: Vec<&[f64]> = y.iter().map(Vec::as_slice).collect();
    let params = SsiParams {
        block_rows: 20,
        order_min: 6,
        order_max: 30,
        order_step: 2,
        reference_channels: None,
        pool_records: false,
        first_lag: 1,
    };
    let r = ssi_cov(&ch, FS, &params).unwrap();
    let labels = stabilisation(&r, &StabilityParams::default());
    for &(f, _) in MODES.iter().filter(|(_, z)| *z <= 0.05) {
        let stable = r.orders[1..]
            .iter()
            .zip(&labels[1..])
            .filter(|(o, l)| {
                o.modes
                    .iter()
                    .zip(l.iter())
                    .any(|(m, &s)| s == Stability::Stable && (m.frequency_hz - f).abs() < 0.01 * f)
            })
            .count();
        let total = r.orders.len() - 1;
        assert!(
            stable * 5 >= total * 4,
            "{f} Hz stable at {stable} of {total} orders"
        );
    }
}

/// `SsiCov::new` solves the shift for the orders up to `order_max` from one QR; higher orders
/// get their own least-squares solution. Both give the same modes (to rounding).
#[test]
fn one_qr_and_per_order_least_squares_agree() {
    let y = simulate(5_000, 7);
    let ch: Vec<&[f64]> = y.iter().map(Vec::as_slice).collect();
    let wide = SsiParams {
        block_rows: 10,
        order_max: 30,
        ..SsiParams::default()
    };
    let narrow = SsiParams {
        order_max: 2,
        ..wide.clone()
    };
    let a = vibmode_ssi::SsiCov::new(&ch, FS, &wide).unwrap();
    let b = vibmode_ssi::SsiCov::new(&ch, FS, &narrow).unwrap();
    for order in [4, 6, 12, 30] {
        let (ma, mb) = (a.poles_at(order).unwrap(), b.poles_at(order).unwrap());
        assert_eq!(ma.len(), mb.len(), "order {order}");
        for (x, z) in ma.iter().zip(&mb) {
            assert!((x.frequency_hz - z.frequency_hz).abs() < 1e-9 * z.frequency_hz);
            assert!((x.damping_ratio - z.damping_ratio).abs() < 1e-9 * z.damping_ratio);
            assert!(1.0 - mac(&x.shape, &z.shape) < 1e-9);
        }
    }
}

/// Segments: one segment gives exactly the single-record planning; 40 000 samples cut into 20
/// records of 2 000 (each too short to identify the 1.2 Hz mode within 1 % on its own) give the
/// three modes within the bounds of `recall_over_seeds` with the correlations averaged, on every
/// seed 0..6.
#[test]
fn segments_average_their_correlations() {
    use vibmode_ssi::SsiCov;
    let params = SsiParams {
        order_min: 6,
        order_max: 6,
        ..SsiParams::default()
    };
    let y = simulate(4000, 99);
    let ch: Vec<&[f64]> = y.iter().map(Vec::as_slice).collect();
    let one = SsiCov::new(&ch, FS, &params).unwrap().poles_at(6).unwrap();
    let seg = SsiCov::from_segments(std::slice::from_ref(&ch), FS, &params)
        .unwrap()
        .poles_at(6)
        .unwrap();
    assert_eq!(one.len(), seg.len());
    for (a, b) in one.iter().zip(&seg) {
        assert!((a.frequency_hz - b.frequency_hz).abs() < 1e-9 * a.frequency_hz);
        assert!((a.damping_ratio - b.damping_ratio).abs() < 1e-9);
    }
    let mut failures = Vec::new();
    for seed in 0..6u64 {
        let y = simulate(40_000, seed);
        let segments: Vec<Vec<&[f64]>> = (0..20)
            .map(|s| y.iter().map(|c| &c[s * 2000..(s + 1) * 2000]).collect())
            .collect();
        let modes = SsiCov::from_segments(&segments, FS, &params)
            .unwrap()
            .poles_at(6)
            .unwrap();
        for (m, &(f, z)) in MODES.iter().enumerate() {
            let ok = modes.iter().any(|q| {
                (q.frequency_hz - f).abs() / f <= 0.01
                    && (q.damping_ratio - z).abs() <= 0.02
                    && mac(&q.shape, &real_shape(&SHAPES[m])) > 0.99
            });
            if !ok {
                failures.push((seed, f));
            }
        }
    }
    assert!(failures.is_empty(), "modes missed (seed, Hz): {failures:?}");
}

/// Two close, heavily damped modes (a vehicle's pitch 1.03 Hz / 0.17 and heave 1.17 Hz / 0.19)
/// with shapes `[1, -1]` and `[1, 1]` at a front and a rear sensor, excited at the front by
/// white noise `e(t)` and at the rear by the same noise `D` samples later (`e(t - D)`: the rear
/// wheels run over the road the front wheels met `wheelbase / speed` earlier). Sampled at 10 Hz,
/// `D` = 7 (0.7 s). The output correlations then follow the modes' free decay only from lag
/// `D + 1` on.
fn delayed_input(n: usize, seed: u64) -> Vec<Vec<f64>> {
    delayed_input_by(n, seed, 7)
}

/// [`delayed_input`] with the rear input `d` samples after the front.
fn delayed_input_by(n: usize, seed: u64, d: usize) -> Vec<Vec<f64>> {
    let fs = 10.0;
    let modes = [(1.03, 0.17, [1.0, -1.0]), (1.17, 0.19, [1.0, 1.0])];
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let burn = 500;
    let e: Vec<f64> = (0..n + burn + d)
        .map(|_| StandardNormal.sample(&mut rng))
        .collect();
    let mut y = vec![vec![0.0; n]; 2];
    for &(f, z, b) in &modes {
        let w = 2.0 * PI * f;
        let (sigma, wd) = (-z * w, w * (1.0 - z * z).sqrt());
        let r = (sigma / fs).exp();
        let (a1, a2) = (2.0 * r * (wd / fs).cos(), -r * r);
        let (mut q1, mut q2) = (0.0, 0.0);
        for t in 0..n + burn {
            let u = b[0] * e[t + d] + b[1] * e[t];
            let q = a1 * q1 + a2 * q2 + u;
            (q2, q1) = (q1, q);
            if t >= burn {
                // Shape = input pattern (a symmetric system): front +1, rear b[1].
                y[0][t - burn] += q;
                y[1][t - burn] += b[1] * q;
            }
        }
    }
    y
}

/// Bias, not scatter: the mean over 8 seeds (200 000 samples each, block rows 10, order 4) of
/// each mode's frequency and damping. From the first lag 1 (lags 1..19) pitch comes out at
/// about 0.935 Hz with damping 0.30 (measured: -9 %, +80 %) on every seed; from the first lag
/// 8 (lags 8..26) the means are within 1 % in frequency and 10 % in damping (single seeds
/// scatter by about 2 %).
#[test]
fn a_first_lag_beyond_the_input_delay_removes_the_bias() {
    let truth = [(1.03, 0.17), (1.17, 0.19)];
    let means = |first_lag: usize| {
        let mut sum = [(0.0, 0.0); 2];
        let seeds = 8;
        for seed in 0..seeds {
            let y = delayed_input(200_000, seed);
            let chans: Vec<&[f64]> = y.iter().map(Vec::as_slice).collect();
            let p = SsiParams {
                block_rows: 10,
                order_min: 4,
                order_max: 4,
                first_lag,
                ..SsiParams::default()
            };
            let res = ssi_cov(&chans, 10.0, &p).unwrap();
            let modes = &res.orders[0].modes;
            assert_eq!(modes.len(), 2, "seed {seed}, first lag {first_lag}");
            for (s, m) in sum.iter_mut().zip(modes) {
                s.0 += m.frequency_hz / seeds as f64;
                s.1 += m.damping_ratio / seeds as f64;
            }
        }
        sum
    };
    let (biased, clean) = (means(1), means(8));
    eprintln!("means (Hz, damping): first lag 1 {biased:?}, first lag 8 {clean:?}");
    for ((&(f, z), c), b) in truth.iter().zip(clean).zip(biased) {
        assert!((c.0 - f).abs() < 0.01 * f, "{f} Hz: first lag 8 gave {c:?}");
        assert!(
            (c.1 - z).abs() < 0.1 * z,
            "damping {z}: first lag 8 gave {c:?}"
        );
        if f < 1.1 {
            assert!((b.0 - f).abs() > 0.05 * f, "{f} Hz: first lag 1 gave {b:?}");
            assert!(
                (b.1 - z).abs() > 0.5 * z,
                "damping {z}: first lag 1 gave {b:?}"
            );
        }
    }
}

/// Records driven at different speeds have different front-to-rear delays: segments of the
/// two-mode system with the delays 4, 7 and 10 samples (0.4-1.0 s), 12 of each (30 000 samples
/// apiece), pooled with each segment's Toeplitz matrix beginning just beyond its own delay
/// (`first_lags` = delay + 1), give both modes within 1.5 % in frequency and 15 % in damping
/// on each of 5 seeds; pooled from lag 1 they do not (pitch off by more than 4 % on average).
#[test]
fn records_with_different_delays_pooled_each_beyond_its_own() {
    use vibmode_ssi::SsiCorrelations;
    let truth = [(1.03, 0.17), (1.17, 0.19)];
    let p = SsiParams {
        block_rows: 10,
        order_min: 4,
        order_max: 4,
        ..SsiParams::default()
    };
    let mut biased_pitch = 0.0;
    for seed in 0..5u64 {
        let mut segs = Vec::new();
        let mut lags = Vec::new();
        for k in 0..36u64 {
            let d = [4usize, 7, 10][(k % 3) as usize];
            segs.push(delayed_input_by(30_000, 100 * seed + k, d));
            lags.push(d + 1);
        }
        let views: Vec<Vec<&[f64]>> = segs
            .iter()
            .map(|s| s.iter().map(Vec::as_slice).collect())
            .collect();
        let own = SsiCorrelations::with_first_lags(&views, 10.0, &p, &lags).unwrap();
        let modes = own.plan().unwrap().sweep(&[4]).unwrap().orders[0]
            .modes
            .clone();
        assert_eq!(modes.len(), 2, "seed {seed}");
        for (&(f, z), m) in truth.iter().zip(&modes) {
            assert!(
                (m.frequency_hz - f).abs() < 0.015 * f,
                "seed {seed}: {f} Hz came out {m:?}"
            );
            assert!(
                (m.damping_ratio - z).abs() < 0.15 * z,
                "seed {seed}: damping {z} came out {m:?}"
            );
        }
        let ones = vec![1; views.len()];
        let lag1 = SsiCorrelations::with_first_lags(&views, 10.0, &p, &ones).unwrap();
        let m1 = lag1.plan().unwrap().sweep(&[4]).unwrap().orders[0]
            .modes
            .clone();
        biased_pitch += (m1[0].frequency_hz / 1.03 - 1.0).abs() / 5.0;
    }
    assert!(biased_pitch > 0.04, "lag 1 pitch error {biased_pitch}");
}

/// With every segment's first lag equal, the per-segment constructor is the common one.
#[test]
fn equal_first_lags_are_the_common_first_lag() {
    use vibmode_ssi::SsiCorrelations;
    for (seed, first_lag) in [(1u64, 1usize), (2, 5), (3, 12)] {
        let segs: Vec<Vec<Vec<f64>>> = (0..4)
            .map(|k| delayed_input_by(2_000 + 37 * k, 10 * seed + k as u64, 3))
            .collect();
        let views: Vec<Vec<&[f64]>> = segs
            .iter()
            .map(|s| s.iter().map(Vec::as_slice).collect())
            .collect();
        let p = SsiParams {
            block_rows: 8,
            order_max: 8,
            first_lag,
            ..SsiParams::default()
        };
        let a = SsiCorrelations::new(&views, 10.0, &p)
            .unwrap()
            .plan()
            .unwrap();
        let lags = vec![first_lag; views.len()];
        let b = SsiCorrelations::with_first_lags(&views, 10.0, &p, &lags)
            .unwrap()
            .plan()
            .unwrap();
        assert_eq!(a.n_samples(), b.n_samples());
        for (x, y) in a.singular_values().iter().zip(b.singular_values()) {
            assert!((x - y).abs() <= 1e-12 * (1.0 + x.abs()), "{x} {y}");
        }
        // and one lag more for one segment changes them
        let mut lags2 = lags.clone();
        lags2[0] += 1;
        let c = SsiCorrelations::with_first_lags(&views, 10.0, &p, &lags2)
            .unwrap()
            .plan()
            .unwrap();
        assert!(a.singular_values()[0] != c.singular_values()[0]);
    }
    let seg = delayed_input_by(100, 1, 3);
    let views = vec![seg.iter().map(Vec::as_slice).collect::<Vec<_>>()];
    let p = SsiParams::default();
    let e = SsiCorrelations::with_first_lags(&views, 10.0, &p, &[1, 2]).unwrap_err();
    assert!(e.to_string().contains("2 first lags for 1 segments"), "{e}");
    assert!(SsiCorrelations::with_first_lags(&views, 10.0, &p, &[0]).is_err());
}

/// The leave-one-segment-out jackknife's standard deviations agree with the actual scatter:
/// over 24 seeds, each 20 segments of 1000 samples (the three-mode system, order 6), the RMS of
/// the jackknife standard deviations of each mode's frequency and damping is within a factor
/// 1.6 of the standard deviation of the 24 all-segment estimates about their truth.
#[test]
fn jackknife_std_matches_the_scatter_over_seeds() {
    use vibmode_ssi::{jackknife_std, SsiCov};
    let params = SsiParams {
        order_min: 6,
        order_max: 6,
        ..SsiParams::default()
    };
    let nearest = |modes: &[vibmode_ssi::SsiMode], f: f64| {
        modes
            .iter()
            .min_by(|a, b| {
                (a.frequency_hz - f)
                    .abs()
                    .total_cmp(&(b.frequency_hz - f).abs())
            })
            .map(|m| (m.frequency_hz, m.damping_ratio))
            .unwrap()
    };
    let seeds = 24;
    let mut err2 = [[0.0f64; 2]; 3];
    let mut jack2 = [[0.0f64; 2]; 3];
    for seed in 0..seeds {
        let y = simulate(20_000, 1000 + seed);
        let segments: Vec<Vec<&[f64]>> = (0..20)
            .map(|s| y.iter().map(|c| &c[s * 1000..(s + 1) * 1000]).collect())
            .collect();
        let all = SsiCov::from_segments(&segments, FS, &params)
            .unwrap()
            .poles_at(6)
            .unwrap();
        let loo: Vec<Vec<vibmode_ssi::SsiMode>> = SsiCov::jackknife(&segments, FS, &params, 20)
            .unwrap()
            .iter()
            .map(|p| p.poles_at(6).unwrap())
            .collect();
        assert_eq!(loo.len(), 20);
        for (m, &(f, z)) in MODES.iter().enumerate() {
            let (fa, za) = nearest(&all, f);
            err2[m][0] += (fa - f).powi(2) / seeds as f64;
            err2[m][1] += (za - z).powi(2) / seeds as f64;
            let (fs, zs): (Vec<f64>, Vec<f64>) = loo.iter().map(|p| nearest(p, f)).unzip();
            jack2[m][0] += jackknife_std(&fs).powi(2) / seeds as f64;
            jack2[m][1] += jackknife_std(&zs).powi(2) / seeds as f64;
        }
    }
    for (m, &(f, _)) in MODES.iter().enumerate() {
        for (k, what) in ["frequency", "damping"].iter().enumerate() {
            let (actual, jack) = (err2[m][k].sqrt(), jack2[m][k].sqrt());
            eprintln!("{f} Hz {what}: scatter {actual:.2e}, jackknife {jack:.2e}");
            assert!(
                jack < 1.6 * actual && actual < 1.6 * jack,
                "{f} Hz {what}: scatter {actual:.3e}, jackknife {jack:.3e}"
            );
        }
    }
}

/// Döhler-style first-order standard deviations from 20 blocks of one record agree with the
/// actual scatter: over 24 seeds of 20 000 samples (the three-mode system, order 6), the RMS of
/// the predicted standard deviations of each mode's frequency and damping is within a factor
/// 1.5 of the standard deviation of the 24 estimates about their truth. The blocks' plan is the
/// whole record's (every product in one block): its poles equal `SsiCov::new`'s to 1e-12.
#[test]
fn perturbation_std_matches_the_scatter_over_seeds() {
    use vibmode_ssi::SsiCov;
    let params = SsiParams {
        order_min: 6,
        order_max: 6,
        ..SsiParams::default()
    };
    let seeds = 24;
    let mut err2 = [[0.0f64; 2]; 3];
    let mut pred2 = [[0.0f64; 2]; 3];
    for seed in 0..seeds {
        let y = simulate(20_000, 2000 + seed);
        let chans: Vec<&[f64]> = y.iter().map(Vec::as_slice).collect();
        let p = SsiCov::perturbation(&chans, FS, &params, 20).unwrap();
        assert_eq!(p.n_blocks(), 20);
        let poles = p.poles_at(6).unwrap();
        let whole = SsiCov::new(&chans, FS, &params)
            .unwrap()
            .poles_at(6)
            .unwrap();
        assert_eq!(poles.len(), whole.len());
        for (a, b) in poles.iter().zip(&whole) {
            assert!((a.mode.frequency_hz - b.frequency_hz).abs() < 1e-12 * b.frequency_hz);
        }
        for (m, &(f, z)) in MODES.iter().enumerate() {
            let s = poles
                .iter()
                .min_by(|a, b| {
                    (a.mode.frequency_hz - f)
                        .abs()
                        .total_cmp(&(b.mode.frequency_hz - f).abs())
                })
                .unwrap();
            err2[m][0] += (s.mode.frequency_hz - f).powi(2) / seeds as f64;
            err2[m][1] += (s.mode.damping_ratio - z).powi(2) / seeds as f64;
            pred2[m][0] += s.frequency_std_hz.powi(2) / seeds as f64;
            pred2[m][1] += s.damping_std.powi(2) / seeds as f64;
        }
    }
    for (m, &(f, _)) in MODES.iter().enumerate() {
        for (k, what) in ["frequency", "damping"].iter().enumerate() {
            let (actual, pred) = (err2[m][k].sqrt(), pred2[m][k].sqrt());
            eprintln!("{f} Hz {what}: scatter {actual:.2e}, first-order {pred:.2e}");
            assert!(
                pred < 1.5 * actual && actual < 1.5 * pred,
                "{f} Hz {what}: scatter {actual:.3e}, first-order {pred:.3e}"
            );
        }
    }
}

#[test]
fn jackknife_std_by_hand() {
    use vibmode_ssi::jackknife_std;
    // m = 4, mean 2.5, sum of squares 5: sqrt(3 / 4 * 5).
    assert!((jackknife_std(&[1.0, 2.0, 3.0, 4.0]) - (3.75f64).sqrt()).abs() < 1e-15);
    assert_eq!(jackknife_std(&[7.0]), 0.0);
    assert_eq!(jackknife_std(&[]), 0.0);
}

/// The whole one-record pipeline (`vibmode ssi`, Python `ssi_cov`): the default order sweep
/// (2..60) clustered over the orders. Over seeds 0..8 (20 000 samples): every true mode is a
/// structural cluster within 1.5 % in frequency, 0.02 in damping and MAC > 0.99 (recall 24/24).
/// Precision is lower, and stated: one record swept to order 60 (ten times the 6 states of the
/// system) also gives clusters of noise poles that recur in half the orders or more, all first
/// appearing at order 8 or above (14 or above for 10 of them) with shape MAC > 0.9 between orders;
/// measured 11 such clusters over the 8 seeds (precision 24/35), at 7.6-21.9 Hz. Hence `vibmode
/// ssi` names the orders a mode first appears at, and the analysis of many records requires a
/// mode to recur over records.
#[test]
fn one_record_pipeline_clusters_the_true_modes_over_seeds() {
    use vibmode_ssi::{identify_record, RecordSsiOptions};
    let (mut found, mut spurious) = (0, Vec::new());
    for seed in 0..8u64 {
        let y = simulate(20_000, 100 + seed);
        let chans: Vec<&[f64]> = y.iter().map(Vec::as_slice).collect();
        let r = identify_record(
            &chans,
            FS,
            &SsiParams::default(),
            &RecordSsiOptions::default(),
        )
        .expect("identify");
        let structural: Vec<_> = r
            .modes
            .iter()
            .filter(|m| m.class == vibmode_core::ModeClass::Structural)
            .collect();
        for (k, &(f, z)) in MODES.iter().enumerate() {
            let hit = structural.iter().any(|m| {
                (m.frequency_hz - f).abs() < 0.015 * f
                    && (m.damping_ratio - z).abs() < 0.02
                    && m.shape
                        .as_ref()
                        .is_some_and(|s| mac(s, &real_shape(&SHAPES[k])) > 0.99)
            });
            found += usize::from(hit);
        }
        for m in &structural {
            if !MODES
                .iter()
                .any(|&(f, _)| (m.frequency_hz - f).abs() < 0.03 * f)
            {
                spurious.push((seed, m.frequency_hz, m.damping_ratio));
            }
        }
    }
    assert_eq!(found, 24, "recall {found}/24");
    assert!(
        spurious.len() <= 11,
        "spurious structural clusters: {spurious:?}"
    );
}

/// Scaling a channel does not change what is identified (each channel is divided by its RMS
/// first) and scales that channel's shape entry by the same factor (the shapes are in the
/// channels' units): frequencies equal to 1e-9, shape ratio within 1e-6.
#[test]
fn one_record_pipeline_is_invariant_to_channel_units() {
    use vibmode_ssi::{identify_record, RecordSsiOptions};
    for seed in 0..4u64 {
        let y = simulate(8_000, 200 + seed);
        let mut scaled = y.clone();
        for v in scaled[2].iter_mut() {
            *v *= 1000.0;
        }
        let p = SsiParams {
            order_min: 6,
            order_max: 6,
            ..SsiParams::default()
        };
        let run = |d: &Vec<Vec<f64>>| {
            let c: Vec<&[f64]> = d.iter().map(Vec::as_slice).collect();
            identify_record(&c, FS, &p, &RecordSsiOptions::default()).expect("identify")
        };
        let (a, b) = (run(&y), run(&scaled));
        let (ma, mb) = (&a.result.orders[0].modes, &b.result.orders[0].modes);
        assert_eq!(ma.len(), mb.len());
        for (x, z) in ma.iter().zip(mb) {
            assert!((x.frequency_hz - z.frequency_hz).abs() < 1e-9 * x.frequency_hz);
            // Entry 2 relative to entry 0, in modulus.
            let m = |s: &[[f64; 2]], i: usize| s[i][0].hypot(s[i][1]);
            let ra = m(&x.shape, 2) / m(&x.shape, 0);
            let rb = m(&z.shape, 2) / m(&z.shape, 0);
            assert!(
                (rb / ra / 1000.0 - 1.0).abs() < 1e-6,
                "seed {seed}: ratio {} vs {}",
                rb,
                ra
            );
        }
    }
}

/// SSI-cov through the analysis's contract (`MultichannelIdentifier`): four records of the
/// three-mode system identified together recover every mode (frequency within 1 %, damping
/// within 0.02, MAC > 0.99) on each of 6 seeds, as one record of the same total length does;
/// the delete-a-group jackknife gives one repetition per group, each holding every mode within
/// 2 %; and the orders offered stop at the block Toeplitz rank bound `(block_rows - 1) l`.
#[test]
fn the_identifier_contract_pools_records_and_jackknifes_them() {
    use vibmode_core::{MultichannelIdentifier, PooledIdentification};
    use vibmode_ssi::SsiCovIdentifier;
    let method = SsiCovIdentifier {
        params: SsiParams {
            block_rows: 20,
            order_min: 2,
            order_max: 200,
            order_step: 2,
            ..SsiParams::default()
        },
    };
    let offered = method.orders(5);
    assert_eq!(offered.first(), Some(&2));
    assert_eq!(offered.last(), Some(&(19 * 5 - 1)));
    let near = |poles: &[vibmode_core::ShapedPole], m: usize| {
        let (f, z) = MODES[m];
        poles
            .iter()
            .filter(|q| q.order == 6)
            .min_by(|a, b| {
                (a.frequency_hz - f)
                    .abs()
                    .total_cmp(&(b.frequency_hz - f).abs())
            })
            .map(|q| {
                (
                    (q.frequency_hz - f).abs() / f,
                    (q.damping_ratio - z).abs(),
                    mac(&q.shape, &real_shape(&SHAPES[m])),
                )
            })
    };
    for seed in 0..6u64 {
        let recs: Vec<Vec<Vec<f64>>> = (0..4).map(|k| simulate(10_000, 100 * seed + k)).collect();
        let views: Vec<Vec<&[f64]>> = recs
            .iter()
            .map(|r| r.iter().map(Vec::as_slice).collect())
            .collect();
        let pooled = method.pool(&views, FS, None).unwrap();
        assert_eq!(pooled.n_records(), 4);
        let poles = pooled.identify(&[6]).unwrap();
        assert!(poles.iter().all(|q| q.record == 0 && q.order == 6));
        for m in 0..MODES.len() {
            let (ef, ez, mc) = near(&poles, m).unwrap();
            assert!(
                ef <= 0.01 && ez <= 0.02 && mc > 0.99,
                "seed {seed} mode {m}: {ef} {ez} {mc}"
            );
        }
        let reps = pooled.jackknife(4, &[6]).unwrap();
        assert_eq!(reps.len(), 4);
        for rep in &reps {
            for m in 0..MODES.len() {
                assert!(near(rep, m).unwrap().0 <= 0.02, "seed {seed} mode {m}");
            }
        }
        // One record through the same contract.
        let one = method.identify_record(&views[0], FS, &[6]).unwrap();
        assert!(near(&one, 0).is_some());
        // Fewer than 2 groups, or more groups than records: the method's own error.
        assert!(pooled.jackknife(1, &[6]).is_err());
        assert!(pooled.jackknife(5, &[6]).is_err());
    }
}
