//! All the singular values of a matrix and only its leading left singular vectors.
//!
//! nalgebra 0.33's `SVD::try_new(m, true, false, eps, max_niter)` bidiagonalises `m`
//! (Householder, `m = U_B B V_B^T`), forms `U_B` and applies every Givens rotation of the
//! implicit-shift QR iterations on `B` to all the columns of `U_B`. SSI-cov uses only the first
//! `k` columns of `U` (`k` = the highest order, 60 of 140 for the benchmark's Toeplitz matrix).
//! [`leading_svd`] runs the same iterations on the same `B` (nalgebra's `Bidiagonal`, the same
//! rotations in the same order: the singular values are nalgebra's bit for bit) but records the
//! rotations instead of applying them; then `U[.., ..k] = U_B (G_1 ... G_m D P)[.., ..k]` (`D`
//! the signs made positive, `P` the sort by decreasing singular value) is formed from the right:
//! the `k` unit vectors picked by `D P`, every rotation applied to their two rows in reverse
//! order (`k` entries each instead of `rows`), and `U_B` applied as its Householder reflections.

use std::cmp::Ordering;

use nalgebra::linalg::givens::GivensRotation;
use nalgebra::linalg::{wilkinson_shift, Bidiagonal};
use nalgebra::{DMatrix, Matrix2x3, Reflection, Unit, Vector2, SVD};

/// The singular values (largest first) and the first `k` left singular vectors.
pub(crate) struct LeadingSvd {
    pub singular_values: Vec<f64>,
    /// `rows x min(k, cols)`.
    pub u: DMatrix<f64>,
}

/// A rotation applied to the columns `p < q` of `U`: `(u_p, u_q) <- (c u_p + s u_q, c u_q - s u_p)`.
struct Rotation {
    p: usize,
    q: usize,
    c: f64,
    s: f64,
}

impl Rotation {
    fn of(p: usize, q: usize, g: &GivensRotation<f64>) -> Rotation {
        Rotation {
            p,
            q,
            c: g.c(),
            s: g.s(),
        }
    }
}

