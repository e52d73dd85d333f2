//! SSI-cov: output correlations, block Toeplitz matrix, its SVD, and poles at any order.

use nalgebra::{DMatrix, SVD};
use num_complex::Complex64;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use vibmode_core::limits::{SSI_SAMPLES_PER_LAG_MIN, SSI_TOEPLITZ_ROWS_MAX};
use vibmode_core::SsiParams;

pub use vibmode_core::stats::jackknife_std;

use crate::eig::kept_eigenvalues;
use crate::error::SsiError;
use crate::shape::mpc;
use crate::svd::leading_svd;

/// One identified mode: one pole of a conjugate pair (`Im > 0`) of the identified state matrix.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SsiMode {
    /// Natural frequency `|s| / 2 pi`, Hz, of the continuous pole `s = ln(lambda) fs_hz`.
    pub frequency_hz: f64,
    /// Damping ratio `-Re(s) / |s|` (dimensionless, in (0, 1)).
    pub damping_ratio: f64,
    /// Complex mode shape `C psi`, one `[re, im]` per channel, scaled so that the entry of
    /// largest modulus is `[1, 0]`.
    pub shape: Vec<[f64; 2]>,
    /// Modal phase collinearity of the shape ([`crate::mpc`]).
    pub mpc: f64,
}

/// The modes identified at one model order, by increasing frequency.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SsiOrder {
    /// Model order (state dimension).
    pub order: usize,
    /// Modes kept at this order (see [`SsiCov::poles_at`] for which poles are dropped).
    pub modes: Vec<SsiMode>,
}

/// The result of an SSI-cov order sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SsiResult {
    /// Sampling rate of the channels, Hz.
    pub fs_hz: f64,
    /// Block rows `i` of the Toeplitz matrix.
    pub block_rows: usize,
    /// One entry per identified order, in the order asked for.
    pub orders: Vec<SsiOrder>,
    /// Singular values of the block Toeplitz matrix, largest first (`i * min(l, r)` of them for
    /// `l` channels and `r` references).
    pub singular_values: Vec<f64>,
}

/// A planned SSI-cov identification: the correlations, block Toeplitz matrix and its SVD are
/// computed once by [`SsiCov::new`]; [`SsiCov::poles_at`] then identifies any order from them.
///
/// Definitions, for `l` channels `y_t` (each with its mean removed), `N` samples and
/// `i = block_rows`:
///
/// * output correlations `R_k = 1/(N - k) sum_{t=0}^{N-1-k} y_{t+k} y_ref,t^T` (`l x r`) for the
///   lags `k = 1..=2i-1` (lag 0, which carries the measurement noise, is not used), where
///   `y_ref` are the `r` reference channels ([`SsiParams::reference_channels`]; by default all
///   channels, `r = l`);
/// * block Toeplitz matrix `T` (`il x ir`) with block `(a, b) = R_{i+a-b}`
///   (`[R_i ... R_1; R_{i+1} ... R_2; ...; R_{2i-1} ... R_i]`), of rank `n` for an `n`-state
///   system: `T = O_i G_i` with the observability matrix `O_i = [C; CA; ...; CA^{i-1}]`;
/// * its SVD `T = U S V^T`; at order `n`, `O = U_n S_n^{1/2}` (first `n` columns), `C` = the
///   first `l` rows of `O`, and `A` the least-squares solution of `O_up A = O_down` (`O` without
///   its last, resp. first, block row).
#[derive(Clone, Debug)]
pub struct SsiCov {
    fs_hz: f64,
    block_rows: usize,
    n_channels: usize,
    n_references: usize,
    n_samples: usize,
    /// The first `min(order_max, i r)` left singular vectors of `T` (`il` rows).
    u: DMatrix<f64>,
    /// The block Toeplitz matrix, kept for an order above `u`'s columns ([`SsiCov::full_u`]).
    toeplitz: DMatrix<f64>,
    /// All of `T`'s left singular vectors, computed when an order above `u`'s columns is asked.
    u_full: std::sync::OnceLock<Option<DMatrix<f64>>>,
    singular_values: Vec<f64>,
    rank: usize,
    rank_tolerance: f64,
    /// The state matrix of every order up to `K` at once. With the QR `O_up = Q R` of the shifted
    /// observability matrix at order `K = min(order_max, max_order())` (the first `n` columns of
    /// `O_up` are `Q[.., ..n] R[..n, ..n]`) and `B = Q^T O_down`, the least-squares `A` of order
    /// `n <= K` is `A_n = R_n^-1 B_n` (`R_n`, `B_n` the leading `n x n` blocks). It is similar
    /// to `M_n = R_n A_n R_n^-1 = B_n R_n^-1`, and `M_n` is the leading `n x n` block of
    /// `M = B R^-1` (`R^-1` is upper triangular: column `c < n` of `R^-1` is zero below row
    /// `c`). So `M` is formed once and order `n` takes its leading block: the same eigenvalues,
    /// and for an eigenvector `phi` of `M_n` the eigenvector of `A_n` is `R_n^-1 phi`, whose
    /// `C` image is `(C R^-1)[.., ..n] phi` (`c_shift`). Kept to the orders `n <= K` whose
    /// pivots `R_jj`, `j < n`, all pass [`shift_pivots_ok`]; others (rank-deficient
    /// `O_up`) get their own least squares.
    m_shift: DMatrix<f64>,
    /// `C R^-1` (`l x K`), `C` the first block row of `O`.
    c_shift: DMatrix<f64>,
}

/// Convergence tolerance of nalgebra's SVD: its own default (`5 eps`). With `eps` alone the
/// iteration stops with inaccurate singular vectors when several singular values are zero
/// (seen on the rank-2 Toeplitz matrix of one exact mode: the column space off by 5e-3).
const SVD_EPS: f64 = 5.0 * f64::EPSILON;

/// Iteration cap of the Toeplitz matrix's SVD (`dim` its larger side).
fn svd_iterations(dim: usize) -> usize {
    60 * dim.max(1) + 100
}

