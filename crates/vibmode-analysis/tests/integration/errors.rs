//! Records that cannot be analysed give one-line errors naming the values, before any fit.

use vibmode_analysis::{analyze, AnalysisConfig, AnalysisError, RecordInput};
use vibmode_core::{Channel, Recording};

fn record(name: &str, fs_hz: f64, n: usize, channels: &[&str]) -> RecordInput {
    let chans = channels
        .iter()
        .enumerate()
        .map(|(c, ch)| {
            let samples = (0..n)
                .map(|i| ((i * (c + 3)) as f64 * 0.37).sin() + 0.1 * ((i * 7) % 5) as f64)
                .collect();
            Channel::new(*ch, "m/s^2", samples)
        })
        .collect();
    RecordInput {
        name: name.into(),
        recording: Recording::new(fs_hz, chans).unwrap(),
    }
}

fn err(records: &[RecordInput], cfg: &AnalysisConfig) -> AnalysisError {
    let e = analyze(records, cfg, &[], &|_, _| {}).unwrap_err();
    let text = e.to_string();
    assert!(!text.contains('\n') && !text.contains("--"), "{text}");
    e
}

#[test]
fn a_record_too_short_for_the_lowest_order_is_refused() {
    // 0.04 s at 500 Hz -> 2 samples at 50 Hz.
    let e = err(
        &[record("short.csv", 500.0, 20, &["z"])],
        &AnalysisConfig::default(),
    );
    let text = e.to_string();
    assert!(
        matches!(
            e,
            AnalysisError::RecordTooShort {
                n_samples: 2,
                needed: 12,
                ..
            }
        ),
        "{text}"
    );
    assert!(
        text.contains("short.csv") && text.contains("0.040 s") && text.contains("0.240 s"),
        "{text}"
    );
    // Exactly long enough: 12 samples at 50 Hz (0.24 s) is analysed (ARMA(2,2) needs 3 x 4)
    // by a sweep that ends there.
    let mut only_2 = AnalysisConfig::default();
    only_2.sweep.order_max = 2;
    let ok = analyze(
        &[record("ok.csv", 50.0, 12, &["z"])],
        &only_2,
        &[],
        &|_, _| {},
    );
    assert!(ok.is_ok(), "{:?}", ok.err());
}

/// The sweep's highest order must be within reach of the longest record: ARMA(p, p) needs
/// 3 x 2p samples, so the default orders up to 30 need 180 samples (3.6 s at 50 Hz). Before,
/// orders beyond every record were "fitted" as failures and no cluster reached its share of
/// the orders: an empty result instead of an error. A shorter last record is fine.
#[test]
fn an_order_max_beyond_the_longest_record_is_refused() {
    let cfg = AnalysisConfig::default();
    // 179 samples at 50 Hz: one short of ARMA(30, 30)'s 180.
    let e = err(&[record("short.csv", 50.0, 179, &["z"])], &cfg);
    let text = e.to_string();
    assert!(
        matches!(
            e,
            AnalysisError::OrderMaxTooHigh {
                order_max: 30,
                needed: 180,
                n_samples: 179,
                highest: 29,
                ..
            }
        ),
        "{text}"
    );
    assert!(
        text.contains("order_max = 30") && text.contains("short.csv") && text.contains("29"),
        "{text}"
    );
    // 180 samples, and a last record of 60: analysed.
    let ok = analyze(
        &[
            record("a.csv", 50.0, 180, &["z"]),
            record("b.csv", 50.0, 60, &["z"]),
        ],
        &cfg,
        &[],
        &|_, _| {},
    );
    assert!(ok.is_ok(), "{:?}", ok.err());
    // AR(p) needs 3 p: the same 179 samples carry AR up to 59.
    let mut ar = AnalysisConfig::default();
    ar.sweep.model = vibmode_core::SweepModel::Ar;
    ar.sweep.order_max = 60;
    let e = err(&[record("short.csv", 50.0, 179, &["z"])], &ar);
    assert!(
        matches!(e, AnalysisError::OrderMaxTooHigh { highest: 59, .. }),
        "{e}"
    );
}

#[test]
fn records_must_share_channels_and_rate() {
    let cfg = AnalysisConfig::default();
    let e = err(
        &[
            record("a", 100.0, 2000, &["x", "z"]),
            record("b", 100.0, 2000, &["z"]),
        ],
        &cfg,
    );
    assert!(
        e.to_string().contains("[x, z]") && e.to_string().contains("'b'"),
        "{e}"
    );
    let e = err(
        &[
            record("a", 100.0, 2000, &["z"]),
            record("b", 200.0, 2000, &["z"]),
        ],
        &cfg,
    );
    assert!(
        e.to_string().contains("200 Hz") && e.to_string().contains("100 Hz"),
        "{e}"
    );
    let e = err(&[], &cfg);
    assert!(matches!(e, AnalysisError::NoRecords));
}
