#!/usr/bin/env python3
"""A corner spring at 80 % from the physical model fitted per drive (issue 31 item 3; docs/fleet.md,
"The spring at 80 %: the model fitted per drive").

Per bus (seeds drawn at random and printed; `VIBMODE_BUS_SEEDS=1,2,3` replays), ONE vibmode
vehicle file (the bus's true geometry, masses and tyres, the generic suspension and inertias of
tools/busgen/update.py, a front anti-roll bar: the fit holds it at 0 where the bus has none), and
per drive of 8 records `vibmode analyze --vehicle` (the model update of issue 30: generalized
total least squares of the body equations), whose fitted springs and dampers per corner are read
from `model_update.json` (also when the fit says the records do not support it); the bus's reference
is one such fit of its 16 baseline records together.

The feature: per corner the fitted spring relative to the other three, `ln k_c - mean_{j != c}
ln k_j` (a load change scales all corners together; the fit's sprung mass is the file's), minus
the same for the bus's baseline fit. A spring at 80 % moves its corner by ln 0.8 = -0.22 and
each other corner by +0.07. Its standard deviation from the fits' jackknife (the springs' own
relative standard deviations in `model_update.json`, taken as independent) gives a score `z` =
change / sqrt(sd_drive^2 + sd_baseline^2).

Drives per bus: the baseline and the 6 checked drives of tools/busgen/fleet.py (same seeds and
draws), `--healthy` more healthy drives (other seeds, 20-40 km/h or busgen's 25-35, load
0.85-1.20, road A-C, drawn at random per bus), and a spring at `--spring-scale` at each of the
four corners, each on such a drawn road, load and speed.

Printed: per drive the change and z per corner (FL FR RL RR), and the damper ratios' change
alike; then the healthy drives' spread (rms over every corner) per road class; per group of
drives (fault, road A apart, a spring at FL apart: no sprung sensor above it) how many have their
lowest corner below 4 healthy spreads (roads B-C) and the fault's corner named (lowest), and the
same with z below -2.81 (a 1 % false-alarm rate per drive were z normal) and -4.

Usage: VIBMODE_BUS_SEEDS=41744,45348 python3 tools/busgen/spring_fit.py [--buses N]
       [--healthy K] [--spring-scale S] [--config ANALYSIS.toml] [--json OUT]
       python3 tools/busgen/spring_fit.py --from-json OUT      (the summary again)
`--config` with `[model_update] band_hz = [0.6, 4.0]` is the band measured best
(docs/fleet.md); without it the model update's default band (0.45 x the lowest, 1.6 x the
highest body mode of the vehicle file).
Needs VIBMODE_BIN (else target/release/vibmode) and a Python with numpy+scipy for busgen
(BUSGEN_PYTHON).
"""

from __future__ import annotations

import argparse
import json
import math
import random
import statistics
import sys
import tempfile
from pathlib import Path
from typing import Dict, List, Optional

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fleet  # noqa: E402
import harness as h  # noqa: E402
import update  # noqa: E402

CORNERS = ("FL", "FR", "RL", "RR")


def drawn_conditions(rng: random.Random) -> List[str]:
    """busgen options of a drive on another day, drawn as fleet.py's healthy drive."""
    return fleet.healthy_drive(rng)[0]


def fit(folders: List[Path], vehicle: Path, out: Path, config: Optional[Path] = None) -> Dict:
    """The fitted springs and dampers per corner (N/m, N s/m) of the records of `folders` taken
    together, and whether the update said the records support it (its reason if not)."""
    extra = ["--config", str(config)] if config else []
    recs = [r for f in folders for r in h.records(f)]
    h.run_vibmode(["analyze", *recs, "-q", "-o", out, "--vehicle", vehicle, *extra])
    res = json.loads((out / "results.json").read_text())
    mu = res.get("model_update") or {}
    reason = mu.get("not_updated")
    if reason is not None:
        full = out / "model_update.json"
        if not full.is_file():
            return {"failed": reason}
        mu = json.loads(full.read_text())
    if "vehicle" not in mu:
        return {"failed": reason or "no vehicle in model_update"}
    p = update.fitted_params(mu)
    sd = {q["name"]: q["sd"] / q["value"] for q in mu.get("parameters", [])
          if q.get("sd") is not None and q["value"] > 0}
    return {"springs": [p[f"spring {c}"] for c in CORNERS],
            "dampers": [p[f"damper {c}"] for c in CORNERS],
            "spring_sd": [sd.get(f"spring {c}", float("nan")) for c in CORNERS],
            "not_supported": reason}


def ratio_sd(rel_sd: List[float]) -> List[float]:
    """Per corner the jackknife standard deviation of `ratios` from the springs' own relative
    ones, the springs taken as independent (the fit reports no covariance)."""
    return [math.sqrt(rel_sd[c] ** 2 + sum(rel_sd[j] ** 2 for j in range(4) if j != c) / 9.0)
            for c in range(4)]