/// Checks the channels: at least one, each with >= 2 samples, equal lengths, finite samples.
/// Returns the common length.
fn check_channels(channels: &[&[f64]]) -> Result<usize, SsiError> {
    let first = channels.first().ok_or(SsiError::NoChannels)?;
    let n = first.len();
    for (c, ch) in channels.iter().enumerate() {
        if ch.len() < 2 {
            return Err(SsiError::TooShort {
                channel: c,
                n_samples: ch.len(),
            });
        }
        if ch.len() != n {
            return Err(SsiError::LengthMismatch {
                channel: c,
                found: ch.len(),
                expected: n,
            });
        }
        if let Some((index, &value)) = ch.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(SsiError::NonFinite {
                channel: c,
                index,
                value,
            });
        }
        if let Some(value) = vibmode_core::stats::constant_value(ch) {
            return Err(SsiError::ConstantChannel { channel: c, value });
        }
    }
    Ok(n)
}

/// The rows of the block Toeplitz matrix, `block_rows x channels`, checked against
/// [`SSI_TOEPLITZ_ROWS_MAX`] (the SVD's cost grows with their cube).
fn check_matrix_size(block_rows: usize, n_channels: usize) -> Result<usize, SsiError> {
    block_rows
        .checked_mul(n_channels)
        .filter(|&rows| rows <= SSI_TOEPLITZ_ROWS_MAX)
        .ok_or(SsiError::MatrixTooLarge {
            block_rows,
            n_channels,
            max_rows: SSI_TOEPLITZ_ROWS_MAX,
            max_block_rows: SSI_TOEPLITZ_ROWS_MAX / n_channels.max(1),
        })
}

/// The lags of the Toeplitz matrix from `first_lag` (`first_lag..=max_lag`,
/// `max_lag = first_lag + 2 block_rows - 2`) and the samples a record needs for them,
/// `first_lag - 1 + SSI_SAMPLES_PER_LAG_MIN (2 block_rows - 1)`, in checked arithmetic.
fn lag_span(block_rows: usize, first_lag: usize) -> Result<(usize, usize), SsiError> {
    let too_large = SsiError::LagsTooLarge {
        block_rows,
        first_lag,
    };
    let n_lags = block_rows
        .checked_mul(2)
        .and_then(|v| v.checked_sub(1))
        .ok_or(too_large.clone())?;
    let skipped = first_lag.checked_sub(1).ok_or(too_large.clone())?;
    let max_lag = skipped.checked_add(n_lags).ok_or(too_large.clone())?;
    let min_samples = n_lags
        .checked_mul(SSI_SAMPLES_PER_LAG_MIN)
        .and_then(|v| v.checked_add(skipped))
        .ok_or(too_large)?;
    Ok((max_lag, min_samples))
}

/// The fewest samples a record (or segment) needs for `block_rows` block rows from `first_lag`:
/// `first_lag - 1 + 2 (2 block_rows - 1)` ([`SSI_SAMPLES_PER_LAG_MIN`]); `None` when the
/// arithmetic overflows (no record is that long) or `block_rows` or `first_lag` is 0.
///
/// ```
/// assert_eq!(vibmode_ssi::samples_needed(20, 1), Some(78));
/// assert_eq!(vibmode_ssi::samples_needed(20, usize::MAX), None);
/// ```
pub fn samples_needed(block_rows: usize, first_lag: usize) -> Option<usize> {
    if block_rows == 0 {
        return None;
    }
    lag_span(block_rows, first_lag).ok().map(|(_, n)| n)
}

/// The output correlations of several segments (records) kept apart: per segment the
/// unnormalised sums `sum_t y_s[t+k] y_s,ref[t]^T` and their product counts `N_s - k`, for the
/// `2i - 1` lags of the Toeplitz matrix (`first_lag..=first_lag + 2i - 2`; the lags before the
/// first are not computed). Computed once; [`SsiCorrelations::plan`] identifies from all
/// segments ([`SsiCov::from_segments`]), [`SsiCorrelations::jackknife`] from all but one group
/// at a time, without recomputing a product.
#[derive(Clone, Debug)]
pub struct SsiCorrelations {
    pub(crate) fs_hz: f64,
    pub(crate) order_max: usize,
    pub(crate) block_rows: usize,
    /// The lag of `sums[s][0]` (of the first segment's, when each has its own), for messages.
    pub(crate) first_lag: usize,
    pub(crate) sums: Vec<Vec<DMatrix<f64>>>,
    pub(crate) counts: Vec<Vec<usize>>,
    pub(crate) n_samples: Vec<usize>,
    pub(crate) max_abs: f64,
}

impl SsiCorrelations {
    /// The correlation sums of `segments` (each the same channels, finite, with at least
    /// `first_lag - 1 + 2 (2 block_rows - 1)` samples, [`SSI_SAMPLES_PER_LAG_MIN`]; each
    /// segment's means removed) sampled at `fs_hz`, for `params`' block rows, first lag and
    /// references. The Toeplitz matrix may have at most [`SSI_TOEPLITZ_ROWS_MAX`] rows
    /// (`block_rows x channels`).
    pub fn new(
        segments: &[Vec<&[f64]>],
        fs_hz: f64,
        params: &SsiParams,
    ) -> Result<SsiCorrelations, SsiError> {
        params.validate()?;
        if !(fs_hz.is_finite() && fs_hz > 0.0) {
            return Err(SsiError::InvalidSampleRate { fs_hz });
        }
        let first = segments.first().ok_or(SsiError::NoChannels)?;
        let l = first.len();
        check_matrix_size(params.block_rows, l)?;
        let refs = reference_indices(params, l)?;
        let mut out = SsiCorrelations::empty(fs_hz, params);
        for seg in segments {
            out.push_segment(seg, l, &refs, params.block_rows, params.first_lag)?;
        }
        Ok(out)
    }

