//! Modes and frequency responses of the full-car model against hand-checkable cases.
use vibmode_vehicle::{
    Corner, FullCar, LateralCoherence, ModeLabel, RoadClass, RoadInput, VehicleParams,
};

/// A car whose body is dynamically 4 point masses m/4 at the corners: a = b, Iy = m a^2,
/// Ix = m (t/2)^2, equal axles, no anti-roll bars. It splits into 4 identical quarter cars
/// (3 body patterns) plus a wheel-only "warp" pattern.
fn quarter_car_equivalent(damping: bool) -> VehicleParams {
    let mut p = VehicleParams::passenger_car();
    let m = 1200.0;
    p.body.mass_kg = m;
    p.geometry.wheelbase_m = 2.6;
    p.geometry.cg_to_front_axle_m = 1.3;
    p.geometry.track_front_m = 1.5;
    p.geometry.track_rear_m = 1.5;
    p.body.pitch_inertia_kgm2 = m * 1.3 * 1.3;
    p.body.roll_inertia_kgm2 = m * 0.75 * 0.75;
    for ax in [&mut p.front, &mut p.rear] {
        ax.unsprung_mass_kg = 40.0;
        ax.spring_stiffness_n_per_m = 25_000.0;
        ax.tyre_stiffness_n_per_m = 200_000.0;
        ax.damper_n_s_per_m = if damping { 2000.0 } else { 0.0 };
        ax.tyre_damping_n_s_per_m = 0.0;
        ax.anti_roll_stiffness_nm_per_rad = 0.0;
    }
    p
}

#[test]
fn quarter_car_reduction_matches_closed_form() {
    let p = quarter_car_equivalent(false);
    let modes = FullCar::new(&p).unwrap().modes().unwrap();
    assert_eq!(modes.len(), 7);
    // Undamped two-mass: ms mu w^4 - (ms (ks + kt) + mu ks) w^2 + ks kt = 0.
    let (ms, mu, ks, kt) = (300.0f64, 40.0f64, 25_000.0f64, 200_000.0f64);
    let a = ms * mu;
    let b = -(ms * (ks + kt) + mu * ks);
    let c = ks * kt;
    let disc = (b * b - 4.0 * a * c).sqrt();
    let f_lo = ((-b - disc) / (2.0 * a)).sqrt() / (2.0 * std::f64::consts::PI);
    let f_hi = ((-b + disc) / (2.0 * a)).sqrt() / (2.0 * std::f64::consts::PI);
    let f_warp = ((ks + kt) / mu).sqrt() / (2.0 * std::f64::consts::PI);
    let want = [f_lo, f_lo, f_lo, f_hi, f_hi, f_hi, f_warp];
    let mut want = want.to_vec();
    want.sort_by(f64::total_cmp);
    for (m, w) in modes.iter().zip(&want) {
        assert!(
            (m.frequency_hz - w).abs() < 1e-7 * w,
            "{} vs {}",
            m.frequency_hz,
            w
        );
        assert!(
            m.damping_ratio.abs() < 1e-9,
            "undamped model has zeta {}",
            m.damping_ratio
        );
    }
}

#[test]
fn zero_damping_gives_zero_damping_ratio() {
    let mut p = VehicleParams::city_bus();
    for ax in [&mut p.front, &mut p.rear] {
        ax.damper_n_s_per_m = 0.0;
        ax.tyre_damping_n_s_per_m = 0.0;
    }
    let modes = FullCar::new(&p).unwrap().modes().unwrap();
    assert_eq!(modes.len(), 7);
    for m in &modes {
        assert!(
            m.damping_ratio.abs() < 1e-9,
            "{} Hz zeta {}",
            m.frequency_hz,
            m.damping_ratio
        );
    }
}

