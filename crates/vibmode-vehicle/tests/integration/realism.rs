#![allow(clippy::needless_range_loop)]
//! The simulator's in-service effects, each checked against what it must do physically, over
//! several seeds: lines that move from record to record and follow the speed, wander and
//! amplitude modulation, misaligned sensors, speed variation, bending shapes at the sensors.
use vibmode_vehicle::*;

const SEEDS: [u64; 5] = [1, 2, 3, 4, 5];

/// Frequency of the largest |DFT| bin of `x` (mean removed, Hann, zero-padded 8x) in [lo, hi].
fn peak_hz(x: &[f64], fs: f64, lo: f64, hi: f64) -> f64 {
    let n = x.len() * 8;
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let mut buf = vec![0.0; n];
    for (i, v) in x.iter().enumerate() {
        let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / x.len() as f64).cos();
        buf[i] = (v - mean) * w;
    }
    let fft = vibmode_fft::forward(n);
    let mut spec = fft.make_output_vec();
    fft.process(&mut buf, &mut spec).unwrap();
    let df = fs / n as f64;
    let (mut best, mut at) = (0.0, 0.0);
    for (k, c) in spec.iter().enumerate() {
        let f = k as f64 * df;
        if f >= lo && f <= hi && c.norm() > best {
            best = c.norm();
            at = f;
        }
    }
    at
}

/// A quiet drive (class A road, low rate) with one strong line at `f0` on the body.
fn one_line(seed: u64, line: EngineLine, dist: Disturbances) -> SimParams {
    SimParams {
        speed_kmh: 40.0,
        road: RoadClass::A,
        fs_hz: 200.0,
        records: 6,
        seed,
        disturbances: Disturbances {
            engine_lines: vec![line],
            ..dist
        },
        ..SimParams::default()
    }
}

#[test]
fn record_to_record_engine_speed_moves_the_line_as_the_truth_says() {
    let bus = VehicleParams::city_bus();
    let mut spreads = Vec::new();
    for seed in SEEDS {
        let line = EngineLine {
            x_m: -3.0,
            ..EngineLine::constant(12.0, 3000.0)
        };
        let sp = one_line(
            seed,
            line,
            Disturbances {
                engine_speed_record_rel_std: 0.03,
                ..Disturbances::default()
            },
        );
        let sim = simulate(&bus, &sp).unwrap();
        let truth = &sim.truth.lines[0];
        assert_eq!(truth.record_mean_hz.len(), 6);
        for (r, rec) in sim.records.iter().enumerate() {
            let x = &rec.recording.channels[5].samples; // RL_sprung
            let f = peak_hz(x, 200.0, 9.0, 15.0);
            // the peak is where the truth says (resolution 1/10.24 s, zero padded)
            assert!(
                (f - truth.record_mean_hz[r]).abs() < 0.03,
                "seed {seed} record {r}: peak {f:.3} Hz, truth {:.3} Hz",
                truth.record_mean_hz[r]
            );
            // a constant factor per record: the line does not move within the record
            assert!(truth.record_max_hz[r] - truth.record_min_hz[r] < 1e-9);
        }
        let m = &truth.record_mean_hz;
        spreads.push(
            m.iter().cloned().fold(f64::MIN, f64::max) - m.iter().cloned().fold(f64::MAX, f64::min),
        );
    }
    // with a 3 % spread, six records span several tenths of a hertz at 12 Hz
    let typical = spreads.iter().sum::<f64>() / spreads.len() as f64;
    assert!(typical > 0.3 && typical < 2.5, "spreads {spreads:?}");
}

#[test]
fn wander_and_modulation_have_their_stated_size() {
    let bus = VehicleParams::city_bus();
    for seed in SEEDS {
        let line = EngineLine {
            wander_rel_std: 0.01,
            wander_correlation_s: 0.5,
            am_rel_std: 0.1,
            ..EngineLine::constant(12.0, 3000.0)
        };
        let sp = one_line(seed, line, Disturbances::default());
        let sim = simulate(&bus, &sp).unwrap();
        let t = &sim.truth.lines[0];
        // within a record of 20 correlation times, the instantaneous frequency ranges over
        // several standard deviations (0.12 Hz each) but stays within 6 of them
        for r in 0..6 {
            let range = t.record_max_hz[r] - t.record_min_hz[r];
            assert!(
                range > 0.2 && range < 6.0 * 2.0 * 0.12,
                "seed {seed}: range {range}"
            );
            assert!(
                (t.record_mean_hz[r] - 12.0).abs() < 0.12,
                "seed {seed}: mean {}",
                t.record_mean_hz[r]
            );
        }
    }
}

#[test]
fn the_driveline_line_follows_the_speed_through_braking() {
    let bus = VehicleParams::city_bus();
    for seed in SEEDS {
        let line = EngineLine {
            speed_coupling: 1.0,
            ..EngineLine::constant(7.0, 3000.0)
        };
        let mut sp = one_line(seed, line, Disturbances::default());
        sp.speed_kmh = 36.0; // 10 m/s
                             // brake by 2.5 m/s in record 1 (peak 1.25 m/s^2 over 4 s of sin^2: mean 0.625)
        sp.manoeuvres = vec![Manoeuvre {
            start_s: 13.0,
            duration_s: 4.0,
            longitudinal_accel_m_s2: -1.25,
            lateral_accel_m_s2: 0.0,
        }];
        let sim = simulate(&bus, &sp).unwrap();
        let t = &sim.truth.lines[0];
        assert!((t.record_mean_hz[0] - 7.0).abs() < 1e-6);
        // after braking: 7 Hz x 7.5 / 10
        assert!(
            (t.record_mean_hz[3] - 5.25).abs() < 0.01,
            "{:?}",
            t.record_mean_hz
        );
        assert!(
            t.record_max_hz[1] - t.record_min_hz[1] > 1.7,
            "swept within record 1"
        );
        let mean_kmh = sim.records[3].mean_speed_kmh;
        assert!((mean_kmh - 27.0).abs() < 0.1, "speed {mean_kmh}");
        let f = peak_hz(
            &sim.records[3].recording.channels[5].samples,
            200.0,
            4.0,
            8.0,
        );
        assert!((f - 5.25).abs() < 0.03, "seed {seed}: peak {f}");
    }
}

