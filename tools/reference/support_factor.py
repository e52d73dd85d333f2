"""Reference values for vibmode_vehicle::update::support_factor (how many jackknife standard
deviations a supported model update's quantities must lie within their tolerance), from scipy.

Writes tools/reference/data/support_factor.json. Run from the repository root:
python3 tools/reference/support_factor.py

Versions: scipy as in tools/reference/requirements.txt (recorded in the JSON's "versions").

Cases: records R in 3..40 and quantities m in {1, 3, 11, 12, 20} (the update judges 3 body modes
and 8 springs and dampers: 11), confidence 0.95 simultaneous over the m two-sided intervals
(Bonferroni): scipy.stats.t.ppf(1 - 0.05 / (2 m), R - 1).

Rust tolerance (crates/vibmode-vehicle/tests/integration/reference.rs): 1e-9 relative (statrs'
inverse of the regularized incomplete beta function against scipy's boost-based one).
"""
import json

import scipy
import scipy.stats

cases = []
for records in list(range(3, 21)) + [24, 32, 40]:
    for m in (1, 3, 11, 12, 20):
        p = 1.0 - 0.05 / (2.0 * m)
        cases.append({"records": records, "quantities": m,
                      "factor": float(scipy.stats.t.ppf(p, records - 1))})

out = {
    "versions": {"scipy": scipy.__version__},
    "tolerance": "1e-9 relative",
    "cases": cases,
}
with open("tools/reference/data/support_factor.json", "w") as f:
    json.dump(out, f)
