//! Exact (first-order-hold) discretisation and the measurement-campaign simulator.

use crate::error::{invalid, Result, VehicleError};
use crate::lines::{EngineLine, LineBank, LineTruth, OrnsteinUhlenbeck};
use crate::model::{FullCar, ModeInfo, DOF_HEAVE, DOF_PITCH, DOF_ROLL};
use crate::params::{Corner, VehicleParams};
use crate::road::{
    LateralCoherence, RoadClass, RoadInput, RoadProfile, DEFAULT_TYRE_ENVELOPE_CYCLES_PER_M,
};
use nalgebra::DMatrix;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use vibmode_core::{Channel, Recording};

/// A sinusoidal tone added to every channel (models pick-up above the anti-alias cutoff).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tone {
    /// Frequency, Hz (may exceed fs_hz / 2: it is then sampled, i.e. aliased, like a real ADC
    /// without analogue filter would).
    pub frequency_hz: f64,
    /// Amplitude, m/s^2.
    pub amplitude_m_s2: f64,
}

/// Switchable non-road effects. `Default` switches everything off. Missing fields take their
/// defaults when deserialised.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Disturbances {
    /// Engine / gear lines entering the body (default none).
    pub engine_lines: Vec<EngineLine>,
    /// Broadband white sensor noise, standard deviation per sample, m/s^2 (default 0).
    pub sensor_noise_std_m_s2: f64,
    /// Sensor bias: each channel gets a constant drawn uniformly from +-this value, m/s^2
    /// (default 0). The drawn values are in [`Truth::sensor_bias_m_s2`].
    pub sensor_bias_max_m_s2: f64,
    /// High-frequency tones added to every channel (random phase per channel; default none).
    pub hf_tones: Vec<Tone>,
    /// Relative standard deviation of the engine speed from record to record (default 0): each
    /// record draws one log-normal factor that multiplies the frequency of every line.
    pub engine_speed_record_rel_std: f64,
    /// Sensor misalignment (default 0): each sensor is tilted by an angle drawn uniformly from
    /// +-this value about the lateral axis and another about the longitudinal axis, deg. It then
    /// measures `cos a cos b` of the vertical acceleration plus `sin a` of the longitudinal
    /// acceleration (speed changes) and `sin b` of the lateral one (turns). Gravity is left out:
    /// its constant component is part of the bias. The angles drawn are in
    /// [`Truth::sensor_misalignment_deg`].
    pub sensor_misalignment_max_deg: f64,
}

impl Disturbances {
    /// In-service preset: engine/gear lines at 7, 11 and 12 Hz (the paper's periodic poles;
    /// 11 Hz drifting by +-0.2 Hz), sensor noise 0.02 m/s^2, bias up to 0.05 m/s^2, tones at
    /// 150 Hz, 1.3 kHz and 6 kHz (0.05, 0.1, 0.2 m/s^2).
    pub fn in_service() -> Self {
        let line = |f: f64, force: f64, drift: f64| EngineLine {
            drift_hz: drift,
            drift_period_s: 20.0,
            x_m: -3.0,
            y_m: 0.3,
            ..EngineLine::constant(f, force)
        };
        Disturbances {
            engine_lines: vec![
                line(7.0, 400.0, 0.0),
                line(11.0, 300.0, 0.2),
                line(12.0, 300.0, 0.0),
            ],
            sensor_noise_std_m_s2: 0.02,
            sensor_bias_max_m_s2: 0.05,
            hf_tones: vec![
                Tone {
                    frequency_hz: 150.0,
                    amplitude_m_s2: 0.05,
                },
                Tone {
                    frequency_hz: 1300.0,
                    amplitude_m_s2: 0.1,
                },
                Tone {
                    frequency_hz: 6000.0,
                    amplitude_m_s2: 0.2,
                },
            ],
            engine_speed_record_rel_std: 0.0,
            sensor_misalignment_max_deg: 0.0,
        }
    }
}

/// A braking/acceleration and/or turning event. Accelerations follow a sin^2 pulse of the
/// given peak over `duration_s`, starting `start_s` after the start of the first record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manoeuvre {
    /// Start time from the beginning of record 0, s.
    pub start_s: f64,
    /// Duration, s (> 0).
    pub duration_s: f64,
    /// Peak longitudinal acceleration, m/s^2 (negative = braking). Changes the speed and
    /// gives a pitch moment m a h_cg (nose down when braking).
    pub longitudinal_accel_m_s2: f64,
    /// Peak lateral acceleration, m/s^2 (positive = turning left). Gives a roll moment
    /// m a h_cg (body rolls towards the outside of the turn).
    pub lateral_accel_m_s2: f64,
}

impl Manoeuvre {
    fn pulse(&self, t: f64) -> f64 {
        if t < self.start_s || t > self.start_s + self.duration_s {
            0.0
        } else {
            (PI * (t - self.start_s) / self.duration_s).sin().powi(2)
        }
    }
}

/// Simulator settings. Defaults (defined here once: `vibmode simulate`, `vibmode demo` and
/// Python's `simulate` take theirs from [`SimParams::default`]): road B, default coherence
/// (exponential, 0.2 cycles/m), tyre enveloping 3 cycles/m, 30 km/h, 8 records of 10.24 s at
/// 20 kHz, seed 1, no manoeuvres, no disturbances, automatic warm-up, no speed wander. Missing fields take these defaults when deserialised (e.g. from a TOML
/// or JSON config); unknown fields are errors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimParams {
    /// ISO 8608 road class (default B).
    pub road: RoadClass,
    /// Left/right track coherence (default exponential, cutoff 0.2 cycles/m).
    pub coherence: LateralCoherence,
    /// Tyre-enveloping cutoff of the road, cycles/m (default Some(3.0); see [`RoadInput`]).
    pub tyre_envelope_cycles_per_m: Option<f64>,
    /// Nominal (initial) speed, km/h (default 30).
    pub speed_kmh: f64,
    /// Length of one record, s (default 10.24).
    pub duration_s: f64,
    /// Sampling rate, Hz (default 20000).
    pub fs_hz: f64,
    /// Number of records (default 8): successive segments of one continuous drive.
    pub records: usize,
    /// Random seed (ChaCha8); the same seed gives bit-identical output (default 1).
    pub seed: u64,
    /// Braking / acceleration / turning events (default none).
    pub manoeuvres: Vec<Manoeuvre>,
    /// Engine lines, sensor noise and bias, HF tones (default all off).
    pub disturbances: Disturbances,
    /// Warm-up driven before record 0 and discarded, s. `None` (default): 5 times the slowest
    /// modal decay time 1/(zeta omega), clamped to 2..30 s.
    pub warmup_s: Option<f64>,
    /// Relative standard deviation of a slow random speed variation on top of the manoeuvres
    /// (default 0): the speed is `v(t) (1 + u(t))` with `u` a Gauss-Markov process of
    /// correlation time `speed_wander_correlation_s`, smoothed by a first-order lag of 1 s so
    /// that the acceleration it implies is bounded (the misaligned sensors see it).
    pub speed_wander_rel_std: f64,
    /// Correlation time of the speed variation, s (default 5).
    pub speed_wander_correlation_s: f64,
}

