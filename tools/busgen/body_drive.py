#!/usr/bin/env python3
"""The body's response to the wheel motions per drive on busgen: does pooling a drive's records
separate a corner spring at 80 % from healthy drives? (issue 31 item 3; docs/fleet.md, "Measured
on busgen (issue 31)").

For the buses of tools/busgen/fleet.py (same seeds, same drives: `VIBMODE_BUS_SEEDS=...`) it
keeps each bus's store, reads the records' body cross-spectra (`body_spectra` of the features)
and the baseline's nominal records, and prints per drive, per sprung channel (FR, RL, RR), in
2-4 Hz, relative to the other axle as the feature `body-response` is (ln units):

- `median`: the median over the drive's records of the per-record feature (the power ratio
  `ln(S_yy / diag(H S_uu H^H))`, what `fleet check` scores today);
- `pooled`: the same power ratio from the drive's summed cross-spectra;
- `xpooled`: the cross-spectral projection `ln(Re sum S_yu conj(P) / sum |P|^2)`, `P = H S_uu`,
  from the drive's summed cross-spectra (noise on the sprung sensors, not coherent with the
  wheels, does not bias it);
- `cond`: the largest condition number of the drive's summed `S_uu` in the band;

and, for the nominal records, the leave-one-out scatter (standard deviation) of the per-record
`xpooled` value (`H` fitted without the record). `H` is fitted as vibmode does,
`(sum S_yu)(sum S_uu)^-1` over the nominal records.

Usage: VIBMODE_BUS_SEEDS=41744,92730,45348 python3 tools/busgen/body_drive.py [--buses N]
Needs VIBMODE_BIN, BUSGEN_PYTHON, and numpy in the Python running it.
"""

from __future__ import annotations

import argparse
import json
import random
import sqlite3
import sys
import tempfile
from pathlib import Path
from typing import Dict, List

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fleet  # noqa: E402
import harness as h  # noqa: E402

BAND_HZ = (2.0, 4.0)


def _complex(a) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    return a[..., 0] + 1j * a[..., 1]


def run_bus(bus_seed: int, n_records: int, work: Path) -> Dict:
    """As fleet.run_bus (same random draws), keeping the store; the drives' record lists."""
    rng = random.Random(bus_seed * 7919 + n_records)
    db = work / f"fleet-{bus_seed}.db"
    vehicle = f"bus{bus_seed}"
    base_seed = rng.randrange(1, 10**6)
    h.run_vibmode(["fleet", "init", "--db", db])
    base = []
    for d in range(2):
        base += h.records(h.simulate(bus_seed, base_seed + 1000 * d, records=n_records))
    h.run_vibmode(["fleet", "ingest", "--db", db, "--vehicle", vehicle, "-q", *base])
    h.run_vibmode(["fleet", "baseline", "--db", db, "--vehicle", vehicle])
    drives = []
    for i, cond in enumerate(fleet.conditions(bus_seed, rng)):
        recs = h.records(h.simulate(bus_seed, base_seed + 10000 * (i + 1), *cond["extra"],
                                    records=n_records))
        h.run_vibmode(["fleet", "check", "--db", db, "--vehicle", vehicle, "-q", "--json", "-",
                       *recs])
        drives.append({"cond": cond, "records": [str(r) for r in recs]})
    return {"db": db, "drives": drives}


def load(db: Path) -> Dict[str, Dict]:
    out = {}
    con = sqlite3.connect(str(db))
    for fn, cond, js in con.execute(
            "select r.file_name, r.condition, f.json from records r "
            "join features f on f.record_id = r.id"):
        bs = json.loads(js).get("body_spectra")
        if not bs:
            continue
        nu, ny = len(bs["unsprung"]), len(bs["sprung"])
        out[fn] = {"f": np.array(bs["freq_hz"]),
                   "suu": _complex(bs["s_uu"]).reshape(-1, nu, nu),
                   "syu": _complex(bs["s_yu"]).reshape(-1, ny, nu),
                   "syy": np.array(bs["s_yy"]), "cond": cond, "sprung": bs["sprung"]}
    con.close()
    return out


def fit_h(rs: List[Dict]) -> np.ndarray:
    suu = sum(r["suu"] for r in rs)
    syu = sum(r["syu"] for r in rs)
    return np.array([np.linalg.solve(suu[b].T, syu[b].T).T for b in range(len(suu))])


def pool(rs: List[Dict]) -> Dict:
    return {"f": rs[0]["f"], "suu": sum(r["suu"] for r in rs),
            "syu": sum(r["syu"] for r in rs), "syy": sum(r["syy"] for r in rs)}


def relative(x: np.ndarray) -> np.ndarray:
    """FR against the rear axle, RL and RR against the front (sprung FR, RL, RR)."""
    return np.array([x[0] - x[1:].mean(), x[1] - x[0], x[2] - x[0]])


def power_ratio(hm: np.ndarray, r: Dict) -> np.ndarray:
    m = (r["f"] >= BAND_HZ[0]) & (r["f"] < BAND_HZ[1])
    pred = np.einsum("bij,bjk,bik->bi", hm[m], r["suu"][m], hm[m].conj()).real
    return relative(np.log(r["syy"][m].sum(0) / pred.sum(0)))


def projection(hm: np.ndarray, r: Dict) -> np.ndarray:
    m = (r["f"] >= BAND_HZ[0]) & (r["f"] < BAND_HZ[1])
    p = np.einsum("bij,bjk->bik", hm[m], r["suu"][m])
    num = (r["syu"][m] * p.conj()).real.sum(axis=(0, 2))
    den = (abs(p) ** 2).sum(axis=(0, 2))
    return relative(np.log(np.maximum(num / den, 1e-6)))


def cond_max(r: Dict) -> float:
    m = (r["f"] >= BAND_HZ[0]) & (r["f"] < BAND_HZ[1])
    return float(max(np.linalg.cond(s) for s in r["suu"][m]))


def fmt(v: np.ndarray) -> str:
    return " ".join(f"{x:+.2f}" for x in v)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--buses", type=int, default=3)
    p.add_argument("--records", type=int, default=h.RECORDS)
    a = p.parse_args()
    try:
        h.vibmode_bin()
        h.busgen_dir()
        h.busgen_python()
    except h.Skip as e:
        print(f"skipped: {e}")
        return 0
    seeds = h.draw_bus_seeds(a.buses, "body per drive")
    with tempfile.TemporaryDirectory(prefix="vibmode-body-drive-") as work:
        for s in seeds:
            bus = run_bus(s, a.records, Path(work))
            recs = load(bus["db"])
            nominal = [k for k, v in recs.items() if v["cond"] == "nominal"]
            hm = fit_h([recs[k] for k in nominal])
            loo = np.array([projection(fit_h([recs[j] for j in nominal if j != k]), recs[k])
                            for k in nominal])
            print(f"bus {s}: {len(nominal)} nominal records; per-record xpooled leave-one-out "
                  f"sd (FR RL RR) {fmt(loo.std(0))}; /sqrt({a.records}) "
                  f"{fmt(loo.std(0) / np.sqrt(a.records))}")
            for d in bus["drives"]:
                rs = [recs[k] for k in d["records"] if k in recs]
                med = np.median([power_ratio(hm, r) for r in rs], axis=0)
                pl = pool(rs)
                print(f"  {d['cond']['name']:<9} {d['cond']['detail']:<30} median {fmt(med)} | "
                      f"pooled {fmt(power_ratio(hm, pl))} | xpooled {fmt(projection(hm, pl))} | "
                      f"cond {cond_max(pl):.0f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
