//! The linear full-car model: matrices, modes, frequency responses, analytic PSDs.

use crate::error::{invalid, Result, VehicleError};
use crate::params::{Corner, SensorKind, VehicleParams};
use crate::road::RoadInput;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Index of body heave z (m, up) in the generalised coordinates.
pub const DOF_HEAVE: usize = 0;
/// Index of body pitch theta (rad, nose up).
pub const DOF_PITCH: usize = 1;
/// Index of body roll phi (rad, left side up).
pub const DOF_ROLL: usize = 2;
/// Index of the first wheel DOF (FL, FR, RL, RR follow; m, up).
pub const DOF_WHEEL0: usize = 3;
/// Index of the body bending modal coordinate (only when `[bending]` is given).
pub const DOF_BENDING: usize = 7;

/// Physical meaning of a mode, from the DOF holding most of its kinetic energy.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModeLabel {
    /// Body vertical motion dominates.
    BodyHeave,
    /// Body pitch dominates.
    BodyPitch,
    /// Body roll dominates.
    BodyRoll,
    /// Front wheels moving in phase.
    FrontAxleBounce,
    /// Front wheels moving in anti-phase.
    FrontAxleTramp,
    /// Rear wheels moving in phase.
    RearAxleBounce,
    /// Rear wheels moving in anti-phase.
    RearAxleTramp,
    /// One wheel moving alone (asymmetric vehicle).
    WheelHop(Corner),
    /// Body bending modal coordinate dominates.
    BodyBending,
}

impl ModeLabel {
    /// Body heave, pitch or roll: a rigid-body mode of the sprung mass on its suspension.
    pub fn is_body_rigid(self) -> bool {
        matches!(
            self,
            ModeLabel::BodyHeave | ModeLabel::BodyPitch | ModeLabel::BodyRoll
        )
    }
}

impl fmt::Display for ModeLabel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModeLabel::BodyHeave => f.write_str("body heave"),
            ModeLabel::BodyPitch => f.write_str("body pitch"),
            ModeLabel::BodyRoll => f.write_str("body roll"),
            ModeLabel::FrontAxleBounce => f.write_str("front axle bounce"),
            ModeLabel::FrontAxleTramp => f.write_str("front axle tramp"),
            ModeLabel::RearAxleBounce => f.write_str("rear axle bounce"),
            ModeLabel::RearAxleTramp => f.write_str("rear axle tramp"),
            ModeLabel::WheelHop(c) => write!(f, "{c} wheel hop"),
            ModeLabel::BodyBending => f.write_str("body bending"),
        }
    }
}

impl std::str::FromStr for ModeLabel {
    type Err = VehicleError;
    /// Parses the [`Display`](fmt::Display) form, e.g. "body heave", "FL wheel hop"
    /// (case-insensitive; '_' and '-' accepted for spaces).
    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim().to_ascii_lowercase().replace(['_', '-'], " ");
        let all = [
            ModeLabel::BodyHeave,
            ModeLabel::BodyPitch,
            ModeLabel::BodyRoll,
            ModeLabel::FrontAxleBounce,
            ModeLabel::FrontAxleTramp,
            ModeLabel::RearAxleBounce,
            ModeLabel::RearAxleTramp,
            ModeLabel::WheelHop(Corner::FL),
            ModeLabel::WheelHop(Corner::FR),
            ModeLabel::WheelHop(Corner::RL),
            ModeLabel::WheelHop(Corner::RR),
            ModeLabel::BodyBending,
        ];
        all.into_iter().find(|l| l.to_string().to_ascii_lowercase() == t).ok_or_else(|| VehicleError::UnknownName {
            what: "mode label",
            value: s.to_string(),
            valid: "body heave, body pitch, body roll, front axle bounce, front axle tramp, rear axle bounce, rear axle tramp, FL/FR/RL/RR wheel hop, body bending",
        })
    }
}