    /// As [`SsiCorrelations::new`], but segment `s`'s Toeplitz matrix starts at its own lag
    /// `first_lags[s]` (`params.first_lag` is not used): the segments' correlations are summed
    /// lag by lag from each one's first lag, `R_s(first_lags[s] + k)` for `k = 0..2i-1`. For
    /// white noise through one system the correlations beyond any lag share the observability
    /// matrix, so records whose excitation is correlated over different delays (a vehicle's
    /// wheelbase at different speeds) can be pooled, each beyond its own delay. Each segment
    /// needs at least `first_lags[s] - 1 + 2 (2i - 1)` samples; `first_lags` needs one entry (at
    /// least 1) per segment.
    pub fn with_first_lags(
        segments: &[Vec<&[f64]>],
        fs_hz: f64,
        params: &SsiParams,
        first_lags: &[usize],
    ) -> Result<SsiCorrelations, SsiError> {
        params.validate()?;
        if !(fs_hz.is_finite() && fs_hz > 0.0) {
            return Err(SsiError::InvalidSampleRate { fs_hz });
        }
        if first_lags.len() != segments.len() || first_lags.contains(&0) {
            return Err(SsiError::FirstLags {
                n_lags: first_lags.len(),
                n_segments: segments.len(),
            });
        }
        if let Some(&first_lag) = first_lags
            .iter()
            .find(|&&f| f > vibmode_core::limits::SSI_FIRST_LAG_MAX)
        {
            return Err(SsiError::LagsTooLarge {
                block_rows: params.block_rows,
                first_lag,
            });
        }
        let first = segments.first().ok_or(SsiError::NoChannels)?;
        let l = first.len();
        check_matrix_size(params.block_rows, l)?;
        let refs = reference_indices(params, l)?;
        let mut out = SsiCorrelations::empty(fs_hz, params);
        out.first_lag = first_lags.first().copied().unwrap_or(1);
        for (seg, &first_lag) in segments.iter().zip(first_lags) {
            out.push_segment(seg, l, &refs, params.block_rows, first_lag)?;
        }
        Ok(out)
    }

    /// Adds one segment (`l` channels, samples enough for the lags, [`lag_span`]): its means
    /// removed, its lag sums for the lags `first_lag..=first_lag + 2 block_rows - 2`.
    fn push_segment(
        &mut self,
        seg: &[&[f64]],
        l: usize,
        refs: &[usize],
        block_rows: usize,
        first_lag: usize,
    ) -> Result<(), SsiError> {
        if seg.len() != l {
            return Err(SsiError::LengthMismatch {
                channel: seg.len().min(l),
                found: seg.len(),
                expected: l,
            });
        }
        let n = check_channels(seg)?;
        let (max_lag, min_samples) = lag_span(block_rows, first_lag)?;
        if n < min_samples {
            return Err(SsiError::TooFewSamples {
                n_samples: n,
                block_rows,
                first_lag,
                max_lag,
                min_samples,
            });
        }
        let demeaned = demeaned(seg, n);
        self.max_abs = demeaned
            .iter()
            .flatten()
            .fold(self.max_abs, |m, v| m.max(v.abs()));
        let (sums, counts) = lag_sums(&demeaned, refs, first_lag..=max_lag, 0..n);
        self.sums.push(sums);
        self.counts.push(counts);
        self.n_samples.push(n);
        Ok(())
    }

    /// The correlation sums of one record (`channels`, equal lengths, finite, means removed
    /// over the whole record) cut into `n_blocks` blocks of consecutive time: block `b` holds,
    /// at every lag `k`, the products `y[t+k] y_ref[t]^T` of the `t` in
    /// `[b N / n_blocks, (b + 1) N / n_blocks)` (and `t < N - k`). Every product of the record
    /// is in exactly one block, so [`SsiCorrelations::plan`] is the plan of the whole record
    /// ([`SsiCov::new`]); the blocks' scatter gives [`SsiCorrelations::perturbation`] and
    /// [`SsiCorrelations::jackknife`]. Needs `n_blocks >= 2`, the record's samples as for
    /// [`SsiCorrelations::new`], at least `first_lag + 2 block_rows - 1` samples per block
    /// (`SsiError::BlocksTooShort`), and the uncertainty's SVDs within
    /// [`vibmode_core::limits::SSI_SVD_WORK_MAX`] (`SsiError::TooManyBlocks`).
    pub fn blocks(
        channels: &[&[f64]],
        fs_hz: f64,
        params: &SsiParams,
        n_blocks: usize,
    ) -> Result<SsiCorrelations, SsiError> {
        params.validate()?;
        if !(fs_hz.is_finite() && fs_hz > 0.0) {
            return Err(SsiError::InvalidSampleRate { fs_hz });
        }
        let mut out = SsiCorrelations::empty(fs_hz, params);
        let n = check_channels(channels)?;
        let l = channels.len();
        let rows = check_matrix_size(params.block_rows, l)?;
        let refs = reference_indices(params, l)?;
        let (max_lag, min_samples) = lag_span(params.block_rows, params.first_lag)?;
        if n < min_samples {
            return Err(SsiError::TooFewSamples {
                n_samples: n,
                block_rows: params.block_rows,
                first_lag: params.first_lag,
                max_lag,
                min_samples,
            });
        }
        if n_blocks < 2 {
            return Err(SsiError::TooFewBlocks { n_blocks });
        }
        // One SVD of the whole record's matrix and two per block.
        let cols = params.block_rows * refs.len();
        let svd_work = (rows as u64) * (rows as u64) * (cols as u64);
        let max_blocks =
            (vibmode_core::limits::SSI_SVD_WORK_MAX / svd_work.max(1)).saturating_sub(1) / 2;
        if n_blocks as u64 > max_blocks {
            return Err(SsiError::TooManyBlocks {
                n_blocks,
                rows,
                cols,
                max_blocks: usize::try_from(max_blocks).unwrap_or(usize::MAX),
            });
        }
        let block_len = n / n_blocks;
        if block_len <= max_lag {
            return Err(SsiError::BlocksTooShort {
                n_samples: n,
                n_blocks,
                block_len,
                min_block_len: max_lag + 1,
                max_blocks: n / (max_lag + 1),
            });
        }
        let demeaned = demeaned(channels, n);
        out.max_abs = demeaned.iter().flatten().fold(0.0, |m, v| m.max(v.abs()));
        for b in 0..n_blocks {
            let (t0, t1) = (b * n / n_blocks, (b + 1) * n / n_blocks);
            let (sums, counts) = lag_sums(&demeaned, &refs, params.first_lag..=max_lag, t0..t1);
            out.sums.push(sums);
            out.counts.push(counts);
            out.n_samples.push(t1 - t0);
        }
        Ok(out)
    }

