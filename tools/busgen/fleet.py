#!/usr/bin/env python3
"""Fleet monitoring on the independent bus family (../shared/busgen): how often `vibmode fleet
check` says what is true, per drive and per record.

Per bus (bus seeds drawn at random, printed; `VIBMODE_BUS_SEEDS=1,2,3` replays):

- baseline: 2 healthy drives of 8 records each (busgen defaults: class B road, 25-35 km/h,
  nominal load), `fleet ingest --condition nominal`, `fleet baseline`;
- a healthy drive on another day: other seeds, speed 20-40 km/h (or busgen's 25-35 km/h
  spread), load 0.85..1.20, road class A, B or C, all drawn at random;
- faults at a corner drawn at random: damper at 60 % and 70 %, spring at 80 %, tyre at 75 %;
- a healthy drive on a class D road.

Each drive is given to one `fleet check --json -` (its 8 records: one drive), on a copy of the
store as the baseline left it: the drives are alternatives, not one vehicle's sequence (the
spring trend pools a vehicle's last drives; `spring_trend.py` measures sequences). Scored:

- healthy: `normal` (per drive, per record);
- faults: `vehicle` or `both` with the faulty corner named first (the first vehicle evidence of
  the record or the drive); `both` counts as a false `both` unless a fault is present;
- class D: `road`; `both` there is a false `both`.

The component a fault drive names (`drives[].component`: damper, spring, tyre or suspension) is
counted apart: a right fault drive whose component is the fault's.

The baseline's own drives held out (`fleet baseline`'s leave-one-drive-out: each checked as a
drive against a model set of the other drive's records, read from the store's model set) are
printed per bus and summed as `held out`: healthy drives, so `normal` is right.

The drive's verdict is the JSON's `drives` entry when the binary writes one, else (older
binaries) it is not scored per drive.

`--test-extra=--no-periodic` (with `=`: the value starts with dashes) adds busgen options to
every checked drive (not the baseline), e.g. to see what the driveline lines or the sensor
noise do to a verdict.

Usage: python3 tools/busgen/fleet.py [--buses N] [--records 8] [--json OUT] [--keep DIR]
       [--test-extra OPTS] [--config FLEET.toml]
Needs VIBMODE_BIN (else target/release/vibmode) and a Python with numpy+scipy for busgen
(BUSGEN_PYTHON).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import random
import shutil
import sqlite3
import sys
import tempfile
from pathlib import Path
from typing import Dict, List, Optional

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness as h  # noqa: E402
import update  # noqa: E402

CORNERS = ["fl", "fr", "rl", "rr"]

#: (name, busgen fault option, scale, what is expected)
FAULTS = [
    ("damper60", "--damper", 0.6),
    ("damper70", "--damper", 0.7),
    ("spring80", "--spring", 0.8),
    ("tyre75", "--tyre", 0.75),
]


def healthy_drive(rng: random.Random):
    """A healthy drive on another day: `(busgen options, load, road class, speed or None)`, the
    speed 20-40 km/h or busgen's 25-35 km/h per record, the load -15..+20 %, the road A-C."""
    speed = rng.choice([None, round(rng.uniform(20.0, 40.0), 1)])
    load = round(rng.uniform(0.85, 1.20), 3)
    road = rng.choice("ABC")
    extra = ["--load", str(load), "--road-class", road]
    if speed is not None:
        extra += ["--speed-kmh", str(speed)]
    return extra, load, road, speed


def conditions(bus_seed: int, rng: random.Random) -> List[Dict]:
    """The drives to check on one bus, with their busgen options and expectation."""
    out = []
    extra, load, road, speed = healthy_drive(rng)
    out.append({"name": "healthy", "extra": extra, "expect": "normal", "corner": None,
                "detail": f"load {load}, road {road}, "
                          + (f"{speed} km/h" if speed else "25-35 km/h")})
    for name, opt, scale in FAULTS:
        corner = rng.choice(CORNERS)
        out.append({"name": name, "extra": [opt, f"{corner}={scale}"], "expect": "vehicle",
                    "corner": corner.upper(), "component": opt[2:],
                    "detail": f"{opt[2:]} {corner.upper()}={scale}"})
    out.append({"name": "roadD", "extra": ["--road-class", "D"], "expect": "road",
                "corner": None, "detail": "class D"})
    return out