/// One vibration mode (one complex-conjugate eigenvalue pair of the first-order system).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModeInfo {
    /// Undamped natural frequency |s| / (2 pi), Hz.
    pub frequency_hz: f64,
    /// Damping ratio -Re(s) / |s| (dimensionless).
    pub damping_ratio: f64,
    /// Damped frequency Im(s) / (2 pi), Hz.
    pub damped_frequency_hz: f64,
    /// Physical label from the dominant DOF kinetic energy.
    pub label: ModeLabel,
    /// Names of the DOFs, in the order of `shape_re` / `shape_im`.
    pub dof_names: Vec<String>,
    /// Real part of the complex mode shape (displacements; m for z and wheels, rad for angles),
    /// normalised so that the largest-energy DOF is 1 + 0i.
    pub shape_re: Vec<f64>,
    /// Imaginary part of the complex mode shape.
    pub shape_im: Vec<f64>,
    /// Fraction of the modal kinetic energy (M_ii |v_i|^2 / sum) per DOF.
    pub energy_fraction: Vec<f64>,
    /// Names of the sensors, in the order of `sensor_shape_re` / `sensor_shape_im`.
    #[serde(default)]
    pub sensor_names: Vec<String>,
    /// Real part of the mode shape seen by the sensors (their displacements; accelerations are
    /// the same shape times -s^2), normalised so that the largest-modulus sensor is 1 + 0i.
    /// This is what a multichannel identification of the sensor signals should find.
    #[serde(default)]
    pub sensor_shape_re: Vec<f64>,
    /// Imaginary part of the sensor mode shape.
    #[serde(default)]
    pub sensor_shape_im: Vec<f64>,
}

impl ModeInfo {
    /// This mode as a reference for the identified modes: frequency, damping, label and the
    /// shape at the sensors (named after them).
    pub fn to_reference(&self) -> vibmode_core::ReferenceMode {
        vibmode_core::ReferenceMode {
            frequency_hz: self.frequency_hz,
            damping_ratio: self.damping_ratio,
            label: self.label.to_string(),
            shape: (!self.sensor_names.is_empty()).then(|| self.sensor_shape()),
            shape_channels: self.sensor_names.clone(),
        }
    }

    /// The sensor mode shape as `[re, im]` pairs (empty when the sensors are unknown).
    pub fn sensor_shape(&self) -> Vec<[f64; 2]> {
        self.sensor_shape_re
            .iter()
            .zip(&self.sensor_shape_im)
            .map(|(&re, &im)| [re, im])
            .collect()
    }
}

#[derive(Debug, Clone)]
pub(crate) struct SensorRow {
    pub name: String,
    /// Role, corner and direction (vertical) of the sensor.
    pub placement: vibmode_core::Placement,
    /// Sensor displacement = row . q.
    pub row: DVector<f64>,
}

/// The assembled linear model M q'' + C q' + K q = Kt r + Ct r' + f.
///
/// q = [z (m), theta (rad, nose up), phi (rad, left up), z_FL, z_FR, z_RL, z_RR (m), (eta)],
/// r = road heights under FL, FR, RL, RR (m), f = generalised forces (N, N m).
#[derive(Debug, Clone)]
pub struct FullCar {
    params: VehicleParams,
    pub(crate) n: usize,
    pub(crate) mass: DVector<f64>,
    pub(crate) c: DMatrix<f64>,
    pub(crate) k: DMatrix<f64>,
    pub(crate) kt: DMatrix<f64>,
    pub(crate) ct: DMatrix<f64>,
    pub(crate) sensors: Vec<SensorRow>,
}