impl Default for SimParams {
    fn default() -> Self {
        SimParams {
            road: RoadClass::B,
            coherence: LateralCoherence::default(),
            tyre_envelope_cycles_per_m: Some(DEFAULT_TYRE_ENVELOPE_CYCLES_PER_M),
            speed_kmh: 30.0,
            duration_s: 10.24,
            fs_hz: 20000.0,
            records: 8,
            seed: 1,
            manoeuvres: Vec::new(),
            disturbances: Disturbances::default(),
            warmup_s: None,
            speed_wander_rel_std: 0.0,
            speed_wander_correlation_s: 5.0,
        }
    }
}

impl SimParams {
    /// The settings of `vibmode demo` (use them with
    /// [`VehicleParams::city_bus_flexible`](crate::VehicleParams::city_bus_flexible)):
    /// [`SimParams::in_service`] on the default ISO 8608 class B road at 30 km/h, `records` records of
    /// 10.24 s at 20 kHz, and what real buses add:
    /// - engine/gear lines of 3 kN each (strong enough to stand out of the body response, as
    ///   on the paper's bus) whose frequency wanders (relative std 1e-3, correlation time 2 s)
    ///   and whose amplitude is modulated (10 %, 1 s); the engine speed differs from record to
    ///   record (2 %), and the 7 Hz driveline line follows the vehicle speed (braking and
    ///   acceleration sweep it);
    /// - a speed that varies within each record (3 %, correlation time 5 s);
    /// - sensors misaligned by up to 3 deg.
    pub fn demo(records: usize, seed: u64) -> Self {
        let mut p = SimParams {
            records,
            seed,
            speed_wander_rel_std: 0.03,
            ..SimParams::in_service()
        };
        p.disturbances.engine_speed_record_rel_std = 0.02;
        p.disturbances.sensor_misalignment_max_deg = 3.0;
        for line in &mut p.disturbances.engine_lines {
            line.force_n = 3000.0;
            line.wander_rel_std = 1e-3;
            line.am_rel_std = 0.1;
            if line.frequency_hz < 8.0 {
                line.speed_coupling = 1.0;
            }
        }
        p
    }

    /// [`SimParams::demo`] as it was before vibmode 0.2: constant-amplitude lines at fixed
    /// frequencies, a steady speed between the manoeuvres, aligned sensors (use it with
    /// [`VehicleParams::city_bus`](crate::VehicleParams::city_bus)). The idealised case.
    pub fn demo_ideal(records: usize, seed: u64) -> Self {
        let mut p = SimParams {
            records,
            seed,
            ..SimParams::in_service()
        };
        for line in &mut p.disturbances.engine_lines {
            line.force_n = 3000.0;
        }
        p
    }

    /// In-service preset: defaults plus [`Disturbances::in_service`], a braking event in
    /// record 1 (-1.5 m/s^2 over 3 s), an acceleration in record 3 (+1 m/s^2 over 4 s) and a
    /// left turn in record 5 (2 m/s^2 lateral over 5 s).
    pub fn in_service() -> Self {
        SimParams {
            disturbances: Disturbances::in_service(),
            manoeuvres: vec![
                Manoeuvre {
                    start_s: 13.0,
                    duration_s: 3.0,
                    longitudinal_accel_m_s2: -1.5,
                    lateral_accel_m_s2: 0.0,
                },
                Manoeuvre {
                    start_s: 33.0,
                    duration_s: 4.0,
                    longitudinal_accel_m_s2: 1.0,
                    lateral_accel_m_s2: 0.0,
                },
                Manoeuvre {
                    start_s: 53.0,
                    duration_s: 5.0,
                    longitudinal_accel_m_s2: 0.0,
                    lateral_accel_m_s2: 2.0,
                },
            ],
            ..SimParams::default()
        }
    }

    /// The manoeuvres with their longitudinal accelerations scaled down, all by one factor, so
    /// that braking alone (a sin^2 pulse of peak `a` over `d` changes the speed by `a d / 2`)
    /// leaves at least the lowest speed the simulation accepts (0.5 m/s, or half the initial
    /// speed when slower) plus 10 % of `speed_kmh`. Unchanged when the speed is high enough:
    /// the in-service preset's braking (-1.5 m/s^2 over 3 s, -2.25 m/s) is kept from 11 km/h
    /// up. Lateral accelerations are kept.
    pub fn manoeuvres_fitted_to_speed(mut self) -> Self {
        let loss: f64 = self
            .manoeuvres
            .iter()
            .map(|m| (-m.longitudinal_accel_m_s2 * m.duration_s / 2.0).max(0.0))
            .sum();
        let v0 = self.speed_kmh / 3.6;
        let allowed = 0.9 * v0 - min_speed_m_s(v0);
        if loss.is_finite() && allowed > 0.0 && loss > allowed {
            let f = allowed / loss;
            for m in &mut self.manoeuvres {
                m.longitudinal_accel_m_s2 *= f;
            }
        }
        self
    }

    /// The road as seen by the wheels (for [`FullCar::acceleration_psd`]).
    pub fn road_input(&self) -> RoadInput {
        RoadInput {
            class: self.road,
            coherence: self.coherence,
            tyre_envelope_cycles_per_m: self.tyre_envelope_cycles_per_m,
        }
    }

