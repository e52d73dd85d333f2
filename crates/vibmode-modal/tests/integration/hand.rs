//! Small cases checkable by hand: clustering, matching, stabilisation, and the bad-input paths.

use crate::common;

use common::script_params;

use vibmode_modal::{
    analyse_poles, find_invariant_modes, match_reference, stabilisation, ClusterParams,
    InvariantMode, ModalError, ModeClass, ModeMatch, PoleObservation, ReferenceMode, Stability,
    StabilityParams,
};

fn pole(f: f64, z: f64, order: usize, record: usize) -> PoleObservation {
    PoleObservation::new(f, z, order, record, "RL")
}

/// 2 records x orders {4, 6} x 1 channel = 4 fits; core threshold = min_points = 2.
fn hand_poles() -> Vec<PoleObservation> {
    vec![
        pole(1.000, 0.20, 4, 0),   // 0  mode A
        pole(1.012, 0.20, 4, 0),   // 1  duplicate of fit (0,4): farther from the centre -> dropped
        pole(1.005, 0.21, 6, 0),   // 2
        pole(0.995, 0.19, 4, 1),   // 3
        pole(1.010, 0.22, 6, 1),   // 4
        pole(5.000, 1.0e-3, 4, 0), // 5  line
        pole(5.001, 1.1e-3, 6, 0), // 6
        pole(4.999, 0.9e-3, 6, 1), // 7
        pole(2.00, 0.10, 4, 1),    // 8  mode B, record 1 only
        pole(2.02, 0.10, 6, 1),    // 9
        pole(3.00, 0.10, 6, 0),    // 10 isolated -> noise
        pole(40.0, 0.10, 6, 0),    // 11 above freq_max_hz -> ignored
        pole(1.00, 0.80, 6, 0),    // 12 above max_damping_ratio -> ignored
    ]
}

fn hand_params() -> ClusterParams {
    ClusterParams {
        min_points: 2,
        min_density_share: 0.0,
        min_record_share: 0.6,
        ..script_params()
    }
}

fn close(a: f64, b: f64, tol: f64) {
    assert!((a - b).abs() <= tol, "{a} vs {b}");
}

