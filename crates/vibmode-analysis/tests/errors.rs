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
    // Exactly long enough: 12 samples at 50 Hz (0.24 s) is analysed (ARMA(2,2) needs 3 x 4).
    let ok = analyze(
        &[record("ok.csv", 50.0, 12, &["z"])],
        &AnalysisConfig::default(),
        &[],
        &|_, _| {},
    );
    assert!(ok.is_ok(), "{:?}", ok.err());
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
