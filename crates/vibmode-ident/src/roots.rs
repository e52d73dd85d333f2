//! Polynomial roots: the Aberth-Ehrlich iteration, or the eigenvalues of a balanced companion matrix.

use nalgebra::{linalg::balancing::balance_parlett_reinsch, DMatrix, Schur};
use num_complex::Complex64;

use crate::IdentError;

/// Roots of the polynomial `coeffs[0] z^n + coeffs[1] z^(n-1) + ... + coeffs[n]` (highest power
/// first, as `numpy.roots`). For `A = [1, a1, ..., ap]` these are the model poles.
///
/// Method: the Aberth-Ehrlich iteration's roots made an exact conjugate set (else, when it does not
/// settle or a root is neither paired nor real: companion matrix, Parlett-Reinsch balancing
/// (nalgebra's `linalg::balancing::balance_parlett_reinsch`), real Schur decomposition), then at most four
/// guarded Newton polishing steps per root on the original polynomial, its value evaluated in
/// double-double arithmetic (a step is kept only if it lowers |p(z)| and is small against the
/// distance to the nearest other root). The eigenvalues alone carry errors of about eps x the
/// roots' condition number, 1e-6 relative for lightly damped modes near 1 Hz at 200 Hz in an
/// order-60 polynomial (as `numpy.roots`); polished, such roots are exact to about 1e-14 relative
/// when the coefficients are exact. Trailing zero
/// coefficients give exact roots at zero. Roots come in exact conjugate pairs; order is unspecified.
///
/// Errors: empty input or zero leading coefficient, non-finite coefficients, or (very unlikely)
/// non-convergence of the Schur iteration.
pub fn polynomial_roots(coeffs: &[f64]) -> Result<Vec<Complex64>, IdentError> {
    roots_impl(coeffs, true)
}

/// As [`polynomial_roots`] without the Newton polishing: the companion matrix's eigenvalues,
/// accurate to about eps x each root's condition number. For uses where that suffices (the
/// reflection of a trial step's C into the unit circle, which only moves a search point).
pub(crate) fn polynomial_roots_unpolished(coeffs: &[f64]) -> Result<Vec<Complex64>, IdentError> {
    roots_impl(coeffs, false)
}

/// Iterations allowed to [`aberth_roots`] before it gives up (it needs 10 to 30 from a circle).
const ABERTH_MAX_ITERATIONS: usize = 200;

/// Roots of `coeffs` (highest power first, nonzero leading coefficient, degree >= 1) by the
/// Aberth-Ehrlich simultaneous iteration (Gauss-Seidel updates), started on a circle of radius
/// `|c_n / c_0|^(1/n)`. O(n^2) per sweep against O(n^3) for the companion matrix's Schur form;
/// the same accuracy as unpolished eigenvalues (a small backward error). `None` when a sweep
/// does not settle within [`ABERTH_MAX_ITERATIONS`] or a value is not finite: the caller then
/// falls back to the companion matrix. Roots of a real polynomial come in conjugate pairs only
/// to the iteration's accuracy.
#[cfg(test)]
pub(crate) fn aberth_roots(coeffs: &[f64]) -> Option<Vec<Complex64>> {
    aberth_roots_from(coeffs, &[])
}

