"""Reference for vibmode-modal: invariant modes by density clustering of pooled poles.

Independent implementation of the method in docs/modal.md with scipy.spatial.cKDTree (radius
neighbour queries) and scipy.sparse.csgraph.connected_components (clusters of core poles); numpy
for medians, percentiles (method="linear") and sample standard deviations (ddof=1).

Writes tools/reference/data/modal.json: a seeded synthetic pole cloud, the clustering parameters,
the expected clusters (all fields of InvariantMode) and the per-pole labels.

Library versions (tools/reference/requirements.txt): numpy 2.1.3, scipy 1.14.1.
Tolerance used by the Rust test: labels and counts exact; floats 1e-9 relative.

Run: python3 tools/reference/modal.py
"""
import json
import math
import os

import numpy as np
from scipy.spatial import cKDTree
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

SEED = 20240611
N_RECORDS = 4
ORDERS = list(range(2, 31))
CHANNELS = ["FR", "RL"]

PARAMS = dict(
    freq_tol_rel=0.02,
    freq_tol_per_damping=0.0,  # fixed radius: this script checks the k = 0 case
    log_damping_tol=0.2,
    min_points=5,
    min_density_share=0.03,
    min_record_share=0.5,
    record_min_order_share=0.1,
    min_order_share=0.25,
    disturbance_damping_max=5e-3,
    disturbance_freq_spread_max=0.01,
    freq_min_hz=0.1,
    freq_max_hz=30.0,
    max_damping_ratio=0.6,
    min_damping_ratio=1e-6,
)


def make_cloud(rng):
    # (freq, zeta, freq jitter rel, log-damping jitter, presence, records or None=all)
    modes = [
        (1.2, 0.2, 0.015, 0.35, 0.85, None),
        (8.0, 0.15, 0.015, 0.35, 0.85, None),
        (6.0, 1e-3, 5e-4, 0.3, 0.9, None),
        (3.0, 0.08, 0.01, 0.3, 0.9, [1]),  # one record only -> spurious
    ]
    poles = []
    for rec in range(N_RECORDS):
        for ch in CHANNELS:
            for order in ORDERS:
                for f0, z0, fj, zj, pres, recs in modes:
                    if recs is not None and rec not in recs:
                        continue
                    if order < 4 or rng.random() >= pres:
                        continue
                    n = 2 if (z0 > 0.01 and rng.random() < 0.1) else 1
                    for _ in range(n):
                        f = f0 * (1 + fj * rng.standard_normal())
                        z = z0 * math.exp(zj * rng.standard_normal())
                        poles.append(dict(frequency_hz=f, damping_ratio=z, order=order, record=rec, channel=ch))
                for _ in range(rng.integers(0, 7)):
                    f = rng.uniform(0.5, 20.0)
                    z = 10 ** rng.uniform(-3, math.log10(0.6))
                    poles.append(dict(frequency_hz=f, damping_ratio=z, order=order, record=rec, channel=ch))
    # a few poles outside the filters
    poles.append(dict(frequency_hz=45.0, damping_ratio=0.1, order=10, record=0, channel="FR"))
    poles.append(dict(frequency_hz=2.0, damping_ratio=0.9, order=10, record=0, channel="FR"))
    poles.append(dict(frequency_hz=2.0, damping_ratio=-0.01, order=10, record=0, channel="FR"))
    return poles


