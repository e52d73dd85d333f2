//! The eigenvalues of a real square matrix `A` and, for the eigenvalues a caller keeps, the
//! matching columns `C psi` of an output matrix `C` times the right eigenvector `psi`, without
//! forming the Schur vectors.
//!
//! `A = Z T Z^T` with `T` real quasi-triangular (its real Schur form): a Householder reduction to
//! Hessenberg form, then Francis double-shift QR sweeps (EISPACK's `hqr2` as in JAMA, without the
//! balancing), every transformation applied to `T` in full and to `G = C Z` (`l x n`, `l` the
//! rows of `C`) instead of to the `n x n` matrix `Z`. An eigenvector `y` of `T` (back
//! substitution through the blocks above its own) gives `C psi = G y`, since `psi = Z y`. Only
//! the complex eigenvalues with a positive imaginary part are offered to the caller (one of
//! each conjugate pair); real eigenvalues (1x1 blocks of `T`; a 2x2 block with real
//! eigenvalues is split into two 1x1 blocks) are skipped, and an eigenvector is computed only
//! for an eigenvalue the caller keeps.

use nalgebra::DMatrixView;
use num_complex::Complex64;

use crate::error::SsiError;

/// A kept eigenvalue (`Im > 0`) and `C psi` for its right eigenvector `psi` (any scale).
pub(crate) struct ShapedEigenvalue {
    pub lambda: Complex64,
    pub shape: Vec<Complex64>,
}

/// Iteration cap of the Schur decomposition: LAPACK allows 30 QR sweeps per eigenvalue.
fn schur_iterations(n: usize) -> usize {
    30 * n.max(1) + 100
}

/// The eigenvalues of `a` with `Im > 0` that `keep` accepts, each with `C psi` for its right
/// eigenvector `psi` (`c` has `a`'s column count), in the order of the Schur form.
/// Errors: a non-finite entry, or no convergence within [`schur_iterations`] sweeps.
pub(crate) fn kept_eigenvalues<'a>(
    a: impl Into<DMatrixView<'a, f64>>,
    c: impl Into<DMatrixView<'a, f64>>,
    keep: impl Fn(Complex64) -> bool,
) -> Result<Vec<ShapedEigenvalue>, SsiError> {
    let (a, c) = (a.into(), c.into());
    let n = a.nrows();
    let l = c.nrows();
    debug_assert_eq!(c.ncols(), n, "C needs one column per state");
    let iterations = schur_iterations(n);
    let not_converged = SsiError::NotConverged {
        what: "Schur form of the state matrix A",
        size: n,
        iterations,
    };
    if n == 0 {
        return Ok(Vec::new());
    }
    if a.iter().any(|v| !v.is_finite()) {
        return Err(not_converged);
    }
    // Column-major copies: t[i + j n] = T[i, j], g[i + j l] = G[i, j].
    let mut t: Vec<f64> = a.iter().copied().collect();
    let mut g: Vec<f64> = c.iter().copied().collect();
    hessenberg(&mut t, n, &mut g, l);
    if !francis(&mut t, n, &mut g, l, iterations) {
        return Err(not_converged);
    }
    Ok(shaped_eigenvalues(&t, n, &g, l, keep))
}

/// Reduces `t` (`n x n`, column-major) to upper Hessenberg form `Q^T t Q` by Householder
/// reflections, the entries below the subdiagonal set to exact zeros, and `g` (`l x n`) to
/// `g Q`.
fn hessenberg(t: &mut [f64], n: usize, g: &mut [f64], l: usize) {
    let mut v = vec![0.0; n];
    let mut w = vec![0.0; n.max(l)];
    for k in 0..n.saturating_sub(2) {
        // x = t[k+1.., k]; reflection P = I - tau v v^T with P x = beta e_1.
        let m = n - k - 1;
        let x = &t[k * n + k + 1..(k + 1) * n];
        let scale = x.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        if scale == 0.0 || x[1..].iter().all(|&v| v == 0.0) {
            continue;
        }
        let v = &mut v[..m];
        for (vi, xi) in v.iter_mut().zip(x) {
            *vi = xi / scale;
        }
        let norm = v.iter().map(|u| u * u).sum::<f64>().sqrt();
        let alpha = v[0];
        let beta = if alpha >= 0.0 { -norm } else { norm };
        v[0] = alpha - beta;
        let tau = 1.0 / (norm * (norm + alpha.abs()));
        // Column k: beta e_1 (scaled back).
        t[k * n + k + 1] = beta * scale;
        for e in &mut t[k * n + k + 2..(k + 1) * n] {
            *e = 0.0;
        }
        // From the left, columns k+1..n, rows k+1..n.
        for j in k + 1..n {
            let col = &mut t[j * n + k + 1..(j + 1) * n];
            let d = tau * vibmode_core::stats::dot(col, v);
            for (e, vi) in col.iter_mut().zip(v.iter()) {
                *e -= d * vi;
            }
        }
        // From the right, columns k+1..n, all rows; and g.
        apply_right(t, n, k + 1, v, tau, &mut w[..n]);
        apply_right(g, l, k + 1, v, tau, &mut w[..l]);
    }
}