    /// Check every value; errors name the field and the fix.
    pub fn validate(&self) -> Result<()> {
        if !(self.speed_kmh.is_finite() && (1.0..=500.0).contains(&self.speed_kmh)) {
            return Err(invalid(
                "speed_kmh",
                vibmode_core::Num(self.speed_kmh),
                "must be 1 to 500 km/h, e.g. 40",
            ));
        }
        if !(self.fs_hz.is_finite()
            && self.fs_hz > 0.0
            && self.fs_hz <= vibmode_core::limits::FS_HZ_MAX)
        {
            return Err(invalid(
                "fs_hz",
                self.fs_hz,
                "must be positive (Hz), e.g. 20000",
            ));
        }
        if !(self.duration_s.is_finite() && self.duration_s > 0.0)
            || self.duration_s * self.fs_hz < 16.0
        {
            return Err(invalid(
                "duration_s",
                self.duration_s,
                format!(
                    "must give at least 16 samples at fs_hz = {}, e.g. 10.24",
                    self.fs_hz
                ),
            ));
        }
        if self.records == 0 {
            return Err(invalid("records", 0, "must be at least 1, e.g. 8"));
        }
        let total = (self.duration_s * self.fs_hz).round() * self.records as f64;
        if total > 50e6 {
            return Err(invalid(
                "records * duration_s * fs_hz",
                total,
                "is more than 50 million samples per channel; reduce records, duration_s or fs_hz",
            ));
        }
        self.road_input().validate()?;
        if let Some(w) = self.warmup_s {
            if !(w.is_finite() && (0.0..=600.0).contains(&w)) {
                return Err(invalid("warmup_s", w, "must be between 0 and 600 s"));
            }
        }
        for (i, m) in self.manoeuvres.iter().enumerate() {
            if !(m.start_s.is_finite() && m.start_s >= 0.0) {
                return Err(invalid(
                    format!("manoeuvres[{i}].start_s"),
                    m.start_s,
                    "must be >= 0 (s)",
                ));
            }
            if !(m.duration_s.is_finite() && m.duration_s > 0.0) {
                return Err(invalid(
                    format!("manoeuvres[{i}].duration_s"),
                    m.duration_s,
                    "must be positive (s)",
                ));
            }
            if !m.longitudinal_accel_m_s2.is_finite() || m.longitudinal_accel_m_s2.abs() > 10.0 {
                return Err(invalid(
                    format!("manoeuvres[{i}].longitudinal_accel_m_s2"),
                    m.longitudinal_accel_m_s2,
                    "must be within +-10 m/s^2",
                ));
            }
            if !m.lateral_accel_m_s2.is_finite() || m.lateral_accel_m_s2.abs() > 10.0 {
                return Err(invalid(
                    format!("manoeuvres[{i}].lateral_accel_m_s2"),
                    m.lateral_accel_m_s2,
                    "must be within +-10 m/s^2",
                ));
            }
        }
        let d = &self.disturbances;
        for (i, l) in d.engine_lines.iter().enumerate() {
            if !(l.frequency_hz.is_finite() && l.frequency_hz > 0.0) {
                return Err(invalid(
                    format!("engine_lines[{i}].frequency_hz"),
                    l.frequency_hz,
                    "must be positive (Hz)",
                ));
            }
            if !(l.drift_hz.is_finite() && l.drift_hz >= 0.0 && l.drift_hz < l.frequency_hz) {
                return Err(invalid(
                    format!("engine_lines[{i}].drift_hz"),
                    l.drift_hz,
                    "must be >= 0 and below frequency_hz",
                ));
            }
            if !(l.drift_period_s.is_finite() && l.drift_period_s > 0.0) {
                return Err(invalid(
                    format!("engine_lines[{i}].drift_period_s"),
                    l.drift_period_s,
                    "must be positive (s)",
                ));
            }
            let rel = |key: &str, v: f64, max: f64| -> Result<()> {
                if v.is_finite() && (0.0..=max).contains(&v) {
                    Ok(())
                } else {
                    Err(invalid(
                        format!("engine_lines[{i}].{key}"),
                        v,
                        format!("must be between 0 and {max}"),
                    ))
                }
            };
            rel("wander_rel_std", l.wander_rel_std, 0.2)?;
            rel("am_rel_std", l.am_rel_std, 0.5)?;
            rel("speed_coupling", l.speed_coupling, 2.0)?;
            for (key, v) in [
                ("wander_correlation_s", l.wander_correlation_s),
                ("am_correlation_s", l.am_correlation_s),
            ] {
                if !(v.is_finite() && v > 0.0 && v <= 1e4) {
                    return Err(invalid(
                        format!("engine_lines[{i}].{key}"),
                        v,
                        "must be positive and at most 10000 (s)",
                    ));
                }
            }
            if !(l.force_n.is_finite() && l.x_m.is_finite() && l.y_m.is_finite()) {
                return Err(invalid(
                    format!("engine_lines[{i}].force_n"),
                    l.force_n,
                    "force_n, x_m and y_m must be finite",
                ));
            }
        }
        if !(d.sensor_noise_std_m_s2.is_finite() && d.sensor_noise_std_m_s2 >= 0.0) {
            return Err(invalid(
                "sensor_noise_std_m_s2",
                d.sensor_noise_std_m_s2,
                "must be >= 0 (m/s^2)",
            ));
        }
        if !(d.sensor_bias_max_m_s2.is_finite() && d.sensor_bias_max_m_s2 >= 0.0) {
            return Err(invalid(
                "sensor_bias_max_m_s2",
                d.sensor_bias_max_m_s2,
                "must be >= 0 (m/s^2)",
            ));
        }
        if !(d.engine_speed_record_rel_std.is_finite()
            && (0.0..=0.3).contains(&d.engine_speed_record_rel_std))
        {
            return Err(invalid(
                "engine_speed_record_rel_std",
                d.engine_speed_record_rel_std,
                "must be between 0 and 0.3",
            ));
        }
        if !(d.sensor_misalignment_max_deg.is_finite()
            && (0.0..=45.0).contains(&d.sensor_misalignment_max_deg))
        {
            return Err(invalid(
                "sensor_misalignment_max_deg",
                d.sensor_misalignment_max_deg,
                "must be between 0 and 45 (deg)",
            ));
        }
        if !(self.speed_wander_rel_std.is_finite()
            && (0.0..=0.3).contains(&self.speed_wander_rel_std))
        {
            return Err(invalid(
                "speed_wander_rel_std",
                self.speed_wander_rel_std,
                "must be between 0 and 0.3",
            ));
        }
        if !(self.speed_wander_correlation_s.is_finite()
            && self.speed_wander_correlation_s > 0.0
            && self.speed_wander_correlation_s <= 1e4)
        {
            return Err(invalid(
                "speed_wander_correlation_s",
                self.speed_wander_correlation_s,
                "must be positive and at most 10000 (s)",
            ));
        }
        for (i, t) in d.hf_tones.iter().enumerate() {
            if !(t.frequency_hz.is_finite() && t.frequency_hz > 0.0 && t.amplitude_m_s2.is_finite())
            {
                return Err(invalid(
                    format!("hf_tones[{i}].frequency_hz"),
                    t.frequency_hz,
                    "must be positive with a finite amplitude_m_s2",
                ));
            }
        }
        Ok(())
    }
}

