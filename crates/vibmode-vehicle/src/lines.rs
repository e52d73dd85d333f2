//! Engine / gear lines as real vehicles make them: slow random frequency wander, amplitude
//! modulation, an engine speed that differs from record to record and follows the vehicle speed
//! during acceleration. Also the other slow random processes of the simulator.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A periodic engine / driveline line: a vertical force on the body.
/// In serialised form every field but `frequency_hz` and `force_n` may be omitted: `drift_hz` (0),
/// `drift_period_s` (30), `x_m` and `y_m` (0), `wander_rel_std` (0), `wander_correlation_s` (2),
/// `am_rel_std` (0), `am_correlation_s` (1), `speed_coupling` (0).
///
/// Instantaneous frequency: `frequency_hz * g_r * (1 + w(t)) * (v(t) / v0)^speed_coupling +
/// drift_hz * sin(2 pi t / drift_period_s)`, where `g_r` is the record's engine-speed factor
/// ([`Disturbances::engine_speed_record_rel_std`](crate::Disturbances::engine_speed_record_rel_std)), `w` a Gauss-Markov wander of relative
/// standard deviation `wander_rel_std` and correlation time `wander_correlation_s`, and `v / v0`
/// the speed ratio from the manoeuvres. Amplitude: `force_n * (1 + m(t))` with `m` a
/// Gauss-Markov modulation of standard deviation `am_rel_std`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EngineLine {
    /// Nominal frequency, Hz.
    pub frequency_hz: f64,
    /// Force amplitude, N (vertical, applied to the body at (x_m, y_m)).
    pub force_n: f64,
    /// Peak slow frequency deviation, Hz (0 = constant frequency).
    #[serde(default)]
    pub drift_hz: f64,
    /// Period of the sinusoidal frequency drift, s.
    #[serde(default = "default_drift_period")]
    pub drift_period_s: f64,
    /// Body x of the force (forward from the centre of gravity), m.
    #[serde(default)]
    pub x_m: f64,
    /// Body y of the force (to the left of the centre of gravity), m.
    #[serde(default)]
    pub y_m: f64,
    /// Relative standard deviation of the slow random frequency wander (0 = none; real engines
    /// ~1e-3).
    #[serde(default)]
    pub wander_rel_std: f64,
    /// Correlation time of the frequency wander, s.
    #[serde(default = "default_wander_correlation")]
    pub wander_correlation_s: f64,
    /// Relative standard deviation of the random amplitude modulation (0 = none; ~0.1).
    #[serde(default)]
    pub am_rel_std: f64,
    /// Correlation time of the amplitude modulation, s.
    #[serde(default = "default_am_correlation")]
    pub am_correlation_s: f64,
    /// Exponent of the speed ratio in the frequency: 0 = independent of the vehicle speed,
    /// 1 = proportional to it (a driveline order in a fixed gear).
    #[serde(default)]
    pub speed_coupling: f64,
}

impl EngineLine {
    /// A constant line of `force_n` at `frequency_hz` applied at the centre of gravity.
    pub fn constant(frequency_hz: f64, force_n: f64) -> Self {
        EngineLine {
            frequency_hz,
            force_n,
            drift_hz: 0.0,
            drift_period_s: default_drift_period(),
            x_m: 0.0,
            y_m: 0.0,
            wander_rel_std: 0.0,
            wander_correlation_s: default_wander_correlation(),
            am_rel_std: 0.0,
            am_correlation_s: default_am_correlation(),
            speed_coupling: 0.0,
        }
    }
}

fn default_drift_period() -> f64 {
    30.0
}

fn default_wander_correlation() -> f64 {
    2.0
}

fn default_am_correlation() -> f64 {
    1.0
}

/// A stationary Ornstein-Uhlenbeck (first-order Gauss-Markov) process of given standard
/// deviation and correlation time, stepped exactly at a fixed interval:
/// `x[k+1] = a x[k] + std sqrt(1 - a^2) n[k]`, `a = exp(-dt / tau)`, started in its stationary
/// distribution. Its autocorrelation is `std^2 exp(-|lag| / tau)`.
#[derive(Clone, Debug)]
pub(crate) struct OrnsteinUhlenbeck {
    a: f64,
    b: f64,
    x: f64,
}

impl OrnsteinUhlenbeck {
    /// `None` when `std` is 0 (the process is switched off and draws nothing).
    pub(crate) fn new(std: f64, tau_s: f64, dt: f64, rng: &mut ChaCha8Rng) -> Option<Self> {
        if std <= 0.0 {
            return None;
        }
        let a = (-dt / tau_s).exp();
        let x0: f64 = rng.sample(StandardNormal);
        Some(OrnsteinUhlenbeck {
            a,
            b: std * (1.0 - a * a).max(0.0).sqrt(),
            x: std * x0,
        })
    }

    /// The current value, then one step.
    pub(crate) fn next(&mut self, rng: &mut ChaCha8Rng) -> f64 {
        let v = self.x;
        let n: f64 = rng.sample(StandardNormal);
        self.x = self.a * self.x + self.b * n;
        v
    }
}

/// What one line did in each record (`truth.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LineTruth {
    /// Nominal frequency, Hz.
    pub nominal_hz: f64,
    /// Mean instantaneous frequency in each record, Hz.
    pub record_mean_hz: Vec<f64>,
    /// Lowest instantaneous frequency in each record, Hz.
    pub record_min_hz: Vec<f64>,
    /// Highest instantaneous frequency in each record, Hz.
    pub record_max_hz: Vec<f64>,
}