/// As [`aberth_roots`], started from `start` when it holds as many finite points as the degree
/// (the roots of a nearby polynomial: a few sweeps then suffice instead of 10 to 30), else on the
/// circle. The roots agree with the cold start's to the iteration's accuracy, not bit for bit.
pub(crate) fn aberth_roots_from(coeffs: &[f64], start: &[Complex64]) -> Option<Vec<Complex64>> {
    let lead = *coeffs.first()?;
    if lead == 0.0 || coeffs.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let n = coeffs.len() - 1;
    if n == 0 {
        return Some(Vec::new());
    }
    let tail = coeffs[n].abs() / lead.abs();
    let radius = if tail > 0.0 {
        tail.powf(1.0 / n as f64)
    } else {
        0.5
    };
    let warm = start.len() == n && start.iter().all(|z| z.re.is_finite() && z.im.is_finite());
    let mut z: Vec<Complex64> = if warm {
        start.to_vec()
    } else {
        (0..n)
            .map(|k| {
                Complex64::from_polar(radius, std::f64::consts::TAU * k as f64 / n as f64 + 0.4)
            })
            .collect()
    };
    let mut done = vec![false; n];
    for _ in 0..ABERTH_MAX_ITERATIONS {
        let mut moving = 0usize;
        for k in 0..n {
            if done[k] {
                continue;
            }
            let (p, dp) = horner(coeffs, z[k]);
            // Converged when |p(z)| is at the rounding level of its evaluation (a backward error
            // of a few eps in the coefficients): sum |c_i| |z|^(n-i) eps.
            let az = z[k].norm();
            let bound = coeffs.iter().fold(0.0, |acc, c| acc * az + c.abs());
            if p.norm() <= 16.0 * f64::EPSILON * bound {
                done[k] = true;
                continue;
            }
            let ratio = p / dp;
            let mut sum = Complex64::new(0.0, 0.0);
            for (j, &zj) in z.iter().enumerate() {
                if j != k {
                    sum += (z[k] - zj).inv();
                }
            }
            let w = ratio / (Complex64::new(1.0, 0.0) - ratio * sum);
            if !(w.re.is_finite() && w.im.is_finite()) {
                return None;
            }
            z[k] -= w;
            moving += 1;
        }
        if moving == 0 {
            return Some(z);
        }
    }
    None
}

fn roots_impl(coeffs: &[f64], polished: bool) -> Result<Vec<Complex64>, IdentError> {
    let lead = match coeffs.first() {
        Some(&v) => v,
        None => return Err(IdentError::ZeroLeading { value: 0.0 }),
    };
    if let Some((index, &value)) = coeffs.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(IdentError::BadCoefficient { index, value });
    }
    if lead == 0.0 {
        return Err(IdentError::ZeroLeading { value: lead });
    }
    // Strip trailing zeros: roots at the origin.
    let mut end = coeffs.len();
    while end > 1 && coeffs[end - 1] == 0.0 {
        end -= 1;
    }
    let zeros_at_origin = coeffs.len() - end;
    let c: Vec<f64> = coeffs[..end].iter().map(|v| v / lead).collect();
    let n = c.len() - 1;
    let mut roots: Vec<Complex64> = Vec::with_capacity(coeffs.len() - 1);
    if n == 1 {
        roots.push(Complex64::new(-c[1], 0.0));
    } else if n >= 2 {
        // Polished roots start from Aberth's (O(n^2) per sweep), made an exact conjugate set;
        // the companion matrix's Schur form (O(n^3)) when that fails.
        let aberth = if polished {
            aberth_roots_from(&c, &[]).and_then(|z| conjugate_set(&z))
        } else {
            None
        };
        let raw = match aberth {
            Some(z) => z,
            None => companion_eigenvalues(&c)?,
        };
        // Polish on the caller's coefficients (dividing by the leading one would round them).
        let original = &coeffs[..end];
        if polished {
            for i in 0..raw.len() {
                roots.push(polish(original, raw[i], &raw, i));
            }
        } else {
            roots.extend_from_slice(&raw);
        }
    }
    roots.extend(std::iter::repeat(Complex64::new(0.0, 0.0)).take(zeros_at_origin));
    Ok(roots)
}

/// A root without a conjugate partner is taken as real when its imaginary part is at most this
/// fraction of its modulus (Aberth's roots of a real polynomial are real only to its accuracy).
const REAL_ROOT_TOL: f64 = 1e-7;

/// A root `z` and the nearest other root `w` are a conjugate pair when `|w - conj z|` is below this
/// fraction of `|Im z|`.
const PAIR_TOL: f64 = 0.25;

