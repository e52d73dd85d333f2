//! Comparison with the independent scipy implementation in tools/reference/modal.py
//! (cKDTree radius queries + csgraph connected components; numpy statistics).

use crate::common;

use common::script_params;

use serde::Deserialize;
use vibmode_modal::{analyse_poles, ClusterParams, InvariantMode, PoleObservation};

#[derive(Deserialize)]
struct Expected {
    modes: Vec<InvariantMode>,
    labels: Vec<Option<usize>>,
    n_used: usize,
    n_ignored: usize,
    n_fits: usize,
    core_threshold: usize,
}

#[derive(Deserialize)]
struct Case {
    n_records: usize,
    orders: Vec<usize>,
    params: ClusterParams,
    poles: Vec<PoleObservation>,
    expected: Expected,
}

fn close(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= 1e-9 * b.abs().max(1e-12),
        "{what}: rust {a} vs scipy {b}"
    );
}

#[test]
fn matches_scipy_reference() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tools/reference/data/modal.json"
    ))
    .unwrap();
    let case: Case = serde_json::from_str(&text).unwrap();
    let a = analyse_poles(&case.poles, case.n_records, &case.orders, &case.params).unwrap();
    let e = &case.expected;
    assert_eq!(a.n_used, e.n_used);
    assert_eq!(a.n_ignored, e.n_ignored);
    assert_eq!(a.n_fits, e.n_fits);
    assert_eq!(a.core_threshold, e.core_threshold);
    assert_eq!(a.modes.len(), e.modes.len());
    assert!(e.modes.len() >= 4, "reference case too easy");
    for (k, (m, x)) in a.modes.iter().zip(&e.modes).enumerate() {
        let w = format!("cluster {k}");
        close(m.frequency_hz, x.frequency_hz, &format!("{w} frequency_hz"));
        close(
            m.frequency_std_hz,
            x.frequency_std_hz,
            &format!("{w} frequency_std_hz"),
        );
        close(
            m.damping_ratio,
            x.damping_ratio,
            &format!("{w} damping_ratio"),
        );
        close(m.damping_iqr.0, x.damping_iqr.0, &format!("{w} q25"));
        close(m.damping_iqr.1, x.damping_iqr.1, &format!("{w} q75"));
        close(m.order_share, x.order_share, &format!("{w} order_share"));
        close(m.record_share, x.record_share, &format!("{w} record_share"));
        assert_eq!(m.n_poles, x.n_poles, "{w}");
        assert_eq!(m.channels, x.channels, "{w}");
        assert_eq!(m.min_order, x.min_order, "{w}");
        assert_eq!(m.class, x.class, "{w}");
    }
    assert_eq!(a.labels, e.labels);
}

#[test]
fn params_default_matches_reference_script() {
    // The script spells out every parameter: vibmode-modal 0.1's defaults (script_params).
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tools/reference/data/modal.json"
    ))
    .unwrap();
    let case: Case = serde_json::from_str(&text).unwrap();
    assert_eq!(case.params, script_params());
}