    /// No segment yet.
    fn empty(fs_hz: f64, params: &SsiParams) -> SsiCorrelations {
        SsiCorrelations {
            fs_hz,
            order_max: params.order_max,
            block_rows: params.block_rows,
            first_lag: params.first_lag,
            sums: Vec::new(),
            counts: Vec::new(),
            n_samples: Vec::new(),
            max_abs: 0.0,
        }
    }

    /// Number of segments.
    pub fn n_segments(&self) -> usize {
        self.sums.len()
    }

    /// The plan from the correlations averaged over every segment (as [`SsiCov::from_segments`]).
    pub fn plan(&self) -> Result<SsiCov, SsiError> {
        self.plan_without(|_| false)
    }

    /// Delete-a-group jackknife plans: the segments split into `groups` groups of consecutive
    /// segments (segment `s` of `m` in group `s * groups / m`; `groups = m` leaves one segment
    /// out at a time), plan `g` from every segment outside group `g`. With an estimate
    /// `theta_g` from each plan, the jackknife standard deviation of the all-segment estimate
    /// is `sqrt((G - 1) / G * sum_g (theta_g - mean)^2)` ([`jackknife_std`]). Needs
    /// `2 <= groups <= n_segments()` (`SsiError::TooFewSegments` otherwise).
    pub fn jackknife(&self, groups: usize) -> Result<Vec<SsiCov>, SsiError> {
        let m = self.n_segments();
        if groups < 2 || groups > m {
            return Err(SsiError::TooFewSegments {
                n_segments: m,
                groups,
            });
        }
        (0..groups)
            .map(|g| self.plan_without(|s| s * groups / m == g))
            .collect()
    }

    /// Per lag of the Toeplitz matrix (`first_lag..`): the sum of the products of every segment `s` but those with
    /// `left_out(s)`, and their number.
    pub(crate) fn totals(&self, left_out: impl Fn(usize) -> bool) -> Vec<(DMatrix<f64>, usize)> {
        let max_lag = self.sums.first().map_or(0, Vec::len);
        (0..max_lag)
            .map(|k| {
                let (rows, cols) = self.sums[0][k].shape();
                let mut total = DMatrix::zeros(rows, cols);
                let mut count = 0usize;
                for s in (0..self.sums.len()).filter(|&s| !left_out(s)) {
                    total += &self.sums[s][k];
                    count += self.counts[s][k];
                }
                (total, count)
            })
            .collect()
    }

    /// The plan from the correlations of every segment `s` but those with `left_out(s)`.
    fn plan_without(&self, left_out: impl Fn(usize) -> bool) -> Result<SsiCov, SsiError> {
        let used = || (0..self.sums.len()).filter(|&s| !left_out(s));
        let r: Vec<DMatrix<f64>> = self
            .totals(&left_out)
            .into_iter()
            .map(|(total, count)| total / count.max(1) as f64)
            .collect();
        if let Some(k) = r.iter().position(|m| m.iter().any(|v| !v.is_finite())) {
            return Err(SsiError::Overflow {
                lag: self.first_lag.saturating_add(k),
                max_abs: self.max_abs,
            });
        }
        let mut cov = SsiCov::from_correlations(&r, self.fs_hz, self.block_rows, self.order_max)?;
        cov.n_samples = used().map(|s| self.n_samples[s]).sum();
        Ok(cov)
    }
}

/// Each channel minus its mean over its `n` samples.
fn demeaned(channels: &[&[f64]], n: usize) -> Vec<Vec<f64>> {
    channels
        .iter()
        .map(|ch| {
            let m = ch.iter().sum::<f64>() / n as f64;
            ch.iter().map(|v| v - m).collect()
        })
        .collect()
}

/// The reference channels' indices of `params` for `l` channels (all by default).
fn reference_indices(params: &SsiParams, l: usize) -> Result<Vec<usize>, SsiError> {
    match &params.reference_channels {
        Some(refs) => {
            if let Some(&index) = refs.iter().find(|&&r| r >= l.max(1)) {
                return Err(SsiError::ReferenceChannel {
                    index,
                    n_channels: l,
                    last: l.saturating_sub(1),
                });
            }
            Ok(refs.clone())
        }
        None => Ok((0..l).collect()),
    }
}

/// For the lags `k` of `lags`: `sum_{t in ts, t < N - k} y[t+k] y[refs][t]^T` and the number
/// of products (`N` the channels' length; `lags` within `1..N`, checked by the callers).
fn lag_sums(
    y: &[Vec<f64>],
    refs: &[usize],
    lags: std::ops::RangeInclusive<usize>,
    ts: std::ops::Range<usize>,
) -> (Vec<DMatrix<f64>>, Vec<usize>) {
    let n = y.first().map_or(0, Vec::len);
    let n_lags = lags.clone().count();
    let mut sums = vec![DMatrix::zeros(y.len(), refs.len()); n_lags];
    let mut counts = vec![0; n_lags];
    for (k, (sum, count)) in lags.zip(sums.iter_mut().zip(counts.iter_mut())) {
        let t1 = ts.end.min(n.saturating_sub(k));
        if t1 <= ts.start {
            continue;
        }
        *count = t1 - ts.start;
        for (a, ya) in y.iter().enumerate() {
            for (b, &rb) in refs.iter().enumerate() {
                let fut = &ya[ts.start + k..t1 + k];
                let past = &y[rb][ts.start..t1];
                sum[(a, b)] += vibmode_core::stats::dot(fut, past);
            }
        }
    }
    (sums, counts)
}

impl SsiCov {
    /// Plans SSI-cov for `channels` (equal lengths, finite) sampled at `fs_hz`, with
    /// `params.block_rows` block rows and `params.reference_channels`. Removes each channel's
    /// mean, computes the correlations, the block Toeplitz matrix, its SVD, and one QR of the
    /// shifted observability matrix that serves every order up to `params.order_max` (any
    /// higher order can still be asked of [`SsiCov::poles_at`]; it gets its own
    /// least-squares solution).
    pub fn new(channels: &[&[f64]], fs_hz: f64, params: &SsiParams) -> Result<SsiCov, SsiError> {
        // One segment: the same correlations (sum over t divided by N - k).
        Self::from_segments(&[channels.to_vec()], fs_hz, params)
    }