def first_corner(evidence: List[Dict]) -> Optional[str]:
    for e in evidence:
        if e.get("group") == "vehicle":
            return e.get("corner")
    return None


def verdict_ok(cls: str, corner: Optional[str], cond: Dict) -> bool:
    if cond["expect"] == "vehicle":
        return cls in ("vehicle", "both") and corner == cond["corner"]
    return cls == cond["expect"]


def more_drives(bus_seed: int, n_healthy: int) -> List[Dict]:
    """`n_healthy` more healthy drives (drawn as the first) and a spring at 80 % at each corner
    on such drawn conditions (`--more`), from their own random stream: the drives of
    `conditions` stay the same."""
    more = random.Random(bus_seed * 104729 + 31)
    out = []
    for k in range(n_healthy):
        extra, load, road, speed = healthy_drive(more)
        out.append({"name": "healthy", "extra": extra, "expect": "normal", "corner": None,
                    "detail": f"load {load}, road {road}, "
                              f"{'25-35' if speed is None else speed} km/h", "seed": 500000 + 1000 * k})
    for i, c in enumerate(CORNERS):
        extra, load, road, speed = healthy_drive(more)
        out.append({"name": "spring80", "extra": ["--spring", f"{c}=0.8", *extra],
                    "expect": "vehicle", "corner": c.upper(), "component": "spring",
                    "detail": f"spring {c.upper()} 0.8, load {load}, road {road}",
                    "seed": 600000 + 1000 * i})
    return out


def make_baseline(bus_seed: int, n_records: int, work: Path, rng: random.Random,
                  model: bool = False, config: Optional[Path] = None, drives: int = 2):
    """A new store `work/fleet-SEED.db` with the bus's baseline: `drives` healthy drives of `n_records`
    (busgen defaults) ingested as nominal, `fleet baseline` built; with `model` the bus's model
    file registered first (`update.vehicle_toml`: its true geometry, masses and tyres, generic
    suspension). The seed of the baseline's simulations is `rng`'s first draw. Returns (store,
    vehicle id, that seed)."""
    db = work / f"fleet-{bus_seed}.db"
    if db.exists():
        db.unlink()
    vehicle = f"bus{bus_seed}"
    base_seed = rng.randrange(1, 10**6)
    h.run_vibmode(["fleet", "init", "--db", db, *(["--config", config] if config else [])])
    base = []
    for d in range(drives):
        folder = h.simulate(bus_seed, base_seed + 1000 * d, records=n_records)
        base += h.records(folder)
        if model and d == 0:
            toml = work / f"bus{bus_seed}.toml"
            toml.write_text(update.vehicle_toml(h.truth(folder), True))
            h.run_vibmode(["fleet", "register", "--db", db, "--vehicle", vehicle, toml])
    h.run_vibmode(["fleet", "ingest", "--db", db, "--vehicle", vehicle, "-q", *base])
    h.run_vibmode(["fleet", "baseline", "--db", db, "--vehicle", vehicle])
    return db, vehicle, base_seed


