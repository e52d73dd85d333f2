//! The body-equation fit (`update::BodyFit`): the measured vehicle's body modes recovered from
//! the demo's records when the vehicle file is not the vehicle that was measured; its errors.
use vibmode_core::{Channel, Recording};
use vibmode_modal::shapes::mac;
use vibmode_vehicle::update::{AntiRollBars, BodyFit, BodyFitParams};
use vibmode_vehicle::*;

const SEEDS: [u64; 5] = [1, 2, 3, 4, 5];
const BODY: [ModeLabel; 3] = [
    ModeLabel::BodyHeave,
    ModeLabel::BodyPitch,
    ModeLabel::BodyRoll,
];

/// The demo bus after a change the vehicle file does not know: rear springs 20 % softer (a
/// leaking air spring on RL on top), front dampers at 70 %, 15 % more pitch and roll inertia.
fn measured_bus() -> VehicleParams {
    changed(VehicleParams::city_bus_flexible())
}

fn changed(mut v: VehicleParams) -> VehicleParams {
    v.rear.spring_stiffness_n_per_m *= 0.8;
    v.front.damper_n_s_per_m *= 0.7;
    v.body.pitch_inertia_kgm2 *= 1.15;
    v.body.roll_inertia_kgm2 *= 1.15;
    v.corner_condition.push(CornerCondition {
        corner: Corner::RL,
        damper_factor: 1.0,
        spring_factor: 0.9,
        tyre_stiffness_factor: 1.0,
    });
    v
}

/// The demo's 8 records (lines, noise, misalignment, speed wander, braking and a turn) of the
/// changed bus at 500 Hz, fitted with the unchanged vehicle file: heave, pitch and roll within
/// 3 % of the measured bus's and MAC >= 0.9 on every seed, while the file's own modes are off.
#[test]
fn body_modes_of_the_measured_vehicle_over_seeds() {
    let truth_car = FullCar::new(&measured_bus()).unwrap();
    let truth = truth_car.modes().unwrap();
    let file = VehicleParams::city_bus_flexible();
    let mut worst = [0.0_f64; 3];
    let mut nominal_off = [0.0_f64; 3];
    for seed in SEEDS {
        let sp = SimParams {
            fs_hz: 500.0,
            ..SimParams::demo(8, seed)
        };
        let sim = simulate(&measured_bus(), &sp).unwrap();
        let mut fit = BodyFit::new(&file, BodyFitParams::default()).unwrap();
        for r in &sim.records {
            fit.add_record(&r.recording).unwrap();
        }
        let res = fit.solve().unwrap();
        assert_eq!(res.records, 8);
        assert!(
            res.explained > 0.9,
            "seed {seed}: explained {}",
            res.explained
        );
        for (i, label) in BODY.iter().enumerate() {
            let t = truth.iter().find(|m| m.label == *label).unwrap();
            let u = res
                .mode(*label)
                .unwrap_or_else(|| panic!("seed {seed}: no {label}"));
            let n = res.nominal_mode(*label).unwrap();
            let err = u.frequency_hz / t.frequency_hz - 1.0;
            let m = mac(&u.sensor_shape(), &t.sensor_shape());
            assert!(
                err.abs() < 0.03 && m >= 0.9,
                "seed {seed}: {label} {:.4} Hz against {:.4} Hz ({:+.2} %), MAC {m:.3}",
                u.frequency_hz,
                t.frequency_hz,
                100.0 * err
            );
            assert!(
                (u.damping_ratio - t.damping_ratio).abs() < 0.03,
                "seed {seed}: {label} damping {:.3} against {:.3}",
                u.damping_ratio,
                t.damping_ratio
            );
            worst[i] = worst[i].max(err.abs());
            nominal_off[i] = (n.frequency_hz / t.frequency_hz - 1.0).abs();
        }
    }
    // The file alone would fail: the fit is what brings the modes within 3 %.
    assert!(
        nominal_off[0] > 0.03 && nominal_off[1] > 0.03,
        "the vehicle file's heave/pitch are only {:.1}/{:.1} % off; the test cannot fail",
        100.0 * nominal_off[0],
        100.0 * nominal_off[1]
    );
    eprintln!(
        "worst |error| over {} seeds: heave {:.2} %, pitch {:.2} %, roll {:.2} % (file: {:.1}, {:.1}, {:.1} %)",
        SEEDS.len(),
        100.0 * worst[0],
        100.0 * worst[1],
        100.0 * worst[2],
        100.0 * nominal_off[0],
        100.0 * nominal_off[1],
        100.0 * nominal_off[2]
    );
}