impl FullCar {
    /// Validate the parameters and assemble mass, damping and stiffness matrices.
    pub fn new(params: &VehicleParams) -> Result<Self> {
        params.validate()?;
        let p = params.clone();
        let n = if p.bending.is_some() { 8 } else { 7 };
        let mut mass = DVector::zeros(n);
        mass[DOF_HEAVE] = p.body.mass_kg;
        mass[DOF_PITCH] = p.body.pitch_inertia_kgm2;
        mass[DOF_ROLL] = p.body.roll_inertia_kgm2;
        for c in Corner::ALL {
            mass[DOF_WHEEL0 + c.index()] = p.axle(c).unsprung_mass_kg;
        }
        let mut k = DMatrix::zeros(n, n);
        let mut cm = DMatrix::zeros(n, n);
        let mut kt = DMatrix::zeros(n, 4);
        let mut ct = DMatrix::zeros(n, 4);
        if let Some(b) = &p.bending {
            let w = 2.0 * std::f64::consts::PI * b.frequency_hz;
            mass[DOF_BENDING] = b.modal_mass_kg;
            k[(DOF_BENDING, DOF_BENDING)] += b.modal_mass_kg * w * w;
            cm[(DOF_BENDING, DOF_BENDING)] += 2.0 * b.damping_ratio * b.modal_mass_kg * w;
        }
        for c in Corner::ALL {
            let ax = p.axle(c);
            let w = DOF_WHEEL0 + c.index();
            // Suspension deflection d = (body point) - (wheel) = g . q
            let (x, y) = p.corner_position_m(c);
            let mut g = DVector::zeros(n);
            g[DOF_HEAVE] = 1.0;
            g[DOF_PITCH] = x;
            g[DOF_ROLL] = y;
            if let Some(b) = &p.bending {
                g[DOF_BENDING] = b.corner_shape[c.index()];
            }
            g[w] = -1.0;
            let ggt = &g * g.transpose();
            k += &ggt * ax.spring_stiffness_n_per_m;
            cm += &ggt * ax.damper_n_s_per_m;
            // Tyre: force kt (r - z_w) on the wheel.
            k[(w, w)] += ax.tyre_stiffness_n_per_m;
            cm[(w, w)] += ax.tyre_damping_n_s_per_m;
            kt[(w, c.index())] = ax.tyre_stiffness_n_per_m;
            ct[(w, c.index())] = ax.tyre_damping_n_s_per_m;
        }
        // Anti-roll bars: moment k_arb * (phi - (z_L - z_R)/track).
        for (front, ax, track) in [
            (true, &p.front, p.geometry.track_front_m),
            (false, &p.rear, p.geometry.track_rear_m),
        ] {
            if ax.anti_roll_stiffness_nm_per_rad > 0.0 {
                let (l, r) = if front {
                    (Corner::FL, Corner::FR)
                } else {
                    (Corner::RL, Corner::RR)
                };
                let mut d = DVector::zeros(n);
                d[DOF_ROLL] = 1.0;
                d[DOF_WHEEL0 + l.index()] = -1.0 / track;
                d[DOF_WHEEL0 + r.index()] = 1.0 / track;
                k += (&d * d.transpose()) * ax.anti_roll_stiffness_nm_per_rad;
            }
        }
        let sensors = p
            .effective_sensors()
            .iter()
            .map(|s| {
                let mut row = DVector::zeros(n);
                match (s.kind, s.corner) {
                    (SensorKind::Unsprung, Some(c)) => row[DOF_WHEEL0 + c.index()] = 1.0,
                    (SensorKind::Sprung, corner) => {
                        let (x, y) = match corner {
                            Some(c) => p.corner_position_m(c),
                            None => (s.x_m.unwrap_or(0.0), s.y_m.unwrap_or(0.0)),
                        };
                        row[DOF_HEAVE] = 1.0;
                        row[DOF_PITCH] = x;
                        row[DOF_ROLL] = y;
                        if p.bending.is_some() {
                            row[DOF_BENDING] = s.bending_shape;
                        }
                    }
                    // validate() guarantees unsprung sensors have a corner.
                    (SensorKind::Unsprung, None) => {}
                }
                SensorRow {
                    name: s.name.clone(),
                    placement: vibmode_core::Placement {
                        role: s.kind.role(),
                        corner: s.corner,
                        direction: Some(vibmode_core::Direction::Z),
                    },
                    row,
                }
            })
            .collect();
        Ok(FullCar {
            params: p,
            n,
            mass,
            c: cm,
            k,
            kt,
            ct,
            sensors,
        })
    }