/// `x[.., c0..c0 + v.len()] -= tau (x[.., c0..] v) v^T` for a column-major `x` with `rows` rows.
fn apply_right(x: &mut [f64], rows: usize, c0: usize, v: &[f64], tau: f64, w: &mut [f64]) {
    if rows == 0 {
        return;
    }
    w.fill(0.0);
    for (j, &vj) in v.iter().enumerate() {
        let col = &x[(c0 + j) * rows..(c0 + j + 1) * rows];
        for (wi, e) in w.iter_mut().zip(col) {
            *wi += vj * e;
        }
    }
    for (j, &vj) in v.iter().enumerate() {
        let f = tau * vj;
        let col = &mut x[(c0 + j) * rows..(c0 + j + 1) * rows];
        for (e, wi) in col.iter_mut().zip(w.iter()) {
            *e -= f * wi;
        }
    }
}

/// Francis double-shift QR on the Hessenberg `t` (`n x n`, column-major) to real Schur form,
/// the transformations also applied to the columns of `g` (`l x n`). On return the
/// subdiagonal of `t` is nonzero exactly at the 2x2 blocks of complex conjugate eigenvalues;
/// the entries below the subdiagonal are left as the sweeps left them (never read after).
/// `false` when `max_sweeps` sweeps did not converge.
fn francis(t: &mut [f64], nn: usize, g: &mut [f64], l: usize, max_sweeps: usize) -> bool {
    macro_rules! h {
        ($i:expr, $j:expr) => {
            t[$i + ($j) * nn]
        };
    }
    let eps = f64::EPSILON;
    let mut exshift = 0.0;
    let mut norm = 0.0;
    for j in 0..nn {
        for i in 0..(j + 2).min(nn) {
            norm += h!(i, j).abs();
        }
    }
    let mut n = nn as isize - 1;
    let mut iter = 0;
    let mut sweeps = 0;
    let (mut p, mut q, mut r, mut s, mut z);
    let (mut x, mut y, mut w);
    while n >= 0 {
        let nu = n as usize;
        // Look for a single small subdiagonal entry.
        let mut lo = nu;
        while lo > 0 {
            s = h!(lo - 1, lo - 1).abs() + h!(lo, lo).abs();
            if s == 0.0 {
                s = norm;
            }
            // `<=` (as LAPACK): an exact zero deflates even where the diagonal is zero too.
            if h!(lo, lo - 1).abs() <= eps * s {
                h!(lo, lo - 1) = 0.0;
                break;
            }
            lo -= 1;
        }
        if lo == nu {
            // One root.
            h!(nu, nu) += exshift;
            n -= 1;
            iter = 0;
        } else if lo == nu - 1 {
            // Two roots.
            w = h!(nu, nu - 1) * h!(nu - 1, nu);
            p = (h!(nu - 1, nu - 1) - h!(nu, nu)) / 2.0;
            q = p * p + w;
            z = q.abs().sqrt();
            h!(nu, nu) += exshift;
            h!(nu - 1, nu - 1) += exshift;
            if q >= 0.0 {
                // Real pair: split the block by a rotation.
                z = if p >= 0.0 { p + z } else { p - z };
                x = h!(nu, nu - 1);
                s = x.abs() + z.abs();
                p = x / s;
                q = z / s;
                r = (p * p + q * q).sqrt();
                p /= r;
                q /= r;
                for j in nu - 1..nn {
                    z = h!(nu - 1, j);
                    h!(nu - 1, j) = q * z + p * h!(nu, j);
                    h!(nu, j) = q * h!(nu, j) - p * z;
                }
                for i in 0..=nu {
                    z = h!(i, nu - 1);
                    h!(i, nu - 1) = q * z + p * h!(i, nu);
                    h!(i, nu) = q * h!(i, nu) - p * z;
                }
                let (a, b) = g.split_at_mut(nu * l);
                for (ga, gb) in a[(nu - 1) * l..].iter_mut().zip(b[..l].iter_mut()) {
                    z = *ga;
                    *ga = q * z + p * *gb;
                    *gb = q * *gb - p * z;
                }
                h!(nu, nu - 1) = 0.0;
            }
            n -= 2;
            iter = 0;
        } else {
            // No convergence yet: form the shift.
            sweeps += 1;
            if sweeps > max_sweeps {
                return false;
            }
            x = h!(nu, nu);
            y = h!(nu - 1, nu - 1);
            w = h!(nu, nu - 1) * h!(nu - 1, nu);
            if iter == 10 {
                // Wilkinson's ad hoc shift.
                exshift += x;
                for i in 0..=nu {
                    h!(i, i) -= x;
                }
                s = h!(nu, nu - 1).abs() + h!(nu - 1, nu - 2).abs();
                x = 0.75 * s;
                y = x;
                w = -0.4375 * s * s;
            }
            if iter == 30 {
                // MATLAB's ad hoc shift.
                s = (y - x) / 2.0;
                s = s * s + w;
                if s > 0.0 {
                    s = s.sqrt();
                    if y < x {
                        s = -s;
                    }
                    s = x - w / ((y - x) / 2.0 + s);
                    for i in 0..=nu {
                        h!(i, i) -= s;
                    }
                    exshift += s;
                    x = 0.964;
                    y = x;
                    w = x;
                }
            }
            iter += 1;
            // Look for two consecutive small subdiagonal entries.
            let mut m = nu - 2;
            loop {
                z = h!(m, m);
                r = x - z;
                s = y - z;
                p = (r * s - w) / h!(m + 1, m) + h!(m, m + 1);
                q = h!(m + 1, m + 1) - z - r - s;
                r = h!(m + 2, m + 1);
                s = p.abs() + q.abs() + r.abs();
                p /= s;
                q /= s;
                r /= s;
                if m == lo {
                    break;
                }
                if h!(m, m - 1).abs() * (q.abs() + r.abs())
                    < eps * (p.abs() * (h!(m - 1, m - 1).abs() + z.abs() + h!(m + 1, m + 1).abs()))
                {
                    break;
                }
                m -= 1;
            }
            for i in m + 2..=nu {
                h!(i, i - 2) = 0.0;
                if i > m + 2 {
                    h!(i, i - 3) = 0.0;
                }
            }
            // Double QR step on rows lo..=n and columns m..=n.
            for k in m..nu {
                let notlast = k != nu - 1;
                if k != m {
                    p = h!(k, k - 1);
                    q = h!(k + 1, k - 1);
                    r = if notlast { h!(k + 2, k - 1) } else { 0.0 };
                    x = p.abs() + q.abs() + r.abs();
                    if x == 0.0 {
                        continue;
                    }
                    p /= x;
                    q /= x;
                    r /= x;
                }
                s = (p * p + q * q + r * r).sqrt();
                if p < 0.0 {
                    s = -s;
                }
                if s == 0.0 {
                    continue;
                }
                if k != m {
                    h!(k, k - 1) = -s * x;
                } else if lo != m {
                    h!(k, k - 1) = -h!(k, k - 1);
                }
                p += s;
                x = p / s;
                y = q / s;
                z = r / s;
                q /= p;
                r /= p;
                // Rows k, k+1 (, k+2), columns k..nn.
                // (Chunk j - k of t[k + k nn..] starts at row k of column j.)
                if notlast {
                    for c in t[k + k * nn..].chunks_mut(nn) {
                        let pp = c[0] + q * c[1] + r * c[2];
                        c[0] -= pp * x;
                        c[1] -= pp * y;
                        c[2] -= pp * z;
                    }
                } else {
                    for c in t[k + k * nn..].chunks_mut(nn) {
                        let pp = c[0] + q * c[1];
                        c[0] -= pp * x;
                        c[1] -= pp * y;
                    }
                }
                // Columns k, k+1 (, k+2), rows 0..=min(n, k+3); and g.
                let rows = nu.min(k + 3) + 1;
                three_columns(t, nn, rows, k, notlast, x, y, z, q, r);
                three_columns(g, l, l, k, notlast, x, y, z, q, r);
            }
        }
    }
    true
}

