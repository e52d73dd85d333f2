//! The default settings on a real recording: the Bratislava city bus (one MEMS channel on the
//! floor, 500 Hz, normal driving with stops; /work/shared/data/README.md). Skips with a message
//! when the shared data folder is absent.

use std::path::Path;

use vibmode_analysis::{analyze, cut_records, AnalysisConfig, Role};
use vibmode_modal::ModeClass;
use vibmode_signal::{read_path, ChannelSelector, ReadOptions};

const BUS: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/real/bratislava_transit/L35_1915_Borska_Zaluhy.csv"
);

#[test]
fn bus_body_mode_with_default_settings() {
    let path = Path::new(BUS);
    if !path.exists() {
        eprintln!("skipped: {BUS} not found (shared real data absent)");
        return;
    }
    let opts = ReadOptions {
        fs_hz: Some(500.0),
        ..ReadOptions::default()
    };
    let rec = read_path(path, &opts).expect("read the bus file");
    let rec = rec
        .select(&[ChannelSelector::Name("z".into())])
        .expect("channel z");
    let cfg = AnalysisConfig::default();
    let records = cut_records("bus", &rec, cfg.record_length_s);
    assert_eq!(records.len(), 21);
    let t0 = std::time::Instant::now();
    let res = analyze(&records, &cfg, &[], &|_, _| {}).expect("analysis");
    eprintln!("analysis took {:.1} s", t0.elapsed().as_secs_f64());
    let stops: Vec<usize> = (0..res.records.len())
        .filter(|&i| res.records[i].stationary)
        .collect();
    eprintln!("stationary records: {stops:?}");
    // The two records at rest (engine idling only, RMS ~0.2-0.3 x the median) are stops; the
    // driving records are not.
    assert!(stops.contains(&4) && stops.contains(&5), "{stops:?}");
    assert!(stops.len() <= 3, "{stops:?}");
    // A channel without a role is analysed alone, never pooled.
    assert!(
        res.roles.is_empty(),
        "no role pools for a channel without a role"
    );
    let role = res
        .channels
        .iter()
        .find(|c| c.name == "z" && c.role == Role::Other)
        .expect("channel z");
    for m in &role.invariant_modes {
        if m.is_invariant() {
            eprintln!(
                "{:.3} Hz zeta {:.3} {:?} orders {:.2} records {:.2}",
                m.frequency_hz, m.damping_ratio, m.class, m.order_share, m.record_share
            );
        }
    }
    let body: Vec<_> = role
        .invariant_modes
        .iter()
        .filter(|m| m.class == ModeClass::Structural && (0.7..=2.0).contains(&m.frequency_hz))
        .collect();
    assert_eq!(body.len(), 1, "one body mode between 0.7 and 2 Hz expected");
    // A heavily damped body mode, as the stabilisation figures show (zeta 0.1-0.6).
    assert!((0.1..0.6).contains(&body[0].damping_ratio), "{:?}", body[0]);
}

const IDLING: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/real/bratislava_transit/L35_1915_Most_Kutiky_neutral.csv"
);

/// The same bus standing with its engine idling: no road input, only engine lines. The firing
/// line near 10.8 Hz and its 1.5 order near 16.3 Hz are reported as periodic lines and every
/// supported cluster is classed periodic (nothing else excites the bus).
#[test]
fn idling_bus_engine_lines_are_lines() {
    let path = Path::new(IDLING);
    if !path.exists() {
        eprintln!("skipped: {IDLING} not found (shared real data absent)");
        return;
    }
    let opts = ReadOptions {
        fs_hz: Some(500.0),
        ..ReadOptions::default()
    };
    let rec = read_path(path, &opts).expect("read the idling file");
    let rec = rec
        .select(&[ChannelSelector::Name("z".into())])
        .expect("channel z");
    let cfg = AnalysisConfig::default();
    let records = cut_records("idling", &rec, cfg.record_length_s);
    let res = analyze(&records, &cfg, &[], &|_, _| {}).expect("analysis");
    let ch = &res.channels[0];
    for f0 in [10.83, 16.27] {
        assert!(
            ch.lines
                .iter()
                .any(|t| (t.frequency_hz - f0).abs() < 0.1 && t.kurtosis < 2.0),
            "no line at {f0} Hz: {:?}",
            ch.lines
        );
    }
    let supported: Vec<_> = ch
        .invariant_modes
        .iter()
        .filter(|m| m.class != ModeClass::Spurious)
        .collect();
    assert!(!supported.is_empty());
    for m in supported {
        assert_eq!(m.class, ModeClass::PeriodicDisturbance, "{m:?}");
    }
}
