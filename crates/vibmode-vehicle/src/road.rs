//! ISO 8608 road roughness: classes, left/right coherence, profile synthesis.

use crate::error::{invalid, Result, VehicleError};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;
use vibmode_fft::Complex;

/// Reference spatial frequency of ISO 8608, cycles/m.
pub const N0_CYCLES_PER_M: f64 = 0.1;

/// ISO 8608 road class. Displacement PSD Gd(n) = Gd(n0) (n / n0)^-2 with n0 = 0.1 cycles/m and
/// the class mid (geometric-mean) value Gd(n0) = 16e-6 * 4^k m^3, k = 0 (A) .. 7 (H):
/// A 16e-6, B 64e-6, C 256e-6, D 1024e-6, E 4096e-6, F 16384e-6, G 65536e-6, H 262144e-6 m^3.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum RoadClass {
    /// Very good (Gd(n0) = 16e-6 m^3).
    A,
    /// Good (64e-6 m^3).
    B,
    /// Average (256e-6 m^3).
    C,
    /// Poor (1024e-6 m^3).
    D,
    /// Very poor (4096e-6 m^3).
    E,
    /// 16384e-6 m^3.
    F,
    /// 65536e-6 m^3.
    G,
    /// 262144e-6 m^3.
    H,
}

impl RoadClass {
    /// All classes, A to H.
    pub const ALL: [RoadClass; 8] = [
        RoadClass::A,
        RoadClass::B,
        RoadClass::C,
        RoadClass::D,
        RoadClass::E,
        RoadClass::F,
        RoadClass::G,
        RoadClass::H,
    ];

    /// Gd(n0), m^3 (displacement PSD at n0 = 0.1 cycles/m, one-sided).
    pub fn gd_n0_m3(self) -> f64 {
        let k = RoadClass::ALL.iter().position(|c| *c == self).unwrap_or(0) as i32;
        16e-6 * 4f64.powi(k)
    }

    /// One-sided displacement PSD Gd(n), m^3 (= m^2 per cycle/m), at spatial frequency
    /// `n_cycles_per_m` (> 0; returns 0 for n <= 0).
    pub fn displacement_psd_m3(self, n_cycles_per_m: f64) -> f64 {
        if n_cycles_per_m <= 0.0 {
            return 0.0;
        }
        let r = n_cycles_per_m / N0_CYCLES_PER_M;
        self.gd_n0_m3() / (r * r)
    }
}

impl fmt::Display for RoadClass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{self:?}")
    }
}

impl FromStr for RoadClass {
    type Err = VehicleError;
    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim().to_ascii_uppercase();
        let t = t
            .strip_prefix("CLASS")
            .map(|x| x.trim().to_string())
            .unwrap_or(t);
        RoadClass::ALL
            .iter()
            .copied()
            .find(|c| c.to_string() == t)
            .ok_or_else(|| VehicleError::UnknownName {
                what: "road class",
                value: s.to_string(),
                valid: "A, B, C, D, E, F, G, H (ISO 8608)",
            })
    }
}

/// Coherence between the left and right wheel tracks (both axles use the same two tracks).
///
/// `gamma(n)` is the coherence amplitude: cross-spectrum / auto-spectrum, so the
/// magnitude-squared coherence is gamma^2. Synthesis: right = gamma * left + sqrt(1 - gamma^2) * w,
/// with w independent of left and of the same PSD.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LateralCoherence {
    /// Left and right identical (gamma = 1): excites heave and pitch only.
    FullyCorrelated,
    /// Left and right independent (gamma = 0).
    Independent,
    /// gamma(n) = exp(-n / cutoff_cycles_per_m): long waves are common to both tracks, short
    /// waves independent (an engineering model of measured road coherence).
    Exponential {
        /// Spatial frequency at which gamma = 1/e, cycles/m (> 0).
        cutoff_cycles_per_m: f64,
    },
}

impl Default for LateralCoherence {
    /// `Exponential { cutoff_cycles_per_m: 0.2 }` (coherent for wavelengths above ~5 m).
    fn default() -> Self {
        LateralCoherence::Exponential {
            cutoff_cycles_per_m: 0.2,
        }
    }
}