/// The reflection of one double QR step applied to columns `k, k+1` (and `k+2` when
/// `notlast`) of the column-major `a` (`ld` rows), rows `0..rows`.
#[allow(clippy::too_many_arguments)]
fn three_columns(
    a: &mut [f64],
    ld: usize,
    rows: usize,
    k: usize,
    notlast: bool,
    x: f64,
    y: f64,
    z: f64,
    q: f64,
    r: f64,
) {
    if rows == 0 {
        return;
    }
    let (c0, rest) = a[k * ld..].split_at_mut(ld);
    let (c1, rest) = rest.split_at_mut(ld);
    if notlast {
        let c2 = &mut rest[..ld];
        for ((a0, a1), a2) in c0[..rows]
            .iter_mut()
            .zip(c1[..rows].iter_mut())
            .zip(c2[..rows].iter_mut())
        {
            let p = x * *a0 + y * *a1 + z * *a2;
            *a0 -= p;
            *a1 -= p * q;
            *a2 -= p * r;
        }
    } else {
        for (a0, a1) in c0[..rows].iter_mut().zip(c1[..rows].iter_mut()) {
            let p = x * *a0 + y * *a1;
            *a0 -= p;
            *a1 -= p * q;
        }
    }
}

/// Blocks `(start, size)` of a quasi-triangular matrix (column-major `t`, `n x n`): a nonzero
/// subdiagonal entry opens a 2x2.
fn blocks(t: &[f64], n: usize) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut j = 0;
    while j < n {
        if j + 1 < n && t[j + 1 + j * n] != 0.0 {
            out.push((j, 2));
            j += 2;
        } else {
            out.push((j, 1));
            j += 1;
        }
    }
    out
}

/// `|Re z| + |Im z|`: LAPACK's `cabs1`, the modulus within a factor sqrt(2) without `hypot`.
fn cabs1(z: Complex64) -> f64 {
    z.re.abs() + z.im.abs()
}

