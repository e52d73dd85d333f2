"""Reference values for vibmode_spectra's multitaper harmonic F-test (dpss, harmonic_f_test).

Writes tools/reference/data/harmonic.json. Run from the repository root:
python3 tools/reference/harmonic.py

Versions: numpy and scipy as in tools/reference/requirements.txt (recorded in the JSON's "versions").

Independent implementation: the Slepian tapers from scipy.signal.windows.dpss(n, nw, k, norm=2)
(scipy's own tridiagonal eigensolver and sign convention); the eigencoefficients by numpy's FFT of
the mean-removed record times each taper, zero-padded to pad * n; mu = sum_k U_k y_k / sum_k U_k^2
with U_k = sum_t v_k(t); F = (K - 1) |mu|^2 sum U_k^2 / sum_k |y_k - mu U_k|^2 (Thomson 1982,
Percival & Walden 1993 eq. 499c); the p-value from scipy.stats.f.sf(F, 2, 2K - 2).

Cases: numpy.random.default_rng(20261126) draws records of white noise plus 0-2 sinusoids
(amplitude 0.2-2, frequency 2-20 Hz at fs 50 Hz) for (n, nw, k, pad) in the list below.
Tolerances (the Rust test): tapers 1e-9 absolute; F 1e-6 relative where F > 1e-3 (else 1e-9
absolute); p-values 1e-9 absolute.
"""
import json

import numpy as np
import scipy
from scipy.signal.windows import dpss
from scipy.stats import f as fdist

rng = np.random.default_rng(20261126)
fs = 50.0
cases = []
for n, nw, k, pad in [(64, 2.0, 3, 2), (200, 3.0, 5, 1), (512, 4.0, 7, 2), (513, 3.5, 6, 1)]:
    t = np.arange(n) / fs
    x = rng.standard_normal(n)
    for _ in range(rng.integers(0, 3)):
        x += rng.uniform(0.2, 2.0) * np.cos(2 * np.pi * rng.uniform(2, 20) * t + rng.uniform(0, 6.3))
    v = dpss(n, nw, k, norm=2)
    u = v.sum(axis=1)
    xm = x - x.mean()
    nfft = pad * n
    y = np.fft.rfft(v * xm[None, :], n=nfft, axis=1)
    mu = (u[:, None] * y).sum(axis=0) / (u ** 2).sum()
    resid = (np.abs(y - mu[None, :] * u[:, None]) ** 2).sum(axis=0)
    F = (k - 1) * np.abs(mu) ** 2 * (u ** 2).sum() / resid
    p = fdist.sf(F, 2, 2 * k - 2)
    cases.append({"n": n, "nw": nw, "k": k, "pad": pad, "fs": fs, "x": x.tolist(),
                  "tapers": v.tolist(), "f": F.tolist(), "p": p.tolist(),
                  "amplitude": (2 * np.abs(mu)).tolist()})

out = {
    "versions": {"numpy": np.__version__, "scipy": scipy.__version__},
    "tolerance": "tapers 1e-9 abs; F 1e-6 rel (1e-9 abs below 1e-3); p 1e-9 abs; amplitude 1e-9 rel to max",
    "cases": cases,
}
with open("tools/reference/data/harmonic.json", "w") as f:
    json.dump(out, f)
print(f"{len(cases)} cases")