/// Aberth's roots `z` of a real polynomial as an exact conjugate set, as the real Schur form gives
/// it: each pair replaced by the mean of `z` and `conj w` and its conjugate, each unpaired root with
/// a negligible imaginary part ([`REAL_ROOT_TOL`]) by its real part. None when a root fits neither
/// (the caller then uses the companion matrix).
fn conjugate_set(z: &[Complex64]) -> Option<Vec<Complex64>> {
    let n = z.len();
    let mut used = vec![false; n];
    let mut out = Vec::with_capacity(n);
    let mut upper: Vec<usize> = (0..n).filter(|&i| z[i].im > 0.0).collect();
    upper.sort_by(|&a, &b| z[b].im.total_cmp(&z[a].im));
    for &i in &upper {
        let target = z[i].conj();
        let partner = (0..n)
            .filter(|&j| j != i && !used[j] && z[j].im < 0.0)
            .min_by(|&a, &b| (z[a] - target).norm().total_cmp(&(z[b] - target).norm()));
        if let Some(j) = partner {
            if (z[j] - target).norm() < PAIR_TOL * z[i].im {
                used[i] = true;
                used[j] = true;
                let m = (z[i] + z[j].conj()) * 0.5;
                out.push(m);
                out.push(m.conj());
            }
        }
    }
    for i in 0..n {
        if !used[i] {
            if z[i].im.abs() > REAL_ROOT_TOL * z[i].norm() {
                return None;
            }
            out.push(Complex64::new(z[i].re, 0.0));
        }
    }
    Some(out)
}

/// Eigenvalues of the balanced companion matrix of the monic `c` (degree >= 2): real Schur form,
/// exact conjugate pairs.
fn companion_eigenvalues(c: &[f64]) -> Result<Vec<Complex64>, IdentError> {
    let n = c.len() - 1;
    {
        let mut m = DMatrix::<f64>::zeros(n, n);
        for j in 0..n {
            m[(0, j)] = -c[j + 1];
        }
        for i in 1..n {
            m[(i, i - 1)] = 1.0;
        }
        balance_parlett_reinsch(&mut m);
        let schur = Schur::try_new(m, f64::EPSILON, SCHUR_ITERATIONS_PER_ROOT * n.max(10))
            .ok_or(IdentError::RootsNotConverged { degree: n })?;
        let eig = schur.complex_eigenvalues();
        Ok(eig.iter().map(|z| Complex64::new(z.re, z.im)).collect())
    }
}

/// Schur iterations allowed per eigenvalue (for at least 10 of them): the QR algorithm needs
/// about 2 to 3 per eigenvalue; 100 only stops an iteration that does not converge.
const SCHUR_ITERATIONS_PER_ROOT: usize = 100;

/// A polishing step is kept only when shorter than this fraction of the distance to the nearest
/// other eigenvalue, so it cannot jump to a neighbouring root.
const MAX_STEP_PER_ROOT_GAP: f64 = 0.1;

/// Value and derivative of the polynomial `c` (highest power first) at z (Horner, f64).
fn horner(c: &[f64], z: Complex64) -> (Complex64, Complex64) {
    let mut p = Complex64::new(c[0], 0.0);
    let mut dp = Complex64::new(0.0, 0.0);
    for &ck in &c[1..] {
        dp = dp * z + p;
        p = p * z + ck;
    }
    (p, dp)
}

/// A double-double number `hi + lo` (|lo| <= ulp(hi) / 2), about 106 bits of mantissa.
#[derive(Clone, Copy)]
struct Dd {
    hi: f64,
    lo: f64,
}

/// Error-free sum: `a + b = s + e` exactly (Knuth's TwoSum).
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