    /// Plans SSI-cov from several segments (records) of the same channels, for example records
    /// of one drive cut apart: the correlations are averaged over the segments,
    /// `R_k = sum_s sum_t y_s[t+k] y_s[t]^T / sum_s (N_s - k)` (each segment's means removed; no
    /// product straddles two segments), then as [`SsiCov::new`]. Long identification data
    /// without the joins of a concatenation. Every segment needs the same channel count and at
    /// least `first_lag + 2 block_rows - 1` samples; segments may differ in length.
    /// ([`SsiCorrelations`] keeps the segments' sums for a jackknife as well.)
    pub fn from_segments(
        segments: &[Vec<&[f64]>],
        fs_hz: f64,
        params: &SsiParams,
    ) -> Result<SsiCov, SsiError> {
        SsiCorrelations::new(segments, fs_hz, params)?.plan()
    }

    /// Delete-a-group jackknife plans of `segments` in `groups` groups
    /// ([`SsiCorrelations::jackknife`]).
    pub fn jackknife(
        segments: &[Vec<&[f64]>],
        fs_hz: f64,
        params: &SsiParams,
        groups: usize,
    ) -> Result<Vec<SsiCov>, SsiError> {
        SsiCorrelations::new(segments, fs_hz, params)?.jackknife(groups)
    }

    /// From given correlations `r[k - 1] = R_k`, `k = 1..=2i-1`, each `l x r` (checked by the
    /// callers).
    /// `order_max` bounds the orders served by the one QR (higher ones get their own).
    pub(crate) fn from_correlations(
        r: &[DMatrix<f64>],
        fs_hz: f64,
        block_rows: usize,
        order_max: usize,
    ) -> Result<SsiCov, SsiError> {
        let i = block_rows;
        let l = r.first().map_or(0, DMatrix::nrows);
        let n_refs = r.first().map_or(0, DMatrix::ncols);
        let mut t = DMatrix::zeros(i * l, i * n_refs);
        for a in 0..i {
            for b in 0..i {
                t.view_mut((a * l, b * n_refs), (l, n_refs))
                    .copy_from(&r[i + a - b - 1]);
            }
        }
        let dim = i * l.max(n_refs);
        let iterations = svd_iterations(dim);
        // Only the left singular vectors the orders up to `order_max` use.
        let k_u = order_max.min(i * n_refs);
        let svd =
            leading_svd(t.clone(), k_u, SVD_EPS, iterations).ok_or(SsiError::NotConverged {
                what: "SVD of the block Toeplitz matrix",
                size: dim,
                iterations,
            })?;
        let (singular_values, u) = (svd.singular_values, svd.u);
        let smax = singular_values.first().copied().unwrap_or(0.0);
        let rank_tolerance = smax * dim as f64 * f64::EPSILON;
        let rank = singular_values
            .iter()
            .filter(|&&s| s > rank_tolerance)
            .count();
        let k_max = ((i - 1) * l).min(i * n_refs).min(rank).min(order_max);
        let rows = (i - 1) * l;
        let (m_shift, c_shift) = if k_max == 0 {
            (DMatrix::zeros(0, 0), DMatrix::zeros(l, 0))
        } else {
            let o = observability(&u, &singular_values, i * l, k_max);
            let qr = o.rows(0, rows).into_owned().qr();
            let r = qr.r();
            // The orders whose leading pivots all pass: a prefix (see `shift_pivots_ok`).
            let k = (1..=k_max)
                .take_while(|&n| shift_pivots_ok(&r, n, rows))
                .last()
                .unwrap_or(0);
            let r = r.view((0, 0), (k, k));
            // M = B R^-1 and C R^-1, as R^T M^T = B^T and R^T (C R^-1)^T = C^T.
            let b = qr.q().columns(0, k).tr_mul(&o.rows(l, rows).columns(0, k));
            let m_t = r.tr_solve_upper_triangular(&b.transpose());
            let c_t = r.tr_solve_upper_triangular(&o.view((0, 0), (l, k)).transpose());
            match (m_t, c_t) {
                (Some(m_t), Some(c_t)) => (m_t.transpose(), c_t.transpose()),
                _ => (DMatrix::zeros(0, 0), DMatrix::zeros(l, 0)),
            }
        };
        Ok(SsiCov {
            fs_hz,
            block_rows: i,
            n_channels: l,
            n_references: n_refs,
            n_samples: 0,
            u,
            singular_values,
            rank,
            rank_tolerance,
            m_shift,
            c_shift,
            toeplitz: t,
            u_full: std::sync::OnceLock::new(),
        })
    }

    /// Sampling rate, Hz.
    pub fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    /// Block rows `i` of the Toeplitz matrix.
    pub fn block_rows(&self) -> usize {
        self.block_rows
    }

    /// Number of channels `l`.
    pub fn n_channels(&self) -> usize {
        self.n_channels
    }

    /// Number of reference channels `r` (`l` unless [`SsiParams::reference_channels`] is set).
    pub fn n_references(&self) -> usize {
        self.n_references
    }

    /// Samples per channel.
    pub fn n_samples(&self) -> usize {
        self.n_samples
    }

    /// Singular values of the block Toeplitz matrix, largest first.
    pub fn singular_values(&self) -> &[f64] {
        &self.singular_values
    }

    /// Numerical rank of the block Toeplitz matrix: the singular values above
    /// `s_max * i max(l, r) * f64::EPSILON` (as numpy's `matrix_rank`).
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// Highest order [`SsiCov::poles_at`] accepts: `min((i - 1) l, i r, rank)`.
    pub fn max_order(&self) -> usize {
        self.shift_max_order().min(self.rank)
    }

    /// `min((i - 1) l, i r)`: the shift of `O` needs at least `n` rows, the Toeplitz matrix has
    /// `i r` columns.
    fn shift_max_order(&self) -> usize {
        ((self.block_rows - 1) * self.n_channels).min(self.block_rows * self.n_references)
    }

