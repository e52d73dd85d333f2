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

Then two other candidates for a soft spring, from the same summed cross-spectra, per sprung
channel relative to the mean of the other sprung channels, as the drive's value minus the
baseline's (both drives of the baseline summed), ln units, in LOW_BANDS_HZ:

- `level`: the sprung channel's RMS (`0.5 ln sum S_yy`): the body's modes tilt towards a soft
  corner (its floor moves more at the heave, pitch and roll frequencies);
- `h1`: the corner's own transmissibility from the cross-spectrum of its sprung and unsprung
  channels, `0.5 ln (sum |S_yu|^2 / S_uu / sum S_uu)` (sprung-sensor noise does not bias it).

`--spring-scale` sets the spring drive's scale (default fleet.py's 0.8; same corner and seeds).
The last lines give per candidate the healthy and class D drives' spread (standard deviation
over the buses) and the spring drives' values at the spring's corner.

Usage: VIBMODE_BUS_SEEDS=41744,92730,45348 python3 tools/busgen/body_drive.py [--buses N]
       [--spring-scale S]
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
#: Bands of the low-frequency spring candidates, Hz.
LOW_BANDS_HZ = [(1.0, 1.5), (1.5, 2.5), (2.5, 4.0)]


def _complex(a) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    return a[..., 0] + 1j * a[..., 1]


def run_bus(bus_seed: int, n_records: int, work: Path, spring_scale: float = 0.8) -> Dict:
    """As fleet.run_bus (same random draws), keeping the store; the drives' record lists. The
    spring drive has `spring_scale` (fleet.py's 0.8 by default)."""
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
        if cond["name"] == "spring80" and spring_scale != 0.8:
            cond = dict(cond, extra=["--spring", f"{cond['corner'].lower()}={spring_scale}"],
                        detail=f"spring {cond['corner']}={spring_scale}")
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
        out[fn] = {"f": np.array(bs["freq_hz"]), "unsprung": bs["unsprung"],
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
    return {"f": rs[0]["f"], "unsprung": rs[0]["unsprung"], "sprung": rs[0]["sprung"],
            "suu": sum(r["suu"] for r in rs),
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


def low_candidates(r: Dict) -> Dict[str, np.ndarray]:
    """`level` and `h1` per band of LOW_BANDS_HZ and sprung channel, each relative to the mean
    of the other sprung channels (ln units)."""
    corners = [c.split("_")[-1].upper() for c in r["unsprung"]]
    own = [corners.index(c.split("_")[-1].upper()) for c in r["sprung"]]
    out = {}
    for lo, hi in LOW_BANDS_HZ:
        m = (r["f"] >= lo) & (r["f"] < hi)
        level = np.array([0.5 * np.log(r["syy"][m, j].sum()) for j in range(len(own))])
        h1 = np.array([0.5 * np.log((abs(r["syu"][m, j, i]) ** 2 / r["suu"][m, i, i].real).sum()
                                    / r["suu"][m, i, i].real.sum())
                       for j, i in enumerate(own)])
        for name, v in (("level", level), ("h1", h1)):
            out[f"{name} {lo:g}-{hi:g} Hz"] = np.array(
                [v[j] - np.delete(v, j).mean() for j in range(len(v))])
    return out


def fmt(v: np.ndarray) -> str:
    return " ".join(f"{x:+.2f}" for x in v)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--buses", type=int, default=3)
    p.add_argument("--records", type=int, default=h.RECORDS)
    p.add_argument("--spring-scale", type=float, default=0.8)
    a = p.parse_args()
    try:
        h.check_tools()
    except h.Skip as e:
        print(f"skipped: {e}")
        return 0
    seeds = h.draw_bus_seeds(a.buses, "body per drive")
    # candidate -> ("healthy" | "spring", values at the spring's corner or every channel)
    low: Dict[str, Dict[str, List[float]]] = {}
    with tempfile.TemporaryDirectory(prefix="vibmode-body-drive-") as work:
        for s in seeds:
            bus = run_bus(s, a.records, Path(work), a.spring_scale)
            recs = load(bus["db"])
            nominal = [k for k, v in recs.items() if v["cond"] == "nominal"]
            hm = fit_h([recs[k] for k in nominal])
            loo = np.array([projection(fit_h([recs[j] for j in nominal if j != k]), recs[k])
                            for k in nominal])
            print(f"bus {s}: {len(nominal)} nominal records; per-record xpooled leave-one-out "
                  f"sd (FR RL RR) {fmt(loo.std(0))}; /sqrt({a.records}) "
                  f"{fmt(loo.std(0) / np.sqrt(a.records))}")
            base_low = low_candidates(pool([recs[k] for k in nominal]))
            for d in bus["drives"]:
                rs = [recs[k] for k in d["records"] if k in recs]
                dl = low_candidates(pool(rs))
                name = d["cond"]["name"]
                sprung = [c.split("_")[-1].upper() for c in rs[0]["sprung"]]
                for k, v in dl.items():
                    x = v - base_low[k]
                    e = low.setdefault(k, {"healthy": [], "spring": []})
                    if name in ("healthy", "roadD"):
                        e["healthy"] += list(x)
                    elif name == "spring80" and d["cond"]["corner"] in sprung:
                        e["spring"].append(float(x[sprung.index(d["cond"]["corner"])]))
                print(f"  {name:<9} low " + "; ".join(f"{k} {fmt(v - base_low[k])}"
                                                    for k, v in dl.items()), flush=True)
                med = np.median([power_ratio(hm, r) for r in rs], axis=0)
                pl = pool(rs)
                print(f"  {d['cond']['name']:<9} {d['cond']['detail']:<30} median {fmt(med)} | "
                      f"pooled {fmt(power_ratio(hm, pl))} | xpooled {fmt(projection(hm, pl))} | "
                      f"cond {cond_max(pl):.0f}", flush=True)
    print(f"low-frequency candidates (drive minus baseline, ln; spring at {a.spring_scale}):")
    for k, e in low.items():
        hv = np.array(e["healthy"])
        print(f"  {k:<18} healthy and class D drives: sd {hv.std():.3f}, largest |x| "
              f"{abs(hv).max():.3f} ({len(hv)} values); spring at its corner: "
              + " ".join(f"{x:+.2f}" for x in e["spring"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
