"""Reference values for vibmode_fleet::suspension::fiducial_z (the Behrens-Fisher fiducial
normal score of a difference whose variance is a sum of estimated parts), by quadrature in scipy.

Writes tools/reference/data/fiducial_z.json. Run from the repository root:
python3 tools/reference/fiducial_z.py

Versions: scipy as in tools/reference/requirements.txt (recorded in the JSON's "versions").

Definition: parts (v_i, k_i); given its estimate v_i with k_i degrees of freedom a part's variance
is v_i k_i / u_i with u_i ~ chi^2(k_i), and the tail probability of d is
p = E[Phi(-|d| / sqrt(sum_i v_i k_i / u_i))], z = -Phi^-1(p) with the sign of d. Here with two
parts, integrated over both chi-squares by Gauss-Legendre quadrature in ln u (4000 nodes each,
u from 1e-12 to k + 80 sqrt(2k)); one part is Student's t exactly (checked against
scipy.stats.t to 1e-6 relative). And a part that shares a factor shared_df / u3, u3 ~
chi^2(shared_df) (vibmode_fleet::suspension::fiducial_z_shared: a drive's
spring variance as its scale times the reference's proportion), beside a part of its own:
a triple quadrature over quantile-bounded ranges, 240 nodes each (checked against the two-part
quadrature with the factor nearly fixed, 20000 degrees of freedom, to 1e-3 relative).

Rust tolerance (crates/vibmode-fleet/tests/integration/reference.rs): 0.03 in z. vibmode's
value is a Monte Carlo average over 32768 fixed draws whose relative error in p is the
integrand's coefficient of variation (printed by this script, "cv", up to 8 here) over
sqrt(32768) = 181: at most 4.4 %, 0.013 in z at |z| near 3.4, so 0.03 is over 2 standard
errors.
"""
import json

import numpy as np
import scipy
import scipy.stats


def log_nodes(k, n=4000):
    """Gauss-Legendre nodes and weights of the chi^2(k) density in y = ln u, y from ln 1e-12 to
    ln(k + 80 sqrt(2k)) (the density is smooth in y and negligible beyond)."""
    x, w = np.polynomial.legendre.leggauss(n)
    lo, hi = np.log(1e-12), np.log(k + 80 * np.sqrt(2 * k))
    y = lo + (hi - lo) * (x + 1) / 2
    u = np.exp(y)
    return u, w * (hi - lo) / 2 * scipy.stats.chi2.pdf(u, k) * u


def tail(d, parts):
    (v1, k1), (v2, k2) = parts
    u1, w1 = log_nodes(k1)
    u2, w2 = log_nodes(k2)
    var = v1 * k1 / u1[:, None] + v2 * k2 / u2[None, :]
    return float(w1 @ scipy.stats.norm.cdf(-abs(d) / np.sqrt(var)) @ w2)


def quantile_nodes(k, n=240):
    """Gauss-Legendre nodes and weights of the chi^2(k) density in y = ln u, y between the
    density's 1e-14 and 1 - 1e-14 quantiles (so that a narrow density is resolved too)."""
    x, w = np.polynomial.legendre.leggauss(n)
    lo, hi = np.log(scipy.stats.chi2.ppf(1e-14, k)), np.log(scipy.stats.chi2.isf(1e-14, k))
    y = lo + (hi - lo) * (x + 1) / 2
    u = np.exp(y)
    return u, w * (hi - lo) / 2 * scipy.stats.chi2.pdf(u, k) * u


def tail_shared(d, shared, own, shared_df):
    """The same with the part `shared` (v1, k1) also multiplied by a factor shared_df / u3, u3 ~
    chi^2(shared_df) (a drive's variance read as its scale times the reference's proportion),
    plus the part `own` (v2, k2): a triple quadrature (quantile_nodes per chi-square)."""
    (v1, k1), (v2, k2) = shared, own
    u1, w1 = quantile_nodes(k1)
    u2, w2 = quantile_nodes(k2)
    u3, w3 = quantile_nodes(shared_df)
    total = 0.0
    for a, wa in zip(u3, w3):
        var = v1 * k1 / u1[:, None] * (shared_df / a) + v2 * k2 / u2[None, :]
        total += wa * float(w1 @ scipy.stats.norm.cdf(-abs(d) / np.sqrt(var)) @ w2)
    return total


def cv(d, parts, n=200_000, seed=1):
    """The coefficient of variation of the integrand (the Monte Carlo's error per draw)."""
    r = np.random.default_rng(seed)
    var = sum(v * k / r.chisquare(k, n) for v, k in parts)
    g = scipy.stats.norm.cdf(-abs(d) / np.sqrt(var))
    return float(g.std() / g.mean())


# One part: Student's t.
for k in (7, 15):
    for t in (-4.0, -2.0):
        p = tail(t, [(1.0, k), (1e-12, 7)])
        assert abs(p / scipy.stats.t.cdf(t, k) - 1) < 1e-6, (k, t, p)

cases = []
for parts in ([(0.0036, 7), (0.0016, 15)],   # a drive of 8 records against a baseline of 16
              [(0.0025, 7), (0.0005, 40)],   # a drive against a precise reference
              [(0.001, 7), (0.001, 7)],      # two equal parts
              [(0.0004, 21), (0.0016, 15)]):  # a trend of 3 drives against a baseline
    sd = np.sqrt(sum(v for v, _ in parts))
    for t in (-5.0, -4.0, -3.227, -2.5, -1.0, 2.0, 3.5):
        p = tail(t * sd, parts)
        z = float(scipy.stats.norm.isf(p))
        cases.append({"d": t * sd, "parts": parts, "z": z if t >= 0 else -z,
                      "cv": round(cv(t * sd, parts), 2)})
        print(cases[-1])

# The triple quadrature's nodes suffice: with a factor of 20000 degrees of freedom (nearly
# fixed) it is the two-part tail of 4000 nodes each to 1e-3 relative.
for t in (-4.0, -2.5):
    a = tail_shared(t * 0.07, (0.0036, 21), (0.0016, 15), 20000)
    b = tail(t * 0.07, [(0.0036, 21), (0.0016, 15)])
    assert abs(a / b - 1) < 1e-3, (t, a, b)

# A shared factor: a drive's spring variance as its scale (21 degrees of freedom) times the
# reference's proportion (15: the baseline alone; 57: with 6 normal drives), against the
# reference's own part.
rs = np.random.default_rng(2)
for shared, own, k in (((0.0036, 21), (0.0016, 15), 15),
                       ((0.0012, 21), (0.0008, 57), 57)):
    sd = np.sqrt(shared[0] + own[0])
    for t in (-5.0, -3.227, -2.0, 3.0):
        p = tail_shared(t * sd, shared, own, k)
        z = float(scipy.stats.norm.isf(p))
        n = 200_000
        var = (shared[0] * shared[1] / rs.chisquare(shared[1], n) * k / rs.chisquare(k, n)
               + own[0] * own[1] / rs.chisquare(own[1], n))
        g = scipy.stats.norm.cdf(-abs(t * sd) / np.sqrt(var))
        cases.append({"d": t * sd, "parts": [list(shared), list(own)], "shared": [True, False],
                      "shared_df": k, "z": z if t >= 0 else -z,
                      "cv": round(float(g.std() / g.mean()), 2)})
        print(cases[-1])

out = {
    "versions": {"scipy": scipy.__version__, "numpy": np.__version__},
    "tolerance": "0.03 in z (Monte Carlo of 32768 draws against quadrature)",
    "cases": cases,
}
with open("tools/reference/data/fiducial_z.json", "w") as f:
    json.dump(out, f)
