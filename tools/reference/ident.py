"""Reference values for crates/vibmode-ident (AR and ARMA identification).

Writes tools/reference/data/ident.json and ident_roots.json. Run from the repository root:

    python3 tools/reference/ident.py          # everything (the ARMA(20,20) statsmodels fit takes minutes)
    python3 tools/reference/ident.py ar       # only the AR section of ident.json (+ roots)
    python3 tools/reference/ident.py roots    # only ident_roots.json

Pinned versions (tools/reference/requirements.txt): Python 3.11, numpy 2.1.3, scipy 1.14.1,
statsmodels 0.14.4.

Contents
--------
* "ar": for a few seeded signals (stored) and orders 2..30:
    - statsmodels.regression.linear_model.yule_walker(x, order, method="mle") -> rho, sigma
      (we store sigma**2); A-convention coefficients are [1, -rho].
    - statsmodels.regression.linear_model.burg(x, order) -> rho, sigma2, and the Burg partial
      autocorrelations from statsmodels.tsa.stattools.pacf_burg.
    - Burg recomputed independently in numpy long double (80-bit) with the denominators summed
      directly ("burg_a_ld", "burg_var_ld"). statsmodels updates the Burg denominator by the
      recursion d_{m+1} = (1 - k_m^2) d_m - ..., which loses up to 2.6e-8 relative on the lightly
      damped "two_modes" signal; the long-double values agree with a direct float64 computation to
      5e-13. Rust tolerance: 1e-8 vs statsmodels where statsmodels agrees with the long-double
      reference to 1e-9, else 1e-7; 1e-10 vs the long-double reference everywhere.
    - forward-backward least squares solved independently with numpy.linalg.lstsq on the stacked
      forward and backward regression (x demeaned; rows t = p..N-1), noise variance = residual sum
      of squares / (2 (N - p)).
  Rust tolerance: 1e-8 relative (max-norm of the coefficient difference over max-norm of the
  coefficients; relative difference of the variances).
* "arma": seeded ARMA signals (stored, already demeaned) and statsmodels
  ARIMA(p, 0, q, trend="n") fits (exact Gaussian likelihood, Kalman filter). We store the
  statsmodels parameters converted to our convention (a = [1, -ar], c = [1, ma]), its sigma2, the
  fit time in seconds, and "lambda_cond": the mean squared one-step prediction error of the
  statsmodels parameters evaluated by the same conditional predictor as vibmode
  (w = lfilter(a, [1], y)[p:], eps = lfilter([1], c, w), lambda = mean(eps**2)), so the Rust test
  can compare like with like.
  Rust requirement: vibmode's quadratic prediction-error lambda <= 1.001 * lambda_cond.
  (Fit times were measured on a shared 2-core machine while other jobs ran; indicative only.)
* ident_roots.json (written by `python3 tools/reference/ident.py roots`, which skips the slow ARMA
  part): an order-60 A(z) built in double precision from modes at 0.5, 1.0, 2.0 Hz (fs = 200 Hz),
  25 lightly damped modes between 25 and 97 Hz and 4 real poles, and the roots of exactly those
  double coefficients computed by mpmath.polyroots at 50 digits (mpmath 1.3.0). The rounded
  coefficients move the intended 0.5-2 Hz roots by up to 2e-3 relative (intrinsic ill-conditioning
  of the monomial basis), so the reference is the exact roots of the stored coefficients, not the
  intended modes. Rust tolerance: 1e-6 relative on every mode frequency (numpy.roots, a balanced
  companion + LAPACK, achieves 4e-11).
"""

import json
import os
import time
import warnings

import numpy as np
import scipy
import scipy.signal as sig
import statsmodels
from statsmodels.regression.linear_model import burg, yule_walker
from statsmodels.tsa.arima.model import ARIMA
from statsmodels.tsa.stattools import pacf_burg

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "ident.json")


def modes_poly(modes, fs):
    a = np.array([1.0])
    for f, zeta in modes:
        w0 = 2 * np.pi * f
        s = complex(-zeta * w0, w0 * np.sqrt(1 - zeta**2))
        z = np.exp(s / fs)
        a = np.convolve(a, [1.0, -2 * z.real, abs(z) ** 2])
    return a