/// The singular values of `matrix` (largest first) and its first `k` left singular vectors, as
/// nalgebra's `SVD::try_new(matrix, true, false, eps, max_niter)` computes them (singular
/// values bit for bit, vectors to rounding). `None` when the iterations do not converge within
/// `max_niter` (as nalgebra) or a singular value is NaN. A matrix with more columns than rows
/// goes to nalgebra's SVD itself.
pub(crate) fn leading_svd(
    mut matrix: DMatrix<f64>,
    k: usize,
    eps: f64,
    max_niter: usize,
) -> Option<LeadingSvd> {
    let (rows, cols) = matrix.shape();
    if rows < cols || cols < 2 {
        let svd = SVD::try_new(matrix, true, false, eps, max_niter)?;
        let u = svd.u?;
        let k = k.min(u.ncols());
        return Some(LeadingSvd {
            singular_values: svd.singular_values.iter().copied().collect(),
            u: u.columns(0, k).into_owned(),
        });
    }
    let dim = cols;
    let m_amax = matrix.camax();
    if m_amax != 0.0 {
        matrix.unscale_mut(m_amax);
    }
    let bi = Bidiagonal::new(matrix);
    let mut d: Vec<f64> = bi.diagonal().iter().copied().collect();
    let mut e: Vec<f64> = bi.off_diagonal().iter().copied().collect();
    let mut rots = Vec::new();

    let mut niter = 0;
    let (mut start, mut end) = delimit_subproblem(&mut d, &mut e, &mut rots, dim - 1, eps);
    while end != start {
        let subdim = end - start + 1;
        if subdim > 2 {
            let m = end - 1;
            let n = end;
            let mut vec = {
                let (dm, dn, fm) = (d[m], d[n], e[m]);
                let tmm = dm * dm + e[m - 1] * e[m - 1];
                let tmn = dm * fm;
                let tnn = dn * dn + fm * fm;
                let shift = wilkinson_shift(tmm, tnn, tmn);
                Vector2::new(d[start] * d[start] - shift, d[start] * e[start])
            };
            for k in start..n {
                let m12 = if k == n - 1 { 0.0 } else { e[k + 1] };
                let mut subm = Matrix2x3::new(d[k], e[k], 0.0, 0.0, d[k + 1], m12);
                let Some((rot1, norm1)) = GivensRotation::cancel_y(&vec) else {
                    break;
                };
                rot1.inverse()
                    .rotate_rows(&mut subm.fixed_columns_mut::<2>(0));
                if k > start {
                    e[k - 1] = norm1;
                }
                let v = Vector2::new(subm[(0, 0)], subm[(1, 0)]);
                let (rot2, norm2) = GivensRotation::cancel_y(&v)
                    .unwrap_or((GivensRotation::identity(), subm[(0, 0)]));
                rot2.rotate(&mut subm.fixed_columns_mut::<2>(1));
                subm[(0, 0)] = norm2;
                rots.push(Rotation::of(k, k + 1, &rot2.inverse()));
                d[k] = subm[(0, 0)];
                d[k + 1] = subm[(1, 1)];
                e[k] = subm[(0, 1)];
                if k != n - 1 {
                    e[k + 1] = subm[(1, 2)];
                }
                vec.x = subm[(0, 1)];
                vec.y = subm[(0, 2)];
            }
        } else if subdim == 2 {
            let (u2, s) = uptrig_2x2_svd(d[start], e[start], d[start + 1]);
            d[start] = s[0];
            d[start + 1] = s[1];
            e[start] = 0.0;
            rots.push(Rotation::of(start, start + 1, &u2));
            end -= 1;
        }
        let sub = delimit_subproblem(&mut d, &mut e, &mut rots, end, eps);
        start = sub.0;
        end = sub.1;
        niter += 1;
        if niter == max_niter {
            return None;
        }
    }

    // Signs, then the order by decreasing singular value (nalgebra's sort: the same call).
    let mut flip = vec![false; dim];
    for (v, f) in d.iter_mut().zip(flip.iter_mut()) {
        *v *= m_amax;
        if *v < 0.0 {
            *v = -*v;
            *f = true;
        }
    }
    if d.iter().any(|v| v.is_nan()) {
        return None;
    }
    let mut sorted: Vec<(f64, usize)> = d.iter().copied().zip(0..).collect();
    sorted.sort_unstable_by(|(a, _), (b, _)| b.partial_cmp(a).unwrap_or(Ordering::Equal));
    let k = k.min(dim);

    // X^T (k x dim, column-major: row r of X is xt[r k..(r + 1) k]) = (D P)[.., ..k]^T, then
    // every rotation from the last: X <- R X on rows p, q.
    let mut xt = vec![0.0; k * dim];
    for (j, &(_, idx)) in sorted.iter().take(k).enumerate() {
        xt[idx * k + j] = if flip[idx] { -1.0 } else { 1.0 };
    }
    for r in rots.iter().rev() {
        let (head, tail) = xt.split_at_mut(r.q * k);
        rotate_pair(&mut head[r.p * k..(r.p + 1) * k], &mut tail[..k], r.c, r.s);
    }
    // U_B X: the reflections of nalgebra's `Bidiagonal::u` (rows beyond `dim` start at zero).
    // The sign `Bidiagonal::u` applies with reflection `i` is that of the bidiagonal's signed
    // diagonal entry `i`, which is minus the sign of the reflection axis's first entry (kept
    // in `uv_internal`): nalgebra's `reflection_axis_mut` adds `sign(x_0) |x|` to `x_0`.
    let mut x = DMatrix::from_fn(rows, k, |r, c| if r < dim { xt[r * k + c] } else { 0.0 });
    let uv = bi.uv_internal();
    for i in (0..dim).rev() {
        let axis = uv.view_range(i.., i);
        if axis.norm_squared() == 0.0 {
            continue;
        }
        let sign = if axis[0] >= 0.0 { -1.0 } else { 1.0 };
        let refl = Reflection::new(Unit::new_unchecked(axis), 0.0);
        refl.reflect_with_sign(&mut x.view_range_mut(i.., ..), sign);
    }
    Some(LeadingSvd {
        singular_values: sorted.iter().map(|&(v, _)| v).collect(),
        u: x,
    })
}

/// `(a, b) <- (c a - s b, s a + c b)`, entry by entry (in blocks of four, which the compiler
/// turns into vector instructions; the plain loop stayed scalar).
fn rotate_pair(a: &mut [f64], b: &mut [f64], c: f64, s: f64) {
    let mut a4 = a.chunks_exact_mut(4);
    let mut b4 = b.chunks_exact_mut(4);
    for (x, y) in (&mut a4).zip(&mut b4) {
        for j in 0..4 {
            let (va, vb) = (x[j], y[j]);
            x[j] = c * va - s * vb;
            y[j] = s * va + c * vb;
        }
    }
    for (x, y) in a4.into_remainder().iter_mut().zip(b4.into_remainder()) {
        let (va, vb) = (*x, *y);
        *x = c * va - s * vb;
        *y = s * va + c * vb;
    }
}