/// One record: successive segment of the drive.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimRecord {
    /// The accelerations: one channel per sensor (named after it, unit m/s^2, with the sensor's
    /// role, corner and direction), at the simulation rate.
    pub recording: Recording,
    /// Time of the first sample from the start of record 0, s.
    pub start_time_s: f64,
    /// Mean speed during the record, km/h.
    pub mean_speed_kmh: f64,
}

/// Ground truth of a simulation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Truth {
    /// Modes of the vehicle model.
    pub modes: Vec<ModeInfo>,
    /// Nominal frequencies of the engine / gear lines, Hz.
    pub disturbance_lines_hz: Vec<f64>,
    /// What each engine / gear line did in each record (its frequency moves with the engine
    /// speed, the wander and the drift).
    pub lines: Vec<LineTruth>,
    /// Tilt of each sensor (about the lateral axis, about the longitudinal axis), deg.
    pub sensor_misalignment_deg: Vec<[f64; 2]>,
    /// Frequencies of the added high-frequency tones, Hz.
    pub hf_tones_hz: Vec<f64>,
    /// Bias drawn for each channel, m/s^2.
    pub sensor_bias_m_s2: Vec<f64>,
    /// Sensor noise standard deviation, m/s^2.
    pub sensor_noise_std_m_s2: f64,
    /// Road class.
    pub road_class: RoadClass,
    /// Gd(n0) of the road class, m^3.
    pub road_gd_n0_m3: f64,
    /// Road as seen by the wheels (class, coherence, enveloping).
    pub road: RoadInput,
    /// Nominal speed, km/h.
    pub speed_kmh: f64,
    /// Warm-up actually used, s.
    pub warmup_s: f64,
    /// Seed.
    pub seed: u64,
}

/// Result of [`simulate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Simulation {
    /// Records in time order.
    pub records: Vec<SimRecord>,
    /// What the identification should find.
    pub truth: Truth,
}

/// Exact discretisation with first-order hold on the inputs u = [r (4), f (n)].
pub(crate) struct Discrete {
    ns: usize,
    nu: usize,
    np: usize,
    phi: Vec<f64>,
    ga: Vec<f64>,
    gb: Vec<f64>,
    cy: Vec<f64>,
    dy: Vec<f64>,
    ey: Vec<f64>,
    /// Static state for a road height vector (x = S r), ns x 4.
    x_static: DMatrix<f64>,
}

fn flat(m: &DMatrix<f64>) -> Vec<f64> {
    let mut v = Vec::with_capacity(m.nrows() * m.ncols());
    for i in 0..m.nrows() {
        for j in 0..m.ncols() {
            v.push(m[(i, j)]);
        }
    }
    v
}

impl Discrete {
    /// States x1 = q, x2 = q' - M^-1 Ct r (removes the road-velocity input from the state
    /// equation); the road velocity then only enters the acceleration output directly.
    pub(crate) fn new(car: &FullCar, fs_hz: f64) -> Result<Self> {
        let n = car.n;
        let ns = 2 * n;
        let nu = 4 + n;
        let h = 1.0 / fs_hz;
        let minv = DMatrix::from_fn(n, n, |i, j| if i == j { 1.0 / car.mass[i] } else { 0.0 });
        let mk = &minv * &car.k;
        let mc = &minv * &car.c;
        let mct = &minv * &car.ct;
        let br = &minv * (&car.kt - &car.c * &mct);
        let mut a = DMatrix::zeros(ns, ns);
        let mut b = DMatrix::zeros(ns, nu);
        for i in 0..n {
            a[(i, n + i)] = 1.0;
            for j in 0..n {
                a[(n + i, j)] = -mk[(i, j)];
                a[(n + i, n + j)] = -mc[(i, j)];
            }
            for j in 0..4 {
                b[(i, j)] = mct[(i, j)];
                b[(n + i, j)] = br[(i, j)];
            }
            b[(n + i, 4 + i)] = minv[(i, i)];
        }
        let na = ns + 2 * nu;
        let mut aug = DMatrix::zeros(na, na);
        aug.view_mut((0, 0), (ns, ns)).copy_from(&(&a * h));
        aug.view_mut((0, ns), (ns, nu)).copy_from(&(&b * h));
        for i in 0..nu {
            aug[(ns + i, ns + nu + i)] = 1.0;
        }
        let e = aug.exp();
        if e.iter().any(|v| !v.is_finite()) {
            return Err(VehicleError::Numerical(format!(
                "matrix exponential overflowed at fs_hz = {fs_hz}"
            )));
        }
        let phi = e.view((0, 0), (ns, ns)).into_owned();
        let e12 = e.view((0, ns), (ns, nu)).into_owned();
        let e13 = e.view((0, ns + nu), (ns, nu)).into_owned();
        let ga = &e12 - &e13;
        // Outputs.
        let p = car.sensors.len();
        let o = DMatrix::from_fn(p, n, |s, i| car.sensors[s].row[i]);
        let mut cy = DMatrix::zeros(p, ns);
        cy.view_mut((0, 0), (p, n)).copy_from(&(-(&o * &mk)));
        cy.view_mut((0, n), (p, n)).copy_from(&(-(&o * &mc)));
        let dy = &o * b.view((n, 0), (n, nu));
        let ey = &o * &mct;
        // Static equilibrium for road heights r: K q = Kt r, q' = 0 -> x2 = -M^-1 Ct r.
        let qs = car
            .k
            .clone()
            .lu()
            .solve(&car.kt)
            .ok_or_else(|| VehicleError::Numerical("stiffness matrix is singular".into()))?;
        let mut x_static = DMatrix::zeros(ns, 4);
        x_static.view_mut((0, 0), (n, 4)).copy_from(&qs);
        x_static.view_mut((n, 0), (n, 4)).copy_from(&(-&mct));
        Ok(Discrete {
            ns,
            nu,
            np: p,
            phi: flat(&phi),
            ga: flat(&ga),
            gb: flat(&e13),
            cy: flat(&cy),
            dy: flat(&dy),
            ey: flat(&ey),
            x_static,
        })
    }

