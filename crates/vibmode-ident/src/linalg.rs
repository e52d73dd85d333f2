//! Internal numeric helpers: input checks, lagged Gram matrices in O(N k), filtering, Cholesky.

use nalgebra::{DMatrix, DMatrixViewMut};

use crate::IdentError;

/// Checks a signal: non-empty, finite, not constant. Returns its mean.
pub(crate) fn check_signal(y: &[f64], min_len: usize) -> Result<f64, IdentError> {
    if y.is_empty() {
        return Err(IdentError::Empty { min_len });
    }
    if let Some((index, &value)) = y.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(IdentError::NonFinite { index, value });
    }
    let first = y[0];
    if y.iter().all(|&v| v == first) {
        return Err(IdentError::Constant { value: first });
    }
    Ok(y.iter().sum::<f64>() / y.len() as f64)
}

pub(crate) use vibmode_core::stats::dot;

/// `sum_{t=t0}^{N-1} x[t-i] * z[t-j]` with zero for negative indices (i, j >= 0).
#[inline]
pub(crate) fn lagged_dot(x: &[f64], i: usize, z: &[f64], j: usize, t0: usize) -> f64 {
    let n = x.len().min(z.len());
    let start = t0.max(i).max(j);
    if start >= n {
        return 0.0;
    }
    dot(&x[start - i..n - i], &z[start - j..n - j])
}

/// A signal and how many of its delays (lags 1..=`count`) form one side of a Gram block.
#[derive(Clone, Copy)]
pub(crate) struct Lags<'a> {
    /// The signal.
    pub(crate) x: &'a [f64],
    /// Number of lags, starting at lag 1.
    pub(crate) count: usize,
}

impl<'a> Lags<'a> {
    /// Lags 1..=`count` of `x`.
    pub(crate) fn new(x: &'a [f64], count: usize) -> Self {
        Lags { x, count }
    }

    /// `x[k]`, zero outside the first `n` samples (and for negative `k`).
    fn at(&self, k: isize, n: usize) -> f64 {
        if k >= 0 && (k as usize) < n {
            self.x[k as usize]
        } else {
            0.0
        }
    }
}

/// Exact Gram block `M[i-1][j-1] = sum_{t=t0}^{N-1} x[t-i] z[t-j]` for i = 1..=lx, j = 1..=lz
/// (`lx = x.count`, `lz = z.count`; zero for negative indices), multiplied by `sign` and written
/// into `out` (an `lx` x `lz` view, usually a block of a larger matrix).
///
/// Cost O(N (lx + lz)) for the first row and column plus O(lx lz) for the shift recursion
/// `M(i+1, j+1) = M(i, j) - x[N-1-i] z[N-1-j] + x[t0-1-i] z[t0-1-j]`.
pub(crate) fn lagged_gram(
    x: Lags<'_>,
    z: Lags<'_>,
    t0: usize,
    mut out: DMatrixViewMut<'_, f64>,
    sign: f64,
) {
    let (lx, lz) = (x.count, z.count);
    if lx == 0 || lz == 0 {
        return;
    }
    let n = x.x.len().min(z.x.len());
    let mut m = DMatrix::<f64>::zeros(lx, lz);
    for j in 1..=lz {
        m[(0, j - 1)] = lagged_dot(x.x, 1, z.x, j, t0);
    }
    // A block of one signal with itself is symmetric bit for bit: `lagged_dot(x, i, x, 1)` sums
    // the same products in the same order as `lagged_dot(x, 1, x, i)` (multiplication commutes
    // exactly), so its first column is its first row.
    let same = std::ptr::eq(x.x, z.x) && lx == lz;
    for i in 2..=lx {
        m[(i - 1, 0)] = if same {
            m[(0, i - 1)]
        } else {
            lagged_dot(x.x, i, z.x, 1, t0)
        };
    }
    let (ni, t0i) = (n as isize, t0 as isize);
    for i in 1..lx {
        for j in 1..lz {
            // m(i+1, j+1) from m(i, j), with 1-based lags i, j.
            let (ii, jj) = (i as isize, j as isize);
            let prev = m[(i - 1, j - 1)];
            m[(i, j)] = prev - x.at(ni - 1 - ii, n) * z.at(ni - 1 - jj, n)
                + x.at(t0i - 1 - ii, n) * z.at(t0i - 1 - jj, n);
        }
    }
    for i in 0..lx {
        for j in 0..lz {
            out[(i, j)] = sign * m[(i, j)];
        }
    }
}