/// nalgebra's `SVD::delimit_subproblem` for an upper bidiagonal (diagonal `d`, superdiagonal
/// `e`) with `U` wanted and `V` not: the rotations of `U` recorded in `rots`.
fn delimit_subproblem(
    d: &mut [f64],
    e: &mut [f64],
    rots: &mut Vec<Rotation>,
    end: usize,
    eps: f64,
) -> (usize, usize) {
    let mut n = end;
    while n > 0 {
        let m = n - 1;
        if e[m] == 0.0 || e[m].abs() <= eps * (d[n].abs() + d[m].abs()) {
            e[m] = 0.0;
        } else if d[m].abs() <= eps {
            d[m] = 0.0;
            cancel_horizontal_off_diagonal_elt(d, e, rots, m, m + 1);
            if m != 0 {
                cancel_vertical_off_diagonal_elt(d, e, m - 1);
            }
        } else if d[n].abs() <= eps {
            d[n] = 0.0;
            cancel_vertical_off_diagonal_elt(d, e, m);
        } else {
            break;
        }
        n -= 1;
    }
    if n == 0 {
        return (0, 0);
    }
    let mut new_start = n - 1;
    while new_start > 0 {
        let m = new_start - 1;
        if e[m].abs() <= eps * (d[new_start].abs() + d[m].abs()) {
            e[m] = 0.0;
            break;
        } else if d[m].abs() <= eps {
            d[m] = 0.0;
            cancel_horizontal_off_diagonal_elt(d, e, rots, m, n);
            if m != 0 {
                cancel_vertical_off_diagonal_elt(d, e, m - 1);
            }
            break;
        }
        new_start -= 1;
    }
    (new_start, n)
}

/// nalgebra's `cancel_horizontal_off_diagonal_elt` (upper bidiagonal, `U` rotations recorded).
fn cancel_horizontal_off_diagonal_elt(
    d: &mut [f64],
    e: &mut [f64],
    rots: &mut Vec<Rotation>,
    i: usize,
    end: usize,
) {
    let mut v = Vector2::new(e[i], d[i + 1]);
    e[i] = 0.0;
    for k in i..end {
        let Some((rot, norm)) = GivensRotation::cancel_x(&v) else {
            break;
        };
        d[k + 1] = norm;
        rots.push(Rotation::of(i, k + 1, &rot.inverse()));
        if k + 1 != end {
            v.x = -rot.s() * e[k + 1];
            v.y = d[k + 2];
            e[k + 1] *= rot.c();
        }
    }
}

/// nalgebra's `cancel_vertical_off_diagonal_elt` (upper bidiagonal: only `V` would rotate).
fn cancel_vertical_off_diagonal_elt(d: &mut [f64], e: &mut [f64], i: usize) {
    let mut v = Vector2::new(d[i], e[i]);
    e[i] = 0.0;
    for k in (0..=i).rev() {
        let Some((rot, norm)) = GivensRotation::cancel_y(&v) else {
            break;
        };
        d[k] = norm;
        if k > 0 {
            v.x = d[k - 1];
            v.y = rot.s() * e[k - 1];
            e[k - 1] *= rot.c();
        }
    }
}