    fn initial_state(&self, r0: &[f64]) -> Vec<f64> {
        (0..self.ns)
            .map(|i| (0..4).map(|j| self.x_static[(i, j)] * r0[j]).sum())
            .collect()
    }

    /// Run over `len` samples. `input(k, u)` fills u (len nu) for sample k in 0..=len;
    /// `rdot(k)` gives the road velocity at sample k; `sink(k, y)` receives the outputs.
    /// `forces` lists, in ascending order, the degrees of freedom whose generalised force
    /// `input` may set to a non-zero value; the other forces stay 0 and are left out of the
    /// sums (adding `a * 0` changes no sum but the sign of a zero).
    fn run(
        &self,
        len: usize,
        forces: &[usize],
        mut input: impl FnMut(usize, &mut [f64]),
        mut rdot: impl FnMut(usize) -> [f64; 4],
        mut sink: impl FnMut(usize, &[f64]),
    ) {
        let (ns, nu, np) = (self.ns, self.nu, self.np);
        // The road heights, then the forces that may be non-zero.
        let active: Vec<usize> = (0..4).chain(forces.iter().map(|&i| 4 + i)).collect();
        let active = &active[..];
        let na = active.len();
        // The input matrices' active columns, row by row, in the order of `active`.
        let pick = |m: &[f64], rows: usize| -> Vec<f64> {
            (0..rows)
                .flat_map(|i| active.iter().map(move |&j| m[i * nu + j]))
                .collect()
        };
        let (ga, gb, dy) = (pick(&self.ga, ns), pick(&self.gb, ns), pick(&self.dy, np));
        let mut u = vec![0.0; nu];
        let mut u0 = vec![0.0; na];
        let mut u1 = vec![0.0; na];
        let gather = |u: &[f64], to: &mut [f64]| {
            for (t, &j) in to.iter_mut().zip(active) {
                *t = u[j];
            }
        };
        input(0, &mut u);
        gather(&u, &mut u0);
        let mut x = self.initial_state(&u[..4]);
        let mut xn = vec![0.0; ns];
        let mut y = vec![0.0; np];
        for k in 0..len {
            let rd = rdot(k);
            for (((ys, c), d), e) in y
                .iter_mut()
                .zip(self.cy.chunks_exact(ns))
                .zip(dy.chunks_exact(na))
                .zip(self.ey.chunks_exact(4))
            {
                let mut acc = 0.0;
                for (ci, xi) in c.iter().zip(&x) {
                    acc += ci * xi;
                }
                for (di, ui) in d.iter().zip(&u0) {
                    acc += di * ui;
                }
                for (ei, ri) in e.iter().zip(&rd) {
                    acc += ei * ri;
                }
                *ys = acc;
            }
            sink(k, &y);
            input(k + 1, &mut u);
            gather(&u, &mut u1);
            for (((xi, p), a), b) in xn
                .iter_mut()
                .zip(self.phi.chunks_exact(ns))
                .zip(ga.chunks_exact(na))
                .zip(gb.chunks_exact(na))
            {
                let mut acc = 0.0;
                for (pj, xj) in p.iter().zip(&x) {
                    acc += pj * xj;
                }
                for ((aj, bj), (v0, v1)) in a.iter().zip(b).zip(u0.iter().zip(&u1)) {
                    acc += aj * v0 + bj * v1;
                }
                *xi = acc;
            }
            std::mem::swap(&mut x, &mut xn);
            std::mem::swap(&mut u0, &mut u1);
        }
    }
}

impl FullCar {
    /// Time response of the sensor accelerations (m/s^2) to given road heights
    /// `road_m[k] = [FL, FR, RL, RR]` (m) sampled at `fs_hz`, starting at rest in static
    /// equilibrium on `road_m[0]`. Exact for road heights linear between samples (first-order
    /// hold); the road velocity in the tyre-damper term is the central difference.
    /// Returns `out[channel][sample]`.
    pub fn response(&self, road_m: &[[f64; 4]], fs_hz: f64) -> Result<Vec<Vec<f64>>> {
        if !(fs_hz.is_finite() && fs_hz > 0.0) {
            return Err(invalid("fs_hz", fs_hz, "must be positive (Hz)"));
        }
        if road_m.iter().flatten().any(|v| !v.is_finite()) {
            return Err(invalid(
                "road_m",
                "non-finite value",
                "road heights must be finite (m)",
            ));
        }
        let len = road_m.len();
        let mut out = vec![vec![0.0; len]; self.sensors.len()];
        if len == 0 {
            return Ok(out);
        }
        let d = Discrete::new(self, fs_hz)?;
        let at = |k: usize| road_m[k.min(len - 1)];
        d.run(
            len,
            &[],
            |k, u| {
                u.iter_mut().for_each(|v| *v = 0.0);
                u[..4].copy_from_slice(&at(k));
            },
            |k| {
                let (a, b, span) = if len < 2 {
                    (0, 0, 1.0)
                } else if k == 0 {
                    (0, 1, 1.0)
                } else if k + 1 >= len {
                    (len - 2, len - 1, 1.0)
                } else {
                    (k - 1, k + 1, 2.0)
                };
                let (ra, rb) = (road_m[a], road_m[b]);
                std::array::from_fn(|i| (rb[i] - ra[i]) * fs_hz / span)
            },
            |k, y| {
                for (o, v) in out.iter_mut().zip(y) {
                    o[k] = *v;
                }
            },
        );
        Ok(out)
    }
}