/// Copies the upper triangle of the off-diagonal block `rows 0..split`, `columns split..k` of the
/// square matrix `h` into the lower one, so that `h` is symmetric across that block.
pub(crate) fn mirror_upper_block(h: &mut DMatrix<f64>, split: usize) {
    let k = h.nrows();
    for i in 0..split {
        for j in split..k {
            h[(j, i)] = h[(i, j)];
        }
    }
}

/// `c[1..=q]` reversed: `[c_q, ..., c_1]`, so that `sum_{k=1}^{m} c_k x[t-k]` is the dot product
/// of its last `m` entries with `x[t-m..t]` (four accumulators in [`dot`], not one serial chain).
fn reversed_tail(c: &[f64]) -> Vec<f64> {
    c.iter().skip(1).rev().copied().collect()
}

/// `out[t] = x[t] / C(q)`: `out[t] = x[t] - sum_{k=1}^{q} c[k] out[t-k]`, zero initial conditions.
pub(crate) fn filter_inv_c(x: &[f64], c: &[f64], out: &mut [f64]) {
    let q = c.len().saturating_sub(1);
    let crev = reversed_tail(c);
    for t in 0..x.len().min(out.len()) {
        let kmax = q.min(t);
        let (done, rest) = out.split_at_mut(t);
        rest[0] = x[t] - dot(&crev[q - kmax..], &done[t - kmax..]);
    }
}

/// [`filter_inv_c`] of each `xs[i]` into `outs[i]` (lengths may differ), the filters run side
/// by side: each output sample waits on the one before it in its own filter only, so the
/// filters' recursions overlap instead of running one after another. Every output is
/// [`filter_inv_c`]'s bit for bit.
pub(crate) fn filter_inv_c_each(xs: &[&[f64]], c: &[f64], outs: &mut [&mut [f64]]) {
    let q = c.len().saturating_sub(1);
    let crev = reversed_tail(c);
    let lens: Vec<usize> = xs
        .iter()
        .zip(outs.iter())
        .map(|(x, o)| x.len().min(o.len()))
        .collect();
    let longest = lens.iter().copied().max().unwrap_or(0);
    for t in 0..longest {
        let kmax = q.min(t);
        for ((x, out), &len) in xs.iter().zip(outs.iter_mut()).zip(&lens) {
            if t < len {
                let (done, rest) = out.split_at_mut(t);
                rest[0] = x[t] - dot(&crev[q - kmax..], &done[t - kmax..]);
            }
        }
    }
}

/// Conditional prediction errors: `eps_t = 0` for `t < p`, and for `t >= p`
/// `eps_t = y_t + sum_{k=1}^{p} a_k y_{t-k} - sum_{k=1}^{q} c_k eps_{t-k}`, i.e. `eps = w / C` with
/// zero initial conditions where `w_t = A(q) y_t` uses measured samples only.
pub(crate) fn predict_errors(y: &[f64], a: &[f64], c: &[f64], eps: &mut [f64]) {
    let p = a.len().saturating_sub(1);
    let q = c.len().saturating_sub(1);
    let n = y.len().min(eps.len());
    for e in eps.iter_mut().take(p.min(n)) {
        *e = 0.0;
    }
    let (arev, crev) = (reversed_tail(a), reversed_tail(c));
    for t in p..n {
        let kmax = q.min(t);
        let (done, rest) = eps.split_at_mut(t);
        rest[0] = y[t] + dot(&arev, &y[t - p..t]) - dot(&crev[q - kmax..], &done[t - kmax..]);
    }
}

/// Adjoint of `x -> x / C`: `u_t = v_t - sum_{k=1}^{q} c_k u_{t+k}` (run backwards).
pub(crate) fn filter_inv_c_adjoint(v: &[f64], c: &[f64], out: &mut [f64]) {
    let q = c.len().saturating_sub(1);
    let n = v.len().min(out.len());
    let tail = c.get(1..).unwrap_or(&[]);
    for t in (0..n).rev() {
        let kmax = q.min(n - 1 - t);
        let (head, later) = out.split_at_mut(t + 1);
        head[t] = v[t] - dot(&tail[..kmax], &later[..kmax]);
    }
}

/// Solves the symmetric positive (semi)definite system `h x = b` by Cholesky, adding a relative
/// ridge `ridge * mean(diag)` to the diagonal. Reads only the lower triangle of `h`. Returns None
/// if not positive definite.
pub(crate) fn cholesky_solve(h: &DMatrix<f64>, b: &[f64], ridge: f64) -> Option<Vec<f64>> {
    let r = cholesky_factor(h, ridge)?;
    let x = cholesky_apply(&r, b);
    if x.iter().all(|v| v.is_finite()) {
        Some(x)
    } else {
        None
    }
}