    /// The parameters the model was built from.
    pub fn params(&self) -> &VehicleParams {
        &self.params
    }

    /// Number of DOFs (7, or 8 with body bending).
    pub fn n_dof(&self) -> usize {
        self.n
    }

    /// DOF names: heave_m, pitch_rad, roll_rad, FL_wheel_m, FR_wheel_m, RL_wheel_m, RR_wheel_m, (bending).
    pub fn dof_names(&self) -> Vec<String> {
        let mut v: Vec<String> = [
            "heave_m",
            "pitch_rad",
            "roll_rad",
            "FL_wheel_m",
            "FR_wheel_m",
            "RL_wheel_m",
            "RR_wheel_m",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        if self.n == 8 {
            v.push("bending_modal".to_string());
        }
        v
    }

    /// Sensor (channel) names in output order.
    pub fn sensor_names(&self) -> Vec<String> {
        self.sensors.iter().map(|s| s.name.clone()).collect()
    }

    /// Sensor placements (role, corner, direction) in output order.
    pub fn sensor_placements(&self) -> Vec<vibmode_core::Placement> {
        self.sensors.iter().map(|s| s.placement).collect()
    }

    /// Mass matrix (diagonal), kg and kg m^2.
    pub fn mass_matrix(&self) -> DMatrix<f64> {
        DMatrix::from_diagonal(&self.mass)
    }
    /// Damping matrix, N s/m (and N m s/rad).
    pub fn damping_matrix(&self) -> DMatrix<f64> {
        self.c.clone()
    }
    /// Stiffness matrix, N/m (and N m/rad).
    pub fn stiffness_matrix(&self) -> DMatrix<f64> {
        self.k.clone()
    }

    /// First-order system matrix of x = [q, q'] (2n x 2n): [[0, I], [-M^-1 K, -M^-1 C]].
    pub fn state_matrix(&self) -> DMatrix<f64> {
        let n = self.n;
        let mut a = DMatrix::zeros(2 * n, 2 * n);
        for i in 0..n {
            a[(i, n + i)] = 1.0;
            for j in 0..n {
                a[(n + i, j)] = -self.k[(i, j)] / self.mass[i];
                a[(n + i, n + j)] = -self.c[(i, j)] / self.mass[i];
            }
        }
        a
    }

    /// Modes sorted by natural frequency: eigenvalues of the 2n-state system (one per conjugate
    /// pair, Im s > 0). Overdamped (real) eigenvalues are not modes and are skipped.
    pub fn modes(&self) -> Result<Vec<ModeInfo>> {
        let a = self.state_matrix();
        let schur = nalgebra::Schur::try_new(a, 1e-14, 100_000).ok_or_else(|| {
            VehicleError::Numerical("eigenvalue iteration did not converge".into())
        })?;
        let eig = schur.complex_eigenvalues();
        let mut out = Vec::new();
        for s in eig.iter() {
            let s = Complex64::new(s.re, s.im);
            if s.im <= 1e-9 * s.norm().max(1e-300) {
                continue;
            }
            let v = self.null_vector(s)?;
            // Kinetic-energy fractions.
            let e: Vec<f64> = (0..self.n)
                .map(|i| self.mass[i] * v[i].norm_sqr())
                .collect();
            let tot: f64 = e.iter().sum::<f64>().max(1e-300);
            let energy: Vec<f64> = e.iter().map(|x| x / tot).collect();
            let imax = (0..self.n).fold(0, |b, i| if energy[i] > energy[b] { i } else { b });
            let norm = v[imax];
            let shape: Vec<Complex64> = v.iter().map(|x| x / norm).collect();
            let label = label_mode(&energy, &shape);
            let sensor_shape = self.sensor_shape(&shape);
            let w = s.norm();
            out.push(ModeInfo {
                frequency_hz: w / (2.0 * std::f64::consts::PI),
                damping_ratio: -s.re / w,
                damped_frequency_hz: s.im / (2.0 * std::f64::consts::PI),
                label,
                dof_names: self.dof_names(),
                shape_re: shape.iter().map(|x| x.re).collect(),
                shape_im: shape.iter().map(|x| x.im).collect(),
                energy_fraction: energy,
                sensor_names: self.sensor_names(),
                sensor_shape_re: sensor_shape.iter().map(|x| x.re).collect(),
                sensor_shape_im: sensor_shape.iter().map(|x| x.im).collect(),
            });
        }
        out.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
        Ok(out)
    }

    /// The DOF shape seen by the sensors (row . shape per sensor), largest modulus 1 + 0i.
    fn sensor_shape(&self, shape: &[Complex64]) -> Vec<Complex64> {
        let raw: Vec<Complex64> = self
            .sensors
            .iter()
            .map(|s| {
                s.row
                    .iter()
                    .zip(shape)
                    .map(|(r, v)| v * *r)
                    .sum::<Complex64>()
            })
            .collect();
        let big = raw.iter().copied().fold(Complex64::new(0.0, 0.0), |b, x| {
            if x.norm() > b.norm() {
                x
            } else {
                b
            }
        });
        if big.norm() == 0.0 {
            return raw;
        }
        raw.iter().map(|x| x / big).collect()
    }

    /// Null vector of s^2 M + s C + K (smallest right singular vector).
    fn null_vector(&self, s: Complex64) -> Result<Vec<Complex64>> {
        let n = self.n;
        let d = DMatrix::from_fn(n, n, |i, j| {
            let m = if i == j { self.mass[i] } else { 0.0 };
            s * s * m + s * self.c[(i, j)] + Complex64::new(self.k[(i, j)], 0.0)
        });
        // Scale rows so that the SVD sees comparable magnitudes.
        let d = DMatrix::from_fn(n, n, |i, j| d[(i, j)] / (self.mass[i] * s.norm_sqr()));
        let svd = nalgebra::SVD::try_new(d, false, true, 1e-15, 100_000)
            .ok_or_else(|| VehicleError::Numerical("mode-shape SVD did not converge".into()))?;
        let vt = svd
            .v_t
            .ok_or_else(|| VehicleError::Numerical("mode-shape SVD returned no vectors".into()))?;
        let (imin, _) =
            svd.singular_values
                .iter()
                .enumerate()
                .fold(
                    (0, f64::INFINITY),
                    |(bi, bv), (i, &v)| if v < bv { (i, v) } else { (bi, bv) },
                );
        Ok((0..n).map(|j| vt[(imin, j)].conj()).collect())
    }

    /// Complex frequency response from the 4 road heights (FL, FR, RL, RR; m) to each sensor's
    /// vertical acceleration (m/s^2), at `freq_hz` (Hz). Returns one `[H_FL, H_FR, H_RL, H_RR]`
    /// per sensor, in (m/s^2)/m.
    pub fn frequency_response(&self, freq_hz: f64) -> Result<Vec<[Complex64; 4]>> {
        if !freq_hz.is_finite() || freq_hz < 0.0 {
            return Err(invalid("freq_hz", freq_hz, "must be finite and >= 0 (Hz)"));
        }
        let n = self.n;
        let w = 2.0 * std::f64::consts::PI * freq_hz;
        let jw = Complex64::new(0.0, w);
        if w == 0.0 {
            return Ok(vec![[Complex64::new(0.0, 0.0); 4]; self.sensors.len()]);
        }
        let d = DMatrix::from_fn(n, n, |i, j| {
            let m = if i == j { self.mass[i] } else { 0.0 };
            Complex64::new(self.k[(i, j)] - w * w * m, w * self.c[(i, j)])
        });
        let rhs = DMatrix::from_fn(n, 4, |i, j| {
            Complex64::new(self.kt[(i, j)], 0.0) + jw * self.ct[(i, j)]
        });
        let q = d.lu().solve(&rhs).ok_or_else(|| {
            VehicleError::Numerical(format!("dynamic stiffness singular at {freq_hz} Hz"))
        })?;
        Ok(self
            .sensors
            .iter()
            .map(|s| {
                let mut h = [Complex64::new(0.0, 0.0); 4];
                for (j, hj) in h.iter_mut().enumerate() {
                    let mut acc = Complex64::new(0.0, 0.0);
                    for i in 0..n {
                        acc += q[(i, j)] * s.row[i];
                    }
                    *hj = acc * (-w * w);
                }
                h
            })
            .collect())
    }

    /// Analytic one-sided acceleration PSD (m^2/s^4/Hz) at each sensor for an ISO 8608 road
    /// road `road` (class, coherence, tyre enveloping) driven at constant `speed_kmh` (km/h),
    /// at the frequencies `freq_hz` (Hz).
    ///
    /// Both axles run on the same left and right tracks; the rear wheels see the front profile
    /// delayed by wheelbase / speed; left and right tracks have the coherence of
    /// `road.coherence`. Temporal road PSD: G(f) = G(f/v) / v with G from
    /// [`RoadInput::displacement_psd_m3`]. Output: S_y(f) = sum_ij H_i S_ij conj(H_j) with
    /// S_ij = G c_ij exp(-j w (d_i - d_j)), c_ij = 1 on the same track and gamma otherwise,
    /// d = [0, 0, wheelbase/v, wheelbase/v].
    pub fn acceleration_psd(
        &self,
        road: &RoadInput,
        speed_kmh: f64,
        freq_hz: &[f64],
    ) -> Result<Vec<SensorPsd>> {
        if !(speed_kmh.is_finite() && speed_kmh > 0.0) {
            return Err(invalid(
                "speed_kmh",
                speed_kmh,
                "must be positive (km/h), e.g. 50",
            ));
        }
        road.validate()?;
        let coherence = road.coherence;
        let v = speed_kmh / 3.6;
        let tau = self.params.geometry.wheelbase_m / v;
        let mut out: Vec<SensorPsd> = self
            .sensors
            .iter()
            .map(|s| SensorPsd {
                name: s.name.clone(),
                freq_hz: freq_hz.to_vec(),
                psd_m2_s4_per_hz: Vec::with_capacity(freq_hz.len()),
            })
            .collect();
        let track = [0usize, 1, 0, 1];
        for &f in freq_hz {
            let h = self.frequency_response(f)?;
            let n = f / v;
            let g = if f > 0.0 {
                road.displacement_psd_m3(n) / v
            } else {
                0.0
            };
            let gamma = coherence.gamma(n);
            let w = 2.0 * std::f64::consts::PI * f;
            let delay = [0.0, 0.0, tau, tau];
            for (o, hs) in out.iter_mut().zip(h.iter()) {
                // S = H S_rr H^H with S_rr[i][j] = g * c_ij * exp(-j w (d_i - d_j)).
                let mut acc = 0.0;
                for i in 0..4 {
                    for j in 0..4 {
                        let cij = if track[i] == track[j] { 1.0 } else { gamma };
                        if cij == 0.0 {
                            continue;
                        }
                        let ph = Complex64::from_polar(1.0, -w * (delay[i] - delay[j]));
                        acc += (hs[i] * ph * hs[j].conj()).re * cij;
                    }
                }
                o.psd_m2_s4_per_hz.push((acc * g).max(0.0));
            }
        }
        Ok(out)
    }
}

/// Analytic PSD of one sensor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorPsd {
    /// Sensor (channel) name.
    pub name: String,
    /// Frequencies, Hz.
    pub freq_hz: Vec<f64>,
    /// One-sided acceleration PSD, m^2/s^4/Hz.
    pub psd_m2_s4_per_hz: Vec<f64>,
}