/// Default warm-up: five times the slowest mode's decay time `1 / (zeta omega)`, within 2-30 s.
fn default_warmup_s(modes: &[ModeInfo]) -> f64 {
    let tmax = modes
        .iter()
        .map(|m| 1.0 / (m.damping_ratio * 2.0 * PI * m.frequency_hz).max(1e-9))
        .fold(0.0, f64::max);
    (5.0 * tmax).clamp(2.0, 30.0)
}

/// Lowest speed the manoeuvres may brake to, m/s: 0.5 m/s, or half the initial speed `v0` when
/// that is slower (a vehicle simulated at 1 km/h).
fn min_speed_m_s(v0: f64) -> f64 {
    0.5f64.min(0.5 * v0)
}

/// Speed (m/s) at each of `nk` samples, integrating the manoeuvres' longitudinal acceleration
/// `ax(t)` by the trapezoidal rule from `v0`; `time(k)` is the time of sample k.
fn speed_profile(
    v0: f64,
    nk: usize,
    dt: f64,
    time: impl Fn(usize) -> f64,
    ax: impl Fn(f64) -> f64,
) -> Result<Vec<f64>> {
    let mut speed = vec![v0; nk];
    let floor = min_speed_m_s(v0);
    for k in 1..nk {
        let t0 = time(k - 1);
        let t1 = time(k);
        speed[k] = speed[k - 1] + 0.5 * (ax(t0) + ax(t1)) * dt;
        if speed[k] < floor {
            return Err(invalid(
                "manoeuvres",
                format!("speed {:.2} m/s at t = {:.2} s", speed[k], t1),
                format!("brakes the vehicle below {} m/s (the floor: 0.5 m/s, or half the initial speed when slower); reduce the braking longitudinal_accel_m_s2 or raise speed_kmh", vibmode_core::Num(floor)),
            ));
        }
    }
    Ok(speed)
}

/// Samples per block of the sensor effects handed from their thread to the response's.
const EFFECT_BLOCK: usize = 8192;

/// Writes each of the `p` channels' bias, high-frequency tones and white sensor noise into `blocks`
/// (`blocks[b][c]`: block `b` of channel `c`, [`EFFECT_BLOCK`] samples but the last) and sends
/// each block on `tx` once written, in order; returns the biases drawn. The draws from `rng` are
/// in the order that keeps a seed's output bit-identical (the biases, then per channel its tones'
/// phases and its noise sample by sample): a first pass draws them all and keeps where each
/// block's noise starts, so that the blocks can then be written in time order.
fn sensor_effects<'a>(
    p: usize,
    blocks: Vec<Vec<&'a mut [f64]>>,
    dist: &Disturbances,
    dt: f64,
    rng: &mut ChaCha8Rng,
    tx: std::sync::mpsc::Sender<Vec<&'a mut [f64]>>,
) -> Vec<f64> {
    let bias: Vec<f64> = (0..p)
        .map(|_| {
            if dist.sensor_bias_max_m_s2 > 0.0 {
                rng.gen_range(-1.0..1.0) * dist.sensor_bias_max_m_s2
            } else {
                0.0
            }
        })
        .collect();
    let noisy = dist.sensor_noise_std_m_s2 > 0.0;
    // Per channel: its tones' phases and the generator's state at the start of each block.
    let mut phases: Vec<Vec<f64>> = Vec::with_capacity(p);
    let mut starts: Vec<Vec<ChaCha8Rng>> = Vec::with_capacity(p);
    for c in 0..p {
        phases.push(
            dist.hf_tones
                .iter()
                .map(|_| rng.gen_range(0.0..2.0 * PI))
                .collect(),
        );
        starts.push(
            blocks
                .iter()
                .map(|b| {
                    let at = rng.clone();
                    if noisy {
                        for _ in 0..b[c].len() {
                            let _: f64 = rng.sample(StandardNormal);
                        }
                    }
                    at
                })
                .collect(),
        );
    }
    for (b, mut block) in blocks.into_iter().enumerate() {
        let j0 = b * EFFECT_BLOCK;
        for (c, s) in block.iter_mut().enumerate() {
            let mut rng = starts[c][b].clone();
            for (i, v) in s.iter_mut().enumerate() {
                let t = (j0 + i) as f64 * dt;
                let mut add = bias[c];
                for (tone, ph) in dist.hf_tones.iter().zip(&phases[c]) {
                    add += tone.amplitude_m_s2 * (2.0 * PI * tone.frequency_hz * t + ph).sin();
                }
                if noisy {
                    let g: f64 = rng.sample(StandardNormal);
                    add += g * dist.sensor_noise_std_m_s2;
                }
                *v = add;
            }
        }
        if tx.send(block).is_err() {
            // The response's thread stopped (a panic, passed on by the scope).
            break;
        }
    }
    bias
}

/// Cuts the drive into records of `n_rec` samples, from the end (`split_off`) so the drive is
/// never held twice; each channel named after its sensor, with its placement.
fn split_records(
    mut samples: Vec<Vec<f64>>,
    car: &FullCar,
    speed: &[f64],
    n_warm: usize,
    n_rec: usize,
    fs: f64,
) -> Vec<SimRecord> {
    let names = car.sensor_names();
    let placements = car.sensor_placements();
    let n_records = samples.first().map_or(0, |s| s.len() / n_rec.max(1));
    let mut records = Vec::with_capacity(n_records);
    for r in (0..n_records).rev() {
        let a = r * n_rec;
        let i0 = n_warm + a + 1;
        let mean_v = speed[i0..i0 + n_rec].iter().sum::<f64>() / n_rec as f64;
        let channels = samples
            .iter_mut()
            .zip(names.iter().zip(&placements))
            .map(|(s, (name, placement))| {
                Channel::new(name.clone(), "m/s^2", s.split_off(a)).with_placement(*placement)
            })
            .collect();
        records.push(SimRecord {
            recording: Recording {
                fs_hz: fs,
                channels,
                time_axis: None,
            },
            start_time_s: a as f64 * (1.0 / fs),
            mean_speed_kmh: mean_v * 3.6,
        });
    }
    records.reverse();
    records
}