def simulate(a, c, n, rng, burn=4000):
    e = rng.standard_normal(n + burn)
    return sig.lfilter(c, a, e)[burn:]


def fb_ls(x, p):
    x = x - x.mean()
    n = len(x)
    rows, rhs = [], []
    for t in range(p, n):
        rows.append([x[t - k] for k in range(1, p + 1)])
        rhs.append(-x[t])
        rows.append([x[t - p + k] for k in range(1, p + 1)])
        rhs.append(-x[t - p])
    m = np.array(rows)
    b = np.array(rhs)
    sol, *_ = np.linalg.lstsq(m, b, rcond=None)
    res = b - m @ sol
    return np.concatenate([[1.0], sol]), float(res @ res / (2 * (n - p)))


def burg_longdouble(x, p):
    x = np.asarray(x, dtype=np.longdouble)
    x = x - x.mean()
    n = len(x)
    f = x.copy()
    b = x.copy()
    a = np.zeros(p + 1, dtype=np.longdouble)
    a[0] = 1
    for m in range(1, p + 1):
        fm = f[m:n].copy()
        bm = b[m - 1 : n - 1].copy()
        k = -2 * np.dot(fm, bm) / (np.dot(fm, fm) + np.dot(bm, bm))
        f[m:n] = fm + k * bm
        b[m:n] = bm + k * fm
        prev = a.copy()
        for i in range(1, m):
            a[i] = prev[i] + k * prev[m - i]
        a[m] = k
    var = (np.dot(f[p:], f[p:]) + np.dot(b[p:], b[p:])) / (2 * (n - p))
    return [float(v) for v in a], float(var)


def ar_cases():
    rng = np.random.default_rng(20240601)
    fs = 200.0
    signals = {
        "ar2_n500": simulate([1.0, -1.2, 0.6], [1.0], 500, rng) + 3.0,
        "two_modes_n2048": simulate(modes_poly([(1.0, 0.1), (9.0, 0.05)], fs), [1.0, 0.4], 2048, rng),
        "arma_n300": simulate([1.0, -0.5, 0.3], [1.0, 0.8, 0.4], 300, rng) - 1.5,
    }
    orders = {"ar2_n500": [2, 4, 10], "two_modes_n2048": [2, 10, 30], "arma_n300": [3, 8, 20]}
    out = []
    for name, x in signals.items():
        for p in orders[name]:
            rho, sigma = yule_walker(x, order=p, method="mle")
            brho, bsig2 = burg(x, order=p)
            pacf, _ = pacf_burg(x, nlags=p)
            ls_a, ls_var = fb_ls(x, p)
            ld_a, ld_var = burg_longdouble(x, p)
            out.append(
                {
                    "name": name,
                    "order": p,
                    "x": x.tolist(),
                    "yw_a": [1.0] + (-rho).tolist(),
                    "yw_var": float(sigma**2),
                    "burg_a": [1.0] + (-brho).tolist(),
                    "burg_var": float(bsig2),
                    "burg_pacf": pacf[1:].tolist(),
                    "burg_a_ld": ld_a,
                    "burg_var_ld": ld_var,
                    "ls_a": ls_a.tolist(),
                    "ls_var": ls_var,
                }
            )
    return out


def cond_errors(a, c, y):
    """eps_t for t >= p: w = A(q) y from measured samples only, then eps = w / C (zero ICs)."""
    p = len(a) - 1
    w = sig.lfilter(a, [1.0], y)[p:]
    return sig.lfilter([1.0], c, w)