/// Relative ridges tried in turn by [`cholesky_solve_ridged`]: none first (the exact normal
/// equations), then 1e-12 (a few units of rounding relative to the mean diagonal: rescues a matrix
/// that is singular only to rounding), then 1e-8 (a genuinely rank-deficient Gram matrix, e.g. an
/// AR order above what the data support; still far below any statistically meaningful ridge).
const FALLBACK_RIDGES: [f64; 3] = [0.0, 1e-12, 1e-8];

/// [`cholesky_solve`] with the first of [`FALLBACK_RIDGES`] that gives a finite solution.
pub(crate) fn cholesky_solve_ridged(h: &DMatrix<f64>, b: &[f64]) -> Option<Vec<f64>> {
    FALLBACK_RIDGES
        .iter()
        .find_map(|&ridge| cholesky_solve(h, b, ridge))
}

/// Rows `0..len` of column `j` of `m`: contiguous in nalgebra's column-major storage.
fn column_head(m: &DMatrix<f64>, j: usize, len: usize) -> &[f64] {
    &m.column(j).data.into_slice()[..len]
}

/// Cholesky factor of `h + ridge * mean(diag h) * I` (only the lower triangle of `h` is read),
/// stored transposed: the upper triangle of the result is `R = L^T`, so that column `j` of `R`
/// holds row `j` of the lower factor `L` contiguously (the strict lower triangle of the result
/// is scratch). None if `h` is not numerically positive definite.
pub(crate) fn cholesky_factor(h: &DMatrix<f64>, ridge: f64) -> Option<DMatrix<f64>> {
    let n = h.nrows();
    if n == 0 {
        return Some(DMatrix::zeros(0, 0));
    }
    let mean_diag = (0..n).map(|i| h[(i, i)]).sum::<f64>() / n as f64;
    if !(mean_diag.is_finite() && mean_diag > 0.0) {
        return None;
    }
    // r[(j, i)] = h[(i, j)]: the lower triangle of h becomes the upper triangle of r.
    let mut r = h.transpose();
    for i in 0..n {
        r[(i, i)] += ridge * mean_diag;
    }
    for j in 0..n {
        let row_j = column_head(&r, j, j);
        let d = r[(j, j)] - dot(row_j, row_j);
        if !(d > 0.0 && d.is_finite()) {
            return None;
        }
        let d = d.sqrt();
        r[(j, j)] = d;
        for i in j + 1..n {
            let s = r[(j, i)] - dot(column_head(&r, i, j), column_head(&r, j, j));
            r[(j, i)] = s / d;
        }
    }
    Some(r)
}

/// Solves `L L^T x = b` with the (transposed) factor `r = L^T` of [`cholesky_factor`].
pub(crate) fn cholesky_apply(r: &DMatrix<f64>, b: &[f64]) -> Vec<f64> {
    let n = r.nrows();
    let mut x = b.to_vec();
    for i in 0..n {
        let s = x[i] - dot(column_head(r, i, i), &x[..i]);
        x[i] = s / r[(i, i)];
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for k in i + 1..n {
            s -= r[(i, k)] * x[k];
        }
        x[i] = s / r[(i, i)];
    }
    x
}

/// Diagonal of the inverse of a symmetric positive definite matrix (lower triangle read), from
/// one Cholesky factor.
pub(crate) fn spd_inverse_diag(h: &DMatrix<f64>) -> Option<Vec<f64>> {
    // diag(H^-1)_i = sum_j (L^-1)_{ji}^2: invert the lower factor column by column.
    let n = h.nrows();
    let r = cholesky_factor(h, 0.0)?;
    let mut out = vec![0.0; n];
    let mut col = vec![0.0; n];
    for i in 0..n {
        // Column i of L^-1 (zero above row i), by forward substitution; row `row` of L is
        // column `row` of r.
        col[..i].iter_mut().for_each(|v| *v = 0.0);
        col[i] = 1.0 / r[(i, i)];
        for row in i + 1..n {
            let s = dot(&column_head(&r, row, row)[i..], &col[i..row]);
            col[row] = -s / r[(row, row)];
        }
        out[i] = col[i..].iter().map(|v| v * v).sum();
    }
    if out.iter().all(|v| v.is_finite()) {
        Some(out)
    } else {
        None
    }
}

