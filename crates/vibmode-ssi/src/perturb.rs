//! First-order (perturbation) uncertainty of SSI-cov poles from the scatter of the block
//! Toeplitz matrix over blocks of data, after Döhler & Mevel (2013), "Efficient multi-order
//! uncertainty computation for stochastic subspace identification", MSSP 38.
//!
//! The covariance of the Toeplitz matrix `T` is estimated from `m` blocks (or segments) as
//! `cov(vec T) = sum_s d_s d_s^T` with `d_s = sqrt(m / (m - 1)) w_s (T_s - T)` (`T_s` a block's
//! own estimate, `w_s` its share of the products; `d_s = (T_s - T) / sqrt(m (m - 1))` for equal
//! blocks, Döhler's estimate). A pole parameter `theta(T)` then has the first-order variance
//! `sum_s (J d_s)^2`, `J` its gradient. Döhler writes `J` in closed form through the SVD's
//! sensitivities; here `J d_s` is the directional derivative computed by central differences,
//! `(theta(T + e d_s) - theta(T - e d_s)) / 2e`, one pair of plans per block serving every order.
//! Both are the same first-order quantity (checked against pyOMA2's implementation of
//! Döhler's formulas in `tests/integration/reference.rs`).

use nalgebra::DMatrix;
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

use crate::cov::{SsiCorrelations, SsiCov, SsiMode};
use crate::error::SsiError;

/// Relative size of the finite-difference step: `e |d_s| = STEP |T|` (Frobenius norms of the
/// correlations). Small enough for the second-order term (~1e-10 relative), large enough that
/// the SVD's rounding (~1e-15 relative) stays below 1e-9 of the derivative.
const STEP: f64 = 1e-5;

/// One pole with the first-order standard deviations of its frequency and damping.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoleStd {
    /// The pole identified from all the data.
    pub mode: SsiMode,
    /// Standard deviation of the natural frequency, Hz. NaN when a perturbed plan has no pole
    /// to match (the pole is at the edge of being dropped: damping near 0 or 1).
    pub frequency_std_hz: f64,
    /// Standard deviation of the damping ratio (same NaN rule).
    pub damping_std: f64,
}

/// The plan of all the data and, per block, the plans of the Toeplitz matrix moved by `+- e d_s`
/// (computed once by [`SsiCorrelations::perturbation`]; [`SsiPerturbation::poles_at`] serves
/// any order up to the plan's `order_max`).
#[derive(Clone, Debug)]
pub struct SsiPerturbation {
    plan: SsiCov,
    /// Per block: `(plan at T + e d_s, plan at T - e d_s, e)`; blocks with `d_s = 0` are left out.
    moved: Vec<(SsiCov, SsiCov, f64)>,
    n_blocks: usize,
}

impl SsiCorrelations {
    /// The first-order uncertainty of the poles from the scatter of the segments' (blocks')
    /// correlations (see the module docs). Needs at least 2 segments
    /// (`SsiError::TooFewBlocks`); 20 to 50 blocks are usual. Costs two SVDs of the Toeplitz
    /// matrix per block.
    pub fn perturbation(&self) -> Result<SsiPerturbation, SsiError> {
        let m = self.n_segments();
        if m < 2 {
            return Err(SsiError::TooFewBlocks { n_blocks: m });
        }
        let plan = self.plan()?;
        let totals = self.totals(|_| false);
        let max_lag = totals.len();
        let r_bar: Vec<DMatrix<f64>> = totals.iter().map(|(t, c)| t / (*c).max(1) as f64).collect();
        let norm = |r: &[DMatrix<f64>]| r.iter().map(|x| x.norm_squared()).sum::<f64>().sqrt();
        let r_norm = norm(&r_bar);
        let scale = (m as f64 / (m as f64 - 1.0)).sqrt();
        let mut moved = Vec::with_capacity(m);
        for s in 0..m {
            let d: Vec<DMatrix<f64>> = (0..max_lag)
                .zip(&r_bar)
                .map(|(k, rb)| {
                    let (total, count) = &totals[k];
                    let c = self.counts[s][k];
                    if c == 0 || *count == 0 {
                        return DMatrix::zeros(total.nrows(), total.ncols());
                    }
                    let w = c as f64 / *count as f64;
                    (&self.sums[s][k] / c as f64 - rb) * (scale * w)
                })
                .collect();
            let d_norm = norm(&d);
            if !(d_norm > 0.0 && d_norm.is_finite()) {
                continue;
            }
            let e = STEP * r_norm / d_norm;
            let shifted = |sign: f64| -> Result<SsiCov, SsiError> {
                let r: Vec<DMatrix<f64>> = r_bar
                    .iter()
                    .zip(&d)
                    .map(|(rb, ds)| rb + ds * (sign * e))
                    .collect();
                SsiCov::from_correlations(&r, self.fs_hz, self.block_rows, self.order_max)
            };
            moved.push((shifted(1.0)?, shifted(-1.0)?, e));
        }
        Ok(SsiPerturbation {
            plan,
            moved,
            n_blocks: m,
        })
    }
}