fn label_mode(energy: &[f64], shape: &[Complex64]) -> ModeLabel {
    let body = energy[DOF_HEAVE] + energy[DOF_PITCH] + energy[DOF_ROLL];
    let bend = energy.get(DOF_BENDING).copied().unwrap_or(0.0);
    let front = energy[DOF_WHEEL0] + energy[DOF_WHEEL0 + 1];
    let rear = energy[DOF_WHEEL0 + 2] + energy[DOF_WHEEL0 + 3];
    if bend >= body && bend >= front && bend >= rear {
        return ModeLabel::BodyBending;
    }
    if body >= front && body >= rear {
        let i = [DOF_HEAVE, DOF_PITCH, DOF_ROLL]
            .into_iter()
            .fold(DOF_HEAVE, |b, i| if energy[i] > energy[b] { i } else { b });
        return match i {
            DOF_HEAVE => ModeLabel::BodyHeave,
            DOF_PITCH => ModeLabel::BodyPitch,
            _ => ModeLabel::BodyRoll,
        };
    }
    let (l, r, is_front) = if front >= rear {
        (Corner::FL, Corner::FR, true)
    } else {
        (Corner::RL, Corner::RR, false)
    };
    let el = energy[DOF_WHEEL0 + l.index()];
    let er = energy[DOF_WHEEL0 + r.index()];
    // One wheel alone: the other has less than 1/10 of its energy.
    if el > 10.0 * er {
        return ModeLabel::WheelHop(l);
    }
    if er > 10.0 * el {
        return ModeLabel::WheelHop(r);
    }
    let zl = shape[DOF_WHEEL0 + l.index()];
    let zr = shape[DOF_WHEEL0 + r.index()];
    let in_phase = (zl + zr).norm() >= (zl - zr).norm();
    match (is_front, in_phase) {
        (true, true) => ModeLabel::FrontAxleBounce,
        (true, false) => ModeLabel::FrontAxleTramp,
        (false, true) => ModeLabel::RearAxleBounce,
        (false, false) => ModeLabel::RearAxleTramp,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64) -> Complex64 {
        Complex64::new(re, 0.0)
    }

    #[test]
    fn labels_from_energy() {
        let shape = |v: [f64; 7]| v.map(c).to_vec();
        // heave dominant
        let e = [0.6, 0.2, 0.0, 0.05, 0.05, 0.05, 0.05];
        assert_eq!(label_mode(&e, &shape([1.0; 7])), ModeLabel::BodyHeave);
        // roll dominant
        let e = [0.1, 0.2, 0.5, 0.05, 0.05, 0.05, 0.05];
        assert_eq!(label_mode(&e, &shape([1.0; 7])), ModeLabel::BodyRoll);
        // front wheels anti-phase -> tramp
        let e = [0.01, 0.01, 0.02, 0.48, 0.48, 0.0, 0.0];
        assert_eq!(
            label_mode(&e, &shape([0.0, 0.0, 0.1, 1.0, -1.0, 0.0, 0.0])),
            ModeLabel::FrontAxleTramp
        );
        // rear wheels in phase -> bounce
        let e = [0.01, 0.01, 0.0, 0.0, 0.0, 0.49, 0.49];
        assert_eq!(
            label_mode(&e, &shape([0.1, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0])),
            ModeLabel::RearAxleBounce
        );
        // one wheel alone -> wheel hop
        let e = [0.01, 0.01, 0.0, 0.0, 0.0, 0.95, 0.03];
        assert_eq!(
            label_mode(&e, &shape([0.1, 0.0, 0.0, 0.0, 0.0, 1.0, 0.18])),
            ModeLabel::WheelHop(Corner::RL)
        );
        // bending dominant
        let e = [0.1, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.8];
        assert_eq!(label_mode(&e, &[c(1.0); 8]), ModeLabel::BodyBending);
    }

    #[test]
    fn label_display_round_trip() {
        for l in [
            ModeLabel::BodyPitch,
            ModeLabel::RearAxleTramp,
            ModeLabel::WheelHop(Corner::FR),
            ModeLabel::BodyBending,
        ] {
            assert_eq!(l.to_string().parse::<ModeLabel>().unwrap(), l);
        }
        assert_eq!(
            "front_axle_bounce".parse::<ModeLabel>().unwrap(),
            ModeLabel::FrontAxleBounce
        );
        assert!("wobble"
            .parse::<ModeLabel>()
            .unwrap_err()
            .to_string()
            .contains("body heave"));
    }
}
