//! Internal numeric helpers: input checks, lagged Gram matrices in O(N k), filtering, Cholesky.

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

/// Dot product.
#[inline]
pub(crate) fn dot(x: &[f64], z: &[f64]) -> f64 {
    // Four accumulators: faster and slightly more accurate than a single running sum.
    let n = x.len().min(z.len());
    let (x, z) = (&x[..n], &z[..n]);
    let mut s = [0.0f64; 4];
    let chunks = n / 4;
    for i in 0..chunks {
        let j = 4 * i;
        s[0] += x[j] * z[j];
        s[1] += x[j + 1] * z[j + 1];
        s[2] += x[j + 2] * z[j + 2];
        s[3] += x[j + 3] * z[j + 3];
    }
    let mut tail = 0.0;
    for j in 4 * chunks..n {
        tail += x[j] * z[j];
    }
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

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

/// Exact Gram block `M[i-1][j-1] = sum_{t=t0}^{N-1} x[t-i] z[t-j]` for i = 1..=lx, j = 1..=lz
/// (zero for negative indices), written row-major into `out` (lx * lz) with stride `stride`
/// starting at `offset`, multiplied by `sign`.
///
/// Cost O(N (lx + lz)) for the first row and column plus O(lx lz) for the shift recursion
/// `M(i+1, j+1) = M(i, j) - x[N-1-i] z[N-1-j] + x[t0-1-i] z[t0-1-j]`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn lagged_gram(
    x: &[f64],
    lx: usize,
    z: &[f64],
    lz: usize,
    t0: usize,
    out: &mut [f64],
    stride: usize,
    row0: usize,
    col0: usize,
    sign: f64,
) {
    if lx == 0 || lz == 0 {
        return;
    }
    let n = x.len().min(z.len());
    let mut m = vec![0.0; lx * lz];
    for j in 1..=lz {
        m[j - 1] = lagged_dot(x, 1, z, j, t0);
    }
    for i in 2..=lx {
        m[(i - 1) * lz] = lagged_dot(x, i, z, 1, t0);
    }
    let xv = |k: isize| -> f64 {
        if k >= 0 && (k as usize) < n {
            x[k as usize]
        } else {
            0.0
        }
    };
    let zv = |k: isize| -> f64 {
        if k >= 0 && (k as usize) < n {
            z[k as usize]
        } else {
            0.0
        }
    };
    let (ni, t0i) = (n as isize, t0 as isize);
    for i in 1..lx {
        for j in 1..lz {
            // m(i+1, j+1) from m(i, j), with 1-based lags i, j.
            let (ii, jj) = (i as isize, j as isize);
            let prev = m[(i - 1) * lz + (j - 1)];
            let v = prev - xv(ni - 1 - ii) * zv(ni - 1 - jj) + xv(t0i - 1 - ii) * zv(t0i - 1 - jj);
            m[i * lz + j] = v;
        }
    }
    for i in 0..lx {
        for j in 0..lz {
            out[(row0 + i) * stride + col0 + j] = sign * m[i * lz + j];
        }
    }
}

/// `out[t] = x[t] / C(q)`: `out[t] = x[t] - sum_{k=1}^{q} c[k] out[t-k]`, zero initial conditions.
pub(crate) fn filter_inv_c(x: &[f64], c: &[f64], out: &mut [f64]) {
    let q = c.len().saturating_sub(1);
    for t in 0..x.len() {
        let mut v = x[t];
        let kmax = q.min(t);
        for k in 1..=kmax {
            v -= c[k] * out[t - k];
        }
        out[t] = v;
    }
}

/// Conditional prediction errors: `eps_t = 0` for `t < p`, and for `t >= p`
/// `eps_t = y_t + sum_{k=1}^{p} a_k y_{t-k} - sum_{k=1}^{q} c_k eps_{t-k}`, i.e. `eps = w / C` with
/// zero initial conditions where `w_t = A(q) y_t` uses measured samples only.
pub(crate) fn predict_errors(y: &[f64], a: &[f64], c: &[f64], eps: &mut [f64]) {
    let p = a.len().saturating_sub(1);
    let q = c.len().saturating_sub(1);
    for e in eps.iter_mut().take(p.min(y.len())) {
        *e = 0.0;
    }
    for t in p..y.len() {
        let mut v = y[t];
        for k in 1..=p {
            v += a[k] * y[t - k];
        }
        for k in 1..=q.min(t) {
            v -= c[k] * eps[t - k];
        }
        eps[t] = v;
    }
}

/// Adjoint of `x -> x / C`: `u_t = v_t - sum_{k=1}^{q} c_k u_{t+k}` (run backwards).
pub(crate) fn filter_inv_c_adjoint(v: &[f64], c: &[f64], out: &mut [f64]) {
    let q = c.len().saturating_sub(1);
    let n = v.len();
    for t in (0..n).rev() {
        let mut s = v[t];
        for k in 1..=q {
            if t + k < n {
                s -= c[k] * out[t + k];
            }
        }
        out[t] = s;
    }
}

/// Solves the symmetric positive (semi)definite system `h x = b` (n x n row-major) by Cholesky,
/// adding a relative ridge `ridge * mean(diag)` to the diagonal. Returns None if not positive definite.
pub(crate) fn cholesky_solve(h: &[f64], b: &[f64], n: usize, ridge: f64) -> Option<Vec<f64>> {
    let l = cholesky_factor(h, n, ridge)?;
    let x = cholesky_apply(&l, b, n);
    if x.iter().all(|v| v.is_finite()) {
        Some(x)
    } else {
        None
    }
}