#[test]
fn misaligned_sensors_feel_the_turn() {
    let bus = VehicleParams::city_bus();
    for seed in SEEDS {
        let turn = Manoeuvre {
            start_s: 10.24,
            duration_s: 10.24,
            longitudinal_accel_m_s2: 0.0,
            lateral_accel_m_s2: 2.0,
        };
        let mut sp = SimParams {
            speed_kmh: 40.0,
            road: RoadClass::A,
            fs_hz: 200.0,
            records: 3,
            seed,
            manoeuvres: vec![turn],
            ..SimParams::default()
        };
        let aligned = simulate(&bus, &sp).unwrap();
        sp.disturbances.sensor_misalignment_max_deg = 5.0;
        let tilted = simulate(&bus, &sp).unwrap();
        let tilt = &tilted.truth.sensor_misalignment_deg;
        assert_eq!(tilt.len(), 7);
        assert!(tilt.iter().flatten().all(|a| a.abs() <= 5.0));
        assert!(tilt.iter().flatten().any(|a| a.abs() > 0.5));
        // during the turn (record 1) the mean difference is sin(b) x mean lateral
        // acceleration (2 m/s^2 x 1/2 for sin^2) plus the (1 - cos) loss of a small signal
        for c in 0..7 {
            let a = &aligned.records[1].recording.channels[c].samples;
            let b = &tilted.records[1].recording.channels[c].samples;
            let d = b.iter().zip(a).map(|(x, y)| x - y).sum::<f64>() / a.len() as f64;
            let expect = tilt[c][1].to_radians().sin() * 1.0;
            assert!(
                (d - expect).abs() < 0.01 + 0.05 * expect.abs(),
                "seed {seed} channel {c}: {d} vs {expect}"
            );
        }
        // record 0 has no manoeuvre: only the cos loss, tiny
        let a = &aligned.records[0].recording.channels[0].samples;
        let b = &tilted.records[0].recording.channels[0].samples;
        let rel = b.iter().zip(a).map(|(x, y)| (x - y).powi(2)).sum::<f64>()
            / a.iter().map(|x| x * x).sum::<f64>();
        assert!(rel < 1e-4, "seed {seed}: {rel}");
    }
}

#[test]
fn speed_wander_moves_the_record_speeds() {
    let bus = VehicleParams::city_bus();
    let mut moved = 0;
    for seed in SEEDS {
        let sp = SimParams {
            road: RoadClass::C,
            speed_kmh: 40.0,
            fs_hz: 200.0,
            records: 4,
            seed,
            speed_wander_rel_std: 0.05,
            ..SimParams::default()
        };
        let sim = simulate(&bus, &sp).unwrap();
        let v: Vec<f64> = sim.records.iter().map(|r| r.mean_speed_kmh).collect();
        assert!(v.iter().all(|x| (x - 40.0).abs() < 40.0 * 0.25), "{v:?}");
        if v.iter().any(|x| (x - 40.0).abs() > 0.2) {
            moved += 1;
        }
    }
    assert!(
        moved >= 4,
        "only {moved} of 5 seeds moved the record speeds"
    );
}

#[test]
fn bending_mode_shape_at_the_sensors_follows_the_body_shape() {
    let car = FullCar::new(&VehicleParams::city_bus_flexible()).unwrap();
    let modes = car.modes().unwrap();
    let bending: Vec<_> = modes
        .iter()
        .filter(|m| m.label == ModeLabel::BodyBending)
        .collect();
    assert_eq!(bending.len(), 1);
    let b = bending[0];
    assert!((b.frequency_hz - 9.0).abs() < 0.1 && (b.damping_ratio - 0.03).abs() < 0.01);
    let names = &b.sensor_names;
    let shape = b.sensor_shape();
    assert_eq!(shape.len(), 7);
    let at = |n: &str| shape[names.iter().position(|x| x == n).unwrap()];
    // FR above the front overhang (-0.6) moves against RL/RR (+0.4)
    let (fr, rl, rr) = (at("FR_sprung"), at("RL_sprung"), at("RR_sprung"));
    assert!(
        fr[0] * rl[0] < 0.0 && rl[0] * rr[0] > 0.0,
        "{fr:?} {rl:?} {rr:?}"
    );
    // body heave: every sprung sensor in phase
    let heave = modes
        .iter()
        .find(|m| m.label == ModeLabel::BodyHeave)
        .unwrap();
    let s = heave.sensor_shape();
    let sprung: Vec<_> = heave
        .sensor_names
        .iter()
        .zip(&s)
        .filter(|(n, _)| n.ends_with("_sprung"))
        .collect();
    assert!(sprung.iter().all(|(_, v)| v[0] > 0.3), "{sprung:?}");
    // largest modulus normalised to 1 + 0i
    for m in &modes {
        let big = m
            .sensor_shape()
            .iter()
            .map(|v| v[0].hypot(v[1]))
            .fold(0.0, f64::max);
        assert!((big - 1.0).abs() < 1e-12, "{}", m.label);
    }
}
