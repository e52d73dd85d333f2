//! Seeded synthetic pole clouds shared by the integration tests.
#![allow(dead_code)]

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use vibmode_modal::ClusterParams;
use vibmode_modal::PoleObservation;

/// A true mode of the synthetic cloud.
#[derive(Clone, Copy, Debug)]
pub struct TrueMode {
    pub freq_hz: f64,
    pub damping_ratio: f64,
    /// relative std of frequency jitter per fit
    pub freq_jitter_rel: f64,
    /// std of ln(damping) per fit
    pub log_damping_jitter: f64,
    /// probability that a fit of sufficient order contains the mode
    pub presence: f64,
    /// lowest order at which the mode can appear
    pub min_order: usize,
}

pub fn structural(freq_hz: f64, damping_ratio: f64) -> TrueMode {
    TrueMode {
        freq_hz,
        damping_ratio,
        freq_jitter_rel: 0.015,
        log_damping_jitter: 0.35,
        presence: 0.85,
        min_order: 6,
    }
}

pub fn line(freq_hz: f64) -> TrueMode {
    TrueMode {
        freq_hz,
        damping_ratio: 1e-3,
        freq_jitter_rel: 5e-4,
        log_damping_jitter: 0.3,
        presence: 0.9,
        min_order: 8,
    }
}

/// Structural modes and lines of the task brief.
pub fn brief_modes() -> (Vec<TrueMode>, Vec<TrueMode>) {
    (
        vec![
            structural(1.1, 0.25),
            structural(1.5, 0.2),
            structural(9.5, 0.15),
            structural(11.0, 0.12),
        ],
        vec![line(7.0), line(11.8)],
    )
}

/// Cloud: `records` x `orders` x `channels` fits; each true mode present with its probability
/// (with a per-record frequency offset of `record_offset_rel` std), plus `spurious_per_fit`
/// (uniform 0..=2*mean) poles uniform in 0.5..20 Hz with log-uniform damping 1e-3..0.6; with
/// probability 0.1 a structural mode is split into two nearby poles in one fit.
pub fn cloud(
    seed: u64,
    records: usize,
    orders: &[usize],
    channels: &[&str],
    modes: &[TrueMode],
    spurious_per_fit: usize,
) -> Vec<PoleObservation> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n01 = Normal::new(0.0, 1.0).unwrap();
    let mut out = Vec::new();
    for record in 0..records {
        let offsets: Vec<f64> = modes
            .iter()
            .map(|m| 1.0 + 0.3 * m.freq_jitter_rel * n01.sample(&mut rng))
            .collect();
        for ch in channels {
            for &order in orders {
                for (m, off) in modes.iter().zip(&offsets) {
                    if order < m.min_order || rng.gen::<f64>() >= m.presence {
                        continue;
                    }
                    let copies = if m.damping_ratio > 0.01 && rng.gen::<f64>() < 0.1 {
                        2
                    } else {
                        1
                    };
                    for _ in 0..copies {
                        let f = m.freq_hz * off * (1.0 + m.freq_jitter_rel * n01.sample(&mut rng));
                        let z =
                            m.damping_ratio * (m.log_damping_jitter * n01.sample(&mut rng)).exp();
                        out.push(PoleObservation::new(f, z, order, record, *ch));
                    }
                }
                let n_sp = rng.gen_range(0..=2 * spurious_per_fit);
                for _ in 0..n_sp {
                    let f = rng.gen_range(0.5..20.0);
                    let z = 10f64.powf(rng.gen_range(-3.0..0.6f64.log10()));
                    out.push(PoleObservation::new(f, z, order, record, *ch));
                }
            }
        }
    }
    out
}

/// The clustering settings of the reference script `tools/reference/modal.py` (and of these
/// tests): vibmode-modal 0.1's defaults, spelled out. The analysis defaults
/// (`ClusterParams::default()`) differ in five fields: a damping-scaled radius (0.5), a stricter
/// order share (0.5), 0.3 Hz lowest frequency, no fixed highest frequency and a 2 % line spread.
#[allow(dead_code)]
pub fn script_params() -> ClusterParams {
    ClusterParams {
        freq_tol_per_damping: 0.0,
        min_order_share: 0.25,
        disturbance_freq_spread_max: 0.01,
        freq_min_hz: 0.1,
        freq_max_hz: Some(30.0),
        ..ClusterParams::default()
    }
}