def ratios(values: List[float]) -> List[float]:
    """Per corner `ln v_c - mean_{j != c} ln v_j`."""
    ln = [math.log(max(v, 1e-9)) for v in values]
    return [ln[c] - sum(ln[j] for j in range(4) if j != c) / 3.0 for c in range(4)]


def run_bus(bus_seed: int, n_healthy: int, spring_scale: float, work: Path,
            config: Optional[Path] = None) -> Dict:
    n = h.RECORDS
    rng = random.Random(bus_seed * 7919 + n)  # as fleet.py
    base_seed = rng.randrange(1, 10**6)
    drives = []
    for d in range(2):
        drives.append({"name": "baseline", "detail": "class B, nominal load, 25-35 km/h",
                       "folder": h.simulate(bus_seed, base_seed + 1000 * d, records=n),
                       "corner": None})
    for i, cond in enumerate(fleet.conditions(bus_seed, rng)):
        drives.append({"name": cond["name"], "detail": cond["detail"], "corner": cond["corner"],
                       "folder": h.simulate(bus_seed, base_seed + 10000 * (i + 1),
                                            *cond["extra"], records=n)})
    more = random.Random(bus_seed * 104729 + 31)
    for k in range(n_healthy):
        extra = drawn_conditions(more)
        drives.append({"name": "healthy", "detail": " ".join(extra[1::2]), "corner": None,
                       "folder": h.simulate(bus_seed, base_seed + 500000 + 1000 * k, *extra,
                                            records=n)})
    for c in CORNERS:
        extra = drawn_conditions(more)
        drives.append({"name": f"spring{round(100 * spring_scale)}", "corner": c,
                       "detail": f"spring {c}={spring_scale} " + " ".join(extra[1::2]),
                       "folder": h.simulate(bus_seed, base_seed + 600000 + 1000 * CORNERS.index(c),
                                            "--spring", f"{c.lower()}={spring_scale}", *extra,
                                            records=n)})
    t = h.truth(drives[0]["folder"])
    vehicle = work / f"bus{bus_seed}.toml"
    vehicle.write_text(update.vehicle_toml(t, True))
    for j, d in enumerate(drives):
        d.update(fit([d["folder"]], vehicle, work / f"bus{bus_seed}-{j}", config))
    # The reference: one fit of the baseline's records together (as a fleet baseline pools them).
    ref = fit([d["folder"] for d in drives if d["name"] == "baseline"], vehicle,
              work / f"bus{bus_seed}-baseline", config)
    for d in drives:
        d["folder"] = str(d["folder"])
    if "springs" not in ref:
        return {"bus": bus_seed, "drives": drives, "failed": "no baseline fit"}
    ref_k = ratios(ref["springs"])
    ref_c = ratios(ref["dampers"])
    ref_var = [x * x for x in ratio_sd(ref["spring_sd"])]
    for d in drives:
        if "springs" in d:
            d["dk"] = [a - b for a, b in zip(ratios(d["springs"]), ref_k)]
            d["z"] = [x / math.sqrt(v + s * s)
                      for x, v, s in zip(d["dk"], ref_var, ratio_sd(d["spring_sd"]))]
            d["dc"] = [a - b for a, b in zip(ratios(d["dampers"]), ref_c)]
    return {"bus": bus_seed, "drives": drives}


def fmt(v: List[float]) -> str:
    return " ".join(f"{x:+.3f}" for x in v)


def road_class(d: Dict) -> str:
    """The drive's road class (fleet.py's fault drives and the baseline drive on busgen's B)."""
    if d["name"] == "roadD":
        return "D"
    for c in "ABC":
        if f"road {c}" in d["detail"] or f" {c} " in f" {d['detail']} ":
            return c
    return "B"


#: The limit of the summary, in healthy spreads (the brief's "beyond ~4 healthy spreads").
LIMIT_SPREADS = 4.0
#: The per-drive false-alarm rate the z limit is set for, the lowest of the 4 corners' z taken
#: as normal (Bonferroni over the corners): z < -Phi^-1(1 - 0.01 / 4) = -2.81.
FALSE_ALARM_RATE = 0.01
Z_LIMIT = statistics.NormalDist().inv_cdf(1.0 - FALSE_ALARM_RATE / 4)


