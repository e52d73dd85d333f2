#!/usr/bin/env python3
"""What is left in the body equations after the fit: each record's residual against the share its
sensors' white noise is expected to leave (issue 30 item 1, issue 31 item 3; docs/model_update.md,
"What the noise leaves").

Reads fleet stores (read-only) whose vehicles have a registered model file, so that every record
keeps its body equations (`features.suspension.equations`: the summed `Z^T Z` of `Z = [X | y]`
and the noise's expected share of it). Per vehicle it fits the nominal records' equations as
`vibmode_vehicle::update` does without bounds (generalized total least squares: the noise share
scaled by the smallest generalized eigenvalue, at most 1) and prints, per record, the residual
`[t; -1]^T Z^T Z [t; -1]` over the noise's share `[t; -1]^T N [t; -1]`. A ratio near 1 says the
equations hold but for the sensors' noise; a model error (a bending the sensors see, a manoeuvre's
moment, a fault the nominal fit lacks) raises it.

    python3 tools/busgen/residual_share.py STORE.db [STORE.db ...]

Needs numpy and scipy. Exit status 0 (it measures, it does not judge).
"""

from __future__ import annotations

import json
import sqlite3
import sys
from typing import List

import numpy as np
import scipy.linalg


def noise_scale(raw: np.ndarray, noise: np.ndarray) -> float:
    """The share of the noise taken out: the smallest generalized eigenvalue, at most 1."""
    try:
        return min(1.0, float(scipy.linalg.eigh(raw, noise, eigvals_only=True).min()))
    except (np.linalg.LinAlgError, ValueError):
        return 1.0


def main(argv: List[str]) -> int:
    if not argv:
        print(__doc__.strip().split("\n\n")[-2].strip())
        return 2
    ratios: List[float] = []
    for db in argv:
        con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
        for vid, name in con.execute("SELECT id, name FROM vehicles ORDER BY id"):
            eqs = []
            for cond, text in con.execute(
                    "SELECT r.condition, f.json FROM records r JOIN features f ON f.record_id = r.id "
                    "WHERE r.vehicle_id = ? ORDER BY r.id", (vid,)):
                s = json.loads(text).get("suspension")
                if not s:
                    continue
                e = s["equations"]
                n = e["unknowns"] + 1
                eqs.append((cond, np.array(e["gram"]).reshape(n, n, order="F"),
                            np.array(e["noise_gram"]).reshape(n, n, order="F")))
            nominal = [e for e in eqs if e[0] == "nominal"]
            if len(nominal) < 3:
                print(f"{db}: vehicle {name}: {len(nominal)} nominal records with body equations, "
                      "3 needed: skipped")
                continue
            raw = sum(e[1] for e in nominal)
            noise = sum(e[2] for e in nominal)
            g = raw - noise_scale(raw, noise) * noise
            v = np.append(np.linalg.solve(g[:-1, :-1], g[:-1, -1]), -1.0)
            r = [float(v @ z @ v / (v @ q @ v)) for _, z, q in eqs]
            rn = [x for x, e in zip(r, eqs) if e[0] == "nominal"]
            ratios += r
            print(f"{db}: vehicle {name}: {len(eqs)} records ({len(nominal)} nominal); residual over "
                  f"noise share: nominal median {np.median(rn):.2f} ({min(rn):.2f}-{max(rn):.2f}), "
                  f"all {np.median(r):.2f} ({min(r):.2f}-{max(r):.2f}); noise share of y'y "
                  f"{np.median([q[-1, -1] / z[-1, -1] for _, z, q in eqs]):.3f}")
    if ratios:
        a = np.array(ratios)
        lo, hi = np.percentile(a, [5, 95])
        print(f"all {len(a)} records: residual over noise share median {np.median(a):.2f}, "
              f"5-95 % {lo:.2f}-{hi:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