impl SsiCov {
    /// The first-order uncertainty of one record's poles from `n_blocks` blocks of it
    /// ([`SsiCorrelations::blocks`], then [`SsiCorrelations::perturbation`]).
    pub fn perturbation(
        channels: &[&[f64]],
        fs_hz: f64,
        params: &vibmode_core::SsiParams,
        n_blocks: usize,
    ) -> Result<SsiPerturbation, SsiError> {
        SsiCorrelations::blocks(channels, fs_hz, params, n_blocks)?.perturbation()
    }
}

/// The continuous pole `s = -zeta w + i w sqrt(1 - zeta^2)` of a mode, rad/s.
fn pole(m: &SsiMode) -> Complex64 {
    let w = 2.0 * std::f64::consts::PI * m.frequency_hz;
    let z = m.damping_ratio;
    Complex64::new(-z * w, w * (1.0 - z * z).max(0.0).sqrt())
}

/// The mode of `modes` whose pole is nearest to `target`'s.
fn nearest<'a>(modes: &'a [SsiMode], target: &SsiMode) -> Option<&'a SsiMode> {
    let p = pole(target);
    modes
        .iter()
        .min_by(|a, b| (pole(a) - p).norm().total_cmp(&(pole(b) - p).norm()))
}

impl SsiPerturbation {
    /// The plan of all the data (the nominal estimate).
    pub fn plan(&self) -> &SsiCov {
        &self.plan
    }

    /// Blocks (segments) whose scatter is propagated.
    pub fn n_blocks(&self) -> usize {
        self.n_blocks
    }

