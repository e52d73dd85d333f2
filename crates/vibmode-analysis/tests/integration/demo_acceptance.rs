//! Acceptance on the project's own simulator, with the default settings (the demo's data):
//! the periodic lines are found within 0.05 Hz and classed as disturbances, the wheel-hop modes
//! within 5 %, the body modes within 10 %, no structural mode is classed as a disturbance, and
//! the model's modes are matched one to one.

use crate::common;

use vibmode_analysis::{analyze, AnalysisConfig, Role};
use vibmode_modal::{ModeClass, ReferenceMode};
use vibmode_vehicle::{simulate, SimParams, VehicleParams};

#[test]
fn demo_data_gives_the_true_modes_and_lines() {
    let vehicle = VehicleParams::city_bus();
    let sim = simulate(&vehicle, &SimParams::demo_ideal(8, 1)).expect("simulation");
    let records = common::inputs(&sim);
    let reference: Vec<ReferenceMode> = sim.truth.modes.iter().map(|m| m.to_reference()).collect();
    let cfg = AnalysisConfig::default();
    let res = analyze(&records, &cfg, &reference, &|_, _| {}).expect("analysis");
    let role = |r: Role| {
        res.roles
            .iter()
            .find(|x| x.role == r)
            .expect("role present")
    };
    let body: Vec<f64> = sim
        .truth
        .modes
        .iter()
        .filter(|m| m.label.is_body_rigid())
        .map(|m| m.frequency_hz)
        .collect();
    let hop: Vec<f64> = sim
        .truth
        .modes
        .iter()
        .filter(|m| m.frequency_hz > 5.0)
        .map(|m| m.frequency_hz)
        .collect();
    let lines = &sim.truth.disturbance_lines_hz;
    assert_eq!(lines.len(), 3);
    let near = |f: f64, set: &[f64], rel: f64| set.iter().any(|t| (f - t).abs() <= rel * t);
    for r in [Role::Sprung, Role::Unsprung] {
        for m in &role(r).invariant_modes {
            eprintln!(
                "{r}: {:.3} Hz zeta {:.4} {:?} orders {:.2} records {:.2}",
                m.frequency_hz, m.damping_ratio, m.class, m.order_share, m.record_share
            );
        }
    }
    // Periodic lines: each found within 0.05 Hz on the sprung channels and classed as such.
    let sprung = role(Role::Sprung);
    for f in lines {
        assert!(
            sprung.invariant_modes.iter().any(|m| {
                m.class == ModeClass::PeriodicDisturbance && (m.frequency_hz - f).abs() <= 0.05
            }),
            "line at {f} Hz not found as a periodic disturbance"
        );
    }
    // No structural mode classed as a disturbance: every disturbance is one of the true lines.
    for r in &res.roles {
        for m in r
            .invariant_modes
            .iter()
            .filter(|m| m.class == ModeClass::PeriodicDisturbance)
        {
            assert!(
                lines.iter().any(|f| (m.frequency_hz - f).abs() <= 0.1),
                "{} Hz on {} classed as a disturbance but is no line",
                m.frequency_hz,
                r.role
            );
        }
    }
    // Body modes (heavily damped, close together) within 10 % on the sprung channels.
    let sprung_body: Vec<f64> = sprung
        .invariant_modes
        .iter()
        .filter(|m| m.class == ModeClass::Structural && m.frequency_hz < 3.0)
        .map(|m| m.frequency_hz)
        .collect();
    assert!(!sprung_body.is_empty(), "no body mode found");
    for f in &sprung_body {
        assert!(
            near(*f, &body, 0.10),
            "body mode {f} Hz not within 10 % of {body:?}"
        );
    }
    // Wheel-hop modes within 5 % on the unsprung channels.
    let unsprung = role(Role::Unsprung);
    let hops: Vec<f64> = unsprung
        .invariant_modes
        .iter()
        .filter(|m| m.class == ModeClass::Structural && m.frequency_hz > 5.0)
        .map(|m| m.frequency_hz)
        .collect();
    assert!(!hops.is_empty(), "no wheel-hop mode found");
    for f in &hops {
        assert!(
            near(*f, &hop, 0.05),
            "wheel-hop mode {f} Hz not within 5 % of {hop:?}"
        );
    }
    // The model's modes are matched one to one, each to its nearest free structural mode: the
    // sprung pool's body cluster is one body mode, not heave, pitch and roll at once.
    for r in &res.roles {
        let mut used = std::collections::HashSet::new();
        for m in &r.matches {
            let Some(k) = m.invariant else { continue };
            assert!(used.insert(k), "{}: mode {k} matched twice", r.role);
            assert_eq!(r.invariant_modes[k].class, ModeClass::Structural);
            assert!(m.freq_diff_rel.abs() <= 0.25, "{m:?}");
        }
        assert_eq!(r.matches.len(), reference.len());
    }
    let sprung_matched = sprung.matches.iter().filter(|m| m.invariant.is_some());
    assert!(
        sprung_matched.count() >= 1,
        "no model mode matched on the sprung channels"
    );
    // Every structural mode on either role is near a true mode (no spurious structural modes).
    let all_true: Vec<f64> = sim.truth.modes.iter().map(|m| m.frequency_hz).collect();
    for r in &res.roles {
        for m in r
            .invariant_modes
            .iter()
            .filter(|m| m.class == ModeClass::Structural)
        {
            assert!(
                near(m.frequency_hz, &all_true, 0.10),
                "structural mode {} Hz on {} is near no true mode",
                m.frequency_hz,
                r.role
            );
        }
    }
}