struct LineState {
    line: EngineLine,
    phase0: f64,
    extra_phase: f64,
    wander: Option<OrnsteinUhlenbeck>,
    am: Option<OrnsteinUhlenbeck>,
    record_factor: Vec<f64>,
    sum: Vec<f64>,
    count: Vec<usize>,
    min: Vec<f64>,
    max: Vec<f64>,
}

/// Every engine line, stepped sample by sample in time order.
pub(crate) struct LineBank {
    lines: Vec<LineState>,
    dt: f64,
    duration_s: f64,
    records: usize,
    rng: ChaCha8Rng,
}

impl LineBank {
    /// Draws each line's start phase from `phase_rng` (as before these effects existed, so a
    /// simulation without them is unchanged) and everything random of the new effects from `rng`:
    /// first the record-to-record engine-speed factors (log-normal, `record_rel_std`), then the
    /// start of each line's wander and modulation processes.
    pub(crate) fn new(
        lines: &[EngineLine],
        record_rel_std: f64,
        records: usize,
        duration_s: f64,
        dt: f64,
        phase_rng: &mut ChaCha8Rng,
        mut rng: ChaCha8Rng,
    ) -> Self {
        let phases: Vec<f64> = lines
            .iter()
            .map(|_| phase_rng.gen_range(0.0..2.0 * PI))
            .collect();
        // One engine: every line of a record moves by the same factor (they are orders of the
        // same shaft speed).
        let shared: Vec<f64> = (0..records)
            .map(|_| {
                if record_rel_std > 0.0 {
                    let n: f64 = rng.sample(StandardNormal);
                    (record_rel_std * n).exp()
                } else {
                    1.0
                }
            })
            .collect();
        let states = lines
            .iter()
            .zip(phases)
            .map(|(l, ph)| LineState {
                line: l.clone(),
                phase0: ph,
                extra_phase: 0.0,
                wander: OrnsteinUhlenbeck::new(
                    l.wander_rel_std,
                    l.wander_correlation_s,
                    dt,
                    &mut rng,
                ),
                am: OrnsteinUhlenbeck::new(l.am_rel_std, l.am_correlation_s, dt, &mut rng),
                record_factor: shared.clone(),
                sum: vec![0.0; records],
                count: vec![0; records],
                min: vec![f64::INFINITY; records],
                max: vec![f64::NEG_INFINITY; records],
            })
            .collect();
        LineBank {
            lines: states,
            dt,
            duration_s,
            records,
            rng,
        }
    }

    /// The vertical force of each line at time `t` (s from the start of record 0), then one
    /// step; `speed_ratio` is the vehicle's speed over the nominal speed (manoeuvres only).
    /// Must be called once per sample, in time order.
    pub(crate) fn forces(
        &mut self,
        t: f64,
        speed_ratio: f64,
    ) -> impl Iterator<Item = (&EngineLine, f64)> {
        let rec = if t < 0.0 || self.records == 0 {
            None
        } else {
            Some(((t / self.duration_s) as usize).min(self.records - 1))
        };
        let dt = self.dt;
        let rng = &mut self.rng;
        self.lines.iter_mut().map(move |s| {
            let l = &s.line;
            let wander = s.wander.as_mut().map_or(0.0, |p| p.next(rng));
            let am = s.am.as_mut().map_or(0.0, |p| p.next(rng));
            let rf = s
                .record_factor
                .get(rec.unwrap_or(0))
                .copied()
                .unwrap_or(1.0);
            let factor = rf * (1.0 + wander) * speed_ratio.max(1e-3).powf(l.speed_coupling);
            let phase = s.phase0
                + 2.0 * PI * l.frequency_hz * t
                + l.drift_hz * l.drift_period_s * (1.0 - (2.0 * PI * t / l.drift_period_s).cos())
                + s.extra_phase;
            let f_inst =
                l.frequency_hz * factor + l.drift_hz * (2.0 * PI * t / l.drift_period_s).sin();
            if let Some(r) = rec {
                s.sum[r] += f_inst;
                s.count[r] += 1;
                s.min[r] = s.min[r].min(f_inst);
                s.max[r] = s.max[r].max(f_inst);
            }
            s.extra_phase += 2.0 * PI * l.frequency_hz * (factor - 1.0) * dt;
            let force = l.force_n * (1.0 + am) * phase.sin();
            (&s.line, force)
        })
    }

    /// What each line did per record.
    pub(crate) fn truth(&self) -> Vec<LineTruth> {
        self.lines
            .iter()
            .map(|s| {
                let clean = |v: &[f64]| -> Vec<f64> {
                    v.iter()
                        .map(|x| {
                            if x.is_finite() {
                                *x
                            } else {
                                s.line.frequency_hz
                            }
                        })
                        .collect()
                };
                LineTruth {
                    nominal_hz: s.line.frequency_hz,
                    record_mean_hz: s
                        .sum
                        .iter()
                        .zip(&s.count)
                        .map(|(sum, &n)| {
                            if n > 0 {
                                sum / n as f64
                            } else {
                                s.line.frequency_hz
                            }
                        })
                        .collect(),
                    record_min_hz: clean(&s.min),
                    record_max_hz: clean(&s.max),
                }
            })
            .collect()
    }
}