/// `m x = r` for a complex 2x2 `m` by Gaussian elimination with complete pivoting, a pivot
/// below `small` in [`cabs1`] replaced by `small` (as LAPACK's `dlaln2`): the solution of a
/// nearby system even when `m` is (nearly) singular, as it is at a (nearly) repeated
/// eigenvalue. (Cramer's rule loses the direction there: its determinant cancels.)
fn solve_2x2(m: [[Complex64; 2]; 2], r: [Complex64; 2], small: f64) -> [Complex64; 2] {
    let (mut pi, mut pj) = (0, 0);
    for (i, row) in m.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            if cabs1(*v) > cabs1(m[pi][pj]) {
                (pi, pj) = (i, j);
            }
        }
    }
    let (oi, oj) = (1 - pi, 1 - pj);
    let floor = |z: Complex64| {
        if cabs1(z) < small {
            Complex64::new(small, 0.0)
        } else {
            z
        }
    };
    let p = floor(m[pi][pj]);
    let f = m[oi][pj] / p;
    let u = floor(m[oi][oj] - f * m[pi][oj]);
    let mut x = [Complex64::new(0.0, 0.0); 2];
    x[oj] = (r[oi] - f * r[pi]) / u;
    x[pj] = (r[pi] - m[pi][oj] * x[oj]) / p;
    x
}

/// For each 2x2 block of the quasi-triangular `t` (`n x n`, column-major) with complex
/// eigenvalues: its eigenvalue with `Im > 0` and, when `keep` accepts it, `g y` (`g` is
/// `l x n`) for the eigenvector `y` of `t` by back substitution.
fn shaped_eigenvalues(
    t: &[f64],
    n: usize,
    g: &[f64],
    l: usize,
    keep: impl Fn(Complex64) -> bool,
) -> Vec<ShapedEigenvalue> {
    let tt = |i: usize, j: usize| t[i + j * n];
    let norm = t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // Smallest pivot accepted in the back substitution (LAPACK's trevc uses eps * norm too):
    // a (near-)repeated eigenvalue gives a (near-)singular diagonal block.
    let small = if norm > 0.0 {
        norm * f64::EPSILON
    } else {
        f64::MIN_POSITIVE
    };
    let zero = Complex64::new(0.0, 0.0);
    let blocks = blocks(t, n);
    let mut out = Vec::new();
    let mut x = vec![zero; n];
    let mut rhs = vec![zero; n];
    for (bi, &(k, size)) in blocks.iter().enumerate() {
        if size != 2 {
            continue;
        }
        let (a, b, c, d) = (tt(k, k), tt(k, k + 1), tt(k + 1, k), tt(k + 1, k + 1));
        let half = 0.5 * (a - d);
        let disc = half * half + b * c;
        if disc >= 0.0 {
            continue; // a 2x2 block with two real eigenvalues (not left by `francis`)
        }
        let lambda = Complex64::new(0.5 * (a + d), (-disc).sqrt());
        if !keep(lambda) {
            continue;
        }
        // Null vector of the 2x2 block minus lambda, from its larger row.
        let am = Complex64::new(a, 0.0) - lambda;
        let dm = Complex64::new(d, 0.0) - lambda;
        let x = &mut x[..k + 2];
        if am.norm() + b.abs() >= c.abs() + dm.norm() {
            x[k] = Complex64::new(b, 0.0);
            x[k + 1] = -am;
        } else {
            x[k] = -dm;
            x[k + 1] = Complex64::new(c, 0.0);
        }
        // The largest |re| + |im| of the entries solved so far.
        let mut big = cabs1(x[k]).max(cabs1(x[k + 1]));
        // rhs = -T[..k, k..k+2] x[k..k+2]; then up through the blocks above, column by column.
        let rhs = &mut rhs[..k];
        for (i, e) in rhs.iter_mut().enumerate() {
            *e = -(x[k] * tt(i, k) + x[k + 1] * tt(i, k + 1));
        }
        for &(j, sj) in blocks[..bi].iter().rev() {
            if sj == 1 {
                let mut den = Complex64::new(tt(j, j), 0.0) - lambda;
                if cabs1(den) < small {
                    den = Complex64::new(small, 0.0);
                }
                x[j] = rhs[j] / den;
            } else {
                let m = [
                    [
                        Complex64::new(tt(j, j), 0.0) - lambda,
                        Complex64::new(tt(j, j + 1), 0.0),
                    ],
                    [
                        Complex64::new(tt(j + 1, j), 0.0),
                        Complex64::new(tt(j + 1, j + 1), 0.0) - lambda,
                    ],
                ];
                let [x0, x1] = solve_2x2(m, [rhs[j], rhs[j + 1]], small);
                x[j] = x0;
                x[j + 1] = x1;
            }
            for m in j..j + sj {
                let xm = x[m];
                let col = &t[m * n..m * n + j];
                for (e, &tv) in rhs[..j].iter_mut().zip(col) {
                    *e -= xm * tv;
                }
            }
            // Keep the partial vector representable.
            big = x[j..j + sj].iter().fold(big, |m, &v| m.max(cabs1(v)));
            if big > 1e100 {
                for v in x[j..].iter_mut().chain(rhs[..j].iter_mut()) {
                    *v /= big;
                }
                big = 1.0;
            }
        }
        // C psi = G y.
        let mut shape = vec![zero; l];
        for (m, &xm) in x.iter().enumerate() {
            for (s, &gv) in shape.iter_mut().zip(&g[m * l..(m + 1) * l]) {
                *s += xm * gv;
            }
        }
        out.push(ShapedEigenvalue { lambda, shape });
    }
    out
}