/// Median of a slice (`vibmode_core::stats::median`), 0 for an empty slice.
pub(crate) fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        0.0
    } else {
        vibmode_core::stats::median(v)
    }
}

/// Ratio of the median absolute deviation to the standard deviation of a Gaussian sample
/// (`Phi^-1(3/4)`, rounded as in the literature and in MATLAB's pem): MAD / 0.6745 estimates the
/// standard deviation robustly.
pub(crate) const MAD_PER_STD: f64 = 0.6745;

/// Robust standard deviation MAD / [`MAD_PER_STD`] (median absolute deviation from the median).
pub(crate) fn robust_std(v: &[f64]) -> f64 {
    let med = median(v);
    let dev: Vec<f64> = v.iter().map(|x| (x - med).abs()).collect();
    median(&dev) / MAD_PER_STD
}

/// Whether the monic polynomial `1 + c1 z^-1 + ...` has all roots strictly inside the unit circle
/// (Schur-Cohn step-down recursion, O(q^2)).
pub(crate) fn is_min_phase(c: &[f64]) -> bool {
    let mut a: Vec<f64> = c.to_vec();
    let mut m = a.len().saturating_sub(1);
    while m >= 1 {
        let k = a[m];
        if k.is_nan() || k.abs() >= 1.0 {
            return false;
        }
        let den = 1.0 - k * k;
        // The step-down a_i <- (a_i - k a_{m-i}) / den, in place: the pair (i, m - i) from its
        // old values (the middle entry of an even m pairs with itself).
        for i in 1..=m / 2 {
            let (x, y) = (a[i], a[m - i]);
            a[i] = (x - k * y) / den;
            if m - i != i {
                a[m - i] = (y - k * x) / den;
            }
        }
        a.truncate(m);
        m -= 1;
    }
    true
}