impl LateralCoherence {
    /// Coherence amplitude gamma(n) in [0, 1] at spatial frequency n (cycles/m).
    pub fn gamma(self, n_cycles_per_m: f64) -> f64 {
        match self {
            LateralCoherence::FullyCorrelated => 1.0,
            LateralCoherence::Independent => 0.0,
            LateralCoherence::Exponential {
                cutoff_cycles_per_m,
            } => (-n_cycles_per_m.abs() / cutoff_cycles_per_m).exp(),
        }
    }

    /// Check the cutoff is positive.
    pub fn validate(self) -> Result<()> {
        if let LateralCoherence::Exponential {
            cutoff_cycles_per_m,
        } = self
        {
            if !(cutoff_cycles_per_m.is_finite() && cutoff_cycles_per_m > 0.0) {
                return Err(invalid(
                    "coherence cutoff_cycles_per_m",
                    cutoff_cycles_per_m,
                    "must be positive, e.g. exponential:0.2",
                ));
            }
        }
        Ok(())
    }
}

impl fmt::Display for LateralCoherence {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LateralCoherence::FullyCorrelated => f.write_str("fully-correlated"),
            LateralCoherence::Independent => f.write_str("independent"),
            LateralCoherence::Exponential {
                cutoff_cycles_per_m,
            } => write!(f, "exponential:{cutoff_cycles_per_m}"),
        }
    }
}

impl FromStr for LateralCoherence {
    type Err = VehicleError;
    /// "fully-correlated", "independent", "exponential" (cutoff 0.2) or "exponential:<cycles/m>".
    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim().to_ascii_lowercase();
        let err = || {
            VehicleError::UnknownName {
            what: "lateral coherence",
            value: s.to_string(),
            valid: "fully-correlated, independent, exponential, exponential:<cutoff cycles/m> (e.g. exponential:0.2)",
        }
        };
        let c = match t.as_str() {
            "fully-correlated" | "fully_correlated" | "correlated" => {
                LateralCoherence::FullyCorrelated
            }
            "independent" => LateralCoherence::Independent,
            "exponential" => LateralCoherence::default(),
            _ => {
                let v = t.strip_prefix("exponential:").ok_or_else(err)?;
                let cutoff: f64 = v.trim().parse().map_err(|_| err())?;
                LateralCoherence::Exponential {
                    cutoff_cycles_per_m: cutoff,
                }
            }
        };
        c.validate()?;
        Ok(c)
    }
}

/// Default tyre-enveloping cutoff, cycles/m (wavelength ~0.33 m, about a truck-tyre contact
/// length; also the short-wave end of the ISO 8608 range, 2.83 cycles/m).
pub const DEFAULT_TYRE_ENVELOPE_CYCLES_PER_M: f64 = 3.0;

/// The road as the wheels see it: ISO 8608 class, left/right coherence and tyre enveloping.
///
/// Effective one-sided displacement PSD per track:
/// G(n) = Gd(n) / (1 + (n / n_e)^2), n_e = `tyre_envelope_cycles_per_m` (None: no enveloping,
/// pure ISO 8608). The enveloping models the tyre contact patch bridging short waves; without it
/// the road velocity is white up to the sampling rate and the tyre damper feeds that white
/// noise straight into the unsprung acceleration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RoadInput {
    /// ISO 8608 class (default C).
    pub class: RoadClass,
    /// Left/right coherence (default exponential, cutoff 0.2 cycles/m).
    pub coherence: LateralCoherence,
    /// Tyre-enveloping cutoff n_e, cycles/m (default Some(3.0)).
    pub tyre_envelope_cycles_per_m: Option<f64>,
}

impl Default for RoadInput {
    fn default() -> Self {
        RoadInput {
            class: RoadClass::C,
            coherence: LateralCoherence::default(),
            tyre_envelope_cycles_per_m: Some(DEFAULT_TYRE_ENVELOPE_CYCLES_PER_M),
        }
    }
}

impl RoadInput {
    /// Effective one-sided displacement PSD of one track, m^3, at n cycles/m.
    pub fn displacement_psd_m3(&self, n_cycles_per_m: f64) -> f64 {
        let g = self.class.displacement_psd_m3(n_cycles_per_m);
        match self.tyre_envelope_cycles_per_m {
            Some(ne) => g / (1.0 + (n_cycles_per_m / ne).powi(2)),
            None => g,
        }
    }