#[test]
fn hand_clusters_shares_and_classes() {
    let a = analyse_poles(&hand_poles(), 2, &[4, 6], &hand_params()).unwrap();
    assert_eq!(
        (a.n_used, a.n_ignored, a.n_fits, a.core_threshold),
        (11, 2, 4, 2)
    );
    assert_eq!(a.modes.len(), 3);
    let m = &a.modes[0];
    // kept 1.000, 1.005, 0.995, 1.010: mean 1.0025, deviations +-0.0025, +-0.0075
    close(m.frequency_hz, 1.0025, 1e-12);
    close(m.frequency_std_hz, (1.25e-4f64 / 3.0).sqrt(), 1e-12);
    // damping 0.19 0.20 0.21 0.22: median 0.205, q25 at position 0.75, q75 at 2.25
    close(m.damping_ratio, 0.205, 1e-12);
    close(m.damping_iqr.0, 0.1975, 1e-12);
    close(m.damping_iqr.1, 0.2125, 1e-12);
    assert_eq!((m.n_poles, m.record_share, m.order_share), (4, 1.0, 1.0));
    assert_eq!(m.class, ModeClass::Structural);
    assert_eq!(m.channels, vec!["RL".to_string()]);
    assert_eq!(m.min_order, 4);

    let b = &a.modes[1]; // 2 Hz, record 1 only: 1 of 2 records < 0.6
    close(b.frequency_hz, 2.01, 1e-12);
    assert_eq!((b.n_poles, b.record_share, b.order_share), (2, 0.5, 0.5));
    assert_eq!(b.class, ModeClass::Spurious);

    let l = &a.modes[2]; // line: 3 of 4 fits
    close(l.frequency_hz, 5.0, 1e-12);
    close(l.frequency_std_hz, 0.001, 1e-12);
    close(l.damping_ratio, 1.0e-3, 1e-15);
    close(l.damping_iqr.0, 0.95e-3, 1e-15);
    close(l.damping_iqr.1, 1.05e-3, 1e-15);
    assert_eq!((l.record_share, l.order_share), (1.0, 0.75));
    assert_eq!(l.class, ModeClass::PeriodicDisturbance);

    let expected_labels = [
        Some(0),
        None,
        Some(0),
        Some(0),
        Some(0),
        Some(2),
        Some(2),
        Some(2),
        Some(1),
        Some(1),
        None,
        None,
        None,
    ];
    assert_eq!(a.labels, expected_labels);

    // With a lower record-share requirement the 2 Hz cluster becomes invariant.
    let p = ClusterParams {
        min_record_share: 0.5,
        ..hand_params()
    };
    let modes = find_invariant_modes(&hand_poles(), 2, &[4, 6], &p).unwrap();
    assert_eq!(modes[1].class, ModeClass::Structural);
    // A tighter fixed frequency tolerance (0.5 %) splits the 2 Hz pair (1 % apart) into noise.
    let p = ClusterParams {
        freq_tol_rel: 0.005,
        freq_tol_per_damping: 0.0,
        ..hand_params()
    };
    let modes = find_invariant_modes(&hand_poles(), 2, &[4, 6], &p).unwrap();
    assert!(modes.iter().all(|m| (m.frequency_hz - 2.01).abs() > 0.05));
    // With the damping-dependent radius the pair (zeta 0.1: radius 0.5 * 0.1 = 5 %) stays one.
    let p = ClusterParams {
        freq_tol_rel: 0.005,
        freq_tol_per_damping: 0.5,
        ..hand_params()
    };
    let modes = find_invariant_modes(&hand_poles(), 2, &[4, 6], &p).unwrap();
    assert!(modes.iter().any(|m| (m.frequency_hz - 2.01).abs() < 1e-12));
    // A line whose frequency spread is too large is not a disturbance.
    let p = ClusterParams {
        disturbance_freq_spread_max: 1e-4,
        ..hand_params()
    };
    let modes = find_invariant_modes(&hand_poles(), 2, &[4, 6], &p).unwrap();
    assert_eq!(modes[2].class, ModeClass::Structural);
}

#[test]
fn single_record_skips_record_test() {
    let poles: Vec<_> = hand_poles().into_iter().filter(|q| q.record == 1).collect();
    let p = ClusterParams {
        min_record_share: 1.0,
        ..hand_params()
    };
    let poles: Vec<_> = poles
        .into_iter()
        .map(|mut q| {
            q.record = 0;
            q
        })
        .collect();
    let modes = find_invariant_modes(&poles, 1, &[4, 6], &p).unwrap();
    assert!(!modes.is_empty());
    assert!(modes.iter().all(|m| m.class == ModeClass::Structural));
}

fn mode(f: f64, z: f64, class: ModeClass) -> InvariantMode {
    InvariantMode {
        frequency_hz: f,
        frequency_std_hz: 0.01,
        damping_ratio: z,
        damping_iqr: (z * 0.8, z * 1.2),
        order_share: 0.9,
        record_share: 1.0,
        n_poles: 100,
        channels: vec!["RL".into()],
        roles: vec![],
        min_order: 4,
        class,
        line_kurtosis: None,
        shape: None,
        shape_mac: None,
        uncertainty: None,
    }
}

fn reference(f: f64, z: f64, label: &str) -> ReferenceMode {
    ReferenceMode::new(f, z, label)
}