/// A seeded xorshift64 generator of uniform numbers in [0, 1) (53 bits), for the crate's tests:
/// the same seed, the same sequence.
#[cfg(test)]
pub(crate) fn xorshift_uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The chunked dot product rounds exactly as four running sums over the indices 4 i + k,
    /// added pairwise, plus the tail summed in order (the arithmetic the ARMA results rest on).
    #[test]
    fn dot_rounds_as_four_running_sums() {
        let mut uniform = crate::linalg::xorshift_uniform(0x9e37_79b9_7f4a_7c15_u64);
        let mut next = move || uniform() - 0.5;
        for n in 0..40 {
            let x: Vec<f64> = (0..n).map(|_| next() * 1e3).collect();
            let z: Vec<f64> = (0..n + 3).map(|_| next()).collect();
            let mut s = [0.0f64; 4];
            for j in 0..n / 4 * 4 {
                s[j % 4] += x[j] * z[j];
            }
            let mut tail = 0.0;
            for j in n / 4 * 4..n {
                tail += x[j] * z[j];
            }
            let want = (s[0] + s[1]) + (s[2] + s[3]) + tail;
            assert_eq!(dot(&x, &z).to_bits(), want.to_bits(), "n = {n}");
        }
    }

    /// The Gram block of a signal with itself (first column copied from the first row) equals,
    /// bit for bit, the block of the signal with a copy of itself (every entry summed).
    #[test]
    fn symmetric_lagged_gram_is_the_general_one_bit_for_bit() {
        let x: Vec<f64> = (0..301)
            .map(|t| ((t * 7919 % 1009) as f64).sin() * 1.7)
            .collect();
        let copy = x.clone();
        for &(l, t0) in &[(1usize, 0usize), (6, 0), (13, 13), (30, 45)] {
            let mut same = DMatrix::<f64>::zeros(l, l);
            let mut general = DMatrix::<f64>::zeros(l, l);
            lagged_gram(
                Lags::new(&x, l),
                Lags::new(&x, l),
                t0,
                same.view_mut((0, 0), (l, l)),
                -1.0,
            );
            lagged_gram(
                Lags::new(&x, l),
                Lags::new(&copy, l),
                t0,
                general.view_mut((0, 0), (l, l)),
                -1.0,
            );
            for (a, b) in same.iter().zip(general.iter()) {
                assert_eq!(a.to_bits(), b.to_bits(), "l {l} t0 {t0}");
            }
        }
    }

    #[test]
    fn lagged_gram_matches_direct_sum() {
        let x: Vec<f64> = (0..37).map(|t| ((t * 7 % 11) as f64 - 5.0) * 0.3).collect();
        let z: Vec<f64> = (0..37).map(|t| ((t * 5 % 13) as f64 - 6.0) * 0.2).collect();
        for &t0 in &[0usize, 3, 9] {
            let (lx, lz) = (5, 4);
            let mut out = DMatrix::<f64>::zeros(lx, lz);
            lagged_gram(
                Lags::new(&x, lx),
                Lags::new(&z, lz),
                t0,
                out.view_mut((0, 0), (lx, lz)),
                1.0,
            );
            for i in 1..=lx {
                for j in 1..=lz {
                    let mut s = 0.0;
                    for t in t0..37 {
                        if t >= i && t >= j {
                            s += x[t - i] * z[t - j];
                        }
                    }
                    assert!(
                        (out[(i - 1, j - 1)] - s).abs() < 1e-12,
                        "t0={t0} i={i} j={j}"
                    );
                }
            }
        }
    }

    /// Filters run side by side give each filter's output bit for bit: 1 to 3 signals of
    /// different lengths (and one longer than its output), C of degree 0 to 12, 200 seeded cases.
    #[test]
    fn filters_side_by_side_are_each_filter() {
        let mut u01 = xorshift_uniform(0x2545_f491_4f6c_dd1d_u64);
        let mut uniform = move || u01() - 0.5;
        for case in 0..200 {
            let q = case % 13;
            let mut c = vec![1.0];
            c.extend((0..q).map(|_| 0.3 * uniform()));
            let k = 1 + case % 3;
            let lens: Vec<usize> = (0..k).map(|i| (case * 7 + 13 * i) % 90).collect();
            let xs: Vec<Vec<f64>> = lens
                .iter()
                .map(|&n| (0..n + case % 2).map(|_| uniform()).collect())
                .collect();
            let mut outs: Vec<Vec<f64>> = lens.iter().map(|&n| vec![f64::NAN; n]).collect();
            let x_refs: Vec<&[f64]> = xs.iter().map(|x| &x[..]).collect();
            let mut out_refs: Vec<&mut [f64]> = outs.iter_mut().map(|o| &mut o[..]).collect();
            filter_inv_c_each(&x_refs, &c, &mut out_refs);
            for (x, got) in xs.iter().zip(&outs) {
                let mut want = vec![f64::NAN; got.len()];
                filter_inv_c(x, &c, &mut want);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(got), bits(&want), "case {case}");
            }
        }
    }

    #[test]
    fn cholesky_solves_small_system() {
        // [[4, 2], [2, 3]] x = [2, 1] -> x = [0.5, 0]
        let h = DMatrix::from_row_slice(2, 2, &[4.0, 2.0, 2.0, 3.0]);
        let x = cholesky_solve(&h, &[2.0, 1.0], 0.0).unwrap();
        assert!((x[0] - 0.5).abs() < 1e-14 && x[1].abs() < 1e-14);
        let h = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(cholesky_solve(&h, &[1.0, 1.0], 0.0).is_none());
    }

    #[test]
    fn min_phase_check() {
        assert!(is_min_phase(&[1.0, -0.5]));
        assert!(!is_min_phase(&[1.0, -2.0]));
        // (1 - 0.9 z^-1)(1 - 0.8 z^-1) = 1 - 1.7 z^-1 + 0.72 z^-2
        assert!(is_min_phase(&[1.0, -1.7, 0.72]));
        // (1 - 1.1 z^-1)(1 - 0.5 z^-1) = 1 - 1.6 z^-1 + 0.55 z^-2
        assert!(!is_min_phase(&[1.0, -1.6, 0.55]));
    }

    #[test]
    fn adjoint_filter_is_the_transpose() {
        // <x / C, v> == <x, adjoint(v)>
        let c = [1.0, -0.6, 0.2];
        let x: Vec<f64> = (0..20).map(|t| ((t * 3 % 7) as f64) - 3.0).collect();
        let v: Vec<f64> = (0..20).map(|t| ((t * 5 % 11) as f64) * 0.1 - 0.5).collect();
        let mut fx = vec![0.0; 20];
        let mut av = vec![0.0; 20];
        filter_inv_c(&x, &c, &mut fx);
        filter_inv_c_adjoint(&v, &c, &mut av);
        assert!((dot(&fx, &v) - dot(&x, &av)).abs() < 1e-12);
    }

    #[test]
    fn median_and_mad() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        // deviations from median 2.5: 1.5, 1.5, 0.5, 0.5 -> median 1.0
        assert!((robust_std(&[4.0, 1.0, 2.0, 3.0]) - 1.0 / 0.6745).abs() < 1e-12);
    }
}