    /// The modes of the order-`order` model, by increasing frequency.
    ///
    /// Every eigenvalue `lambda` of `A` gives a continuous pole `s = ln(lambda) fs_hz`. Kept:
    /// one pole of each complex conjugate pair (the one with `Im(lambda) > 0`) with a damping
    /// ratio `-Re(s)/|s|` above 0. Dropped: real eigenvalues (no oscillation; a negative real
    /// eigenvalue would map to the Nyquist frequency), and poles on or outside the unit circle
    /// (damping <= 0: not a stable mode). The mode shape is `C psi` for the right eigenvector
    /// `psi` of `A`, scaled so that its entry of largest modulus is `1 + 0i`.
    ///
    /// Errors: order 0 ([`SsiError::ZeroOrder`]), above `min((i - 1) l, i r)`
    /// ([`SsiError::OrderTooHigh`]) or above the Toeplitz matrix's rank
    /// ([`SsiError::OrderAboveRank`]).
    pub fn poles_at(&self, order: usize) -> Result<Vec<SsiMode>, SsiError> {
        let (i, l) = (self.block_rows, self.n_channels);
        if order == 0 {
            return Err(SsiError::ZeroOrder);
        }
        let max_order = self.shift_max_order();
        if order > max_order {
            return Err(SsiError::OrderTooHigh {
                order,
                block_rows: i,
                n_channels: l,
                n_references: self.n_references,
                max_order,
                needed_block_rows: (order.div_ceil(l) + 1).max(order.div_ceil(self.n_references)),
            });
        }
        if order > self.rank {
            return Err(SsiError::OrderAboveRank {
                order,
                rank: self.rank,
                tolerance: self.rank_tolerance,
            });
        }
        let fs_hz = self.fs_hz;
        let pole = |lambda: Complex64| {
            let s = lambda.ln() * fs_hz;
            let abs = s.norm();
            (abs, -s.re / abs)
        };
        let keep = |lambda| {
            let (abs, damping_ratio) = pole(lambda);
            abs.is_finite() && abs > 0.0 && damping_ratio > 0.0
        };
        let kept = if order <= self.m_shift.nrows() {
            kept_eigenvalues(
                self.m_shift.view((0, 0), (order, order)),
                self.c_shift.columns(0, order),
                keep,
            )?
        } else {
            let dim = i * l;
            let o = if order <= self.u.ncols() {
                observability(&self.u, &self.singular_values, dim, order)
            } else {
                observability(self.full_u()?, &self.singular_values, dim, order)
            };
            let rows = dim - l;
            let a = least_squares(o.rows(0, rows).into_owned(), &o.rows(l, rows).into_owned())?;
            kept_eigenvalues(&a, o.rows(0, l), keep)?
        };
        let mut modes: Vec<SsiMode> = kept
            .into_iter()
            .map(|k| {
                let (abs, damping_ratio) = pole(k.lambda);
                let shape = normalised_shape(&k.shape);
                let mpc = mpc(&shape);
                SsiMode {
                    frequency_hz: abs / (2.0 * std::f64::consts::PI),
                    damping_ratio,
                    shape,
                    mpc,
                }
            })
            .collect();
        modes.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
        Ok(modes)
    }

    /// All the left singular vectors of `T` (nalgebra's SVD, computed once, on the first order
    /// above the columns kept by [`SsiCov::from_correlations`]).
    fn full_u(&self) -> Result<&DMatrix<f64>, SsiError> {
        let dim = self.toeplitz.nrows().max(self.toeplitz.ncols());
        let iterations = svd_iterations(dim);
        self.u_full
            .get_or_init(|| {
                SVD::try_new(self.toeplitz.clone(), true, false, SVD_EPS, iterations)
                    .and_then(|svd| svd.u)
            })
            .as_ref()
            .ok_or(SsiError::NotConverged {
                what: "SVD of the block Toeplitz matrix",
                size: dim,
                iterations,
            })
    }

    /// [`SsiCov::poles_at`] for every order of `orders`, the orders on all of rayon's threads
    /// (`RAYON_NUM_THREADS=1` for one); the result is the same whatever the thread count.
    pub fn sweep(&self, orders: &[usize]) -> Result<SsiResult, SsiError> {
        let orders = orders
            .par_iter()
            .map(|&order| {
                Ok(SsiOrder {
                    order,
                    modes: self.poles_at(order)?,
                })
            })
            .collect::<Result<Vec<_>, SsiError>>()?;
        Ok(SsiResult {
            fs_hz: self.fs_hz,
            block_rows: self.block_rows,
            orders,
            singular_values: self.singular_values.clone(),
        })
    }
}

/// Whether the leading `n x n` block of the triangular `r` (of the QR of `O_up`, `rows` rows)
/// is safely invertible: every pivot `|R_jj|`, `j < n`, above `max_j |R_jj| max(rows, n) eps`
/// (over `j < n`); false for a non-finite pivot. True for `n` implies true for every smaller
/// `n` (the bound only grows with `n`), so the orders that pass are a prefix.
fn shift_pivots_ok(r: &DMatrix<f64>, n: usize, rows: usize) -> bool {
    let diag = r.view((0, 0), (n, n)).diagonal();
    let rmax = diag.amax();
    let tiny = rmax * rows.max(n) as f64 * f64::EPSILON;
    rmax > 0.0 && diag.iter().all(|d| d.abs() > tiny)
}

/// `O = U[.., ..n] S[..n]^{1/2}` (`rows x n`).
fn observability(u: &DMatrix<f64>, singular_values: &[f64], rows: usize, n: usize) -> DMatrix<f64> {
    DMatrix::from_fn(rows, n, |r, c| u[(r, c)] * singular_values[c].sqrt())
}

/// `C psi`, scaled so that its entry of largest modulus is `1 + 0i` (left as is when zero).
fn normalised_shape(phi: &[Complex64]) -> Vec<[f64; 2]> {
    let pivot = phi
        .iter()
        .copied()
        .max_by(|a, b| a.norm().total_cmp(&b.norm()))
        .unwrap_or(Complex64::new(0.0, 0.0));
    phi.iter()
        .map(|v| {
            let w = if pivot.norm() > 0.0 { *v / pivot } else { *v };
            [w.re, w.im]
        })
        .collect()
}