#[test]
fn hand_match_reference() {
    let modes = vec![
        mode(1.0, 0.2, ModeClass::Structural),
        mode(3.0, 0.1, ModeClass::Spurious),
        mode(5.0, 1e-3, ModeClass::PeriodicDisturbance),
        mode(10.0, 0.15, ModeClass::Structural),
    ];
    let refs = vec![
        reference(1.05, 0.3, "heave"),
        reference(5.0, 0.1, "at the line"),
        reference(3.0, 0.1, "at the spurious cluster"),
        reference(9.8, 0.25, "hop FL"),
        reference(10.3, 0.2, "hop RR"),
    ];
    let m = match_reference(&modes, &refs, 0.1);
    assert_eq!(m.len(), 5);
    assert_eq!(m[0].invariant, Some(0));
    close(m[0].freq_diff_rel, (1.0 - 1.05) / 1.05, 1e-12);
    close(m[0].damping_diff, -0.1, 1e-12);
    // the line and the spurious cluster are never matched; the nearest structural mode is 1 Hz
    assert_eq!(m[1].invariant, None);
    close(m[1].freq_diff_rel, -0.8, 1e-12);
    assert_eq!(m[2].invariant, None);
    close(m[2].freq_diff_rel, (1.0 - 3.0) / 3.0, 1e-12);
    // two reference modes may share one invariant mode
    assert_eq!((m[3].invariant, m[4].invariant), (Some(3), Some(3)));
    close(m[3].damping_diff, -0.1, 1e-12);
    assert_eq!(m[4].reference.label, "hop RR");
    // a tighter tolerance leaves 10.3 Hz (2.9 % away) unmatched but keeps 9.8 Hz (2.0 %)
    let m = match_reference(&modes, &refs, 0.025);
    assert_eq!((m[3].invariant, m[4].invariant), (Some(3), None));
    // no structural modes at all: NaN differences, which survive a JSON round trip as null
    let m = match_reference(&modes[1..3], &refs[..1], 0.1);
    assert!(m[0].invariant.is_none() && m[0].freq_diff_rel.is_nan() && m[0].damping_diff.is_nan());
    let json = serde_json::to_string(&m[0]).unwrap();
    let back: ModeMatch = serde_json::from_str(&json).unwrap();
    assert!(back.freq_diff_rel.is_nan());
    // NaN tolerance or NaN reference frequency match nothing
    assert!(match_reference(&modes, &refs, f64::NAN)
        .iter()
        .all(|x| x.invariant.is_none()));
    let m = match_reference(&modes, &[reference(f64::NAN, 0.1, "bad")], 0.1);
    assert!(m[0].invariant.is_none());
    assert!(match_reference(&modes, &[], 0.1).is_empty());
}

#[test]
fn hand_stabilisation() {
    let mk = |f: f64, z: f64, order: usize, ch: &str| PoleObservation::new(f, z, order, 0, ch);
    let poles = vec![
        mk(1.0, 0.2, 2, "A"),     // first order -> new
        mk(1.005, 0.205, 4, "A"), // 0.5 %, 2.5 % -> s
        mk(3.0, 0.1, 4, "A"),     // new
        mk(1.02, 0.2, 6, "A"),    // 1.49 % from 1.005 -> new
        mk(3.01, 0.13, 6, "A"),   // 0.33 %, 30 % -> f
        mk(5.0, 0.01, 6, "A"),    // new
        mk(1.005, 0.205, 4, "B"), // other sweep, first order -> new
        mk(1.0, 0.2, 6, "B"),     // 0.5 %, 2.4 % -> s
    ];
    let s = stabilisation(&poles, &StabilityParams::default()).unwrap();
    use Stability::*;
    assert_eq!(s, vec![New, Stable, New, New, Frequency, New, New, Stable]);
    let symbols: String = s.iter().map(|x| x.symbol()).collect();
    assert_eq!(symbols, "osoofoos");
    // looser frequency tolerance: 1.02 vs 1.005 becomes frequency-stable (damping 2.4 % -> s)
    let p = StabilityParams {
        freq_tol_rel: 0.02,
        ..StabilityParams::default()
    };
    assert_eq!(stabilisation(&poles, &p).unwrap()[3], Stable);
    assert_eq!("s".parse::<Stability>().unwrap(), Stable);
    assert_eq!(
        Frequency.to_string().parse::<Stability>().unwrap(),
        Frequency
    );
    assert!("x"
        .parse::<Stability>()
        .unwrap_err()
        .to_string()
        .contains("frequency_damping"));
    // With shapes on both poles the MAC applies too: orthogonal shapes stop at frequency and
    // damping, equal ones are stable; a pole without a shape is judged without it.
    let shaped = |f: f64, order: usize, shape: [[f64; 2]; 2]| {
        let mut o = mk(f, 0.2, order, "S");
        o.shape = Some(shape.to_vec());
        o
    };
    let with_shapes = vec![
        shaped(2.0, 2, [[1.0, 0.0], [0.0, 0.0]]),
        shaped(2.0, 4, [[0.0, 0.0], [1.0, 0.0]]),
        shaped(2.0, 6, [[0.0, 0.0], [1.0, 0.0]]),
        mk(2.0, 0.2, 8, "S"),
    ];
    assert_eq!(
        stabilisation(&with_shapes, &StabilityParams::default()).unwrap(),
        vec![New, FrequencyDamping, Stable, Stable]
    );
    assert!(stabilisation(&[], &p).unwrap().is_empty());
}

