#!/usr/bin/env python3
"""A spring lost slowly, on the independent bus family (../shared/busgen): how often `vibmode fleet
check` finds it as a vehicle's drives go on, and how often a healthy sequence of drives cries
wolf. The spring trend (docs/fleet.md, "The spring trend") pools the fitted springs of a vehicle's
last 3 drives, so it is measured on sequences, in one store per bus.

Per bus (bus seeds drawn at random, printed; `VIBMODE_BUS_SEEDS=1,2,3` replays):

- the bus's model file registered (its true geometry, masses and tyres, generic suspension:
  `update.vehicle_toml`), a baseline of 2 healthy drives of 8 records (busgen defaults: class B,
  25-35 km/h, nominal load; `--baseline-drives` for more);
- `--healthy` healthy drives, each on drawn conditions (speed 20-40 km/h or busgen's 25-35, load
  0.85-1.20, road class A-C: `fleet.healthy_drive`);
- then `--faulty` drives with the spring at 80 % at one corner drawn per bus, on drawn conditions
  likewise.

Each drive is one `fleet check --drive dK --json -`, in order, in the bus's one store. Scored per
drive: healthy `normal`; a spring drive `vehicle` or `both` with its corner named first (and how:
by the drive's own fit, by the trend, or by other features). Printed per position after onset
(1st, 2nd, 3rd spring drive: the 3rd is the first whose trend holds only spring drives).

Usage: python3 tools/busgen/spring_trend.py [--buses N] [--healthy 4] [--faulty 3] [--json OUT]
       [--baseline-drives 2]
Needs VIBMODE_BIN (else target/release/vibmode) and a Python with numpy+scipy for busgen
(BUSGEN_PYTHON).
"""

from __future__ import annotations

import argparse
import json
import random
import shutil
import sys
import tempfile
from pathlib import Path
from typing import Dict, List, Optional

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fleet  # noqa: E402
import harness as h  # noqa: E402


def how_found(drive: Dict, corner: str) -> Optional[str]:
    """`trend`, `fit` or `other` for a drive naming `corner` first as `vehicle`/`both`; None
    otherwise."""
    if drive["classification"] not in ("vehicle", "both"):
        return None
    if (drive.get("corner") or fleet.first_corner(drive.get("evidence", []))) != corner:
        return None
    keys = [e["key"] for e in drive.get("evidence", [])
            if e.get("group") == "vehicle" and e.get("corner") == corner]
    if any(k.startswith("fit:spring-trend:") for k in keys):
        return "trend"
    if any(k.startswith("fit:spring:") for k in keys):
        return "fit"
    return "other"


def run_bus(bus_seed: int, n_healthy: int, n_faulty: int, work: Path,
            baseline_drives: int = 2, config: Optional[Path] = None) -> Dict:
    rng = random.Random(bus_seed * 7919 + 3)
    db, vehicle, base_seed = fleet.make_baseline(bus_seed, h.RECORDS, work, rng, model=True,
                                                 drives=baseline_drives, config=config)
    corner = rng.choice(fleet.CORNERS)
    rows = []
    for k in range(n_healthy + n_faulty):
        extra, load, road, speed = fleet.healthy_drive(rng)
        faulty = k >= n_healthy
        if faulty:
            extra = ["--spring", f"{corner}=0.8", *extra]
        folder = h.simulate(bus_seed, 700000 + 1000 * k + base_seed % 1000, *extra)
        r = h.run_vibmode(["fleet", "check", "--db", db, "--vehicle", vehicle, "-q", "--json",
                           "-", "--drive", f"d{k}", *h.records(folder)])
        dv = json.loads(r.stdout)["drives"][0]
        susp = dv.get("suspension") or {}
        trend = susp.get("trend")
        rows.append({
            "bus": bus_seed, "k": k, "faulty": faulty, "corner": corner.upper(),
            "detail": f"load {load}, road {road}, "
                      f"{'25-35' if speed is None else speed} km/h",
            "classification": dv["classification"], "named": dv.get("corner"),
            "summary": dv.get("summary", ""),
            "found": how_found(dv, corner.upper()) if faulty else None,
            "trend": trend is not None,
            "trend_z": None if trend is None else {
                s["corner"]: round(s["z"], 2) for s in trend["scores"]},
            "fit_z": {s["corner"]: round(s["z"], 2) for s in susp.get("scores", [])
                      if s["part"] == "spring"},
            # Raw, for studies of other limits offline: the drive's fit, scores and trend, and
            # its evidence (key, group, corner, z, limit).
            "suspension": susp,
            "evidence": [{k: e.get(k) for k in ("key", "group", "corner", "z", "limit")}
                         for e in dv.get("evidence", [])],
        })
    return {"bus": bus_seed, "corner": corner.upper(), "rows": rows}