def arma_cases():
    rng = np.random.default_rng(7)
    fs = 200.0
    cases = []
    # Numerators with zeros near z = 1 (as in accelerations) keep var(y) / lambda moderate, so the
    # zero-initial-condition transient does not dominate the criterion.
    hp = [1.0, -1.96, 0.9604]
    hp2 = np.convolve(hp, hp)
    four = modes_poly([(1.0, 0.1), (4.0, 0.05), (9.0, 0.03), (30.0, 0.1)], fs)
    four_c = np.convolve(hp2, [1.0, 0.5, 0.2, 0.1, 0.1])
    specs = [
        ("arma22_n1000", [1.0, -1.5, 0.8], [1.0, 0.5, 0.3], 1000, 2, 2),
        ("arma43_n1500", modes_poly([(2.0, 0.08), (11.0, 0.03)], fs), np.convolve(hp, [1.0, -0.3]),
         1500, 4, 3),
        ("arma66_n2048", modes_poly([(1.0, 0.1), (7.0, 0.02), (12.0, 0.04)], fs),
         np.convolve(hp2, [1.0, 0.6, 0.2]), 2048, 6, 6),
        ("arma88_n2048", four, four_c, 2048, 8, 8),
        ("arma2020_n2048", four, four_c, 2048, 20, 20),
    ]
    for name, a, c, n, p, q in specs:
        y = simulate(np.asarray(a), np.asarray(c), n, rng)
        y = y - y.mean()
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = ARIMA(y, order=(p, 0, q), trend="n").fit()
        dt = time.perf_counter() - t0
        ar = np.asarray(res.arparams)
        ma = np.asarray(res.maparams)
        a_sm = np.concatenate([[1.0], -ar])
        c_sm = np.concatenate([[1.0], ma])
        eps = cond_errors(a_sm, c_sm, y)
        cases.append(
            {
                "name": name,
                "p": p,
                "q": q,
                "y": y.tolist(),
                "true_a": list(map(float, a)),
                "true_c": list(map(float, c)),
                "sm_a": a_sm.tolist(),
                "sm_c": c_sm.tolist(),
                "sm_sigma2": float(res.params[-1]),
                "sm_fit_seconds": dt,
                "lambda_cond": float(np.mean(eps**2)),
            }
        )
        print(f"{name}: var(y) {y.var():.4g}, statsmodels fit {dt:.2f} s, sigma2 {res.params[-1]:.6g}, lambda_cond {np.mean(eps**2):.6g}")
    return cases


def roots_case():
    import mpmath

    mpmath.mp.dps = 50
    fs = 200.0
    modes = [(0.5, 0.1), (1.0, 0.05), (2.0, 0.05)] + [(f, 0.02) for f in np.linspace(25, 97, 25)]
    a = np.array([1.0])
    for f, zeta in modes:
        a = np.convolve(a, modes_poly([(f, zeta)], fs))
    for r in [0.5, -0.3, 0.8, 0.1]:
        a = np.convolve(a, [1.0, -r])
    roots = mpmath.polyroots([mpmath.mpf(float(x)) for x in a], maxsteps=800, extraprec=800)
    return {
        "mpmath": mpmath.__version__,
        "fs_hz": fs,
        "intended_modes": [list(m) for m in modes],
        "a": a.tolist(),
        "roots_re": [float(mpmath.re(r)) for r in roots],
        "roots_im": [float(mpmath.im(r)) for r in roots],
    }


def main():
    import sys

    out_roots = os.path.join(os.path.dirname(OUT), "ident_roots.json")
    with open(out_roots, "w") as f:
        json.dump(roots_case(), f)
    print("wrote", out_roots, os.path.getsize(out_roots), "bytes")
    if len(sys.argv) > 1 and sys.argv[1] == "roots":
        return
    if len(sys.argv) > 1 and sys.argv[1] == "relambda":
        # Recompute lambda_cond of the stored statsmodels parameters (no refit).
        with open(OUT) as f:
            data = json.load(f)
        for case in data["arma"]:
            eps = cond_errors(np.array(case["sm_a"]), np.array(case["sm_c"]), np.array(case["y"]))
            case["lambda_cond"] = float(np.mean(eps**2))
        with open(OUT, "w") as f:
            json.dump(data, f)
        print("recomputed lambda_cond in", OUT)
        return
    if len(sys.argv) > 1 and sys.argv[1] == "ar":
        # Regenerate only the AR section (deterministic), keep the slow ARMA section.
        with open(OUT) as f:
            data = json.load(f)
        data["ar"] = ar_cases()
        with open(OUT, "w") as f:
            json.dump(data, f)
        print("rewrote the AR section of", OUT)
        return
    data = {
        "versions": {
            "numpy": np.__version__,
            "scipy": scipy.__version__,
            "statsmodels": statsmodels.__version__,
        },
        "ar": ar_cases(),
        "arma": arma_cases(),
    }
    with open(OUT, "w") as f:
        json.dump(data, f)
    print("wrote", OUT, os.path.getsize(OUT), "bytes")


if __name__ == "__main__":
    main()