def run_bus(bus_seed: int, n_records: int, work: Path, rng: random.Random,
            test_extra: Optional[List[str]] = None, keep: bool = False,
            model: bool = False, n_more: int = 0,
            config: Optional[Path] = None) -> Dict:
    """Simulates, ingests, baselines and checks one bus; returns its rows.

    Each drive is checked on a copy of the store as the baseline left it. The stores are deleted
    unless `keep` (then each drive's stays in `work` as fleet-SEED-I-CONDITION.db, beside its
    check's JSON as check-SEED-CONDITION.json)."""
    db, vehicle, base_seed = make_baseline(bus_seed, n_records, work, rng, model, config)
    held = held_out(db)
    for d in held:
        print(f"bus {bus_seed:>5} baseline drive held out: {d['classification']}"
              f"{'/' + d['component'] if d.get('component') else ''} against "
              f"{d['reference_records']} records  {d.get('summary', '')[:160]}", flush=True)
    # The drives are alternatives, not one vehicle's sequence: each is checked on a copy of the
    # store as the baseline left it, so that the spring trend (which pools a vehicle's last
    # drives) does not carry one condition's fault into the next (tools/busgen/spring_trend.py
    # measures sequences).
    pristine = work / f"fleet-{bus_seed}.base.db"
    h.copy_store(db, pristine)
    rows = []
    drives = conditions(bus_seed, rng)
    n_first = len(drives)
    if n_more:
        drives += more_drives(bus_seed, n_more)
    for i, cond in enumerate(drives):
        seed = base_seed + (10000 * (i + 1) if i < n_first else cond["seed"])
        folder = h.simulate(bus_seed, seed, *cond["extra"], *(test_extra or []),
                            records=n_records)
        if keep:
            db = work / f"fleet-{bus_seed}-{i}-{cond['name']}.db"
        h.copy_store(pristine, db)
        r = h.run_vibmode(["fleet", "check", "--db", db, "--vehicle", vehicle, "-q",
                           "--json", "-", *h.records(folder)])
        out = json.loads(r.stdout)
        if keep:
            (work / f"check-{bus_seed}-{cond['name']}.json").write_text(r.stdout)
        recs = [(x["classification"], first_corner(x.get("evidence", [])), x.get("summary", ""))
                for x in out["records"]]
        drives = out.get("drives") or []
        drive = None
        if drives:
            dv = drives[0]
            drive = (dv["classification"], dv.get("corner") or first_corner(dv.get("evidence", [])),
                     dv.get("summary", ""), dv.get("component"))
        susp = (drives[0].get("suspension") if drives else None)
        rows.append({"bus": bus_seed, "cond": cond["name"], "detail": cond["detail"],
                     "suspension": susp,
                     "expect": cond["expect"], "corner": cond["corner"], "records": recs,
                     "drive": drive,
                     "record_ok": sum(verdict_ok(c, k, cond) for c, k, _ in recs),
                     "drive_ok": None if drive is None else verdict_ok(drive[0], drive[1], cond),
                     "component_ok": None if drive is None or not cond.get("component")
                     else verdict_ok(drive[0], drive[1], cond) and drive[3] == cond["component"],
                     "false_both": sum(c == "both" for c, _, _ in recs)
                     if cond["expect"] != "vehicle" else 0})
    pristine.unlink()
    if not keep:
        for f in work.glob(f"fleet-{bus_seed}.db*"):
            f.unlink()
    return {"bus": bus_seed, "rows": rows, "held_out": held}


def held_out(db: Path) -> List[Dict]:
    """The latest model set's nominal drives held out (`fleet baseline`'s leave-one-drive-out:
    each checked against a model set of the other nominal records), read from the store."""
    with contextlib.closing(sqlite3.connect(f"file:{db}?mode=ro", uri=True)) as c:
        row = c.execute("SELECT json FROM model_sets ORDER BY version DESC LIMIT 1").fetchone()
    return json.loads(row[0]).get("held_out_drives", []) if row else []


def summarise(buses: List[Dict]) -> Dict[str, Dict]:
    """Per condition: records right / total, drives right / total, false `both`."""
    summary: Dict[str, Dict] = {}
    for b in buses:
        for r in b["rows"]:
            s = summary.setdefault(r["cond"], {"rec_ok": 0, "rec_n": 0, "drive_ok": 0,
                                               "drive_n": 0, "false_both": 0,
                                               "component_ok": 0})
            s["rec_ok"] += r["record_ok"]
            s["rec_n"] += len(r["records"])
            s["false_both"] += r["false_both"]
            if r["drive_ok"] is not None:
                s["drive_ok"] += int(r["drive_ok"])
                s["drive_n"] += 1
            if r.get("component_ok"):
                s["component_ok"] += 1
        for d in b.get("held_out", []):
            s = summary.setdefault("held out", {"rec_ok": 0, "rec_n": 0, "drive_ok": 0,
                                                "drive_n": 0, "false_both": 0,
                                                "component_ok": 0})
            s["drive_ok"] += int(d["classification"] == "normal")
            s["drive_n"] += 1
    return summary