/// The previous path, kept as the tests' reference: nalgebra's real Schur form with its Schur
/// vectors, eigenvectors of every complex pair by back substitution, `psi = Q z`.
#[cfg(test)]
mod reference {
    use nalgebra::{DMatrix, Schur};
    use num_complex::Complex64;

    use crate::error::SsiError;

    /// An eigenvalue with `Im > 0` and its right eigenvector (unit Euclidean norm).
    pub(super) struct EigenPair {
        pub lambda: Complex64,
        pub vector: Vec<Complex64>,
    }

    /// Iteration cap of the Schur decomposition: LAPACK allows 30 QR sweeps per eigenvalue.
    fn schur_iterations_ref(n: usize) -> usize {
        30 * n.max(1) + 100
    }

    /// The complex eigenpairs (`Im(lambda) > 0`) of `a`, in the order of the Schur form.
    pub(super) fn complex_eigenpairs(a: DMatrix<f64>) -> Result<Vec<EigenPair>, SsiError> {
        let n = a.nrows();
        if n == 0 {
            return Ok(Vec::new());
        }
        let iterations = schur_iterations_ref(n);
        let schur = Schur::try_new(a, f64::EPSILON, iterations).ok_or(SsiError::NotConverged {
            what: "Schur form of the state matrix A",
            size: n,
            iterations,
        })?;
        let (q, t) = schur.unpack();
        Ok(quasi_triangular_eigenpairs(&q, &t))
    }