#[test]
fn symmetric_bus_gives_bounce_tramp_pairs_and_paper_like_frequencies() {
    let modes = FullCar::new(&VehicleParams::city_bus())
        .unwrap()
        .modes()
        .unwrap();
    let labels: Vec<ModeLabel> = modes.iter().map(|m| m.label).collect();
    for l in [
        ModeLabel::BodyHeave,
        ModeLabel::BodyPitch,
        ModeLabel::BodyRoll,
        ModeLabel::FrontAxleBounce,
        ModeLabel::FrontAxleTramp,
        ModeLabel::RearAxleBounce,
        ModeLabel::RearAxleTramp,
    ] {
        assert_eq!(
            labels.iter().filter(|x| **x == l).count(),
            1,
            "{l} in {labels:?}"
        );
    }
    for m in &modes {
        let z = |c: Corner| {
            num_complex::Complex64::new(m.shape_re[3 + c.index()], m.shape_im[3 + c.index()])
        };
        let scale = m
            .shape_re
            .iter()
            .zip(&m.shape_im)
            .map(|(a, b)| a.hypot(*b))
            .fold(0.0, f64::max);
        let sym = |c: num_complex::Complex64| c.norm() < 1e-8 * scale;
        match m.label {
            ModeLabel::FrontAxleBounce => assert!(sym(z(Corner::FL) - z(Corner::FR))),
            ModeLabel::FrontAxleTramp => assert!(sym(z(Corner::FL) + z(Corner::FR))),
            ModeLabel::RearAxleBounce => assert!(sym(z(Corner::RL) - z(Corner::RR))),
            ModeLabel::RearAxleTramp => assert!(sym(z(Corner::RL) + z(Corner::RR))),
            // symmetric body: heave/pitch modes have no roll, roll mode no heave/pitch
            ModeLabel::BodyHeave | ModeLabel::BodyPitch => assert!(m.energy_fraction[2] < 1e-12),
            ModeLabel::BodyRoll => assert!(m.energy_fraction[0] + m.energy_fraction[1] < 1e-12),
            _ => {}
        }
        let e: f64 = m.energy_fraction.iter().sum();
        assert!((e - 1.0).abs() < 1e-12);
        assert!(m.damping_ratio > 0.05 && m.damping_ratio < 0.5);
        // damped frequency = f sqrt(1 - zeta^2)
        assert!(
            (m.damped_frequency_hz - m.frequency_hz * (1.0 - m.damping_ratio.powi(2)).sqrt()).abs()
                < 1e-9
        );
    }
    // The paper's bus: body ~1 Hz, pitch/roll 1-1.8 Hz, wheel hop 8-12 Hz.
    let f = |l: ModeLabel| {
        modes
            .iter()
            .find(|m| m.label == l)
            .map(|m| m.frequency_hz)
            .unwrap()
    };
    assert!((0.9..1.2).contains(&f(ModeLabel::BodyHeave)));
    assert!((1.0..1.8).contains(&f(ModeLabel::BodyPitch)));
    assert!((1.0..1.8).contains(&f(ModeLabel::BodyRoll)));
    for l in [ModeLabel::FrontAxleBounce, ModeLabel::RearAxleTramp] {
        assert!((8.0..12.0).contains(&f(l)));
    }
}

#[test]
fn low_frequency_response_is_rigid_translation() {
    // All four wheels lifted together by r(t) = R sin(wt) at w -> 0: everything follows, so
    // every sensor acceleration is -w^2 R.
    let car = FullCar::new(&VehicleParams::city_bus()).unwrap();
    let f = 0.01;
    let w = 2.0 * std::f64::consts::PI * f;
    for h in car.frequency_response(f).unwrap() {
        let sum: num_complex::Complex64 = h.iter().sum();
        assert!(
            (sum.re + w * w).abs() < 1e-3 * w * w && sum.im.abs() < 0.05 * w * w,
            "{sum}"
        );
    }
    assert!(car.frequency_response(-1.0).is_err());
    assert!(car.frequency_response(f64::NAN).is_err());
}