/// Lower Cholesky factor (row-major, n x n) of `h + ridge * mean(diag h) * I`; None if `h` is not
/// numerically positive definite.
pub(crate) fn cholesky_factor(h: &[f64], n: usize, ridge: f64) -> Option<Vec<f64>> {
    if n == 0 {
        return Some(Vec::new());
    }
    let mean_diag = (0..n).map(|i| h[i * n + i]).sum::<f64>() / n as f64;
    if !(mean_diag.is_finite() && mean_diag > 0.0) {
        return None;
    }
    let mut l = h.to_vec();
    for i in 0..n {
        l[i * n + i] += ridge * mean_diag;
    }
    for j in 0..n {
        let (head, tail) = l.split_at_mut((j + 1) * n);
        let row_j = &mut head[j * n..(j + 1) * n];
        let d = row_j[j] - dot(&row_j[..j], &row_j[..j]);
        if !(d > 0.0 && d.is_finite()) {
            return None;
        }
        let d = d.sqrt();
        row_j[j] = d;
        let row_j = &head[j * n..j * n + j];
        for i in j + 1..n {
            let row_i = &mut tail[(i - j - 1) * n..(i - j) * n];
            let s = row_i[j] - dot(&row_i[..j], row_j);
            row_i[j] = s / d;
        }
    }
    Some(l)
}

/// Solves `L L^T x = b` with the factor of [`cholesky_factor`].
pub(crate) fn cholesky_apply(l: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut x = b.to_vec();
    for i in 0..n {
        let s = x[i] - dot(&l[i * n..i * n + i], &x[..i]);
        x[i] = s / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for k in i + 1..n {
            s -= l[k * n + i] * x[k];
        }
        x[i] = s / l[i * n + i];
    }
    x
}

/// Diagonal of the inverse of a symmetric positive definite matrix, from one Cholesky factor.
pub(crate) fn spd_inverse_diag(h: &[f64], n: usize) -> Option<Vec<f64>> {
    // diag(H^-1)_i = sum_j (L^-1)_{ji}^2: invert the lower factor column by column.
    let l = cholesky_factor(h, n, 0.0)?;
    let mut out = vec![0.0; n];
    let mut col = vec![0.0; n];
    for i in 0..n {
        // Column i of L^-1 (zero above row i), by forward substitution.
        col[..i].iter_mut().for_each(|v| *v = 0.0);
        col[i] = 1.0 / l[i * n + i];
        for r in i + 1..n {
            let s = dot(&l[r * n + i..r * n + r], &col[i..r]);
            col[r] = -s / l[r * n + r];
        }
        out[i] = col[i..].iter().map(|v| v * v).sum();
    }
    if out.iter().all(|v| v.is_finite()) {
        Some(out)
    } else {
        None
    }
}

/// Median of a slice (copied; NaN-free input assumed).
pub(crate) fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut w = v.to_vec();
    let mid = w.len() / 2;
    let (_, m, _) = w.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    let m = *m;
    if w.len() % 2 == 1 {
        m
    } else {
        let lower = w[..mid].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        0.5 * (lower + m)
    }
}

/// Robust standard deviation MAD / 0.6745 (median absolute deviation from the median).
pub(crate) fn robust_std(v: &[f64]) -> f64 {
    let med = median(v);
    let dev: Vec<f64> = v.iter().map(|x| (x - med).abs()).collect();
    median(&dev) / 0.6745
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
        let prev = a.clone();
        for i in 1..m {
            a[i] = (prev[i] - k * prev[m - i]) / den;
        }
        a.truncate(m);
        m -= 1;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lagged_gram_matches_direct_sum() {
        let x: Vec<f64> = (0..37).map(|t| ((t * 7 % 11) as f64 - 5.0) * 0.3).collect();
        let z: Vec<f64> = (0..37).map(|t| ((t * 5 % 13) as f64 - 6.0) * 0.2).collect();
        for &t0 in &[0usize, 3, 9] {
            let (lx, lz) = (5, 4);
            let mut out = vec![0.0; lx * lz];
            lagged_gram(&x, lx, &z, lz, t0, &mut out, lz, 0, 0, 1.0);
            for i in 1..=lx {
                for j in 1..=lz {
                    let mut s = 0.0;
                    for t in t0..37 {
                        if t >= i && t >= j {
                            s += x[t - i] * z[t - j];
                        }
                    }
                    assert!(
                        (out[(i - 1) * lz + j - 1] - s).abs() < 1e-12,
                        "t0={t0} i={i} j={j}"
                    );
                }
            }
        }
    }

    #[test]
    fn cholesky_solves_small_system() {
        // [[4, 2], [2, 3]] x = [2, 1] -> x = [0.5, 0]
        let x = cholesky_solve(&[4.0, 2.0, 2.0, 3.0], &[2.0, 1.0], 2, 0.0).unwrap();
        assert!((x[0] - 0.5).abs() < 1e-14 && x[1].abs() < 1e-14);
        assert!(cholesky_solve(&[1.0, 2.0, 2.0, 1.0], &[1.0, 1.0], 2, 0.0).is_none());
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