def print_row(r: Dict) -> None:
    classes = " ".join(f"{c}{'/' + k if k else ''}" for c, k, _ in r["records"])
    drive = "-" if r["drive"] is None else (
        f"{r['drive'][0]}{'/' + r['drive'][1] if r['drive'][1] else ''}"
        f"{'/' + r['drive'][3] if r['drive'][3] else ''}")
    print(f"bus {r['bus']:>5} {r['cond']:<9} {r['detail']:<34} records {r['record_ok']}/"
          f"{len(r['records'])} drive {drive:<18} [{classes}]", flush=True)
    bad = [s for (c, k, s) in r["records"] if not verdict_ok(c, k, {"expect": r["expect"],
                                                                      "corner": r["corner"]})]
    if bad:
        print(f"      first wrong: {bad[0][:200]}", flush=True)


def main(argv: Optional[List[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--buses", type=int, default=4)
    p.add_argument("--records", type=int, default=h.RECORDS, help="records per drive")
    p.add_argument("--json", type=Path, help="write the rows and the summary here")
    p.add_argument("--keep", type=Path,
                   help="keep each bus's store and checks' JSON in this folder (made if absent)")
    p.add_argument("--model", action="store_true",
                   help="register each bus's vehicle model file (its true geometry, masses and "
                        "tyres, generic suspension: tools/busgen/update.py) before the baseline, "
                        "for the suspension fitted per drive")
    p.add_argument("--more", type=int, default=0, metavar="K",
                   help="K more healthy drives per bus and a spring at 80 %% at each corner")
    p.add_argument("--config", type=Path,
                   help="fleet settings (TOML) given to `fleet init --config`")
    p.add_argument("--test-extra", default="",
                   help="busgen options added to every checked drive, "
                        "e.g. --test-extra=--no-periodic")
    a = p.parse_args(argv)
    try:
        h.check_tools()
    except h.Skip as e:
        print(f"skipped: {e}")
        return 0
    seeds = h.draw_bus_seeds(a.buses, "fleet")
    buses = measure(seeds, a.records, a.test_extra.split(), a.keep, a.model, a.more, a.config)
    summary = summarise(buses)
    print_summary(summary)
    if a.json:
        a.json.write_text(json.dumps({"buses": buses, "summary": summary}, indent=1))
    return 0


def measure(seeds: List[int], n_records: int = h.RECORDS,
            test_extra: Optional[List[str]] = None, keep: Optional[Path] = None,
            model: bool = False, n_more: int = 0,
            config: Optional[Path] = None) -> List[Dict]:
    """Runs the buses of `seeds`; with `keep`, their stores and checks stay in that folder."""
    if keep is not None:
        keep.mkdir(parents=True, exist_ok=True)
    work = keep if keep is not None else Path(tempfile.mkdtemp(prefix="vibmode-fleet-busgen-"))
    buses = []
    try:
        for s in seeds:
            rng = random.Random(s * 7919 + n_records)
            b = run_bus(s, n_records, work, rng, test_extra, keep is not None, model, n_more,
                        config)
            for r in b["rows"]:
                print_row(r)
            buses.append(b)
    finally:
        if keep is None:
            shutil.rmtree(work, ignore_errors=True)
    return buses


def print_summary(summary: Dict[str, Dict]) -> None:
    print("summary (right = healthy normal; fault vehicle|both with its corner first; "
          "class D road; component = right drives naming the fault's component):")
    for cond, s in summary.items():
        comp = (f" component {s.get('component_ok', 0)}/{s['drive_n']}"
                if cond not in ("healthy", "roadD", "held out") else "")
        if cond == "held out":
            print(f"  {cond:<9} baseline drives checked against the other baseline drive(s): "
                  f"normal {h.rate(s['drive_ok'], s['drive_n'])}")
            continue
        print(f"  {cond:<9} records {h.rate(s['rec_ok'], s['rec_n']):<16} drives "
              f"{h.rate(s['drive_ok'], s['drive_n']):<14} false 'both' records "
              f"{s['false_both']}{comp}")


if __name__ == "__main__":
    sys.exit(main())