/// 4 noise-free records of `truth` at 200 Hz on a class C road at 40 km/h.
fn rigid_records(truth: &VehicleParams, seed: u64) -> Vec<Recording> {
    let sp = SimParams {
        road: RoadClass::C,
        speed_kmh: 40.0,
        fs_hz: 200.0,
        records: 4,
        seed,
        ..SimParams::default()
    };
    simulate(truth, &sp)
        .unwrap()
        .records
        .into_iter()
        .map(|r| r.recording)
        .collect()
}

/// Noise-free records of the rigid bus (no bending, lines, misalignment or manoeuvres; steady
/// speed): the fitted springs, dampers and inertias are the changed bus's within 1 %.
#[test]
fn clean_records_give_the_parameters() {
    let truth = changed(VehicleParams::city_bus());
    let mut fit = BodyFit::new(&VehicleParams::city_bus(), BodyFitParams::default()).unwrap();
    for r in &rigid_records(&truth, 7) {
        fit.add_record(r).unwrap();
    }
    let res = fit.solve().unwrap();
    let close = |what: &str, got: f64, want: f64, tol: f64| {
        assert!(
            (got / want - 1.0).abs() < tol,
            "{what}: {got:.1} against {want:.1}"
        );
    };
    for c in Corner::ALL {
        close(
            &format!("{c} spring"),
            res.vehicle.axle(c).spring_stiffness_n_per_m,
            truth.axle(c).spring_stiffness_n_per_m,
            0.01,
        );
        close(
            &format!("{c} damper"),
            res.vehicle.axle(c).damper_n_s_per_m,
            truth.axle(c).damper_n_s_per_m,
            0.05,
        );
    }
    close(
        "pitch inertia",
        res.vehicle.body.pitch_inertia_kgm2,
        truth.body.pitch_inertia_kgm2,
        0.02,
    );
    close(
        "roll inertia",
        res.vehicle.body.roll_inertia_kgm2,
        truth.body.roll_inertia_kgm2,
        0.05,
    );
    assert!(res.explained > 0.99, "explained {}", res.explained);
}

fn demo_record() -> Recording {
    let sp = SimParams {
        road: RoadClass::C,
        speed_kmh: 40.0,
        seed: 0,
        fs_hz: 100.0,
        records: 1,
        ..SimParams::default()
    };
    let sim = simulate(&VehicleParams::city_bus_flexible(), &sp).unwrap();
    sim.records.into_iter().next().unwrap().recording
}

