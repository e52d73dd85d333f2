//! `InvariantMode::support_failures` names exactly the tests a cluster failed: checked against
//! the clustering's own classification over many seeds and settings, and on a hand case.

use crate::common;

use common::{brief_modes, cloud, script_params, structural};
use vibmode_core::SupportFailure;
use vibmode_modal::{analyse_poles, ClusterParams, InvariantMode, ModeClass};

#[test]
fn failures_are_empty_exactly_for_invariant_clusters() {
    let orders: Vec<usize> = (2..=30).collect();
    let (mut modes, lines) = brief_modes();
    modes.extend(lines);
    // A mode in few records: present with probability 0.3 in each fit.
    modes.push(common::TrueMode {
        presence: 0.3,
        ..structural(4.0, 0.1)
    });
    let mut n_spurious = 0;
    for seed in 1..=8u64 {
        for params in [script_params(), ClusterParams::default()] {
            let poles = cloud(seed, 6, &orders, &["FR", "RL"], &modes, 4);
            let a = analyse_poles(&poles, 6, &orders, &params).unwrap();
            for m in &a.modes {
                let f = m.support_failures(&params, 6);
                assert_eq!(
                    f.is_empty(),
                    m.class != ModeClass::Spurious,
                    "seed {seed}: {m:?}"
                );
                n_spurious += usize::from(m.class == ModeClass::Spurious);
            }
        }
    }
    assert!(
        n_spurious > 10,
        "the clouds must hold spurious clusters: {n_spurious}"
    );
}

#[test]
fn hand_case_message() {
    let m = InvariantMode {
        frequency_hz: 0.98,
        frequency_std_hz: 0.05,
        damping_ratio: 0.27,
        damping_iqr: (0.2, 0.3),
        order_share: 0.44,
        record_share: 0.75,
        n_poles: 100,
        channels: vec!["z".into()],
        roles: vec![],
        min_order: 4,
        class: ModeClass::Spurious,
        line_kurtosis: None,
        shape: None,
        shape_mac: None,
        uncertainty: None,
    };
    let f = m.support_failures(&ClusterParams::default(), 20);
    assert_eq!(
        f,
        vec![SupportFailure::OrderShare {
            share: 0.44,
            min: 0.5
        }]
    );
    assert_eq!(
        f[0].to_string(),
        "in 44 % of orders, below min_order_share 0.5"
    );
    // One record: the record share is not tested.
    let one = InvariantMode {
        record_share: 0.0,
        ..m
    };
    assert_eq!(one.support_failures(&ClusterParams::default(), 1).len(), 1);
}
