//! Eigenvalues and eigenvectors of a real square matrix through its real Schur form
//! `A = Q T Q^T` (nalgebra), with eigenvectors of the quasi-triangular `T` by back substitution.
//! Only the complex eigenvalues with a positive imaginary part are returned (one of each
//! conjugate pair); real eigenvalues (1x1 blocks of `T`, or 2x2 blocks with real eigenvalues)
//! are skipped.

use nalgebra::{DMatrix, Schur};
use num_complex::Complex64;

use crate::error::SsiError;

/// An eigenvalue with `Im > 0` and its right eigenvector (unit Euclidean norm).
pub(crate) struct EigenPair {
    pub lambda: Complex64,
    pub vector: Vec<Complex64>,
}

/// Iteration cap of the Schur decomposition: LAPACK allows 30 QR sweeps per eigenvalue.
fn schur_iterations(n: usize) -> usize {
    30 * n.max(1) + 100
}

/// The complex eigenpairs (`Im(lambda) > 0`) of `a`, in the order of the Schur form.
pub(crate) fn complex_eigenpairs(a: DMatrix<f64>) -> Result<Vec<EigenPair>, SsiError> {
    let n = a.nrows();
    if n == 0 {
        return Ok(Vec::new());
    }
    let iterations = schur_iterations(n);
    let schur = Schur::try_new(a, f64::EPSILON, iterations).ok_or(SsiError::NotConverged {
        what: "Schur form of the state matrix A",
        size: n,
        iterations,
    })?;
    let (q, t) = schur.unpack();
    Ok(quasi_triangular_eigenpairs(&q, &t))
}

/// Blocks `(start, size)` of a quasi-triangular matrix: a nonzero subdiagonal entry opens a 2x2.
fn blocks(t: &DMatrix<f64>) -> Vec<(usize, usize)> {
    let n = t.nrows();
    let mut out = Vec::new();
    let mut j = 0;
    while j < n {
        if j + 1 < n && t[(j + 1, j)] != 0.0 {
            out.push((j, 2));
            j += 2;
        } else {
            out.push((j, 1));
            j += 1;
        }
    }
    out
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
    let blocks = blocks(t);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A x = lambda x for a random-looking nonsymmetric matrix with several complex pairs.
    #[test]
    fn eigenpairs_satisfy_the_definition() {
        let n = 9;
        let a = DMatrix::from_fn(n, n, |r, c| {
            let x = ((r * 7 + c * 13 + 3) % 17) as f64 / 17.0 - 0.5;
            x + if c == (r + 1) % n { 1.0 } else { 0.0 }
        });
        let pairs = complex_eigenpairs(a.clone()).unwrap();
        assert!(pairs.len() >= 2, "{}", pairs.len());
        for p in &pairs {
            assert!(p.lambda.im > 0.0);
            let mut worst = 0.0f64;
            for r in 0..n {
                let mut s = Complex64::new(0.0, 0.0);
                for c in 0..n {
                    s += p.vector[c] * a[(r, c)];
                }
                worst = worst.max((s - p.lambda * p.vector[r]).norm());
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
        match complex_eigenpairs(a) {
            Err(e @ SsiError::NotConverged { .. }) => {
                let m = e.to_string();
                assert!(m.contains("4x4") && m.contains("Schur"), "{m}");
            }
            Err(e) => panic!("unexpected error {e}"),
            Ok(p) => panic!("NaN matrix gave {} eigenpairs", p.len()),
        }
    }
}