impl Dd {
    #[inline]
    fn renorm(hi: f64, lo: f64) -> Dd {
        let s = hi + lo;
        Dd {
            hi: s,
            lo: lo - (s - hi),
        }
    }
    #[inline]
    fn mul_f64(self, x: f64) -> Dd {
        // Error-free product of the high parts through a fused multiply-add.
        let p = self.hi * x;
        let e = self.hi.mul_add(x, -p);
        Dd::renorm(p, e + self.lo * x)
    }
    #[inline]
    fn add(self, o: Dd) -> Dd {
        let (s, e) = two_sum(self.hi, o.hi);
        Dd::renorm(s, e + self.lo + o.lo)
    }
    #[inline]
    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

/// `c(z)` for real `c` (highest power first) and a double-precision z, evaluated in double-double
/// arithmetic and rounded once. Near a cluster of roots the terms of the plain Horner sum cancel
/// to many digits, and its rounding error (about eps x sum |c_k| |z|^k) can exceed the value
/// itself; here that error is about eps^2 x the same sum, so Newton steps can reach the root to
/// full double precision where plain Horner stalls (compensated Horner, Graillat, Langlois and
/// Louvet 2005, in complex form).
fn horner_dd(c: &[f64], z: Complex64) -> Complex64 {
    let mut re = Dd { hi: c[0], lo: 0.0 };
    let mut im = Dd { hi: 0.0, lo: 0.0 };
    for &ck in &c[1..] {
        let nre = re.mul_f64(z.re).add(im.mul_f64(z.im).neg());
        let nim = re.mul_f64(z.im).add(im.mul_f64(z.re));
        re = nre.add(Dd { hi: ck, lo: 0.0 });
        im = nim;
    }
    Complex64::new(re.hi + re.lo, im.hi + im.lo)
}

/// Newton polishing of the eigenvalue `all[idx]` on the original polynomial `c`: the value comes
/// from [`horner_dd`], the derivative from plain Horner. A step is kept only if it lowers |c(z)|
/// and is small against the distance to the nearest other eigenvalue (so it cannot jump to a
/// neighbouring root); at most `POLISH_STEPS` steps.
fn polish(c: &[f64], z0: Complex64, all: &[Complex64], idx: usize) -> Complex64 {
    const POLISH_STEPS: usize = 4;
    let min_dist = all
        .iter()
        .enumerate()
        .filter(|(j, _)| *j != idx)
        .map(|(_, w)| (w - z0).norm())
        .fold(f64::INFINITY, f64::min);
    let mut z = z0;
    let mut pz = horner_dd(c, z);
    for _ in 0..POLISH_STEPS {
        let (_, dp) = horner(c, z);
        if dp.norm() == 0.0 || pz.norm() == 0.0 {
            break;
        }
        let step = pz / dp;
        if step.norm().is_nan() || step.norm() >= MAX_STEP_PER_ROOT_GAP * min_dist {
            break;
        }
        let mut zn = z - step;
        if z.im == 0.0 {
            zn.im = 0.0;
        }
        if zn == z {
            break;
        }
        let pn = horner_dd(c, zn);
        if pn.norm() < pz.norm() {
            z = zn;
            pz = pn;
        } else {
            break;
        }
    }
    z
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted(mut r: Vec<Complex64>) -> Vec<Complex64> {
        r.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
        r
    }

    /// Aberth's roots against the companion matrix's (the definition: the same set) on seeded
    /// random real polynomials of degree 1..60 with roots inside and outside the unit circle, as
    /// a trial C of the ARMA search has them; started on the circle and from nearby roots.
    #[test]
    fn aberth_roots_match_the_companion_matrix() {
        let mut uniform = crate::linalg::xorshift_uniform(0x2545_f491_4f6c_dd1d_u64);
        // Runs that fell back to the companion matrix, started cold and warm.
        let mut fallbacks = [0usize; 2];
        for case in 0..300 {
            let n = 1 + case % 60;
            let mut roots = Vec::new();
            while roots.len() < n {
                let r = 0.3 + 0.9 * uniform();
                let th = std::f64::consts::PI * uniform();
                if roots.len() + 2 <= n && uniform() < 0.8 {
                    let z = Complex64::from_polar(r, th);
                    roots.push(z);
                    roots.push(z.conj());
                } else {
                    roots.push(Complex64::new(if uniform() < 0.5 { r } else { -r }, 0.0));
                }
            }
            let c = crate::arma::poly_from_roots(&roots);
            // Cold (on the circle), and warm from the roots of a nearby polynomial (each root
            // moved by 1e-3 of its modulus, as between two trial steps of a search).
            let start: Vec<Complex64> = roots
                .iter()
                .enumerate()
                .map(|(k, r)| r * (1.0 + Complex64::from_polar(1e-3, k as f64)))
                .collect();
            for (warm, got) in [
                (false, aberth_roots(&c)),
                (true, aberth_roots_from(&c, &start)),
            ] {
                let Some(got) = got else {
                    fallbacks[usize::from(warm)] += 1;
                    continue;
                };
                let want = polynomial_roots(&c).unwrap_or_default();
                assert_eq!(got.len(), want.len());
                for w in &want {
                    let d = got
                        .iter()
                        .map(|g| (g - w).norm())
                        .fold(f64::INFINITY, f64::min);
                    // Clustered roots are ill-conditioned for both methods: the tolerance is on the
                    // polynomial's value, scaled by its size there.
                    let scale: f64 =
                        c.iter().map(|v| v.abs()).sum::<f64>() * w.norm().max(1.0).powi(n as i32);
                    let nearest = got
                        .iter()
                        .min_by(|a, b| (*a - w).norm().total_cmp(&(*b - w).norm()));
                    let val = nearest
                        .map(|g| horner(&c, *g).0.norm())
                        .unwrap_or(f64::INFINITY);
                    assert!(
                        d < 1e-6 || val <= 1e-11 * scale,
                        "case {case} n {n} warm {warm}: {w} nearest {d} away, |p| {val}"
                    );
                }
            }
        }
        assert!(
            fallbacks[0] <= 3 && fallbacks[1] <= 3,
            "{fallbacks:?} of 300 cases (cold, warm) fell back to the companion matrix"
        );
    }

    /// Polished roots (from Aberth's, made a conjugate set) against the polished companion-matrix
    /// eigenvalues (the previous method) on seeded random real polynomials of degree 2..60 with
    /// conjugate pairs and real roots inside and outside the unit circle, some lightly damped
    /// poles near z = 1 as at 200 Hz: the same set, and every complex root's conjugate in it bit
    /// for bit.
    #[test]
    fn polished_roots_are_a_conjugate_set_matching_the_companion_matrix() {
        let mut uniform = crate::linalg::xorshift_uniform(0x1234_5678_9abc_def1_u64);
        for case in 0..200 {
            let n = 2 + case % 59;
            let mut roots = Vec::new();
            while roots.len() < n {
                if roots.len() + 2 <= n && uniform() < 0.8 {
                    // Half of the pairs lightly damped near z = 1 (1-20 Hz at 200 Hz).
                    let z = if uniform() < 0.5 {
                        let w = std::f64::consts::TAU * (1.0 + 19.0 * uniform()) / 200.0;
                        Complex64::from_polar((-0.02 * w * uniform()).exp(), w)
                    } else {
                        Complex64::from_polar(
                            0.3 + 0.9 * uniform(),
                            std::f64::consts::PI * uniform(),
                        )
                    };
                    roots.push(z);
                    roots.push(z.conj());
                } else {
                    let r = 0.3 + 0.9 * uniform();
                    roots.push(Complex64::new(if uniform() < 0.5 { r } else { -r }, 0.0));
                }
            }
            let c = crate::arma::poly_from_roots(&roots);
            let got = polynomial_roots(&c).unwrap_or_default();
            let raw = companion_eigenvalues(&c).unwrap_or_default();
            let want: Vec<Complex64> = (0..raw.len())
                .map(|i| polish(&c, raw[i], &raw, i))
                .collect();
            assert_eq!(got.len(), n, "case {case}");
            for z in &got {
                assert!(
                    got.iter().any(|w| *w == z.conj()),
                    "case {case}: {z} without its conjugate"
                );
            }
            let scale: f64 = c.iter().map(|v| v.abs()).sum();
            for w in &want {
                let nearest = got
                    .iter()
                    .min_by(|a, b| (*a - w).norm().total_cmp(&(*b - w).norm()))
                    .copied()
                    .unwrap_or(Complex64::new(f64::NAN, 0.0));
                let d = (nearest - w).norm();
                let val = horner(&c, nearest).0.norm();
                assert!(
                    d < 1e-9 || val <= 1e-12 * scale * w.norm().max(1.0).powi(n as i32),
                    "case {case} n {n}: {w} nearest {nearest} ({d} away, |p| {val})"
                );
            }
        }
    }

    #[test]
    fn aberth_by_hand() {
        // (z - 0.5)(z + 0.25)(z^2 - z + 0.5): roots 0.5, -0.25, 0.5 +- 0.5i.
        let c = [1.0, -1.25, 0.625, 0.0, -0.0625];
        let got = aberth_roots(&c).unwrap_or_default();
        assert_eq!(got.len(), 4);
        for w in [
            Complex64::new(-0.25, 0.0),
            Complex64::new(0.5, -0.5),
            Complex64::new(0.5, 0.0),
            Complex64::new(0.5, 0.5),
        ] {
            let d = got
                .iter()
                .map(|g| (g - w).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-12, "{w}: nearest root {d} away in {got:?}");
        }
        assert!(aberth_roots(&[0.0, 1.0]).is_none());
        assert!(aberth_roots(&[1.0, f64::NAN]).is_none());
    }

    /// Unpolished roots are the same set as polished ones to eps x condition: by hand for
    /// (z - 0.5)(z + 0.25)(z^2 - z + 0.5) (roots 0.5, -0.25, 0.5 +- 0.5i).
    #[test]
    fn unpolished_roots_by_hand() {
        // (z^2 - 0.25 z - 0.125)(z^2 - z + 0.5) = z^4 - 1.25 z^3 + 0.625 z^2 + 0 z - 0.0625
        let c = [1.0, -1.25, 0.625, 0.0, -0.0625];
        let want = [
            Complex64::new(-0.25, 0.0),
            Complex64::new(0.5, -0.5),
            Complex64::new(0.5, 0.0),
            Complex64::new(0.5, 0.5),
        ];
        for got in [polynomial_roots_unpolished(&c), polynomial_roots(&c)] {
            let got = got.unwrap_or_default();
            assert_eq!(got.len(), 4);
            for w in &want {
                let d = got
                    .iter()
                    .map(|g| (g - w).norm())
                    .fold(f64::INFINITY, f64::min);
                assert!(d < 1e-12, "{w}: nearest root {d} away in {got:?}");
            }
        }
    }

    #[test]
    fn quadratic_by_hand() {
        // z^2 - 3z + 2 = (z-1)(z-2)
        let r = sorted(polynomial_roots(&[1.0, -3.0, 2.0]).unwrap());
        assert!((r[0].re - 1.0).abs() < 1e-14 && (r[1].re - 2.0).abs() < 1e-14);
        // 2z^2 + 2 = 0 -> +-i
        let r = sorted(polynomial_roots(&[2.0, 0.0, 2.0]).unwrap());
        assert!(r[0].re.abs() < 1e-14 && (r[0].im + 1.0).abs() < 1e-14);
        assert!((r[1].im - 1.0).abs() < 1e-14);
        // z^3 - z^2 = z^2 (z - 1): two zeros at the origin
        let r = sorted(polynomial_roots(&[1.0, -1.0, 0.0, 0.0]).unwrap());
        assert_eq!(r.len(), 3);
        assert!((r[2].re - 1.0).abs() < 1e-14 && r[0].norm() == 0.0);
        let r = polynomial_roots(&[4.0, 2.0]).unwrap();
        assert_eq!(r, vec![Complex64::new(-0.5, 0.0)]);
        assert!(polynomial_roots(&[5.0]).unwrap().is_empty());
    }

    #[test]
    fn bad_inputs() {
        assert!(matches!(
            polynomial_roots(&[]),
            Err(IdentError::ZeroLeading { .. })
        ));
        assert!(matches!(
            polynomial_roots(&[0.0, 1.0]),
            Err(IdentError::ZeroLeading { .. })
        ));
        let e = polynomial_roots(&[1.0, f64::NAN]).unwrap_err();
        assert!(matches!(e, IdentError::BadCoefficient { index: 1, .. }));
        assert!(e.to_string().contains("coefficient 1"));
    }
}