#[test]
fn psd_symmetry_and_scaling() {
    let car = FullCar::new(&VehicleParams::city_bus()).unwrap();
    let freqs: Vec<f64> = (1..60).map(|i| i as f64 * 0.5).collect();
    let road = |class, coherence| RoadInput {
        class,
        coherence,
        tyre_envelope_cycles_per_m: Some(3.0),
    };
    let c = car
        .acceleration_psd(
            &road(RoadClass::C, LateralCoherence::Independent),
            40.0,
            &freqs,
        )
        .unwrap();
    let d = car
        .acceleration_psd(
            &road(RoadClass::D, LateralCoherence::Independent),
            40.0,
            &freqs,
        )
        .unwrap();
    // Class D has 4x the road PSD of class C: linear system -> 4x the acceleration PSD.
    for (a, b) in c.iter().zip(&d) {
        for (x, y) in a.psd_m2_s4_per_hz.iter().zip(&b.psd_m2_s4_per_hz) {
            assert!((y - 4.0 * x).abs() <= 1e-9 * y.abs());
        }
    }
    // Symmetric vehicle, independent tracks: FL and FR unsprung sensors have equal PSD.
    for (x, y) in c[0].psd_m2_s4_per_hz.iter().zip(&c[1].psd_m2_s4_per_hz) {
        assert!((x - y).abs() <= 1e-9 * x.abs());
    }
    // Fully correlated tracks excite no roll: RL_sprung and RR_sprung see the same motion.
    let fc = car
        .acceleration_psd(
            &road(RoadClass::C, LateralCoherence::FullyCorrelated),
            40.0,
            &freqs,
        )
        .unwrap();
    for (x, y) in fc[5].psd_m2_s4_per_hz.iter().zip(&fc[6].psd_m2_s4_per_hz) {
        assert!((x - y).abs() <= 1e-9 * x.abs());
    }
    assert!(car
        .acceleration_psd(&RoadInput::default(), 0.0, &freqs)
        .unwrap_err()
        .to_string()
        .contains("speed_kmh = 0"));
    let bad = RoadInput {
        coherence: LateralCoherence::Exponential {
            cutoff_cycles_per_m: 0.0,
        },
        ..RoadInput::default()
    };
    assert!(car.acceleration_psd(&bad, 40.0, &freqs).is_err());
}

/// A corner condition acts on its wheel station only, by its factor: the wheel's diagonal
/// entries of the damping and stiffness matrices change by exactly the scaled damper, spring
/// and tyre; the other wheels do not move. Read from TOML as a user writes it.
#[test]
fn corner_condition_changes_that_corner_only() {
    let bus = VehicleParams::city_bus();
    let text = bus.to_toml_string().unwrap()
        + "\n[[corner_condition]]\ncorner = \"RL\"\ndamper_factor = 0.5\ntyre_stiffness_factor = 0.7\n";
    let worn = VehicleParams::from_toml_str(&text).unwrap();
    assert_eq!(worn.corner_condition.len(), 1);
    let (a, b) = (FullCar::new(&bus).unwrap(), FullCar::new(&worn).unwrap());
    let (ca, cb) = (a.damping_matrix(), b.damping_matrix());
    let (ka, kb) = (a.stiffness_matrix(), b.stiffness_matrix());
    // DOFs: heave, pitch, roll, FL, FR, RL, RR.
    let rl = 5;
    let d = bus.rear.damper_n_s_per_m;
    let kt = bus.rear.tyre_stiffness_n_per_m;
    assert!((ca[(rl, rl)] - cb[(rl, rl)] - 0.5 * d).abs() < 1e-9 * d);
    assert!((ka[(rl, rl)] - kb[(rl, rl)] - 0.3 * kt).abs() < 1e-9 * kt);
    for w in [3, 4, 6] {
        assert_eq!(ca[(w, w)], cb[(w, w)]);
        assert_eq!(ka[(w, w)], kb[(w, w)]);
    }
    // A factor out of range is an error naming the key.
    let bad = bus.to_toml_string().unwrap()
        + "\n[[corner_condition]]\ncorner = \"FL\"\ndamper_factor = -1\n";
    let e = VehicleParams::from_toml_str(&bad).unwrap_err().to_string();
    assert!(e.contains("corner_condition[0].damper_factor"), "{e}");
}