/// nalgebra's `compute_2x2_uptrig_svd(m11, m12, m22, true, false)` (as its SVD calls it for
/// an upper bidiagonal with `U` wanted): the rotation of `U` and the two singular values.
fn uptrig_2x2_svd(m11: f64, m12: f64, m22: f64) -> (GivensRotation<f64>, [f64; 2]) {
    let denom = (m11 + m22).hypot(m12) + (m11 - m22).hypot(m12);
    let mut v1 = m11 * m22 * 2.0 / denom;
    let mut v2 = 0.5 * denom;
    let (csv, sgn_v) = GivensRotation::new(m11 * m12, v1 * v1 - m11 * m11);
    v1 *= sgn_v;
    v2 *= sgn_v;
    let cu = (m11 * csv.c() + m12 * csv.s()) / v1;
    let su = (m22 * csv.s()) / v1;
    let (csu, sgn_u) = GivensRotation::new(cu, su);
    v1 *= sgn_u;
    v2 *= sgn_u;
    (csu, [v1, v2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    const EPS: f64 = 5.0 * f64::EPSILON;

    fn gaussian(rng: &mut ChaCha8Rng, rows: usize, cols: usize) -> DMatrix<f64> {
        DMatrix::from_fn(rows, cols, |_, _| StandardNormal.sample(rng))
    }

    /// Against nalgebra's own SVD of the same matrix: the singular values bit for bit, the
    /// first `k` left singular vectors to 1e-12 (the same rotations, applied in another order),
    /// orthonormal to 1e-13.
    fn check(m: &DMatrix<f64>, k: usize, what: &str) {
        let want = SVD::try_new(m.clone(), true, false, EPS, 100_000).unwrap();
        let got = leading_svd(m.clone(), k, EPS, 100_000).unwrap();
        let sv: Vec<f64> = want.singular_values.iter().copied().collect();
        assert_eq!(got.singular_values, sv, "{what}");
        let u = want.u.unwrap();
        let k = k.min(m.ncols());
        assert_eq!(got.u.shape(), (m.nrows(), k), "{what}");
        let worst = (got.u.clone() - u.columns(0, k)).amax();
        assert!(worst < 1e-12, "{what}: U differs by {worst}");
        let gram = got.u.tr_mul(&got.u) - DMatrix::<f64>::identity(k, k);
        assert!(gram.amax() < 1e-13, "{what}: U^T U - I {}", gram.amax());
    }

    #[test]
    fn matches_nalgebras_svd_on_random_matrices() {
        let mut rng = ChaCha8Rng::seed_from_u64(20261126);
        for case in 0..60 {
            let cols = 2 + case % 23;
            let rows = cols + (case / 3) % 5;
            let m = gaussian(&mut rng, rows, cols);
            for k in [1, cols / 2, cols, cols + 3] {
                check(&m, k, &format!("case {case}: {rows} x {cols}, k {k}"));
            }
        }
    }

    /// The Toeplitz matrix's size in the benchmark (140 x 140, 60 vectors), graded singular
    /// values down to 1e-12 of the largest (as a correlation matrix's noise floor).
    #[test]
    fn matches_nalgebras_svd_at_the_benchmarks_size() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for case in 0..4 {
            let (a, b) = (gaussian(&mut rng, 140, 140), gaussian(&mut rng, 140, 140));
            let qa = a.qr().q();
            let qb = b.qr().q();
            let s = DMatrix::from_fn(140, 140, |r, c| {
                if r == c {
                    10f64.powf(-12.0 * r as f64 / 139.0) * (1.0 + case as f64)
                } else {
                    0.0
                }
            });
            check(&(qa * s * qb.transpose()), 60, &format!("graded {case}"));
        }
    }

    /// Rank-deficient and structured matrices, which take the deflation paths (a zero on the
    /// bidiagonal's diagonal, exact zeros, repeated singular values): the same answer as
    /// nalgebra's.
    #[test]
    fn matches_nalgebras_svd_on_degenerate_matrices() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        // Rank 2 of 9 columns.
        let low = gaussian(&mut rng, 12, 2) * gaussian(&mut rng, 2, 9);
        check(&low, 4, "rank 2");
        // A zero column and a zero row.
        let mut z = gaussian(&mut rng, 8, 8);
        z.column_mut(3).fill(0.0);
        z.row_mut(5).fill(0.0);
        check(&z, 8, "zero column and row");
        // Orthogonal: every singular value 1.
        let q = gaussian(&mut rng, 10, 10).qr().q();
        check(&q, 5, "orthogonal");
        // Identity and zero.
        check(&DMatrix::identity(6, 6), 3, "identity");
        check(&DMatrix::zeros(5, 4), 2, "zero");
        // Upper bidiagonal with a zero on the diagonal.
        let mut b = DMatrix::zeros(7, 7);
        for i in 0..7 {
            b[(i, i)] = if i == 3 { 0.0 } else { 1.0 + i as f64 };
            if i + 1 < 7 {
                b[(i, i + 1)] = 0.5;
            }
        }
        check(&b, 7, "zero on the diagonal");
        // Wider than tall: nalgebra's SVD itself.
        check(&gaussian(&mut rng, 4, 9), 3, "wide");
    }

    /// By hand: diag(3, -5, 1) has singular values 5, 3, 1 and left vectors -e_1 (for 5, from
    /// the sign made positive), e_0, e_2 up to sign.
    #[test]
    fn diagonal_by_hand() {
        let m = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![3.0, -5.0, 1.0]));
        let got = leading_svd(m.clone(), 2, EPS, 1000).unwrap();
        assert_eq!(got.singular_values, vec![5.0, 3.0, 1.0]);
        assert!((got.u[(1, 0)].abs() - 1.0).abs() < 1e-15 && got.u[(0, 0)] == 0.0);
        assert!((got.u[(0, 1)].abs() - 1.0).abs() < 1e-15 && got.u[(1, 1)] == 0.0);
        // U S V^T = M on the leading part: column j of U times s_j is M times v_j, and M's
        // columns are axis-aligned, so |U[.., j]| s_j matches the column of M of that size.
        assert_eq!((got.u[(1, 0)] * 5.0).abs(), m[(1, 1)].abs());
    }
}
