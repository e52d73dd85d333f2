"""Reference values for vibmode_fleet::suspension::t_as_normal (a Student t score made a standard
normal score with the same tail probability), from scipy.

Writes tools/reference/data/t_as_normal.json. Run from the repository root:
python3 tools/reference/t_as_normal.py

Versions: scipy as in tools/reference/requirements.txt (recorded in the JSON's "versions").

Cases: t in -40..8 and degrees of freedom 2..1000 (a drive of 8 records against a baseline of 16
has about 14): z = -scipy.stats.norm.isf(scipy.stats.t.cdf(-|t|, df)) with the sign of t.

Rust tolerance (crates/vibmode-fleet/tests/integration/reference.rs): 1e-7 absolute plus 1e-7
relative (statrs' regularized incomplete beta function and vibmode's Acklam normal quantile,
relative error 1.2e-9, against scipy's boost-based ones).
"""
import json

import scipy
import scipy.stats

cases = []
for df in (2.0, 3.0, 5.0, 7.0, 9.5, 14.0, 15.0, 21.7, 30.0, 100.0, 1000.0):
    for t in (-40.0, -12.0, -8.0, -5.0, -4.0, -3.5, -3.227, -3.0, -2.0, -1.0, -0.25, 0.0, 0.5,
              1.5, 3.5, 8.0):
        lower = float(scipy.stats.t.cdf(-abs(t), df))
        z = float(scipy.stats.norm.isf(lower))
        cases.append({"t": t, "df": df, "z": z if t >= 0 else -z})

out = {
    "versions": {"scipy": scipy.__version__},
    "tolerance": "1e-7 absolute + 1e-7 relative",
    "cases": cases,
}
with open("tools/reference/data/t_as_normal.json", "w") as f:
    json.dump(out, f)