    /// Check the coherence and envelope parameters.
    pub fn validate(&self) -> Result<()> {
        self.coherence.validate()?;
        if let Some(ne) = self.tyre_envelope_cycles_per_m {
            if !(ne.is_finite() && ne > 0.0) {
                return Err(invalid(
                    "tyre_envelope_cycles_per_m",
                    ne,
                    "must be positive (cycles/m), e.g. 3.0, or None to switch enveloping off",
                ));
            }
        }
        Ok(())
    }
}

/// Left and right road profiles on a uniform spatial grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RoadProfile {
    /// Grid spacing, m.
    pub dx_m: f64,
    /// Left-track heights, m.
    pub left_m: Vec<f64>,
    /// Right-track heights, m.
    pub right_m: Vec<f64>,
}

impl RoadProfile {
    /// Synthesise a profile of at least `length_m` metres with spacing `dx_m` by FFT synthesis:
    /// complex Gaussian Fourier coefficients with variance Gd(n_k) dn per bin (G of [`RoadInput::displacement_psd_m3`]; all bins from
    /// 1/L to the spatial Nyquist frequency 1/(2 dx), DC and Nyquist zero), left/right mixed
    /// per bin with the coherence. Deterministic for a given `rng` state.
    pub fn generate(
        road: &RoadInput,
        length_m: f64,
        dx_m: f64,
        rng: &mut ChaCha8Rng,
    ) -> Result<Self> {
        road.validate()?;
        let coherence = road.coherence;
        if !(dx_m.is_finite() && dx_m > 0.0) {
            return Err(invalid("dx_m", dx_m, "must be positive (m)"));
        }
        if !(length_m.is_finite() && length_m > 0.0) {
            return Err(invalid("length_m", length_m, "must be positive (m)"));
        }
        let npts = (length_m / dx_m).ceil() as usize + 2;
        if npts > 400_000_000 {
            return Err(invalid(
                "road length / spacing",
                npts,
                "is too many points; lower fs_hz, duration_s or records",
            ));
        }
        let nfft = npts.next_power_of_two().max(16);
        let dn = 1.0 / (nfft as f64 * dx_m);
        let half = nfft / 2;
        let mut planner = vibmode_fft::Planner::new();
        let inv = planner.inverse(nfft);
        let mut left = vec![Complex::new(0.0, 0.0); half + 1];
        let mut right = vec![Complex::new(0.0, 0.0); half + 1];
        for (k, (l, r)) in left
            .iter_mut()
            .zip(right.iter_mut())
            .enumerate()
            .take(half)
            .skip(1)
        {
            let n = k as f64 * dn;
            let sigma = (road.displacement_psd_m3(n) * dn / 4.0).sqrt();
            let mut draw = || {
                let a: f64 = rng.sample(StandardNormal);
                let b: f64 = rng.sample(StandardNormal);
                Complex::new(a * sigma, b * sigma)
            };
            let w1 = draw();
            let w2 = draw();
            let g = coherence.gamma(n);
            *l = w1;
            *r = w1 * g + w2 * (1.0 - g * g).max(0.0).sqrt();
        }
        let mut out = Vec::with_capacity(2);
        for spec in [&mut left, &mut right] {
            let mut x = vec![0.0; nfft];
            inv.process(spec, &mut x)
                .map_err(|e| VehicleError::Numerical(format!("inverse FFT failed: {e}")))?;
            x.truncate(npts);
            out.push(x);
        }
        let right_m = out.pop().unwrap_or_default();
        let left_m = out.pop().unwrap_or_default();
        Ok(RoadProfile {
            dx_m,
            left_m,
            right_m,
        })
    }

    /// Linearly interpolated height of a track (0 = left, 1 = right) at distance `s_m`; clamps
    /// at the ends.
    pub fn height_m(&self, track: usize, s_m: f64) -> f64 {
        let v = if track == 0 {
            &self.left_m
        } else {
            &self.right_m
        };
        if v.is_empty() {
            return 0.0;
        }
        let u = (s_m / self.dx_m).max(0.0);
        let i = u.floor() as usize;
        if i + 1 >= v.len() {
            return v[v.len() - 1];
        }
        let f = u - i as f64;
        v[i] * (1.0 - f) + v[i + 1] * f
    }
}