/// Least-squares solution `X` of `a X = b` (`a` tall, full column rank expected): QR, with an
/// SVD-based minimum-norm solution when `R` has a zero pivot.
fn least_squares(a: DMatrix<f64>, b: &DMatrix<f64>) -> Result<DMatrix<f64>, SsiError> {
    let qr = a.clone().qr();
    let r = qr.r();
    let rmax = r.diagonal().amax();
    let tiny = rmax * a.nrows().max(a.ncols()) as f64 * f64::EPSILON;
    if rmax > 0.0 && r.diagonal().iter().all(|d| d.abs() > tiny) {
        let qtb = qr.q().tr_mul(b);
        if let Some(x) = r.solve_upper_triangular(&qtb) {
            return Ok(x);
        }
    }
    let size = a.nrows().max(a.ncols());
    let iterations = 60 * size + 100;
    let svd = SVD::try_new(a, true, true, SVD_EPS, iterations).ok_or(SsiError::NotConverged {
        what: "SVD of the shifted observability matrix",
        size,
        iterations,
    })?;
    let eps = svd.singular_values.amax() * size as f64 * f64::EPSILON;
    svd.solve(b, eps).map_err(|_| SsiError::NotConverged {
        what: "SVD of the shifted observability matrix",
        size,
        iterations,
    })
}