    /// The poles at `order` ([`SsiCov::poles_at`] of the plan of all the data), each with the
    /// first-order standard deviations of its frequency and damping. Each pole is matched to
    /// the nearest pole of every moved plan. Errors as [`SsiCov::poles_at`].
    pub fn poles_at(&self, order: usize) -> Result<Vec<PoleStd>, SsiError> {
        let nominal = self.plan.poles_at(order)?;
        let mut var = vec![[0.0f64; 2]; nominal.len()];
        for (plus, minus, e) in &self.moved {
            let (p, q) = (plus.poles_at(order)?, minus.poles_at(order)?);
            for (m, v) in nominal.iter().zip(var.iter_mut()) {
                match (nearest(&p, m), nearest(&q, m)) {
                    (Some(a), Some(b)) => {
                        let df = (a.frequency_hz - b.frequency_hz) / (2.0 * e);
                        let dz = (a.damping_ratio - b.damping_ratio) / (2.0 * e);
                        v[0] += df * df;
                        v[1] += dz * dz;
                    }
                    _ => *v = [f64::NAN; 2],
                }
            }
        }
        Ok(nominal
            .into_iter()
            .zip(var)
            .map(|(mode, v)| PoleStd {
                mode,
                frequency_std_hz: v[0].sqrt(),
                damping_std: v[1].sqrt(),
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact correlations `R_k = r^k cos(k wd / fs)` of one damped mode, lags `1..=2i-1`, as
    /// the sums of `count` products.
    fn sums(f_hz: f64, zeta: f64, fs_hz: f64, i: usize, count: usize) -> Vec<DMatrix<f64>> {
        let w = 2.0 * std::f64::consts::PI * f_hz;
        let (r, wd) = (
            (-zeta * w / fs_hz).exp(),
            w * (1.0 - zeta * zeta).sqrt() / fs_hz,
        );
        (1..2 * i)
            .map(|k| {
                let v = r.powi(k as i32) * (k as f64 * wd).cos();
                DMatrix::from_element(1, 1, v * count as f64)
            })
            .collect()
    }

    fn correlations(blocks: Vec<Vec<DMatrix<f64>>>, i: usize, count: usize) -> SsiCorrelations {
        let m = blocks.len();
        SsiCorrelations {
            fs_hz: 20.0,
            order_max: 2,
            block_rows: i,
            first_lag: 1,
            counts: vec![vec![count; 2 * i - 1]; m],
            n_samples: vec![count; m],
            sums: blocks,
            max_abs: 1.0,
        }
    }

    /// By hand: two equal blocks, one of a mode at 1.000 Hz, the other at 1.002 Hz (damping
    /// 0.05 both). The estimate lies between; to first order each block moves it by half the
    /// difference, so the standard deviation is |1.002 - 1.000| / 2 = 0.001 Hz (with `m = 2`:
    /// `d_s = (T_s - T) / sqrt(2)`, variance `2 (J d_s)^2 = (J (T_1 - T))^2`). The damping is
    /// the same in both blocks: its standard deviation is of second order (< 1e-4).
    #[test]
    fn two_blocks_of_different_modes_give_half_their_difference() {
        let (i, n) = (6, 1000);
        let c = correlations(
            vec![sums(1.000, 0.05, 20.0, i, n), sums(1.002, 0.05, 20.0, i, n)],
            i,
            n,
        );
        let p = c.perturbation().unwrap();
        let poles = p.poles_at(2).unwrap();
        assert_eq!(poles.len(), 1);
        let s = &poles[0];
        assert!((s.mode.frequency_hz - 1.001).abs() < 1e-5, "{s:?}");
        assert!(
            (s.frequency_std_hz - 0.001).abs() < 0.01 * 0.001,
            "frequency std {} Hz, expected 0.001",
            s.frequency_std_hz
        );
        assert!(s.damping_std < 1e-4, "damping std {}", s.damping_std);
    }

    /// Blocks that differ by a factor only (one block twice the amplitude of the other)
    /// carry no information against the poles: every standard deviation is 0 (to rounding).
    /// (The correlations are made of full rank by a small deterministic term: on an exactly
    /// rank-deficient Toeplitz matrix nalgebra's SVD returns inaccurate singular vectors.)
    #[test]
    fn blocks_differing_by_a_factor_give_no_uncertainty() {
        let (i, n) = (6, 1000);
        let mut a = sums(1.3, 0.04, 20.0, i, n);
        for (k, x) in a.iter_mut().enumerate() {
            x[(0, 0)] += 1e-2 * n as f64 * (7.3 * k as f64).sin();
        }
        let b: Vec<DMatrix<f64>> = a.iter().map(|x| x * 4.0).collect();
        let p = correlations(vec![a, b], i, n).perturbation().unwrap();
        let poles = p.poles_at(2).unwrap();
        assert_eq!(poles.len(), 1);
        assert!(poles[0].frequency_std_hz < 1e-8, "{:?}", poles[0]);
        assert!(poles[0].damping_std < 1e-8, "{:?}", poles[0]);
    }

    /// One block has no scatter: refused with a one-line message.
    #[test]
    fn one_block_is_refused() {
        let (i, n) = (6, 1000);
        let err = correlations(vec![sums(1.0, 0.05, 20.0, i, n)], i, n)
            .perturbation()
            .unwrap_err();
        assert_eq!(err, SsiError::TooFewBlocks { n_blocks: 1 });
        assert!(err.to_string().contains("at least 2 blocks"));
    }
}