def summarise(buses: List[Dict], n_healthy: int) -> Dict:
    healthy = [r for b in buses for r in b["rows"] if not r["faulty"]]
    with_trend = [r for r in healthy if r["trend"]]
    out = {
        "healthy_normal": sum(r["classification"] == "normal" for r in healthy),
        "healthy_n": len(healthy),
        "healthy_trend_normal": sum(r["classification"] == "normal" for r in with_trend),
        "healthy_trend_n": len(with_trend),
        "spring": [],
    }
    n_faulty = max((len(b["rows"]) - n_healthy for b in buses), default=0)
    for pos in range(n_faulty):
        rs = [b["rows"][n_healthy + pos] for b in buses if len(b["rows"]) > n_healthy + pos]
        out["spring"].append({
            "position": pos + 1, "n": len(rs),
            "found": sum(r["found"] is not None for r in rs),
            "by_trend": sum(r["found"] == "trend" for r in rs),
            "by_fit": sum(r["found"] == "fit" for r in rs),
            "by_other": sum(r["found"] == "other" for r in rs),
        })
    first = []
    for b in buses:
        hits = [r["k"] - n_healthy for r in b["rows"] if r["found"] is not None]
        first.append(min(hits) + 1 if hits else None)
    out["found_by"] = {str(p): sum(f is not None and f <= p for f in first)
                       for p in range(1, n_faulty + 1)}
    out["buses"] = len(buses)
    return out


def print_summary(s: Dict) -> None:
    print(f"healthy drives normal: {h.rate(s['healthy_normal'], s['healthy_n'])}; of those with "
          f"a trend made: {h.rate(s['healthy_trend_normal'], s['healthy_trend_n'])}")
    for p in s["spring"]:
        print(f"spring drive {p['position']} after onset: found {h.rate(p['found'], p['n'])} "
              f"(by the trend {p['by_trend']}, the drive's fit {p['by_fit']}, other features "
              f"{p['by_other']})")
    print("buses whose spring was found by the Nth spring drive: "
          + ", ".join(f"{k}: {v}/{s['buses']}" for k, v in s["found_by"].items()))


def measure(seeds: List[int], n_healthy: int = 4, n_faulty: int = 3,
            baseline_drives: int = 2, config: Optional[Path] = None) -> List[Dict]:
    work = Path(tempfile.mkdtemp(prefix="vibmode-spring-trend-"))
    buses = []
    try:
        for s in seeds:
            b = run_bus(s, n_healthy, n_faulty, work, baseline_drives, config)
            for r in b["rows"]:
                tag = "spring " + r["corner"] if r["faulty"] else "healthy"
                print(f"bus {r['bus']:>5} d{r['k']} {tag:<10} {r['detail']:<30} "
                      f"{r['classification']:<8} {r['named'] or '-':<3} "
                      f"{'found by ' + r['found'] if r['found'] else ''} "
                      f"trend {r['trend_z'] or '-'}", flush=True)
            buses.append(b)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return buses


def main(argv: Optional[List[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--buses", type=int, default=4)
    p.add_argument("--healthy", type=int, default=4, help="healthy drives before the fault")
    p.add_argument("--faulty", type=int, default=3, help="drives with the spring at 80 %%")
    p.add_argument("--json", type=Path, help="write the rows and the summary here")
    p.add_argument("--baseline-drives", type=int, default=2,
                   help="healthy drives of 8 records in the baseline (busgen defaults)")
    p.add_argument("--config", type=Path,
                   help="fleet settings (TOML) given to `fleet init --config`, e.g. reference_drives = 6")
    a = p.parse_args(argv)
    if a.baseline_drives < 1:
        p.error(f"--baseline-drives {a.baseline_drives}: at least 1")
    try:
        h.check_tools()
    except h.Skip as e:
        print(f"skipped: {e}")
        return 0
    seeds = h.draw_bus_seeds(a.buses, "spring trend")
    buses = measure(seeds, a.healthy, a.faulty, a.baseline_drives, a.config)
    s = summarise(buses, a.healthy)
    print_summary(s)
    if a.json:
        a.json.write_text(json.dumps({"buses": buses, "summary": s}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