/// SSI-cov in one call: [`SsiCov::new`] and [`SsiCov::sweep`] over `params.orders()`.
///
/// ```
/// use vibmode_core::SsiParams;
/// use vibmode_ssi::ssi_cov;
/// // Two channels of a 3 Hz mode with 5 % damping, free decay sampled at 50 Hz.
/// let fs_hz = 50.0;
/// let (f, z) = (3.0, 0.05);
/// let w = 2.0 * std::f64::consts::PI * f;
/// let y1: Vec<f64> = (0..4000)
///     .map(|t| {
///         let t = t as f64 / fs_hz;
///         (-z * w * t).exp() * (w * (1.0 - z * z).sqrt() * t).cos()
///     })
///     .collect();
/// let y2: Vec<f64> = y1.iter().map(|v| -0.5 * v).collect();
/// let params = SsiParams { block_rows: 10, order_min: 2, order_max: 2, ..SsiParams::default() };
/// let result = ssi_cov(&[&y1, &y2], fs_hz, &params).unwrap();
/// let mode = &result.orders[0].modes[0];
/// assert!((mode.frequency_hz - f).abs() < 1e-3);
/// assert!((mode.damping_ratio - z).abs() < 1e-3);
/// assert!((mode.shape[1][0] + 0.5).abs() < 1e-6); // channel 2 moves against channel 1
/// ```
pub fn ssi_cov(channels: &[&[f64]], fs_hz: f64, params: &SsiParams) -> Result<SsiResult, SsiError> {
    SsiCov::new(channels, fs_hz, params)?.sweep(&params.orders())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Exact correlations of one mode, `R_k = Re(a lambda^k)` with a complex amplitude `a`:
    /// the Toeplitz matrix has rank 2 and order 2 must return the pole itself.
    fn one_mode_correlations(f_hz: f64, zeta: f64, fs_hz: f64, i: usize) -> Vec<DMatrix<f64>> {
        let w = 2.0 * PI * f_hz;
        let s = Complex64::new(-zeta * w, w * (1.0 - zeta * zeta).sqrt());
        let lambda = (s / fs_hz).exp();
        let a = Complex64::new(0.7, -0.3);
        (1..2 * i)
            .map(|k| DMatrix::from_element(1, 1, (a * lambda.powu(k as u32)).re))
            .collect()
    }

    #[test]
    fn exact_correlations_give_the_pole_to_1e_8() {
        for &(f, z, i) in &[
            (2.0, 0.05, 5),
            (7.3, 0.15, 10),
            (0.8, 0.01, 20),
            (20.0, 0.3, 3),
        ] {
            let r = one_mode_correlations(f, z, 50.0, i);
            let cov = SsiCov::from_correlations(&r, 50.0, i, 60).unwrap();
            assert_eq!(
                cov.rank(),
                2,
                "f {f} z {z} i {i}: {:?}",
                cov.singular_values()
            );
            let modes = cov.poles_at(2).unwrap();
            assert_eq!(modes.len(), 1);
            let m = &modes[0];
            assert!(
                (m.frequency_hz - f).abs() < 1e-8 * f,
                "f {f}: {}",
                m.frequency_hz
            );
            assert!(
                (m.damping_ratio - z).abs() < 1e-8,
                "z {z}: {}",
                m.damping_ratio
            );
            assert_eq!(m.shape, vec![[1.0, 0.0]]);
            assert_eq!(m.mpc, 1.0);
        }
    }

    #[test]
    fn order_above_the_rank_of_exact_correlations_is_refused() {
        let r = one_mode_correlations(2.0, 0.05, 50.0, 5);
        let cov = SsiCov::from_correlations(&r, 50.0, 5, 60).unwrap();
        let e = cov.poles_at(4).unwrap_err();
        assert!(
            matches!(
                e,
                SsiError::OrderAboveRank {
                    order: 4,
                    rank: 2,
                    ..
                }
            ),
            "{e:?}"
        );
        let m = e.to_string();
        assert!(
            m.contains("order 4") && m.contains("rank 2") && m.contains("<= 2"),
            "{m}"
        );
    }

    /// The correlations `R_1 ..= R_{2i-1}` of a seeded random record: three damped modes
    /// (1.3, 4.1 and 9.7 Hz at 50 Hz) driven by white noise, mixed into `l` channels, plus
    /// white noise, `n` samples.
    fn three_mode_correlations(seed: u64, l: usize, n: usize, i: usize) -> Vec<DMatrix<f64>> {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let fs = 50.0;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut noise = || -> f64 { StandardNormal.sample(&mut rng) };
        let mut y = vec![vec![0.0; n]; l];
        for (m, &(f, z)) in [(1.3, 0.02), (4.1, 0.05), (9.7, 0.03)].iter().enumerate() {
            let w = 2.0 * PI * f / fs;
            let r = (-z * w).exp();
            let (a1, a2) = (2.0 * r * (w * (1.0 - z * z).sqrt()).cos(), -r * r);
            let (mut x1, mut x2) = (0.0, 0.0);
            let gains: Vec<f64> = (0..l)
                .map(|c| ((c + 1) * (m + 2)) as f64 % 3.0 - 1.1)
                .collect();
            let xs: Vec<f64> = (0..n)
                .map(|_| {
                    let x = a1 * x1 + a2 * x2 + noise();
                    (x2, x1) = (x1, x);
                    x
                })
                .collect();
            for (ch, g) in y.iter_mut().zip(&gains) {
                for (v, x) in ch.iter_mut().zip(&xs) {
                    *v += g * x;
                }
            }
        }
        for ch in &mut y {
            for v in ch.iter_mut() {
                *v += 0.3 * noise();
            }
        }
        let r: Vec<DMatrix<f64>> = (1..2 * i)
            .map(|k| {
                DMatrix::from_fn(l, l, |a, b| {
                    (0..n - k).map(|t| y[a][t + k] * y[b][t]).sum::<f64>() / (n - k) as f64
                })
            })
            .collect();
        r
    }

    /// An order above `order_max` (above the singular vectors kept) takes all of `T`'s left
    /// singular vectors from nalgebra's SVD: the same modes as from a plan for that order, to
    /// rounding (1e-9 relative in frequency and damping, 1e-7 in the shapes).
    #[test]
    fn orders_above_order_max_are_still_served() {
        let (l, n, i) = (5, 1200, 8);
        let r = three_mode_correlations(1, l, n, i);
        let small = SsiCov::from_correlations(&r, 50.0, i, 6).unwrap();
        let large = SsiCov::from_correlations(&r, 50.0, i, 20).unwrap();
        assert_eq!(small.u.ncols(), 6);
        for order in [8, 14, 20] {
            let (a, b) = (
                small.poles_at(order).unwrap(),
                large.poles_at(order).unwrap(),
            );
            assert_eq!(a.len(), b.len(), "order {order}");
            for (x, y) in a.iter().zip(&b) {
                assert!((x.frequency_hz - y.frequency_hz).abs() < 1e-9 * y.frequency_hz);
                assert!((x.damping_ratio - y.damping_ratio).abs() < 1e-9 * y.damping_ratio);
                for (p, q) in x.shape.iter().zip(&y.shape) {
                    assert!(
                        (p[0] - q[0]).abs().max((p[1] - q[1]).abs()) < 1e-7,
                        "{p:?} {q:?}"
                    );
                }
            }
        }
    }

    /// The modes of order `n` from the leading block of `M = B R^-1` against the definition:
    /// `A_n` as the least-squares solution of `O_up A = O_down` of that order alone (its own QR)
    /// and `C` the first block row of `O`, on the correlations of seeded random records (three
    /// damped modes plus white noise, 5 channels, 1200 samples), every even order up to 30 (the
    /// noise poles included). The same eigenproblem up to a similarity, so the poles agree to
    /// rounding times their condition: frequencies and damping ratios to 1e-9 relative, shapes
    /// (scaled to their largest entry) to 1e-7.
    #[test]
    fn leading_blocks_of_the_shared_state_matrix_give_each_orders_least_squares_modes() {
        let (fs, l, n, i) = (50.0, 5, 1200, 8);
        let mut checked = 0;
        for seed in 0..12u64 {
            let r = three_mode_correlations(seed, l, n, i);
            let cov = SsiCov::from_correlations(&r, fs, i, 30).unwrap();
            assert_eq!(cov.m_shift.nrows(), 30, "seed {seed}: every order from M");
            for order in (2..=30).step_by(2) {
                let got = cov.poles_at(order).unwrap();
                let o = observability(&cov.u, &cov.singular_values, i * l, order);
                let rows = (i - 1) * l;
                let a = least_squares(o.rows(0, rows).into_owned(), &o.rows(l, rows).into_owned())
                    .unwrap();
                let want = kept_eigenvalues(&a, o.rows(0, l), |lambda| {
                    let s = lambda.ln() * fs;
                    s.norm() > 0.0 && -s.re / s.norm() > 0.0
                })
                .unwrap();
                assert_eq!(got.len(), want.len(), "seed {seed} order {order}");
                for k in want {
                    let s = k.lambda.ln() * fs;
                    let f = s.norm() / (2.0 * PI);
                    let z = -s.re / s.norm();
                    let m = got
                        .iter()
                        .min_by(|a, b| {
                            (a.frequency_hz - f)
                                .abs()
                                .total_cmp(&(b.frequency_hz - f).abs())
                        })
                        .unwrap();
                    assert!(
                        (m.frequency_hz - f).abs() < 1e-9 * f,
                        "seed {seed} order {order}: {} vs {f}",
                        m.frequency_hz
                    );
                    assert!(
                        (m.damping_ratio - z).abs() < 1e-9 * z,
                        "seed {seed} order {order}: {} vs {z}",
                        m.damping_ratio
                    );
                    let shape = normalised_shape(&k.shape);
                    for (p, q) in m.shape.iter().zip(&shape) {
                        assert!(
                            (p[0] - q[0]).abs().max((p[1] - q[1]).abs()) < 1e-7,
                            "seed {seed} order {order}: {p:?} vs {q:?}"
                        );
                    }
                    checked += 1;
                }
            }
        }
        assert!(checked > 1000, "{checked} poles compared");
    }

    /// `R_1` and `R_5` only, i = 3: the Toeplitz matrix `[[0,0,R1],[0,0,0],[R5,0,0]]` has rank 2
    /// but the observability matrix without its last block row has rank 1, so the QR pivot is
    /// zero and the minimum-norm least-squares fallback is used: no panic, a finite answer.
    #[test]
    fn rank_deficient_shifted_observability_uses_the_fallback() {
        let mut r = vec![DMatrix::from_element(1, 1, 0.0); 5];
        r[0][(0, 0)] = 1.0;
        r[4][(0, 0)] = 0.5;
        let cov = SsiCov::from_correlations(&r, 50.0, 3, 60).unwrap();
        assert_eq!(cov.rank(), 2);
        let modes = cov.poles_at(2).unwrap();
        for m in modes {
            assert!(m.frequency_hz.is_finite() && m.damping_ratio > 0.0);
        }
    }
}
