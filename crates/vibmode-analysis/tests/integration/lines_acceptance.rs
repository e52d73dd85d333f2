//! Acceptance of the periodic-line detection on the realistic simulator (the demo's settings:
//! wandering, amplitude-modulated lines whose engine speed changes from record to record and a
//! driveline line that follows the speed, swept by braking and acceleration; a flexible bus
//! whose bending mode sits between the axle modes), over five seeds, with recall and precision
//! per record over every true line of every record:
//! - steady lines (frequency range within the record < 0.2 Hz): found when a steady entry of the
//!   record (`record_hz`) lies within 0.1 Hz of its mean;
//! - swept lines (range >= 0.2 Hz; the subset >= `sweep_min_range_hz` counted apart): found by a
//!   steady entry as above, or by a sweep entry (`record_sweep`) whose mean is within 0.2 Hz of
//!   the line's mean and whose lowest and highest frequencies are each within 0.3 Hz of the
//!   line's (the ridge starts and ends half a slice inside the record);
//! - precision: of all entries (steady and swept), the share matching a true line of that
//!   record by the same rules;
//! - no cluster within 0.3 Hz of a structural mode and away from every line is classed periodic.
//!
//! The same records are analysed with swept lines off (`sweep_min_range_hz = 0`: the detection
//! before swept lines) and on (the defaults), and both figures printed (docs/analysis.md).
//! Simulated at 500 Hz (the lines and modes lie below 15 Hz) and with a short order sweep: the
//! line stage does not depend on the sweep.

use crate::common;

use vibmode_analysis::{analyze, AnalysisConfig, LineSweep, Role};
use vibmode_core::{LineParams, ModeClass, SweepParams};
use vibmode_vehicle::LineTruth;

#[derive(Default, Debug)]
struct Counts {
    steady: (usize, usize),
    swept: (usize, usize),
    wide: (usize, usize),
    entries: usize,
    correct: usize,
    wrongly_periodic: Vec<(u64, f64, Option<f64>)>,
}

fn sweep_matches(s: &LineSweep, l: &LineTruth, r: usize) -> bool {
    (s.mean_hz - l.record_mean_hz[r]).abs() < 0.2
        && (s.range_hz.0 - l.record_min_hz[r]).abs() < 0.3
        && (s.range_hz.1 - l.record_max_hz[r]).abs() < 0.3
}

fn run(lines: LineParams) -> Counts {
    let mut c = Counts::default();
    for seed in 1..=5u64 {
        let (_, sim) = common::realistic_demo(seed);
        let records = common::inputs(&sim);
        let cfg = AnalysisConfig {
            sweep: SweepParams {
                order_max: 8,
                ..SweepParams::default()
            },
            lines: lines.clone(),
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
            let steady_got: Vec<f64> = sprung.lines.iter().filter_map(|t| t.record_hz[r]).collect();
            let swept_got: Vec<&LineSweep> = sprung
                .lines
                .iter()
                .filter_map(|t| t.record_sweep.get(r).and_then(Option::as_ref))
                .collect();
            for l in truth {
                let range = l.record_max_hz[r] - l.record_min_hz[r];
                let by_steady = steady_got
                    .iter()
                    .any(|g| (g - l.record_mean_hz[r]).abs() < 0.1);
                let by_sweep = swept_got.iter().any(|s| sweep_matches(s, l, r));
                let hit = usize::from(by_steady || by_sweep);
                if range < 0.2 {
                    c.steady.0 += usize::from(by_steady);
                    c.steady.1 += 1;
                } else {
                    c.swept.0 += hit;
                    c.swept.1 += 1;
                    if range >= LineParams::default().sweep_min_range_hz {
                        c.wide.0 += hit;
                        c.wide.1 += 1;
                    }
                }
            }
            c.entries += steady_got.len() + swept_got.len();
            c.correct += steady_got
                .iter()
                .filter(|g| truth.iter().any(|l| (*g - l.record_mean_hz[r]).abs() < 0.1))
                .count();
            c.correct += swept_got
                .iter()
                .filter(|s| truth.iter().any(|l| sweep_matches(s, l, r)))
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
                c.wrongly_periodic
                    .push((seed, m.frequency_hz, m.line_kurtosis));
            }
        }
    }
    c
}

fn describe(name: &str, c: &Counts) -> String {
    let f = |(a, b): (usize, usize)| format!("{a}/{b} = {:.2}", a as f64 / b.max(1) as f64);
    format!(
        "{name}: steady recall {}, swept recall {} (range >= {} Hz: {}), precision {}, clusters wrongly periodic {:?}",
        f(c.steady),
        f(c.swept),
        LineParams::default().sweep_min_range_hz,
        f(c.wide),
        f((c.correct, c.entries)),
        c.wrongly_periodic
    )
}

#[test]
#[ignore = "acceptance tier (about 10 s): cargo test --workspace -- --ignored"]
fn lines_are_found_per_record_over_five_seeds() {
    let before = run(LineParams {
        sweep_min_range_hz: 0.0,
        ..LineParams::default()
    });
    let after = run(LineParams::default());
    let msg = format!(
        "{}\n{}",
        describe("swept lines off", &before),
        describe("swept lines on (defaults)", &after)
    );
    eprintln!("{msg}");
    let ratio = |(a, b): (usize, usize)| a as f64 / b.max(1) as f64;
    for c in [&before, &after] {
        assert!(ratio(c.steady) >= 0.85, "{msg}");
        assert!(c.wrongly_periodic.is_empty(), "{msg}");
    }
    // Precision with the defaults. With swept lines off (not a default) the F-test's steady
    // line at the end of a braking sweep (5.15 Hz after braking from 7 Hz; the record's mean
    // is 5.9 Hz) counts as a wrong entry: 101/111 measured when the F-test came in (issue 30),
    // against 99/99 with the kurtosis rule alone; required there: 0.85.
    assert!(ratio((after.correct, after.entries)) >= 0.95, "{msg}");
    assert!(ratio((before.correct, before.entries)) >= 0.85, "{msg}");
    // Swept lines on: the steady recall not lower (a braking sweep carries its track to the
    // steady line after it: 61 -> 68 of 70 measured), the wide sweeps found.
    assert!(after.steady.0 >= before.steady.0, "{msg}");
    assert!(ratio(after.steady) >= 0.95, "{msg}");
    assert!(ratio(after.wide) >= 0.9, "{msg}");
    assert!(after.swept.0 > before.swept.0, "{msg}");
}