#[test]
fn empty_input_is_ok_empty() {
    let p = script_params();
    assert!(find_invariant_modes(&[], 8, &[2, 3], &p)
        .unwrap()
        .is_empty());
    // even with no records/orders: nothing to check
    assert!(find_invariant_modes(&[], 0, &[], &p).unwrap().is_empty());
    // only filtered poles -> empty, counted as ignored
    let a = analyse_poles(&[pole(50.0, 0.1, 2, 0)], 1, &[2], &p).unwrap();
    assert!(a.modes.is_empty());
    assert_eq!(
        (a.n_used, a.n_ignored, a.labels.clone()),
        (0, 1, vec![None])
    );
}

#[test]
fn bad_inputs_are_errors_naming_the_value() {
    let p = script_params();
    let mut poles = hand_poles();
    poles[7].frequency_hz = f64::NAN;
    let e = find_invariant_modes(&poles, 2, &[4, 6], &p).unwrap_err();
    assert!(
        matches!(e, ModalError::NonFiniteFrequency { index: 7, .. }),
        "{e}"
    );
    assert!(e.to_string().contains("pole 7"));
    assert!(!e.to_string().contains('\n'));

    let mut poles = hand_poles();
    poles[3].damping_ratio = f64::INFINITY;
    let e = find_invariant_modes(&poles, 2, &[4, 6], &p).unwrap_err();
    assert!(
        matches!(e, ModalError::NonFiniteDamping { index: 3, .. }),
        "{e}"
    );
    let e = stabilisation(&poles, &StabilityParams::default()).unwrap_err();
    assert!(
        matches!(e, ModalError::NonFiniteDamping { index: 3, .. }),
        "{e}"
    );

    let e = find_invariant_modes(&hand_poles(), 1, &[4, 6], &p).unwrap_err();
    assert!(
        matches!(
            e,
            ModalError::RecordOutOfRange {
                index: 3,
                record: 1,
                n_records: 1,
                needed: 2
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("n_records >= 2"), "{e}");

    let e = find_invariant_modes(&hand_poles(), 2, &[4], &p).unwrap_err();
    assert!(
        matches!(
            e,
            ModalError::OrderNotListed {
                index: 2,
                order: 6,
                ..
            }
        ),
        "{e}"
    );

    let e = find_invariant_modes(&hand_poles(), 0, &[4, 6], &p).unwrap_err();
    assert!(
        matches!(
            e,
            ModalError::EmptySupport {
                what: "n_records",
                ..
            }
        ),
        "{e}"
    );
    let e = find_invariant_modes(&hand_poles(), 2, &[], &p).unwrap_err();
    assert!(
        matches!(e, ModalError::EmptySupport { what: "orders", .. }),
        "{e}"
    );
}

#[test]
fn invalid_params_are_errors() {
    let bad = [
        ClusterParams {
            freq_tol_rel: 0.0,
            ..script_params()
        },
        ClusterParams {
            freq_tol_per_damping: -0.5,
            ..script_params()
        },
        ClusterParams {
            freq_tol_per_damping: f64::NAN,
            ..script_params()
        },
        ClusterParams {
            freq_tol_rel: -0.01,
            ..script_params()
        },
        ClusterParams {
            log_damping_tol: 0.0,
            ..script_params()
        },
        ClusterParams {
            log_damping_tol: f64::NAN,
            ..script_params()
        },
        ClusterParams {
            min_points: 0,
            ..script_params()
        },
        ClusterParams {
            min_record_share: 1.5,
            ..script_params()
        },
        ClusterParams {
            min_order_share: -0.1,
            ..script_params()
        },
        ClusterParams {
            min_density_share: f64::NAN,
            ..script_params()
        },
        ClusterParams {
            disturbance_damping_max: 0.0,
            ..script_params()
        },
        ClusterParams {
            freq_min_hz: 0.0,
            ..script_params()
        },
        ClusterParams {
            freq_max_hz: Some(0.05),
            ..script_params()
        },
        ClusterParams {
            max_damping_ratio: -1.0,
            ..script_params()
        },
        ClusterParams {
            min_damping_ratio: 0.7,
            ..script_params()
        },
    ];
    for p in &bad {
        let e = find_invariant_modes(&hand_poles(), 2, &[4, 6], p).unwrap_err();
        assert!(matches!(e, ModalError::Param(_)), "{e}");
        assert!(e.to_string().contains("use e.g."), "{e}");
        // even empty input reports bad params
        assert!(find_invariant_modes(&[], 2, &[4, 6], p).is_err());
    }
    let e = find_invariant_modes(&[], 2, &[4, 6], &bad[0]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "freq_tol_rel = 0 must be in [1e-4, 1]; use e.g. freq_tol_rel = 0.02"
    );
    let sp = StabilityParams {
        damping_tol_rel: -1.0,
        ..StabilityParams::default()
    };
    assert!(matches!(
        stabilisation(&hand_poles(), &sp),
        Err(ModalError::Param(_))
    ));
}

#[test]
fn mode_class_parse_display_serde() {
    for c in [
        ModeClass::Structural,
        ModeClass::PeriodicDisturbance,
        ModeClass::Spurious,
    ] {
        assert_eq!(c.to_string().parse::<ModeClass>().unwrap(), c);
        let j = serde_json::to_string(&c).unwrap();
        assert_eq!(j, format!("\"{c}\""));
    }
    assert_eq!(
        "Periodic_Disturbance".parse::<ModeClass>().unwrap(),
        ModeClass::PeriodicDisturbance
    );
    let e = "bogus".parse::<ModeClass>().unwrap_err().to_string();
    assert!(
        e.contains("bogus") && e.contains("structural, periodic-disturbance, spurious"),
        "{e}"
    );
    let m = mode(1.0, 0.2, ModeClass::Structural);
    let back: InvariantMode = serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
    assert_eq!(back, m);
}

/// Two poles of equal damping zeta are neighbours when their frequency ratio is within
/// 1 + max(freq_tol_rel, freq_tol_per_damping * zeta); with min_points = 2 a neighbouring pair
/// is a cluster and a lone pole is noise.
#[test]
fn damping_dependent_radius_boundaries() {
    let p = ClusterParams {
        min_points: 2,
        min_density_share: 0.0,
        min_record_share: 0.0,
        min_order_share: 0.0,
        freq_tol_per_damping: 0.5,
        ..script_params()
    };
    let pair = |f2: f64, z: f64| {
        let poles = vec![pole(1.0, z, 4, 0), pole(f2, z, 6, 0)];
        find_invariant_modes(&poles, 1, &[4, 6], &p).unwrap().len()
    };
    // zeta 0.2: radius 0.5 * 0.2 = 10 %.
    assert_eq!(pair(1.099, 0.2), 1);
    assert_eq!(pair(1.101, 0.2), 0);
    // zeta 0.3: radius 15 %.
    assert_eq!(pair(1.149, 0.3), 1);
    assert_eq!(pair(1.151, 0.3), 0);
    // zeta 0.002 (a line): 0.5 * 0.002 = 0.1 % < freq_tol_rel, so the floor of 2 % holds.
    assert_eq!(pair(1.0199, 0.002), 1);
    assert_eq!(pair(1.0201, 0.002), 0);
    // Different dampings: the radius uses the geometric mean, sqrt(0.16 * 0.25) = 0.2 -> 10 %,
    // and the damping distance log10(0.25 / 0.16) / 0.2 = 0.969 must be added in quadrature:
    // sqrt((ln(f2) / ln(1.1))^2 + 0.969^2) <= 1 needs ln(f2) <= 0.2467 * ln(1.1), f2 <= 1.0238.
    let mixed = |f2: f64| {
        let poles = vec![pole(1.0, 0.16, 4, 0), pole(f2, 0.25, 6, 0)];
        find_invariant_modes(&poles, 1, &[4, 6], &p).unwrap().len()
    };
    assert_eq!(mixed(1.0230), 1);
    assert_eq!(mixed(1.0246), 0);
    // Off (0): the fixed 2 % radius for every damping.
    let fixed = ClusterParams {
        freq_tol_per_damping: 0.0,
        ..p.clone()
    };
    assert_eq!(ClusterParams::default().freq_tol_per_damping, 0.5);
    let poles = vec![pole(1.0, 0.3, 4, 0), pole(1.05, 0.3, 6, 0)];
    assert!(find_invariant_modes(&poles, 1, &[4, 6], &fixed)
        .unwrap()
        .is_empty());
}

/// A heavily damped mode whose poles scatter by 10 % steps (1.0, 1.1, 1.21, 1.331 Hz, zeta 0.3)
/// is one cluster with freq_tol_per_damping 0.5 (15 % at zeta 0.3) but only noise with the old fixed
/// 2 %; two lines 3 % apart (zeta 0.002) stay two clusters either way.
#[test]
fn damped_mode_is_not_fragmented_lines_stay_apart() {
    let orders = [4, 6, 8, 10];
    let mut poles = Vec::new();
    for (k, &o) in orders.iter().enumerate() {
        poles.push(pole(1.1f64.powi(k as i32), 0.3, o, 0));
        poles.push(pole(5.0, 0.002, o, 0));
        poles.push(pole(5.15, 0.002, o, 0));
    }
    let p = ClusterParams {
        min_points: 3,
        min_density_share: 0.0,
        freq_tol_per_damping: 0.5,
        ..script_params()
    };
    let modes = find_invariant_modes(&poles, 1, &orders, &p).unwrap();
    assert_eq!(modes.len(), 3, "{modes:?}");
    close(
        modes[0].frequency_hz,
        (1.0 + 1.1 + 1.21 + 1.331) / 4.0,
        1e-12,
    );
    assert_eq!((modes[0].n_poles, modes[0].order_share), (4, 1.0));
    assert_eq!(modes[0].class, ModeClass::Structural);
    close(modes[1].frequency_hz, 5.0, 1e-12);
    close(modes[2].frequency_hz, 5.15, 1e-12);
    assert!(modes[1..]
        .iter()
        .all(|m| m.class == ModeClass::PeriodicDisturbance));
    let fixed = ClusterParams {
        freq_tol_per_damping: 0.0,
        ..p
    };
    let modes = find_invariant_modes(&poles, 1, &orders, &fixed).unwrap();
    assert_eq!(modes.len(), 2);
    assert!(modes.iter().all(|m| m.frequency_hz > 4.0));
}