/// Per corner (FL, FR, RL, RR): the road track it runs on (0 left, 1 right) and its distance
/// ahead of the rear axle, m.
fn wheel_tracks(wheelbase_m: f64) -> [(usize, f64); 4] {
    Corner::ALL.map(|c| {
        (
            if c.is_left() { 0 } else { 1 },
            if c.is_front() { wheelbase_m } else { 0.0 },
        )
    })
}

/// Adds the engine/gear lines' generalised forces at time `t` (s) to `f` (heave N, pitch and
/// roll N m), stepping the lines' random processes.
fn add_line_forces(f: &mut [f64], lines: &mut LineBank, t: f64, speed_ratio: f64) {
    for (l, force) in lines.forces(t, speed_ratio) {
        f[DOF_HEAVE] += force;
        f[DOF_PITCH] += force * l.x_m;
        f[DOF_ROLL] += force * l.y_m;
    }
}

/// Multiplies the speed by `1 + u(t)`, `u` the speed wander (stream 4 of the seed), kept
/// above half the speed.
fn add_speed_wander(speed: &mut [f64], sim: &SimParams, dt: f64) {
    let mut rng = ChaCha8Rng::seed_from_u64(sim.seed);
    rng.set_stream(4);
    // A Gauss-Markov process low-passed once more (time constant SPEED_SMOOTHING_S), so that
    // the speed has a derivative: the longitudinal acceleration stays bounded and does not grow
    // with the sampling rate. The driving process' standard deviation is raised so that the
    // smoothed one keeps `speed_wander_rel_std`.
    let tau = sim.speed_wander_correlation_s;
    let gain = ((tau + SPEED_SMOOTHING_S) / tau).sqrt();
    if let Some(mut u) = OrnsteinUhlenbeck::new(sim.speed_wander_rel_std * gain, tau, dt, &mut rng)
    {
        let alpha = 1.0 - (-dt / SPEED_SMOOTHING_S).exp();
        // Start at a draw of the smoothed process' stationary distribution.
        let mut w = u.next(&mut rng) / gain;
        for v in speed.iter_mut() {
            w += alpha * (u.next(&mut rng) - w);
            *v *= (1.0 + w).max(0.5);
        }
    }
}

/// Time constant of the smoothing of the speed wander, s: a driver changes speed with a
/// bounded acceleration (at 40 km/h and 3 %, about 0.15 m/s^2 rms: v0 sigma sqrt(tau_s / tau) / tau_s).
const SPEED_SMOOTHING_S: f64 = 1.0;

/// Each sensor's tilt angles (about the lateral axis, about the longitudinal axis), deg.
fn misalignment_angles(n: usize, max_deg: f64, rng: &mut ChaCha8Rng) -> Vec<[f64; 2]> {
    (0..n)
        .map(|_| {
            if max_deg > 0.0 {
                [
                    rng.gen_range(-1.0..1.0) * max_deg,
                    rng.gen_range(-1.0..1.0) * max_deg,
                ]
            } else {
                [0.0, 0.0]
            }
        })
        .collect()
}

/// Position along the road (m) at each sample, integrating `speed` (m/s) by the trapezoidal rule
/// from one road step `dx = max speed x dt`, and that step.
fn positions(speed: &[f64], dt: f64) -> (Vec<f64>, f64) {
    let vmax = speed.iter().copied().fold(0.0, f64::max);
    let dx = vmax * dt;
    let mut pos = vec![dx; speed.len()];
    for k in 1..speed.len() {
        pos[k] = pos[k - 1] + 0.5 * (speed[k - 1] + speed[k]) * dt;
    }
    (pos, dx)
}

/// What the identification should find, and what was drawn.
fn make_truth(
    sim: &SimParams,
    modes: Vec<ModeInfo>,
    bias: Vec<f64>,
    warmup_s: f64,
    lines: Vec<LineTruth>,
    misalignment: Vec<[f64; 2]>,
) -> Truth {
    let dist = &sim.disturbances;
    Truth {
        modes,
        lines,
        sensor_misalignment_deg: misalignment,
        disturbance_lines_hz: dist.engine_lines.iter().map(|l| l.frequency_hz).collect(),
        hf_tones_hz: dist.hf_tones.iter().map(|t| t.frequency_hz).collect(),
        sensor_bias_m_s2: bias,
        sensor_noise_std_m_s2: dist.sensor_noise_std_m_s2,
        road_class: sim.road,
        road_gd_n0_m3: sim.road.gd_n0_m3(),
        road: sim.road_input(),
        speed_kmh: sim.speed_kmh,
        warmup_s,
        seed: sim.seed,
    }
}

