//! Acceptance of the periodic-line detection on the realistic simulator (the demo's settings:
//! wandering, amplitude-modulated lines whose engine speed changes from record to record and a
//! driveline line that follows the speed; a flexible bus whose bending mode sits between the
//! axle modes), over five seeds, with recall and precision per record:
//! - recall: of the lines steady within a record (frequency range < 0.2 Hz), the share found in
//!   that record's tracks within 0.1 Hz;
//! - precision: of the track entries, the share within 0.1 Hz of a true line of that record;
//! - no cluster within 0.3 Hz of a structural mode and away from every line is classed periodic.
//!
//! Simulated at 500 Hz (the lines and modes lie below 15 Hz) and with a short order sweep: the
//! line stage does not depend on the sweep.

mod common;

use vibmode_analysis::{analyze, AnalysisConfig, Role};
use vibmode_core::{ModeClass, SweepParams};

#[test]
fn lines_are_found_per_record_over_five_seeds() {
    let (mut true_lines, mut found, mut entries, mut correct) = (0, 0, 0, 0);
    let mut wrongly_periodic = Vec::new();
    for seed in 1..=5u64 {
        let (_, sim) = common::realistic_demo(seed);
        let records = common::inputs(&sim);
        let cfg = AnalysisConfig {
            sweep: SweepParams {
                order_max: 8,
                ..SweepParams::default()
            },
            ..AnalysisConfig::default()
        };
        let res = analyze(&records, &cfg, &[], &|_, _| {}).expect("analysis");
        let sprung = res
            .roles
            .iter()
            .find(|x| x.role == Role::Sprung)
            .expect("sprung pool");
        let truth = &sim.truth.lines;
        for r in 0..records.len() {
            if res.records[r].stationary {
                continue;
            }
            let steady: Vec<f64> = truth
                .iter()
                .filter(|l| l.record_max_hz[r] - l.record_min_hz[r] < 0.2)
                .map(|l| l.record_mean_hz[r])
                .collect();
            let all: Vec<f64> = truth.iter().map(|l| l.record_mean_hz[r]).collect();
            let got: Vec<f64> = sprung.lines.iter().filter_map(|t| t.record_hz[r]).collect();
            true_lines += steady.len();
            found += steady
                .iter()
                .filter(|f| got.iter().any(|g| (g - *f).abs() < 0.1))
                .count();
            entries += got.len();
            correct += got
                .iter()
                .filter(|g| all.iter().any(|f| (*g - f).abs() < 0.1))
                .count();
        }
        for m in &sprung.invariant_modes {
            let near_line = truth.iter().any(|l| {
                (l.record_min_hz
                    .iter()
                    .cloned()
                    .fold(f64::INFINITY, f64::min)
                    - 0.3
                    ..=l.record_max_hz.iter().cloned().fold(0.0, f64::max) + 0.3)
                    .contains(&m.frequency_hz)
            });
            if m.class == ModeClass::PeriodicDisturbance && !near_line {
                wrongly_periodic.push((seed, m.frequency_hz, m.line_kurtosis));
            }
        }
    }
    let recall = found as f64 / true_lines as f64;
    let precision = correct as f64 / entries.max(1) as f64;
    let msg = format!(
        "recall {found}/{true_lines} = {recall:.2}, precision {correct}/{entries} = {precision:.2}, clusters wrongly periodic {wrongly_periodic:?}"
    );
    eprintln!("{msg}");
    assert!(recall >= 0.85, "{msg}");
    assert!(precision >= 0.85, "{msg}");
    assert!(wrongly_periodic.is_empty(), "{msg}");
}