fn fit_error(rec: &Recording) -> String {
    let mut fit = BodyFit::new(
        &VehicleParams::city_bus_flexible(),
        BodyFitParams::default(),
    )
    .unwrap();
    match fit.add_record(rec) {
        Ok(()) => panic!("the record was accepted"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_missing_wheel_is_named() {
    let mut rec = demo_record();
    rec.channels.retain(|c| c.name != "RL_unsprung");
    let e = fit_error(&rec);
    assert!(e.contains("no unsprung channel at RL"), "{e}");
}

#[test]
fn two_sprung_sensors_are_too_few() {
    let mut rec = demo_record();
    rec.channels.retain(|c| c.name != "FR_sprung");
    let e = fit_error(&rec);
    assert!(e.contains("2 sprung channel(s)"), "{e}");
}

#[test]
fn collinear_sprung_sensors_are_refused() {
    let mut v = VehicleParams::city_bus_flexible();
    v.sensors = ["FL", "FR", "RL", "RR"]
        .iter()
        .map(|c| {
            SensorSpec::at_corner(
                &format!("{c}_unsprung"),
                SensorKind::Unsprung,
                c.parse().unwrap(),
            )
        })
        .chain((0..3).map(|i| SensorSpec {
            name: format!("body_{i}"),
            kind: SensorKind::Sprung,
            corner: None,
            x_m: Some(i as f64),
            y_m: Some(0.0),
            bending_shape: 0.0,
        }))
        .collect();
    let sim = simulate(
        &v,
        &SimParams {
            road: RoadClass::C,
            speed_kmh: 40.0,
            seed: 0,
            fs_hz: 100.0,
            records: 1,
            ..SimParams::default()
        },
    )
    .unwrap();
    let mut fit = BodyFit::new(&v, BodyFitParams::default()).unwrap();
    let e = fit
        .add_record(&sim.records[0].recording)
        .unwrap_err()
        .to_string();
    assert!(e.contains("on one line"), "{e}");
}

#[test]
fn short_records_and_bad_samples_are_refused() {
    let rec = demo_record();
    let mut short = rec.clone();
    short
        .channels
        .iter_mut()
        .for_each(|c| c.samples.truncate(150));
    let e = fit_error(&short);
    assert!(e.contains("150 samples (1.50 s) is shorter"), "{e}");
    let mut nan = rec.clone();
    nan.channels[2].samples[17] = f64::NAN;
    let e = fit_error(&nan);
    assert!(e.contains("sample 17 is NaN"), "{e}");
    let mut slow = rec;
    slow.fs_hz = 4.0;
    let e = fit_error(&slow);
    assert!(e.contains("above the Nyquist frequency 2.00 Hz"), "{e}");
}

#[test]
fn unplaced_channels_are_found_by_the_files_sensor_names_and_solve_needs_records() {
    let rec = demo_record();
    // Placements removed: the vehicle file's sensor names place them again.
    let bare = Recording {
        fs_hz: rec.fs_hz,
        channels: rec
            .channels
            .iter()
            .map(|c| Channel::new(c.name.to_lowercase(), "m/s^2", c.samples.clone()))
            .collect(),
        time_axis: None,
    };
    let mut fit = BodyFit::new(
        &VehicleParams::city_bus_flexible(),
        BodyFitParams::default(),
    )
    .unwrap();
    let e = fit.solve().unwrap_err().to_string();
    assert!(e.contains("no record was added"), "{e}");
    fit.add_record(&bare).unwrap();
    assert_eq!(fit.records(), 1);
    let bad = BodyFitParams {
        band_hz: Some([2.0, 1.0]),
        ..BodyFitParams::default()
    };
    let e = BodyFit::new(&VehicleParams::city_bus_flexible(), bad)
        .unwrap_err()
        .to_string();
    assert!(e.contains("band_hz = [2, 1]"), "{e}");
}

/// A bar in the file that the measured bus does not have (the independent bus family has no
/// front bar; issue 30): noise-free records of the rigid bus without its front bar, fitted with
/// the file that has one, over six seeds. The fit never ends on a negative bar: the bounded fit
/// holds it at 0 and lists it in `absent` where the records pull it below 0, and otherwise it comes
/// out below 1 % of the file's bar; the springs within 1 %, the dampers and the rear bar within 5 %
/// of the bus's, its body modes within 1 %.
#[test]
fn a_bar_the_bus_does_not_have_comes_out_as_zero() {
    let file = VehicleParams::city_bus();
    let file_bar = file.front.anti_roll_stiffness_nm_per_rad;
    assert!(file_bar > 0.0);
    let mut truth = changed(VehicleParams::city_bus());
    truth.front.anti_roll_stiffness_nm_per_rad = 0.0;
    let truth_modes = FullCar::new(&truth).unwrap().modes().unwrap();
    let close = |what: String, got: f64, want: f64, tol: f64| {
        assert!(
            (got / want - 1.0).abs() < tol,
            "{what}: {got:.1} against {want:.1}"
        );
    };
    let mut held = 0;
    for seed in 1..=6 {
        let sp = SimParams {
            road: RoadClass::C,
            speed_kmh: 40.0,
            fs_hz: 200.0,
            records: 4,
            seed,
            ..SimParams::default()
        };
        let sim = simulate(&truth, &sp).unwrap();
        let mut fit = BodyFit::new(&file, BodyFitParams::default()).unwrap();
        for r in &sim.records {
            fit.add_record(&r.recording).unwrap();
        }
        let res = fit.solve().unwrap();
        let bar = res.vehicle.front.anti_roll_stiffness_nm_per_rad;
        assert!(
            bar >= 0.0 && bar < 0.01 * file_bar,
            "seed {seed}: front bar {bar:.1} N m/rad (file {file_bar:.1}, bus 0)"
        );
        if bar == 0.0 {
            held += 1;
            assert_eq!(res.absent, vec!["front anti-roll bar".to_string()]);
        } else {
            assert!(res.absent.is_empty(), "seed {seed}: {:?}", res.absent);
        }
        close(
            format!("seed {seed}: rear bar"),
            res.vehicle.rear.anti_roll_stiffness_nm_per_rad,
            truth.rear.anti_roll_stiffness_nm_per_rad,
            0.05,
        );
        for c in Corner::ALL {
            close(
                format!("seed {seed}: {c} spring"),
                res.vehicle.axle(c).spring_stiffness_n_per_m,
                truth.axle(c).spring_stiffness_n_per_m,
                0.01,
            );
            close(
                format!("seed {seed}: {c} damper"),
                res.vehicle.axle(c).damper_n_s_per_m,
                truth.axle(c).damper_n_s_per_m,
                0.05,
            );
        }
        for label in BODY {
            let t = truth_modes.iter().find(|m| m.label == label).unwrap();
            let u = res.mode(label).unwrap();
            close(
                format!("seed {seed}: {label}"),
                u.frequency_hz,
                t.frequency_hz,
                0.01,
            );
        }
    }
    eprintln!("front bar held at 0 on {held} of 6 seeds");
}

/// A bar the bus has and the vehicle file lacks (half of the independent bus family's buses
/// draw a front bar; issue 30): records of the rigid bus with its front bar, fitted with the
/// file without one, over three seeds. Both axles' bars are fitted by default, so the bar is
/// found (within 5 %, and named as found) with the springs within 1 %, the body modes within 1 %
/// and the roll inertia within 5 %; fitting only the file's bars (`AntiRollBars::File`) cannot
/// represent the bus: its roll mode comes out right only by a roll inertia 30-38 % too small
/// (asserted: more than 20 %).
#[test]
fn a_bar_the_file_lacks_is_fitted() {
    let truth = changed(VehicleParams::city_bus());
    let bus_bar = truth.front.anti_roll_stiffness_nm_per_rad;
    assert!(bus_bar > 0.0);
    let mut file = VehicleParams::city_bus();
    file.front.anti_roll_stiffness_nm_per_rad = 0.0;
    let truth_modes = FullCar::new(&truth).unwrap().modes().unwrap();
    let err = |res: &vibmode_vehicle::update::BodyFitResult, label: ModeLabel| {
        let t = truth_modes.iter().find(|m| m.label == label).unwrap();
        res.mode(label).unwrap().frequency_hz / t.frequency_hz - 1.0
    };
    for seed in 1..=3 {
        let records = rigid_records(&truth, seed);
        let fit_with = |bars: AntiRollBars| {
            let params = BodyFitParams {
                anti_roll_bars: bars,
                ..BodyFitParams::default()
            };
            let mut fit = BodyFit::new(&file, params).unwrap();
            for r in &records {
                fit.add_record(r).unwrap();
            }
            (fit.unknowns(), fit.solve().unwrap())
        };
        let (n_both, both) = fit_with(AntiRollBars::Both);
        let (n_file, only_file) = fit_with(AntiRollBars::File);
        assert_eq!((n_both, n_file), (12, 11));
        let bar = both.vehicle.front.anti_roll_stiffness_nm_per_rad;
        eprintln!(
            "seed {seed}: front bar {:.1} kN m/rad (bus {:.1}); roll {:+.2} % (file's bars only {:+.2} %)",
            bar / 1e3,
            bus_bar / 1e3,
            100.0 * err(&both, ModeLabel::BodyRoll),
            100.0 * err(&only_file, ModeLabel::BodyRoll)
        );
        assert!(
            (bar / bus_bar - 1.0).abs() < 0.05,
            "seed {seed}: front bar {bar:.1}"
        );
        assert!(both.absent.is_empty(), "seed {seed}: {:?}", both.absent);
        assert_eq!(
            both.found_bars(&file),
            vec![format!("front anti-roll bar of {:.0} kN m/rad", bar / 1e3)]
        );
        assert!(both
            .summary_text(&file)
            .contains("found where the file has none: front anti-roll bar of"));
        for c in Corner::ALL {
            let (got, want) = (
                both.vehicle.axle(c).spring_stiffness_n_per_m,
                truth.axle(c).spring_stiffness_n_per_m,
            );
            assert!(
                (got / want - 1.0).abs() < 0.01,
                "seed {seed}: {c} spring {got:.1} against {want:.1}"
            );
        }
        for label in BODY {
            assert!(err(&both, label).abs() < 0.01, "seed {seed}: {label}");
        }
        assert!(only_file.found_bars(&file).is_empty());
        let roll_inertia = |res: &vibmode_vehicle::update::BodyFitResult| {
            res.vehicle.body.roll_inertia_kgm2 / truth.body.roll_inertia_kgm2 - 1.0
        };
        eprintln!(
            "seed {seed}: roll inertia {:+.2} % (file's bars only {:+.2} %)",
            100.0 * roll_inertia(&both),
            100.0 * roll_inertia(&only_file)
        );
        assert!(
            roll_inertia(&both).abs() < 0.05,
            "seed {seed}: roll inertia"
        );
        assert!(
            roll_inertia(&only_file).abs() > 0.2,
            "seed {seed}: the file's bars alone fit the roll inertia"
        );
    }
}

/// A record's equations kept (through JSON, as the fleet store keeps them) and added later give
/// the very fit of the records added directly; equations of another vehicle file's unknowns
/// (one anti-roll bar fewer) are refused.
#[test]
fn equations_kept_and_added_later_give_the_same_fit() {
    let truth = changed(VehicleParams::city_bus());
    let records = rigid_records(&truth, 11);
    let file = VehicleParams::city_bus();
    let mut direct = BodyFit::new(&file, BodyFitParams::default()).unwrap();
    let mut later = BodyFit::new(&file, BodyFitParams::default()).unwrap();
    for r in &records {
        direct.add_record(r).unwrap();
        let eq = later.record_equations(r).unwrap();
        let text = serde_json::to_string(&eq).unwrap();
        let back: vibmode_vehicle::update::RecordEquations = serde_json::from_str(&text).unwrap();
        later.add_equations(&back).unwrap();
    }
    assert_eq!(later.records(), 4);
    let (a, b) = (direct.solve().unwrap(), later.solve().unwrap());
    assert_eq!(a.parameters, b.parameters);
    assert_eq!(a.replicates, b.replicates);
    // One replicate per record left out, each parameter's jackknife sd their spread.
    assert_eq!(a.replicates.len(), 4);
    for (i, p) in a.parameters.iter().enumerate() {
        let xs: Vec<f64> = a.replicates.iter().map(|r| r[i]).collect();
        let mean = xs.iter().sum::<f64>() / 4.0;
        let sd = (0.75 * xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>()).sqrt();
        let want = p.sd.unwrap();
        assert!(
            (sd - want).abs() <= 1e-9 * want.max(1.0),
            "{}: {sd} vs {want}",
            p.name
        );
    }
    assert_eq!(a.equations, b.equations);
    assert_eq!(a.noise_density, b.noise_density);
    for c in Corner::ALL {
        let (sa, sb) = (a.spring(c).unwrap(), b.spring(c).unwrap());
        assert_eq!(sa, sb);
        assert!(sa.sd.is_some(), "{c}: a spring's sd from 4 records");
        assert!(a.damper(c).is_some());
    }
    // One bar fewer: one unknown fewer.
    let mut no_front = file.clone();
    no_front.front.anti_roll_stiffness_nm_per_rad = 0.0;
    let file_bars = BodyFitParams {
        anti_roll_bars: AntiRollBars::File,
        ..BodyFitParams::default()
    };
    let mut other = BodyFit::new(&no_front, file_bars).unwrap();
    let eq = direct.record_equations(&records[0]).unwrap();
    let e = other.add_equations(&eq).unwrap_err().to_string();
    assert!(e.contains("unknowns"), "{e}");
    assert_eq!(other.records(), 0);
}

/// `choose_band`: the same records fitted in the default band and in the wide one. On the rigid
/// bus (no bending) the wide band's body modes agree with the default band's (within 1 % or
/// two standard deviations) and its fit is taken; on the flexible bus, whose bending the sprung sensors see, a body mode
/// moves by more than both in the wide band and the default band's fit is kept, with the mode
/// named. Records of the changed
/// bus (the demo's effects: noise, lines, misalignment, manoeuvres) at 2 kHz, where both bands
/// have a noise range.
#[test]
fn the_wide_band_is_taken_only_where_the_body_stays_rigid() {
    use vibmode_vehicle::update::{choose_band, wide_band_hz};
    for (file, rigid) in [
        (VehicleParams::city_bus(), true),
        (VehicleParams::city_bus_flexible(), false),
    ] {
        let sp = SimParams {
            fs_hz: 2000.0,
            ..SimParams::demo(8, 3)
        };
        let sim = simulate(&changed(file.clone()), &sp).unwrap();
        let wide_band = wide_band_hz(&file).unwrap();
        let mut narrow = BodyFit::new(&file, BodyFitParams::default()).unwrap();
        let mut wide = BodyFit::new(
            &file,
            BodyFitParams {
                band_hz: Some(wide_band),
                ..BodyFitParams::default()
            },
        )
        .unwrap();
        for r in &sim.records {
            narrow.add_record(&r.recording).unwrap();
            wide.add_record(&r.recording).unwrap();
        }
        let n = narrow.solve().unwrap();
        let wide_fit = wide.solve().unwrap();
        let chosen = choose_band(n.clone(), wide_band, Ok(wide_fit.clone()));
        let c = chosen.band_choice.clone().unwrap();
        assert_eq!(c.wide_taken, rigid, "rigid {rigid}: {}", c.reason);
        assert_eq!(c.default_band_hz, n.band_hz);
        assert_eq!(c.wide_band_hz, wide_band);
        let shift = c.largest_shift_sd.unwrap();
        if rigid {
            assert_eq!(chosen.band_hz, wide_band);
            assert!(c.reason.starts_with("wide band"), "{}", c.reason);
        } else {
            assert_eq!(chosen.band_hz, n.band_hz);
            assert!(shift > 2.0 && c.reason.contains("moved by"), "{}", c.reason);
            let moved = chosen.body_mode_pairs().iter().any(|(_, u)| {
                let w = wide_fit.mode(u.label).unwrap();
                (w.frequency_hz / u.frequency_hz - 1.0).abs() > 0.01
            });
            assert!(moved, "{}", c.reason);
        }
        eprintln!("rigid {rigid}: {}", c.reason);
    }
}

/// `choose_band` by hand: one fit (4 noise-free records of the rigid bus) as the default band's,
/// its copy with the body pitch moved as the wide band's, and the default band's pitch standard
/// deviation set to 1 % of its frequency. Taken: 0.8 % (below 1 %, 0.8 sd), 3 % (3 sd); kept:
/// 4 % (4 sd > 3.5); with the sd at 0.1 %: 0.8 % taken (below 1 %), 1.5 % kept (15 sd); a wide
/// fit without the pitch, or a failed one, kept; fewer than three records' worth of sd (none),
/// kept.
#[test]
fn choose_band_by_hand() {
    use vibmode_vehicle::update::choose_band;
    let mut fit = BodyFit::new(&VehicleParams::city_bus(), BodyFitParams::default()).unwrap();
    for r in &rigid_records(&VehicleParams::city_bus(), 3) {
        fit.add_record(r).unwrap();
    }
    let base = fit.solve().unwrap();
    let pitch = ModeLabel::BodyPitch;
    let f = base.mode(pitch).unwrap().frequency_hz;
    let with_sd = |rel_sd: f64| {
        let mut r = base.clone();
        for m in r.mode_sd.iter_mut() {
            m.frequency_hz_sd = 1e-9;
            if m.label == pitch {
                m.frequency_hz_sd = rel_sd * f;
            }
        }
        r
    };
    let moved = |rel: f64| {
        let mut w = base.clone();
        w.band_hz = [0.5, 4.0];
        for m in w.modes.iter_mut().filter(|m| m.label == pitch) {
            m.frequency_hz *= 1.0 + rel;
        }
        w
    };
    for (rel_sd, rel, taken) in [
        (0.01, 0.008, true),
        (0.01, 0.03, true),
        (0.01, -0.04, false),
        (0.001, 0.008, true),
        (0.001, -0.015, false),
    ] {
        let r = choose_band(with_sd(rel_sd), [0.5, 4.0], Ok(moved(rel)));
        let c = r.band_choice.clone().unwrap();
        assert_eq!(
            c.wide_taken, taken,
            "sd {rel_sd}, shift {rel}: {}",
            c.reason
        );
        assert_eq!(r.band_hz, if taken { [0.5, 4.0] } else { base.band_hz });
        let sd_shift = c.largest_shift_sd.unwrap();
        assert!((sd_shift - rel.abs() / rel_sd).abs() < 1e-6, "{sd_shift}");
        if !taken {
            assert!(c.reason.contains("body pitch moved by"), "{}", c.reason);
        }
    }
    // The wide fit without a body pitch, a failed wide fit, no standard deviations: kept.
    let mut no_pitch = moved(0.0);
    no_pitch.modes.retain(|m| m.label != pitch);
    let r = choose_band(with_sd(0.01), [0.5, 4.0], Ok(no_pitch));
    assert!(!r.band_choice.unwrap().wide_taken);
    let failed = BodyFit::new(
        &VehicleParams::city_bus(),
        BodyFitParams {
            band_hz: Some([2.0, 1.0]),
            ..BodyFitParams::default()
        },
    )
    .and_then(|f| f.solve());
    let r = choose_band(with_sd(0.01), [0.5, 4.0], failed);
    let c = r.band_choice.unwrap();
    assert!(!c.wide_taken && c.reason.contains("failed"), "{}", c.reason);
    assert_eq!(c.wide_band_hz, [0.5, 4.0]);
    let mut no_sd = base.clone();
    no_sd.mode_sd.clear();
    let c = choose_band(no_sd, [0.5, 4.0], Ok(moved(0.0)))
        .band_choice
        .unwrap();
    assert!(
        !c.wide_taken && c.reason.contains("three records"),
        "{}",
        c.reason
    );
}

/// Records sampled at twice `EQUATION_RATE_HZ` (5 kHz) or more are brought down by an integer
/// factor with the paper's ideal filter before their equations are formed: 3 of the demo's
/// records of the changed bus at 20 kHz give exactly the fit of the same records brought down
/// to 5 kHz by `vibmode_signal::resample` (same equations, noise densities and parameters),
/// and that fit finds the measured bus: heave, pitch and roll within 3 % of its modes. The
/// equations made from the channels' spectra taken before are the same bit for bit.
#[test]
fn records_above_the_equation_rate_are_fitted_at_it() {
    use vibmode_vehicle::update::{decimation_factor, EQUATION_RATE_HZ};
    assert_eq!(decimation_factor(20_000.0), 4);
    assert_eq!(decimation_factor(9_999.0), 1);
    assert_eq!(decimation_factor(10_000.0), 2);
    assert_eq!(decimation_factor(EQUATION_RATE_HZ), 1);
    assert_eq!(decimation_factor(500.0), 1);
    // The bins the equations read from a spectrum: up to the 5 kHz rate's Nyquist frequency.
    use vibmode_vehicle::update::spectrum_bins_read;
    assert_eq!(spectrum_bins_read(204_800, 20_000.0), Some(25_602));
    assert_eq!(spectrum_bins_read(102_400, 10_000.0), Some(25_602));
    assert_eq!(spectrum_bins_read(20_480, 2_000.0), None);
    let sp = SimParams {
        fs_hz: 20_000.0,
        ..SimParams::demo(3, 2)
    };
    let sim = simulate(&measured_bus(), &sp).unwrap();
    let file = VehicleParams::city_bus_flexible();
    let mut fast = BodyFit::new(&file, BodyFitParams::default()).unwrap();
    let mut slow = BodyFit::new(&file, BodyFitParams::default()).unwrap();
    let down = vibmode_signal::ResampleParams {
        fs_out_hz: 5000.0,
        cutoff_hz: None,
        filter: true,
    };
    for r in &sim.records {
        let rec = &r.recording;
        fast.add_record(rec).unwrap();
        // The same equations from the channels' spectra taken before (the fleet's path: the
        // analysis resamples the same channels), whole or up to the new Nyquist frequency's bin.
        let json = |e: &vibmode_vehicle::update::RecordEquations| serde_json::to_string(e).unwrap();
        let want = json(&fast.record_equations(rec).unwrap());
        let read = vibmode_vehicle::update::spectrum_bins_read(rec.len(), rec.fs_hz);
        assert_eq!(read, Some(rec.len() / 8 + 2));
        for bins in [usize::MAX, rec.len() / 8 + 2] {
            let channels = rec.channels.iter().map(|c| &c.samples[..]);
            let spectra = vibmode_signal::ChannelSpectrum::of_each(channels, bins).unwrap();
            let got = fast
                .record_equations_spectra(rec, |c| Some(c.placement), Some(&spectra))
                .unwrap();
            assert_eq!(json(&got), want, "spectra of {bins} bins");
        }
        let channels = rec
            .channels
            .iter()
            .map(|c| Channel {
                samples: vibmode_signal::resample(&c.samples, rec.fs_hz, &down).unwrap(),
                ..c.clone()
            })
            .collect();
        let low = Recording {
            fs_hz: 5000.0,
            channels,
            ..rec.clone()
        };
        slow.add_record(&low).unwrap();
    }
    let (a, b) = (fast.solve().unwrap(), slow.solve().unwrap());
    assert_eq!(a.equations, b.equations);
    assert_eq!(a.noise_density, b.noise_density);
    assert_eq!(a.parameters.len(), b.parameters.len());
    for (p, q) in a.parameters.iter().zip(&b.parameters) {
        assert_eq!((p.value, p.sd), (q.value, q.sd), "{}", p.name);
    }
    let truth = FullCar::new(&measured_bus()).unwrap().modes().unwrap();
    for label in BODY {
        let t = truth.iter().find(|m| m.label == label).unwrap();
        let u = a.mode(label).unwrap();
        let err = u.frequency_hz / t.frequency_hz - 1.0;
        assert!(err.abs() < 0.03, "{label}: {:+.2} %", 100.0 * err);
    }
}
