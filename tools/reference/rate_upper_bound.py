"""Reference values for vibmode_fleet::stats::rate_upper_bound (the one-sided Clopper-Pearson
upper bound of a rate from k events in n trials), from scipy.

Writes tools/reference/data/rate_upper_bound.json. Run from the repository root:
python3 tools/reference/rate_upper_bound.py

Versions: scipy as in tools/reference/requirements.txt (recorded in the JSON's "versions").

Cases: k flagged of n held-out drives, n 1..2000, confidence 0.8..0.999:
scipy.stats.beta.ppf(confidence, k + 1, n - k) (1 when k == n).

Rust tolerance (crates/vibmode-fleet/tests/integration/reference.rs): 1e-9 absolute plus 1e-7
relative (statrs' inverse of the regularized incomplete beta function against scipy's boost one).
"""
import json

import scipy
import scipy.stats

cases = []
for n in (1, 2, 3, 5, 8, 20, 40, 100, 300, 2000):
    for k in sorted({0, 1, 2, n // 10, n // 2, n - 1, n}):
        if k > n:
            continue
        for conf in (0.8, 0.95, 0.99, 0.999):
            bound = 1.0 if k == n else float(scipy.stats.beta.ppf(conf, k + 1, n - k))
            cases.append({"k": k, "n": n, "confidence": conf, "bound": bound})

out = {
    "versions": {"scipy": scipy.__version__},
    "tolerance": "1e-9 absolute + 1e-7 relative",
    "cases": cases,
}
with open("tools/reference/data/rate_upper_bound.json", "w") as f:
    json.dump(out, f)
