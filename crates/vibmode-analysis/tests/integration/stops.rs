//! Stops (issue #5): a simulated drive with two records at rest (small sensor noise plus an engine
//! tone, no road input). The stop records must be marked stationary and left out of the mode
//! statistics, and the body mode must still be found in every driving record.

use vibmode_analysis::{analyze, AnalysisConfig, RecordInput, Role};
use vibmode_modal::ModeClass;
use vibmode_signal::{Channel, Recording};
use vibmode_vehicle::{simulate, SimParams, VehicleParams};

/// Deterministic pseudo-random noise in [-1, 1) (a 64-bit LCG; no extra dependency).
fn noise(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

fn records_with_stops() -> (Vec<RecordInput>, Vec<f64>) {
    let vehicle = VehicleParams::city_bus();
    let params = SimParams {
        fs_hz: 500.0,
        ..SimParams::demo_ideal(6, 3)
    };
    let sim = simulate(&vehicle, &params).expect("simulation");
    let body: Vec<f64> = sim
        .truth
        .modes
        .iter()
        .filter(|m| m.frequency_hz < 3.0)
        .map(|m| m.frequency_hz)
        .collect();
    let mut out: Vec<RecordInput> = Vec::new();
    let mut state = 7u64;
    for (i, r) in sim.records.iter().enumerate() {
        let fs_hz = r.recording.fs_hz;
        let rec = |samples: Vec<Vec<f64>>| Recording {
            fs_hz,
            channels: r
                .recording
                .channels
                .iter()
                .zip(samples)
                .map(|(c, s)| Channel {
                    samples: s,
                    ..c.clone()
                })
                .collect(),
            time_axis: None,
        };
        out.push(RecordInput {
            name: format!("drive {i}"),
            recording: r.recording.clone(),
        });
        if i == 1 || i == 4 {
            // A stop after records 1 and 4: engine idling at 13.3 Hz (0.02 m/s^2) plus sensor
            // noise (0.01 m/s^2), nothing else.
            let stop: Vec<Vec<f64>> = r
                .recording
                .channels
                .iter()
                .map(|c| {
                    (0..c.samples.len())
                        .map(|k| {
                            let t = k as f64 / fs_hz;
                            0.02 * (2.0 * std::f64::consts::PI * 13.3 * t).sin()
                                + 0.01 * noise(&mut state)
                        })
                        .collect()
                })
                .collect();
            out.push(RecordInput {
                name: format!("stop after {i}"),
                recording: rec(stop),
            });
        }
    }
    (out, body)
}

#[test]
fn stop_records_are_excluded_and_modes_still_found() {
    let (records, body) = records_with_stops();
    assert_eq!(records.len(), 8);
    // Fewer orders than the default to keep the test short; stop detection does not depend on it.
    let mut cfg = AnalysisConfig::default();
    cfg.sweep.order_max = 16;
    let res = analyze(&records, &cfg, &[], &|_, _| {}).expect("analysis");
    for r in &res.records {
        eprintln!(
            "{}: activity {:.3} stationary {} {:?}",
            r.name, r.activity_ratio, r.stationary, r.excluded_reason
        );
        assert_eq!(r.stationary, r.name.starts_with("stop"), "{}", r.name);
        assert_eq!(r.excluded_reason.is_some(), r.stationary);
        assert_eq!(r.activity_rms.len(), 7);
    }
    assert_eq!(res.n_stationary, 2);
    // The stops are decided before the sweep, which runs only on the other records (and on the
    // first, for the report's model spectra): no pole or fit of a stop record.
    let stops: Vec<usize> = (0..res.records.len())
        .filter(|&i| res.records[i].stationary)
        .collect();
    assert!(!stops.contains(&0));
    for ch in &res.channels {
        assert!(ch.poles.iter().all(|p| !stops.contains(&p.record)));
        assert!(ch.fits.iter().all(|f| !stops.contains(&f.record)));
        assert!(ch.poles.iter().any(|p| p.record == 1));
    }
    assert_eq!(res.n_fits, 6 * 7 * cfg.orders().len());

    let sprung = res
        .roles
        .iter()
        .find(|r| r.role == Role::Sprung)
        .expect("sprung role");
    for m in &sprung.invariant_modes {
        eprintln!(
            "{:.3} Hz zeta {:.3} {:?} orders {:.2} records {:.2}",
            m.frequency_hz, m.damping_ratio, m.class, m.order_share, m.record_share
        );
    }
    let body_mode = sprung
        .invariant_modes
        .iter()
        .find(|m| m.class == ModeClass::Structural && m.frequency_hz < 3.0)
        .expect("body mode found");
    assert!(
        body.iter()
            .any(|f| (body_mode.frequency_hz - f).abs() <= 0.1 * f),
        "{} Hz vs {body:?}",
        body_mode.frequency_hz
    );
    // Shares are over the 6 driving records: the body mode is in all of them.
    assert_eq!(body_mode.record_share, 1.0);
    // The idling tone of the stops is no invariant mode.
    assert!(res
        .roles
        .iter()
        .flat_map(|r| &r.invariant_modes)
        .all(|m| !m.is_invariant() || (m.frequency_hz - 13.3).abs() > 0.2));

    // The averaged Welch PSD leaves the stops out: averaged in (below), the two quiet stop records
    // pull the mean of the 8 records down to about 6/8 of the driving records' level.
    let tone_level = |r: &vibmode_analysis::AnalysisResults| -> f64 {
        let ch = &r.channels[0];
        let k = ch
            .welch_freq_hz
            .iter()
            .enumerate()
            .min_by(|a, b| (a.1 - 13.3).abs().total_cmp(&(b.1 - 13.3).abs()))
            .map(|(k, _)| k)
            .expect("welch bins");
        ch.welch_psd[k]
    };
    let tone_without_stops = tone_level(&res);

    // Without stop detection the stops dilute the shares: 6 of 8 records at most.
    let mut off = cfg;
    off.stops.stop_rms_ratio = 0.0;
    let res = analyze(&records, &off, &[], &|_, _| {}).expect("analysis");
    assert_eq!(res.n_stationary, 0);
    let ratio = tone_level(&res) / tone_without_stops;
    assert!((0.7..0.8).contains(&ratio), "ratio {ratio}");
    let sprung = res
        .roles
        .iter()
        .find(|r| r.role == Role::Sprung)
        .expect("sprung role");
    assert!(sprung
        .invariant_modes
        .iter()
        .filter(|m| m.frequency_hz < 3.0)
        .all(|m| m.record_share <= 0.75));
}
