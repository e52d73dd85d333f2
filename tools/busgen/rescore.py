#!/usr/bin/env python3
"""The suspension fit's verdicts of `spring_trend.py --json` runs computed again offline under
two rules, so that one run of busgen buses compares them paired (docs/fleet.md, "Scores of
estimated spread"):

- `normal`: the scores before 2026-11-28, `z = d / sqrt(var)` against the normal limits, the
  trend's inverse-variance mean with the variance `1 / sum(1 / var_i)`;
- `t`: the scores since, `t = d / sqrt(var)` with Welch-Satterthwaite's degrees of freedom made
  the normal score of the same tail probability, the trend's mean with Meier's factor.

From each drive's stored fit (`suspension.fit`) and scores, the baseline's `r_c` and variance
are recovered (`ln centre`; the score's variance minus the drive's), and every drive's 8 tests
and (from the 3rd drive on) the trend's 4 are scored again; a drive is `normal` without flagged
fit evidence and without other evidence (kept from the run). A spring drive counts as found
when a flagged fit or trend test names its corner, or the run found it by other features.
Computing a run's own rule gives its binary's counts (docs/fleet.md states both).

Usage: python3 tools/busgen/rescore.py RUN.json [RUN.json ...]  (needs numpy and scipy; runs
with the default baseline of 2 drives of 8 records: `BASELINE_RECORDS`)
"""

from __future__ import annotations

import json
import math
import sys
from typing import Dict, List, Optional, Tuple

import numpy as np
from scipy import stats

CORNERS = ["FL", "FR", "RL", "RR"]
DRIVE_LIMIT = float(stats.norm.isf(0.01 / 16))   # suspension_limit(0.01)
TREND_LIMIT = float(stats.norm.isf(0.01 / 8))    # trend_limit(0.01)
TREND_DRIVES = 3
MIN_LOSS = 0.10                                   # MIN_FLAGGED_LOSS
BASELINE_RECORDS = 16


def relative(fit: Dict, part: str) -> Tuple[np.ndarray, np.ndarray]:
    """`CornerFit::relative`: per corner `ln v_c - mean_{j != c} ln v_j` and its variance."""
    v = np.log(np.array(fit["spring_n_per_m" if part == "spring" else "damper_n_s_per_m"]))
    stat = np.array([v[c] - np.mean([v[j] for j in range(4) if j != c]) for c in range(4)])
    if part == "spring" and fit.get("spring_relative_sd"):
        return stat, np.array(fit["spring_relative_sd"]) ** 2
    sd = np.array(fit["spring_rel_sd" if part == "spring" else "damper_rel_sd"])
    var = np.array([sd[c] ** 2 + sum(sd[j] ** 2 for j in range(4) if j != c) / 9
                    for c in range(4)])
    return stat, var


def t_as_normal(t: float, df: float) -> float:
    if not math.isfinite(df):
        return t
    z = float(stats.norm.isf(stats.t.cdf(-abs(t), df)))
    return -z if t < 0 else z


def baseline(bus: Dict) -> Optional[Dict[str, Tuple[np.ndarray, np.ndarray]]]:
    """The baseline's `r_c` and variance per part, from the first drive with a fit."""
    for row in bus["rows"]:
        s = row.get("suspension") or {}
        if "fit" not in s:
            continue
        out = {}
        for part in ("spring", "damper"):
            _, var = relative(s["fit"], part)
            rb, vb = np.zeros(4), np.full(4, np.nan)
            for sc in s["scores"]:
                if sc["part"] != part:
                    continue
                c = CORNERS.index(sc["corner"])
                rb[c] = math.log(sc["centre"])
                ratio = sc.get("t") or sc["z"]   # the ratio (runs before t kept only z)
                if ratio:
                    vb[c] = ((math.log(sc["value"]) - rb[c]) / ratio) ** 2 - var[c]
            out[part] = (rb, vb)
        return out
    return None


def score(d: float, parts: List[Tuple[float, float]], rule: str) -> float:
    var = sum(p[0] for p in parts)
    t = d / math.sqrt(var)
    if rule == "normal":
        return t
    df = var ** 2 / sum(p[0] ** 2 / p[1] for p in parts if p[0] > 0)
    return t_as_normal(t, df)


def flags(fits: List[Dict], base: Dict, rule: str) -> List[Tuple[str, str]]:
    """The flagged (part, corner) of the last drive of `fits` (the drive's own tests and, with
    enough drives, the trend's)."""
    out = []
    fit = fits[-1]
    df_d, df_b = fit["records"] - 1, BASELINE_RECORDS - 1
    for part in ("spring", "damper"):
        stat, var = relative(fit, part)
        rb, vb = base[part]
        for c in range(4):
            d = stat[c] - rb[c]
            if (score(d, [(var[c], df_d), (vb[c], df_b)], rule) < -DRIVE_LIMIT
                    and math.exp(d) - 1 <= -MIN_LOSS):
                out.append((part, CORNERS[c]))
    if len(fits) >= TREND_DRIVES:
        last = fits[-TREND_DRIVES:]
        rel = [relative(f, "spring") for f in last]
        rb, vb = base["spring"]
        for c in range(4):
            w = np.array([1 / r[1][c] for r in rel])
            w /= w.sum()
            factor = 1.0
            if rule == "t":
                factor = 1 + 4 * sum(w[i] * (1 - w[i]) / (f["records"] - 1)
                                     for i, f in enumerate(last))
            mean = sum(w[i] * rel[i][0][c] for i in range(len(last)))
            parts = [(factor * w[i] ** 2 * rel[i][1][c], f["records"] - 1)
                     for i, f in enumerate(last)]
            parts.append((vb[c], df_b))
            d = mean - rb[c]
            if score(d, parts, rule) < -TREND_LIMIT and math.exp(d) - 1 <= -MIN_LOSS:
                out.append(("spring", CORNERS[c]))
    return out


def rescore(buses: List[Dict], rule: str) -> Dict:
    healthy = [0, 0]
    n_faulty = max(sum(r["faulty"] for r in b["rows"]) for b in buses)
    positions = [[0, 0] for _ in range(n_faulty)]
    first = []
    for bus in buses:
        base = baseline(bus)
        if base is None:
            continue
        fits: List[Dict] = []
        onset = sum(not r["faulty"] for r in bus["rows"])
        found_at = None
        for row in bus["rows"]:
            fit = (row.get("suspension") or {}).get("fit")
            flagged = []
            if fit:
                fits.append(fit)
                flagged = flags(fits, base, rule)
            other = [e for e in row["evidence"] if not e["key"].startswith("fit:")]
            if not row["faulty"]:
                healthy[1] += 1
                healthy[0] += not flagged and not other
            else:
                pos = row["k"] - onset
                hit = any(c == row["corner"] for _, c in flagged) or row["found"] == "other"
                positions[pos][1] += 1
                positions[pos][0] += hit
                if hit and found_at is None:
                    found_at = pos + 1
        first.append(found_at)
    return {"healthy": healthy, "positions": positions,
            "found_by_last": sum(f is not None for f in first), "buses": len(first)}


def main(argv: List[str]) -> int:
    if not argv:
        print(__doc__)
        return 2
    buses = []
    for path in argv:
        buses += json.load(open(path))["buses"]
    for rule in ("normal", "t"):
        r = rescore(buses, rule)
        pos = ", ".join(f"{a}/{n}" for a, n in r["positions"])
        print(f"{rule:<6} healthy drives normal {r['healthy'][0]}/{r['healthy'][1]}; spring drive "
              f"1.. after onset found {pos}; buses found by the last spring drive "
              f"{r['found_by_last']}/{r['buses']}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
