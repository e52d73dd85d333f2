"""Reference values for vibmode_vehicle::update::noise_scale (how much of the sensors' expected
noise share the model update takes out of its normal equations: generalized total least squares,
capped at the whole share), from scipy.

Writes tools/reference/data/noise_scale.json. Run from the repository root:
python3 tools/reference/noise_scale.py

Versions: numpy and scipy as in tools/reference/requirements.txt (recorded in the JSON's "versions").

Cases: numpy.random.default_rng(20261126) draws, for n = 4, 8, 11, 13 (the update's augmented
normal matrices are 11-13 wide) and six draws each, a signal X (3n x n) and a noise E (2n x n),
standard normal with columns scaled by 10^U(-2, 2) (the unknowns differ in scale by orders of
magnitude), a noise level s = 10^U(0, 2) and a misjudged share c = U(0.5, 1.5):
raw = X^T X + s E^T E, noise = c s E^T E. scipy.linalg.eigh(noise, raw) gives the generalized
eigenvalues mu of noise v = mu raw v; the share is 1 / max(mu) when max(mu) > 1, else 1 (the
smallest lambda that makes raw - lambda noise singular, capped at 1).

Rust tolerance (crates/vibmode-vehicle/tests/integration/reference.rs): 1e-8 relative (Cholesky and a symmetric
eigensolver against LAPACK's generalized symmetric eigensolver, on matrices whose conditioning
reaches 1e8).
"""
import json

import numpy as np
import scipy
import scipy.linalg

rng = np.random.default_rng(20261126)
cases = []
for n in (4, 8, 11, 13):
    for _ in range(6):
        scale = 10.0 ** rng.uniform(-2, 2, n)
        x = rng.standard_normal((3 * n, n)) * scale
        e = rng.standard_normal((2 * n, n)) * scale
        s = 10.0 ** rng.uniform(0.0, 2.0)
        c = rng.uniform(0.5, 1.5)
        raw = x.T @ x + s * (e.T @ e)
        noise = c * s * (e.T @ e)
        mu = scipy.linalg.eigh(noise, raw, eigvals_only=True).max()
        share = 1.0 / mu if mu > 1.0 else 1.0
        cases.append({"n": n, "raw": raw.ravel().tolist(), "noise": noise.ravel().tolist(),
                      "share": float(share)})

out = {
    "versions": {"numpy": np.__version__, "scipy": scipy.__version__},
    "tolerance": "1e-8 relative",
    "cases": cases,
}
with open("tools/reference/data/noise_scale.json", "w") as f:
    json.dump(out, f)
print(f"{len(cases)} cases, {sum(1 for c in cases if c['share'] < 1.0)} with a share below 1")
