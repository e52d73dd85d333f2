//! Non-negative least squares from the normal equations: `min |A x - b|^2` subject to `x >= 0`,
//! given `A^T A` and `A^T b` (the model update sums them record by record and never holds `A`).
//!
//! Lawson and Hanson's active-set method (Solving Least Squares Problems, 1974, ch. 23), the
//! algorithm of `scipy.optimize.nnls`: unknowns enter the passive (free) set one at a time by the
//! largest positive gradient, the free subproblem is solved exactly, and a step that would make a
//! free unknown negative is cut at the bound, which then leaves the free set. The result satisfies
//! the Karush-Kuhn-Tucker conditions: `x >= 0`, `w = A^T b - A^T A x <= 0` where `x = 0`, and
//! `w = 0` where `x > 0` (to rounding).
//!
//! A (crate's) own solver rather than the `nnls` crate: that one takes `A` itself (in `ndarray`);
//! here only the normal equations exist, in `nalgebra`.
use nalgebra::{DMatrix, DVector};

/// The solution of [`nnls_normal`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Nnls {
    /// The unknowns, each `>= 0`.
    pub x: DVector<f64>,
    /// Whether each unknown is held at its bound 0.
    pub at_bound: Vec<bool>,
}

/// `argmin |A x - b|^2` over `x >= 0`, from `ata = A^T A` (symmetric, positive semi-definite)
/// and `atb = A^T b`.
///
/// Returns `None` when the sizes disagree, a value is not finite, or a free subproblem is
/// singular (the equations do not determine the free unknowns). Stops after `3 n` outer steps
/// (Lawson and Hanson's bound; scipy's default), returning the last feasible point.
pub fn nnls_normal(ata: &DMatrix<f64>, atb: &DVector<f64>) -> Option<Nnls> {
    let n = atb.len();
    if ata.nrows() != n || ata.ncols() != n {
        return None;
    }
    if ata.iter().chain(atb.iter()).any(|v| !v.is_finite()) {
        return None;
    }
    let scale = atb.amax().max(ata.amax()).max(f64::MIN_POSITIVE);
    let tol = 1e3 * f64::EPSILON * scale * n as f64;
    let mut x = DVector::<f64>::zeros(n);
    let mut free = vec![false; n];
    for _ in 0..3 * n.max(1) {
        let w = atb - ata * &x;
        // The bound unknown with the largest positive gradient enters.
        let Some(j) = (0..n)
            .filter(|&j| !free[j] && w[j] > tol)
            .max_by(|&a, &b| w[a].total_cmp(&w[b]))
        else {
            break;
        };
        free[j] = true;
        loop {
            let s = solve_free(ata, atb, &free)?;
            if (0..n).all(|i| !free[i] || s[i] > 0.0) {
                x = s;
                break;
            }
            // Step from x towards s until the first free unknown reaches 0; it leaves the free
            // set, with any other that reached 0 on the way.
            let (first, alpha) = (0..n)
                .filter(|&i| free[i] && s[i] <= 0.0)
                .map(|i| {
                    let gap = x[i] - s[i];
                    (i, if gap > 0.0 { x[i] / gap } else { 0.0 })
                })
                .fold((usize::MAX, f64::INFINITY), |best, c| {
                    if c.1 < best.1 {
                        c
                    } else {
                        best
                    }
                });
            x += (s - &x) * alpha;
            for i in 0..n {
                if free[i] && (i == first || x[i] <= 0.0) {
                    free[i] = false;
                    x[i] = 0.0;
                }
            }
        }
    }
    let at_bound = (0..n).map(|i| !free[i] || x[i] <= 0.0).collect();
    x.iter_mut().for_each(|v| *v = v.max(0.0));
    Some(Nnls { x, at_bound })
}

/// The unconstrained least-squares solution over the free unknowns, 0 elsewhere.
fn solve_free(ata: &DMatrix<f64>, atb: &DVector<f64>, free: &[bool]) -> Option<DVector<f64>> {
    let idx: Vec<usize> = (0..free.len()).filter(|&i| free[i]).collect();
    let k = idx.len();
    let sub = DMatrix::from_fn(k, k, |r, c| ata[(idx[r], idx[c])]);
    let rhs = DVector::from_fn(k, |r, _| atb[idx[r]]);
    let sol = sub.cholesky()?.solve(&rhs);
    let mut s = DVector::zeros(free.len());
    for (r, &i) in idx.iter().enumerate() {
        s[i] = sol[r];
    }
    Some(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn solve(a: &[[f64; 2]], b: &[f64]) -> Nnls {
        let a = DMatrix::from_fn(a.len(), 2, |r, c| a[r][c]);
        let b = DVector::from_column_slice(b);
        nnls_normal(&(a.transpose() * &a), &(a.transpose() * b)).unwrap()
    }

    /// By hand: A = [[1, 0], [1, 1]]. For b = [2, -1], A^T b = [1, -1] and the unconstrained
    /// solution is [2, -3]; with x2 held at 0, x1 = 1 / 2, and the gradient of x2 there,
    /// -1 - 1 x 0.5 = -1.5, is negative: x = [0.5, 0].
    #[test]
    fn two_unknowns_by_hand() {
        let r = solve(&[[1.0, 0.0], [1.0, 1.0]], &[2.0, -1.0]);
        assert!((r.x[0] - 0.5).abs() < 1e-14 && r.x[1] == 0.0, "{:?}", r.x);
        assert_eq!(r.at_bound, vec![false, true]);
        // b = [1, -2]: A^T b = [-1, -2] <= 0, so x = 0.
        let r = solve(&[[1.0, 0.0], [1.0, 1.0]], &[1.0, -2.0]);
        assert_eq!(r.x.as_slice(), &[0.0, 0.0]);
        // A feasible unconstrained solution is returned as it is: b = A [1, 2].
        let r = solve(&[[1.0, 0.0], [1.0, 1.0]], &[1.0, 3.0]);
        assert!((r.x[0] - 1.0).abs() < 1e-13 && (r.x[1] - 2.0).abs() < 1e-13);
        assert_eq!(r.at_bound, vec![false, false]);
    }

    #[test]
    fn bad_input_is_none() {
        let a = DMatrix::<f64>::identity(2, 2);
        assert!(nnls_normal(&a, &DVector::from_vec(vec![1.0, f64::NAN])).is_none());
        assert!(nnls_normal(&a, &DVector::from_vec(vec![1.0])).is_none());
    }

    /// The Karush-Kuhn-Tucker conditions on seeded random problems (12 x 6 to 40 x 10, half of
    /// the unconstrained unknowns negative on average).
    #[test]
    fn kkt_conditions_over_seeds() {
        let mut state: u64 = 0x2545_F491_4F6C_DD1D;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for seed in 0..200 {
            let n = 2 + seed % 9;
            let m = 3 * n + seed % 7;
            let a = DMatrix::from_fn(m, n, |_, _| uniform());
            let b = DVector::from_fn(m, |_, _| uniform());
            let ata = a.transpose() * &a;
            let atb = a.transpose() * &b;
            let r = nnls_normal(&ata, &atb).unwrap();
            let w = &atb - &ata * &r.x;
            let tol = 1e-10 * atb.amax().max(1.0);
            for i in 0..n {
                assert!(r.x[i] >= 0.0, "seed {seed}: x[{i}] = {}", r.x[i]);
                if r.x[i] > 0.0 {
                    assert!(w[i].abs() < tol, "seed {seed}: free w[{i}] = {}", w[i]);
                } else {
                    assert!(w[i] < tol, "seed {seed}: bound w[{i}] = {}", w[i]);
                }
            }
        }
    }
}
