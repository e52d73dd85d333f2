"""Reference values for vibmode_vehicle::nnls (non-negative least squares), from scipy.

Writes tools/reference/data/nnls.json. Run from the repository root: python3 tools/reference/nnls.py

Versions: numpy and scipy as in tools/reference/requirements.txt (recorded in the JSON's "versions").

Cases: numpy.random.default_rng(20261125) draws A (m x n, standard normal, columns scaled by
10^U(-2, 3) as the model update's unknowns differ in scale by orders of magnitude) and b (standard
normal), for (m, n) = (8, 3), (20, 6), (40, 10), (60, 14) and five draws each; scipy.optimize.nnls
(Lawson-Hanson) gives x. The Rust test forms A^T A and A^T b and compares x within 1e-8 relative to
max |x| (the normal equations square the condition number; scipy works on A itself).
"""
import json

import numpy as np
import scipy
from scipy.optimize import nnls

rng = np.random.default_rng(20261125)
cases = []
for m, n in [(8, 3), (20, 6), (40, 10), (60, 14)]:
    for _ in range(5):
        a = rng.standard_normal((m, n)) * 10.0 ** rng.uniform(-2, 3, n)
        b = rng.standard_normal(m)
        x, _ = nnls(a, b)
        cases.append({"m": m, "n": n, "a": a.ravel().tolist(), "b": b.tolist(), "x": x.tolist()})

out = {
    "versions": {"numpy": np.__version__, "scipy": scipy.__version__},
    "tolerance": "1e-8 relative to max |x|",
    "cases": cases,
}
with open("tools/reference/data/nnls.json", "w") as f:
    json.dump(out, f)
print(f"{len(cases)} cases, {sum(int((np.array(c['x']) == 0).sum()) for c in cases)} unknowns at 0")