    fn quasi_triangular_eigenpairs(q: &DMatrix<f64>, t: &DMatrix<f64>) -> Vec<EigenPair> {
        let n = t.nrows();
        let norm = t.amax();
        // Smallest pivot accepted in the back substitution (LAPACK's trevc uses eps * norm too):
        // a (near-)repeated eigenvalue gives a (near-)singular diagonal block.
        let small = if norm > 0.0 {
            norm * f64::EPSILON
        } else {
            f64::MIN_POSITIVE
        };
        // nalgebra's matrices are column-major, as the path's own.
        let blocks = super::blocks(t.as_slice(), t.nrows());
        let mut out = Vec::new();
        for (bi, &(k, size)) in blocks.iter().enumerate() {
            if size != 2 {
                continue;
            }
            let (a, b, c, d) = (t[(k, k)], t[(k, k + 1)], t[(k + 1, k)], t[(k + 1, k + 1)]);
            let half = 0.5 * (a - d);
            let disc = half * half + b * c;
            if disc >= 0.0 {
                continue; // a 2x2 block with two real eigenvalues
            }
            let lambda = Complex64::new(0.5 * (a + d), (-disc).sqrt());
            let mut z = vec![Complex64::new(0.0, 0.0); k + 2];
            // Null vector of the 2x2 block minus lambda, from its larger row.
            let am = Complex64::new(a, 0.0) - lambda;
            let dm = Complex64::new(d, 0.0) - lambda;
            if am.norm() + b.abs() >= c.abs() + dm.norm() {
                z[k] = Complex64::new(b, 0.0);
                z[k + 1] = -am;
            } else {
                z[k] = -dm;
                z[k + 1] = Complex64::new(c, 0.0);
            }
            // Back substitution through the blocks above.
            for &(j, sj) in blocks[..bi].iter().rev() {
                let rhs = |row: usize| -> Complex64 {
                    let mut s = Complex64::new(0.0, 0.0);
                    for (m, zm) in z.iter().enumerate().skip(j + sj) {
                        s += *zm * t[(row, m)];
                    }
                    -s
                };
                if sj == 1 {
                    let mut den = Complex64::new(t[(j, j)], 0.0) - lambda;
                    if den.norm() < small {
                        den = Complex64::new(small, 0.0);
                    }
                    z[j] = rhs(j) / den;
                } else {
                    let (r0, r1) = (rhs(j), rhs(j + 1));
                    let m00 = Complex64::new(t[(j, j)], 0.0) - lambda;
                    let m01 = Complex64::new(t[(j, j + 1)], 0.0);
                    let m10 = Complex64::new(t[(j + 1, j)], 0.0);
                    let m11 = Complex64::new(t[(j + 1, j + 1)], 0.0) - lambda;
                    let mut det = m00 * m11 - m01 * m10;
                    if det.norm() < small * small.max(norm) {
                        det = Complex64::new(small * small.max(norm), 0.0);
                    }
                    z[j] = (r0 * m11 - m01 * r1) / det;
                    z[j + 1] = (m00 * r1 - m10 * r0) / det;
                }
                // Keep the partial vector representable.
                let big = z.iter().fold(0.0f64, |m, v| m.max(v.norm()));
                if big > 1e100 {
                    for v in z.iter_mut() {
                        *v /= big;
                    }
                }
            }
            // Back to the original coordinates: v = Q z.
            let mut v = vec![Complex64::new(0.0, 0.0); n];
            for (r, vr) in v.iter_mut().enumerate() {
                let mut s = Complex64::new(0.0, 0.0);
                for (m, zm) in z.iter().enumerate() {
                    s += *zm * q[(r, m)];
                }
                *vr = s;
            }
            let nv = v.iter().map(|x| x.norm_sqr()).sum::<f64>().sqrt();
            if nv > 0.0 && nv.is_finite() {
                for x in v.iter_mut() {
                    *x /= nv;
                }
            }
            out.push(EigenPair { lambda, vector: v });
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    fn all(_: Complex64) -> bool {
        true
    }

    /// A x = lambda x for a random-looking nonsymmetric matrix with several complex pairs, with
    /// `C = I` so that the shape is the eigenvector itself.
    #[test]
    fn eigenpairs_satisfy_the_definition() {
        let n = 9;
        let a = DMatrix::from_fn(n, n, |r, c| {
            let x = ((r * 7 + c * 13 + 3) % 17) as f64 / 17.0 - 0.5;
            x + if c == (r + 1) % n { 1.0 } else { 0.0 }
        });
        let pairs = kept_eigenvalues(&a, &DMatrix::identity(n, n), all).unwrap();
        assert!(pairs.len() >= 2, "{}", pairs.len());
        for p in &pairs {
            assert!(p.lambda.im > 0.0);
            let scale = p.shape.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
            let mut worst = 0.0f64;
            for r in 0..n {
                let mut s = Complex64::new(0.0, 0.0);
                for c in 0..n {
                    s += p.shape[c] * a[(r, c)];
                }
                worst = worst.max((s - p.lambda * p.shape[r]).norm() / scale);
            }
            assert!(worst < 1e-12, "residual {worst}");
        }
        // Conjugate pairs: the eigenvalues with Im > 0 are as many as the Schur 2x2 blocks.
        let all = a.complex_eigenvalues();
        let upper = all.iter().filter(|l| l.im > 0.0).count();
        assert_eq!(upper, pairs.len());
    }

    #[test]
    fn non_finite_matrix_does_not_converge() {
        let mut a = DMatrix::from_element(4, 4, 1.0);
        a[(1, 2)] = f64::NAN;
        match kept_eigenvalues(&a, &DMatrix::identity(4, 4), all) {
            Err(e @ SsiError::NotConverged { .. }) => {
                let m = e.to_string();
                assert!(m.contains("4x4") && m.contains("Schur"), "{m}");
            }
            Err(e) => panic!("unexpected error {e}"),
            Ok(p) => panic!("NaN matrix gave {} eigenpairs", p.len()),
        }
    }

    /// Matrices with exact zeros where the sweeps test for them: the zero matrix and a strictly
    /// upper triangular one (every eigenvalue 0: nothing returned), and a matrix already in
    /// real Schur form (rotation blocks on the diagonal, zeros between them, a zero block among
    /// them): its pairs, exactly as its blocks give them, each shape `C` times the block's
    /// eigenvector.
    #[test]
    fn exact_zeros_deflate() {
        for n in [1, 2, 5] {
            let c = DMatrix::identity(n, n);
            assert!(kept_eigenvalues(&DMatrix::zeros(n, n), &c, all)
                .unwrap()
                .is_empty());
            let upper =
                DMatrix::from_fn(n, n, |r, k| if k > r { 1.0 + (r + k) as f64 } else { 0.0 });
            assert!(kept_eigenvalues(&upper, &c, all).unwrap().is_empty());
        }
        let mut t = DMatrix::zeros(6, 6);
        for (k, (re, im)) in [(0, (0.5, 0.25)), (4, (-0.25, 0.75))] {
            t[(k, k)] = re;
            t[(k, k + 1)] = -im;
            t[(k + 1, k)] = im;
            t[(k + 1, k + 1)] = re;
        }
        let got = kept_eigenvalues(&t, &DMatrix::identity(6, 6), all).unwrap();
        let lambdas: Vec<Complex64> = got.iter().map(|p| p.lambda).collect();
        assert_eq!(
            lambdas,
            vec![Complex64::new(0.5, 0.25), Complex64::new(-0.25, 0.75)]
        );
        for (p, k) in got.iter().zip([0, 4]) {
            let mut want = vec![Complex64::new(0.0, 0.0); 6];
            want[k] = Complex64::new(1.0, 0.0);
            want[k + 1] = Complex64::new(0.0, -1.0);
            assert!(shape_distance(&p.shape, &want) < 1e-15, "{:?}", p.shape);
        }
    }

    /// `|a - alpha b| / |a|` for the complex `alpha` that fits `b` to `a` best: 0 when the two
    /// shapes are the same up to a complex factor.
    fn shape_distance(a: &[Complex64], b: &[Complex64]) -> f64 {
        let bb: f64 = b.iter().map(|v| v.norm_sqr()).sum();
        let ab: Complex64 = a.iter().zip(b).map(|(x, y)| *x * y.conj()).sum();
        let alpha = ab / bb;
        let num: f64 = a
            .iter()
            .zip(b)
            .map(|(x, y)| (*x - alpha * *y).norm_sqr())
            .sum();
        let den: f64 = a.iter().map(|v| v.norm_sqr()).sum();
        (num / den).sqrt()
    }

    /// `C psi` of the previous path (nalgebra's Schur form with its vectors).
    fn reference_shapes(a: &DMatrix<f64>, c: &DMatrix<f64>) -> Vec<(Complex64, Vec<Complex64>)> {
        reference::complex_eigenpairs(a.clone())
            .unwrap()
            .into_iter()
            .map(|p| {
                let phi = (0..c.nrows())
                    .map(|r| (0..c.ncols()).map(|m| p.vector[m] * c[(r, m)]).sum())
                    .collect();
                (p.lambda, phi)
            })
            .collect()
    }

    /// Pairs each eigenvalue of `got` with the nearest unused one of `want`; returns the pairs'
    /// indices and the largest distance relative to `max(1, |lambda|)`.
    fn matched(got: &[Complex64], want: &[Complex64]) -> (Vec<(usize, usize)>, f64) {
        let mut used = vec![false; want.len()];
        let mut worst = 0.0f64;
        let mut pairs = Vec::new();
        for (i, g) in got.iter().enumerate() {
            let best = (0..want.len())
                .filter(|&j| !used[j])
                .min_by(|&x, &y| (want[x] - g).norm().total_cmp(&(want[y] - g).norm()));
            let Some(j) = best else { break };
            used[j] = true;
            worst = worst.max((want[j] - g).norm() / g.norm().max(1.0));
            pairs.push((i, j));
        }
        (pairs, worst)
    }

    fn gaussian(rng: &mut ChaCha8Rng, rows: usize, cols: usize) -> DMatrix<f64> {
        DMatrix::from_fn(rows, cols, |_, _| StandardNormal.sample(rng))
    }

    /// Random Gaussian matrices of 1..=60 rows (a state matrix's sizes) and 1..=8 output rows:
    /// the same eigenvalues (`Im > 0`) as the previous path to 1e-9 and the same shapes `C psi`
    /// (up to their complex scale) to 1e-8; backward-stable algorithms differ by
    /// `eps |A| cond`, far below. 300 seeds, each checked.
    #[test]
    fn same_poles_and_shapes_as_the_full_schur_path_on_random_matrices() {
        for seed in 0..300u64 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let n = rng.gen_range(1..=60);
            let l = rng.gen_range(1..=8);
            let a = gaussian(&mut rng, n, n) / (n as f64).sqrt();
            let c = gaussian(&mut rng, l, n);
            let got = kept_eigenvalues(&a, &c, all).unwrap();
            let want = reference_shapes(&a, &c);
            assert_eq!(got.len(), want.len(), "seed {seed} n {n}");
            let gl: Vec<Complex64> = got.iter().map(|p| p.lambda).collect();
            let wl: Vec<Complex64> = want.iter().map(|p| p.0).collect();
            let (pairs, worst) = matched(&gl, &wl);
            assert!(
                worst < 1e-9,
                "seed {seed} n {n}: eigenvalues differ by {worst:e}"
            );
            for (i, j) in pairs {
                let d = shape_distance(&got[i].shape, &want[j].1);
                assert!(
                    d < 1e-8,
                    "seed {seed} n {n} lambda {}: shapes differ by {d:e}",
                    gl[i]
                );
            }
            // Keeping a subset computes the same shapes for it.
            let right = |z: Complex64| z.re > 0.0;
            let some = kept_eigenvalues(&a, &c, right).unwrap();
            let kept: Vec<&ShapedEigenvalue> = got.iter().filter(|p| right(p.lambda)).collect();
            assert_eq!(some.len(), kept.len(), "seed {seed}");
            for (s, k) in some.iter().zip(kept) {
                assert_eq!(s.lambda, k.lambda);
                assert_eq!(s.shape, k.shape);
            }
        }
    }

    /// `A = S D S^-1` with `D` block diagonal: complex pairs `r (cos t, sin t)` as 2x2 rotation
    /// blocks, some of them repeated (a double pair), and real eigenvalues (some repeated,
    /// negative, zero). Returned: exactly one eigenvalue per complex pair of `D` (multiplicity
    /// counted), none for the real ones, each within 1e-9 of `D`'s; a simple pair's shape is
    /// `C (s_k - i s_k+1)` to 1e-8, a double pair's shape lies in the span of its two; and both
    /// agree with the previous path the same way. 200 seeds.
    #[test]
    fn repeated_and_real_eigenvalues() {
        for seed in 0..200u64 {
            let mut rng = ChaCha8Rng::seed_from_u64(1000 + seed);
            // Blocks: (radius, angle) for a pair, (value, 0) for a real eigenvalue.
            let mut blocks: Vec<(f64, f64, bool)> = Vec::new();
            for _ in 0..rng.gen_range(1..=12) {
                let r = rng.gen_range(0.2..1.1);
                let t = rng.gen_range(0.05..3.0);
                blocks.push((r, t, true));
                if rng.gen_bool(0.4) {
                    blocks.push((r, t, true)); // the same pair again
                }
            }
            for _ in 0..rng.gen_range(0..=6) {
                let v: f64 = match rng.gen_range(0..4) {
                    0 => 0.0,
                    1 => -rng.gen_range(0.1..1.0),
                    _ => rng.gen_range(0.1..1.0),
                };
                blocks.push((v, 0.0, false));
                if rng.gen_bool(0.4) {
                    blocks.push((v, 0.0, false));
                }
            }
            // Shuffle the blocks so repeats are not adjacent in D.
            for i in (1..blocks.len()).rev() {
                let j = rng.gen_range(0..=i);
                blocks.swap(i, j);
            }
            let n: usize = blocks.iter().map(|b| if b.2 { 2 } else { 1 }).sum();
            let mut d = DMatrix::zeros(n, n);
            let mut starts = Vec::new();
            let mut k = 0;
            for &(r, t, pair) in &blocks {
                if pair {
                    let (re, im) = (r * t.cos(), r * t.sin());
                    d[(k, k)] = re;
                    d[(k, k + 1)] = -im;
                    d[(k + 1, k)] = im;
                    d[(k + 1, k + 1)] = re;
                    starts.push((k, Complex64::new(re, im)));
                    k += 2;
                } else {
                    d[(k, k)] = r;
                    k += 1;
                }
            }
            let s = gaussian(&mut rng, n, n) + DMatrix::identity(n, n) * 2.0;
            let Some(s_inv) = s.clone().try_inverse() else {
                continue; // singular S: no matrix to test (probability 0)
            };
            let a = &s * &d * &s_inv;
            let l = 6;
            let c = gaussian(&mut rng, l, n);
            // A repeated real eigenvalue may come back as a pair with an imaginary part of
            // rounding size: such a pair must sit on one of D's real eigenvalues; the others are
            // D's pairs, one each.
            let reals: Vec<f64> = blocks.iter().filter(|b| !b.2).map(|b| b.0).collect();
            let split = |z: Complex64| {
                z.im < 1e-6
                    && reals
                        .iter()
                        .any(|&r| (z - Complex64::new(r, 0.0)).norm() < 1e-6)
            };
            let (_split_reals, got): (Vec<_>, Vec<_>) = kept_eigenvalues(&a, &c, all)
                .unwrap()
                .into_iter()
                .partition(|p| split(p.lambda));
            assert_eq!(got.len(), starts.len(), "seed {seed}: {:?}", blocks);
            let gl: Vec<Complex64> = got.iter().map(|p| p.lambda).collect();
            let true_l: Vec<Complex64> = starts.iter().map(|p| p.1).collect();
            let (pairs, worst) = matched(&gl, &true_l);
            assert!(worst < 1e-9, "seed {seed}: eigenvalues off by {worst:e}");
            // The true shapes: C (s_k - i s_k+1) for the pair at column k.
            let true_shape = |k: usize| -> Vec<Complex64> {
                (0..l)
                    .map(|r| {
                        (0..n)
                            .map(|m| Complex64::new(s[(m, k)], -s[(m, k + 1)]) * c[(r, m)])
                            .sum()
                    })
                    .collect()
            };
            for (i, j) in pairs {
                let twins: Vec<usize> = starts
                    .iter()
                    .map(|p| p.1)
                    .enumerate()
                    .filter(|(_, z)| (*z - true_l[j]).norm() < 1e-12)
                    .map(|(m, _)| starts[m].0)
                    .collect();
                let d = if twins.len() == 1 {
                    shape_distance(&got[i].shape, &true_shape(twins[0]))
                } else {
                    span_distance(
                        &got[i].shape,
                        &twins.iter().map(|&k| true_shape(k)).collect::<Vec<_>>(),
                    )
                };
                assert!(
                    d < 1e-8,
                    "seed {seed} lambda {}: shape off by {d:e} ({} twins)",
                    gl[i],
                    twins.len()
                );
            }
            // The previous path: same eigenvalues, same shapes for the simple pairs.
            let want: Vec<_> = reference_shapes(&a, &c)
                .into_iter()
                .filter(|p| !split(p.0))
                .collect();
            assert_eq!(want.len(), got.len(), "seed {seed}");
            let wl: Vec<Complex64> = want.iter().map(|p| p.0).collect();
            let (pairs, worst) = matched(&gl, &wl);
            assert!(worst < 1e-9, "seed {seed}: paths differ by {worst:e}");
            for (i, j) in pairs {
                let simple = true_l
                    .iter()
                    .filter(|z| (**z - gl[i]).norm() < 1e-6)
                    .count()
                    == 1;
                if simple {
                    let d = shape_distance(&got[i].shape, &want[j].1);
                    assert!(d < 1e-8, "seed {seed}: paths' shapes differ by {d:e}");
                }
            }
        }
    }

    /// Distance of `a` (relative) from the span of `basis` (least squares through the normal
    /// equations of a two-vector basis; more are not used here).
    fn span_distance(a: &[Complex64], basis: &[Vec<Complex64>]) -> f64 {
        let m = basis.len();
        let g = nalgebra::DMatrix::<Complex64>::from_fn(m, m, |i, j| {
            basis[i]
                .iter()
                .zip(&basis[j])
                .map(|(x, y)| x.conj() * y)
                .sum()
        });
        let rhs = nalgebra::DVector::<Complex64>::from_fn(m, |i, _| {
            basis[i].iter().zip(a).map(|(x, y)| x.conj() * y).sum()
        });
        let Some(coef) = g.lu().solve(&rhs) else {
            return f64::INFINITY;
        };
        let num: f64 = a
            .iter()
            .enumerate()
            .map(|(r, v)| {
                let fit: Complex64 = (0..m).map(|i| coef[i] * basis[i][r]).sum();
                (*v - fit).norm_sqr()
            })
            .sum();
        let den: f64 = a.iter().map(|v| v.norm_sqr()).sum();
        (num / den).sqrt()
    }
}