def cluster(poles, n_records, orders, p):
    f = np.array([q["frequency_hz"] for q in poles])
    z = np.array([q["damping_ratio"] for q in poles])
    used = np.flatnonzero((f >= p["freq_min_hz"]) & (f <= p["freq_max_hz"]) & (z >= 0) & (z <= p["max_damping_ratio"]))
    n_channels = len({poles[i]["channel"] for i in used})
    n_fits = n_records * len(orders) * n_channels
    thr = max(p["min_points"], math.ceil(p["min_density_share"] * n_fits))
    u = np.log(f[used]) / np.log1p(p["freq_tol_rel"])
    v = np.log10(np.maximum(z[used], p["min_damping_ratio"])) / p["log_damping_tol"]
    xy = np.column_stack([u, v])
    tree = cKDTree(xy)
    nbrs = tree.query_ball_point(xy, r=1.0)
    core = np.array([len(nb) >= thr for nb in nbrs])
    rows, cols = [], []
    for i, nb in enumerate(nbrs):
        if core[i]:
            for j in nb:
                if core[j]:
                    rows.append(i)
                    cols.append(j)
    n = len(used)
    g = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    _, comp = connected_components(g, directed=False)
    lab = np.full(n, -1)
    lab[core] = comp[core]
    for i in np.flatnonzero(~core):
        cands = [j for j in nbrs[i] if core[j]]
        if cands:
            d = [np.sum((xy[j] - xy[i]) ** 2) for j in cands]
            lab[i] = comp[cands[int(np.argmin(d))]]
    modes = []
    for c in sorted(set(lab[lab >= 0].tolist())):
        mem = np.flatnonzero(lab == c)
        cu, cv = np.median(u[mem]), np.median(v[mem])
        best = {}
        for i in mem:
            q = poles[used[i]]
            d2 = (u[i] - cu) ** 2 + (v[i] - cv) ** 2
            key = (q["record"], q["channel"], q["order"])
            if key not in best or d2 < best[key][0] or (d2 == best[key][0] and used[i] < best[key][1]):
                best[key] = (d2, int(used[i]))
        kept = sorted(b[1] for b in best.values())
        ff = np.array([poles[k]["frequency_hz"] for k in kept])
        zz = np.array([poles[k]["damping_ratio"] for k in kept])
        rec_orders = {(poles[k]["record"], poles[k]["order"]) for k in kept}
        per_rec = {}
        for r, _ in rec_orders:
            per_rec[r] = per_rec.get(r, 0) + 1
        min_orders = max(1, math.ceil(p["record_min_order_share"] * len(orders)))
        record_share = sum(1 for k in per_rec.values() if k >= min_orders) / n_records
        order_share = len(rec_orders) / (n_records * len(orders))
        fm = float(np.mean(ff))
        fs = float(np.std(ff, ddof=1)) if len(ff) > 1 else 0.0
        zmed = float(np.median(zz))
        supported = (n_records <= 1 or record_share >= p["min_record_share"]) and order_share >= p["min_order_share"]
        if not supported:
            cls = "spurious"
        elif zmed < p["disturbance_damping_max"] and fs < p["disturbance_freq_spread_max"] * fm:
            cls = "periodic-disturbance"
        else:
            cls = "structural"
        modes.append(dict(
            frequency_hz=fm, frequency_std_hz=fs, damping_ratio=zmed,
            damping_iqr=[float(np.percentile(zz, 25)), float(np.percentile(zz, 75))],
            order_share=order_share, record_share=record_share, n_poles=len(kept),
            channels=sorted({poles[k]["channel"] for k in kept}), roles=[],
            min_order=min(poles[k]["order"] for k in kept), cls=cls, kept=kept,
        ))
    modes.sort(key=lambda m: (m["frequency_hz"], m["damping_ratio"]))
    labels = [None] * len(poles)
    for k, m in enumerate(modes):
        for i in m.pop("kept"):
            labels[i] = k
        m["class"] = m.pop("cls")
    return dict(modes=modes, labels=labels, n_used=int(n), n_ignored=len(poles) - int(n),
                n_fits=n_fits, core_threshold=thr)


def main():
    rng = np.random.default_rng(SEED)
    poles = make_cloud(rng)
    for q in poles:
        q["role"] = None
    expected = cluster(poles, N_RECORDS, ORDERS, PARAMS)
    out = dict(n_records=N_RECORDS, orders=ORDERS, params=PARAMS, poles=poles, expected=expected,
               numpy=np.__version__)
    path = os.path.join(os.path.dirname(__file__), "data", "modal.json")
    with open(path, "w") as fh:
        json.dump(out, fh)
    print(path, len(poles), "poles;", [(round(m["frequency_hz"], 3), m["class"], m["n_poles"]) for m in expected["modes"]])


if __name__ == "__main__":
    main()