def summarize(buses: List[Dict]) -> None:
    """The healthy spread per road class, and per fault how often its corner has the lowest
    change and lies beyond LIMIT_SPREADS healthy spreads (rms over every corner of the healthy
    drives on roads B and C); the false alarms of that limit."""
    drives = [d for b in buses for d in b["drives"] if "dk" in d]
    def rms(v: List[float]) -> float:
        return math.sqrt(sum(x * x for x in v) / len(v)) if v else float("nan")
    for classes in ("A", "B", "C", "BC", "ABC"):
        hv = [x for d in drives if d["name"] == "healthy" and road_class(d) in classes
              for x in d["dk"]]
        if hv:
            print(f"healthy drives, road {classes}: {len(hv) // 4} drives, rms {rms(hv):.3f}, "
                  f"largest |x| {max(abs(x) for x in hv):.3f}")
    hv = [x for d in drives if d["name"] == "healthy" and road_class(d) in "BC" for x in d["dk"]]
    if not hv:
        print("no healthy drive on roads B-C fitted")
        return
    lim = LIMIT_SPREADS * rms(hv)
    print(f"limit: {LIMIT_SPREADS:g} x {rms(hv):.3f} = {lim:.3f} below the baseline (ln units)")
    groups: Dict[str, List[Dict]] = {}
    for d in drives:
        if d["name"] == "baseline":
            continue
        key = d["name"] + (" road A" if road_class(d) == "A" else "")
        if d["name"].startswith("spring") and d["corner"] == "FL":
            key += " FL"
        groups.setdefault(key, []).append(d)
    hz = [x for d in drives if d["name"] == "healthy" and road_class(d) in "BC"
          for x in d.get("z", [])]
    if hz:
        print(f"the same scored by the fits' jackknife (z = change / sd of drive and baseline): "
              f"healthy B-C rms {rms(hz):.2f}, largest |z| {max(abs(x) for x in hz):.2f}; "
              f"per group below the drives with the lowest z beyond {Z_LIMIT:.2f} (a "
              f"{100 * FALSE_ALARM_RATE:g} % false-alarm rate per drive if z is normal) and "
              f"{LIMIT_SPREADS:g}")
    for key, ds in sorted(groups.items()):
        flagged = [d for d in ds if min(d["dk"]) < -lim]
        named = [d for d in ds if d["corner"] and min(d["dk"]) < -lim
                 and CORNERS[min(range(4), key=lambda c: d["dk"][c])] == d["corner"]]
        lowest = [d for d in ds if d["corner"]
                  and CORNERS[min(range(4), key=lambda c: d["dk"][c])] == d["corner"]]
        at = [d["dk"][CORNERS.index(d["corner"])] for d in ds if d["corner"]]
        at_txt = (f"; at its corner {min(at):+.2f}..{max(at):+.2f}, median "
                  f"{sorted(at)[len(at) // 2]:+.2f}; its corner lowest {len(lowest)}/{len(ds)}"
                  if at else "")
        print(f"  {key:<22} {len(ds):>2} drives: beyond the limit {len(flagged)}/{len(ds)}"
              + (f", its corner named {len(named)}/{len(ds)}" if ds[0]["corner"] else "") + at_txt
              + "".join(f"; z < -{zl:.2f}: {sum(min(d['z']) < -zl for d in ds)}/{len(ds)}, named "
                        + str(sum(1 for d in ds if d["corner"] and min(d["z"]) < -zl
                                  and CORNERS[min(range(4), key=lambda c: d["z"][c])]
                                  == d["corner"]))
                        for zl in (Z_LIMIT, LIMIT_SPREADS) if all("z" in d for d in ds)))


def main(argv: Optional[List[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--buses", type=int, default=5)
    p.add_argument("--healthy", type=int, default=6, help="extra healthy drives per bus")
    p.add_argument("--spring-scale", type=float, default=0.8)
    p.add_argument("--json", type=Path, help="write every drive's fit here")
    p.add_argument("--from-json", type=Path, help="summarize a --json of an earlier run")
    p.add_argument("--config", type=Path,
                   help="analysis config for every analyze (e.g. [model_update] band_hz)")
    a = p.parse_args(argv)
    if a.from_json:
        summarize(json.loads(a.from_json.read_text()))
        return 0
    try:
        h.check_tools()
    except h.Skip as e:
        print(f"skipped: {e}")
        return 0
    seeds = h.draw_bus_seeds(a.buses, "spring fit")
    buses = []
    with tempfile.TemporaryDirectory(prefix="vibmode-spring-fit-") as work:
        for s in seeds:
            b = run_bus(s, a.healthy, a.spring_scale, Path(work), a.config)
            buses.append(b)
            for d in b["drives"]:
                head = f"bus {s:>5} {d['name']:<9} {d['detail']:<36}"
                if "dk" not in d:
                    print(f"{head} FAILED: {d.get('failed', '')[:120]}", flush=True)
                    continue
                ns = " (not supported)" if d.get("not_supported") else ""
                print(f"{head} spring ratio change FL FR RL RR {fmt(d['dk'])} | z {fmt(d['z'])}"
                      f" | damper {fmt(d['dc'])}{ns}", flush=True)
    if a.json:
        a.json.write_text(json.dumps(buses, indent=1))
    summarize(buses)
    return 0


if __name__ == "__main__":
    sys.exit(main())