/// Simulate the measurement campaign: one continuous drive over an ISO 8608 road, cut into
/// `records` successive records, with the optional manoeuvres and disturbances.
///
/// Same parameters and seed give bit-identical output.
pub fn simulate(vehicle: &VehicleParams, sim: &SimParams) -> Result<Simulation> {
    sim.validate()?;
    let car = FullCar::new(vehicle)?;
    let modes = car.modes()?;
    let fs = sim.fs_hz;
    let dt = 1.0 / fs;
    let warmup_s = sim.warmup_s.unwrap_or_else(|| default_warmup_s(&modes));
    let n_warm = (warmup_s * fs).round() as usize;
    let n_rec = (sim.duration_s * fs).round() as usize;
    let n_total = n_warm + n_rec * sim.records;
    // Speed and position per sample (index k covers t = (k - n_warm) dt), one extra at each end.
    let v0 = sim.speed_kmh / 3.6;
    let body_m = vehicle.body.mass_kg;
    let h_cg = vehicle.body.cg_height_m;
    let time = |k: usize| (k as f64 - n_warm as f64 - 1.0) * dt; // index shifted by one
    let ax = |t: f64| {
        sim.manoeuvres
            .iter()
            .map(|m| m.longitudinal_accel_m_s2 * m.pulse(t))
            .sum::<f64>()
    };
    let ay = |t: f64| {
        sim.manoeuvres
            .iter()
            .map(|m| m.lateral_accel_m_s2 * m.pulse(t))
            .sum::<f64>()
    };
    let nk = n_total + 2;
    let speed_manoeuvres = speed_profile(v0, nk, dt, time, ax)?;
    let mut speed = speed_manoeuvres.clone();
    add_speed_wander(&mut speed, sim, dt);
    let wb = vehicle.geometry.wheelbase_m;
    let (pos, dx) = positions(&speed, dt);
    let length = pos[nk - 1] + wb + 4.0 * dx;
    let mut rng = ChaCha8Rng::seed_from_u64(sim.seed);
    rng.set_stream(1);
    let road = RoadProfile::generate(&sim.road_input(), length, dx, &mut rng)?;
    let mut rng2 = ChaCha8Rng::seed_from_u64(sim.seed);
    rng2.set_stream(2);
    // Road heights: front axle at pos + wb, rear at pos.
    let corners = wheel_tracks(wb);
    // Generalised forces.
    let n = car.n;
    let mut rng3 = ChaCha8Rng::seed_from_u64(sim.seed);
    rng3.set_stream(3);
    let p = car.sensors.len();
    let dist = &sim.disturbances;
    let tilt = misalignment_angles(p, dist.sensor_misalignment_max_deg, &mut rng3);
    let mut lines = LineBank::new(
        &dist.engine_lines,
        dist.engine_speed_record_rel_std,
        sim.records,
        sim.duration_s,
        dt,
        &mut rng2,
        rng3,
    );
    let d = Discrete::new(&car, fs)?;
    // Per sensor: cos a cos b (the vertical gain), sin a (longitudinal), sin b (lateral).
    let tilt_gains: Vec<[f64; 3]> = tilt
        .iter()
        .map(|[a, b]| {
            let (a, b) = (a.to_radians(), b.to_radians());
            [a.cos() * b.cos(), a.sin(), b.sin()]
        })
        .collect();
    let n_out = n_rec * sim.records;
    let mut samples: Vec<Vec<f64>> = vec![vec![0.0; n_out]; p];
    // The sensor effects do not depend on the vehicle's response: a second thread writes them
    // into `samples` block by block (ahead of the response) and hands each block over; the
    // response is then added to what is there (`add + value`, the same sum as before).
    let bias = {
        let mut blocks: Vec<Vec<&mut [f64]>> = (0..n_out.div_ceil(EFFECT_BLOCK))
            .map(|_| Vec::new())
            .collect();
        for s in samples.iter_mut() {
            for (b, chunk) in s.chunks_mut(EFFECT_BLOCK).enumerate() {
                blocks[b].push(chunk);
            }
        }
        let (tx, rx) = std::sync::mpsc::channel::<Vec<&mut [f64]>>();
        std::thread::scope(|scope| {
            let effects = scope.spawn(|| sensor_effects(p, blocks, dist, dt, &mut rng2, tx));
            // The road heights of index k are used three times (input k - 1, road velocity at
            // k - 2 and k): kept for the last four indices.
            let cache = std::cell::RefCell::new([(usize::MAX, [0.0; 4]); 4]);
            let road_at = |k: usize| -> [f64; 4] {
                let mut c = cache.borrow_mut();
                let slot = &mut c[k % 4];
                if slot.0 != k {
                    *slot = (
                        k,
                        std::array::from_fn(|i| road.height_m(corners[i].0, pos[k] + corners[i].1)),
                    );
                }
                slot.1
            };
            let mut block: Vec<&mut [f64]> = Vec::new();
            // State index k of `run` corresponds to array index k + 1.
            d.run(
                n_total,
                &[DOF_HEAVE, DOF_PITCH, DOF_ROLL],
                |k, u| {
                    let idx = k + 1;
                    let r = road_at(idx);
                    u.iter_mut().for_each(|v| *v = 0.0);
                    u[..4].copy_from_slice(&r);
                    let t = time(idx);
                    let f = &mut u[4..4 + n];
                    add_line_forces(f, &mut lines, t, speed_manoeuvres[idx] / v0);
                    if !sim.manoeuvres.is_empty() {
                        f[DOF_PITCH] += body_m * ax(t) * h_cg;
                        f[DOF_ROLL] += body_m * ay(t) * h_cg;
                    }
                },
                |k| {
                    let (a, b) = (road_at(k), road_at(k + 2));
                    std::array::from_fn(|i| (b[i] - a[i]) / (2.0 * dt))
                },
                |k, y| {
                    if k < n_warm {
                        return;
                    }
                    let j = (k - n_warm) % EFFECT_BLOCK;
                    if j == 0 {
                        // The effects thread sends every block in order; it fails only by a panic,
                        // which the scope's end passes on.
                        match rx.recv() {
                            Ok(b) => block = b,
                            Err(_) => return,
                        }
                    }
                    if dist.sensor_misalignment_max_deg > 0.0 {
                        // Longitudinal acceleration from the speed, lateral from the manoeuvres.
                        let idx = k + 1;
                        let a_x = (speed[idx + 1] - speed[idx - 1]) / (2.0 * dt);
                        let a_y = ay(time(idx));
                        for ((s, v), [cc, sa, sb]) in block.iter_mut().zip(y).zip(&tilt_gains) {
                            s[j] += cc * v + sa * a_x + sb * a_y;
                        }
                    } else {
                        for (s, v) in block.iter_mut().zip(y) {
                            s[j] += *v;
                        }
                    }
                },
            );
            effects.join()
        })
    };
    let bias = match bias {
        Ok(b) => b,
        Err(panic) => std::panic::resume_unwind(panic),
    };
    let records = split_records(samples, &car, &speed, n_warm, n_rec, fs);
    Ok(Simulation {
        records,
        truth: make_truth(sim, modes, bias, warmup_s, lines.truth(), tilt),
    })
}
