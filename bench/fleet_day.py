#!/usr/bin/env python3
"""A fleet's day on Dask: simulate a fleet of buses (busgen, ../shared/busgen), compute every
record's fleet features on a dask.distributed LocalCluster with 1 and then 2 workers through the
package (vibmode.fleet.features on the workers, vibmode.fleet.store_features in this process, the
store's one writer), build each bus's baseline, check the day's records, and report records per
second per worker, the scaling from 1 to 2 workers, the time to the fleet's verdicts, and the
projection to 100 buses x 8 h.

    pip install ./python "dask[distributed]" numpy scipy
    python bench/fleet_day.py --buses 20 --records 8 [--fs 2000] [--workers 1 2] [--seeds 3,17,...]

The fleet: `--buses` buses drawn at random from busgen's family (seeds printed; `--seeds` replays),
each with a baseline drive and a day drive of `--records` records of 10.24 s (the day scaled down
from 8 h, which is 2 812 records, and stated). One bus has a worn damper (50 % at a random corner)
in its day drive, one drives its day on a class D road; the others are healthy. The verdicts must
name the worn damper's bus and corner and the rough road's bus: the script says whether they do.
Timings are wall-clock seconds of this machine, one run.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import random
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "tools", "busgen"))

import harness  # noqa: E402

RECORD_S = 10.24
DAY_RECORDS_8H = int(8 * 3600 / RECORD_S)
CORNERS = ["fl", "fr", "rl", "rr"]


def features_task(path, settings, content_hash):
    # One core per task: the worker's parallelism is the cluster's, not rayon's.
    os.environ.setdefault("RAYON_NUM_THREADS", "1")
    import vibmode

    return vibmode.fleet.features(path, settings=settings, content_hash=content_hash)


def simulate_fleet(seeds, records, fs, damper_bus, damper_corner, road_bus):
    jobs = []
    for i, s in enumerate(seeds):
        jobs.append((i, "baseline", s, 1, ()))
        extra = ()
        if i == damper_bus:
            extra = ("--damper", f"{damper_corner}=0.5")
        elif i == road_bus:
            extra = ("--road-class", "D")
        jobs.append((i, "day", s, 2, extra))

    def one(job):
        i, kind, s, seed, extra = job
        return i, kind, harness.simulate(s, seed, *extra, records=records, fs_hz=fs)

    out = collections.defaultdict(dict)
    with ThreadPoolExecutor(max_workers=2) as ex:
        for i, kind, folder in ex.map(one, jobs):
            out[i][kind] = [str(p) for p in harness.records(folder)]
    return out


def run(fleet, seeds, n_workers, workdir):
    import dask.distributed as dd
    import vibmode

    db = os.path.join(workdir, f"fleet-{n_workers}.db")
    vibmode.fleet.init(db)
    settings = vibmode.fleet.settings(db)
    content_hash = vibmode.fleet.content_hash(db)
    paths = [(i, kind, p) for i in sorted(fleet) for kind in ("baseline", "day") for p in fleet[i][kind]]
    os.environ["RAYON_NUM_THREADS"] = "1"
    with dd.LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                         dashboard_address=None) as cluster, dd.Client(cluster) as client:
        client.run(lambda: os.environ.__setitem__("RAYON_NUM_THREADS", "1"))
        t0 = time.perf_counter()
        futures = client.map(features_task, [p for _, _, p in paths], settings=settings,
                             content_hash=content_hash, pure=False)
        items = client.gather(futures)
        t_features = time.perf_counter() - t0
    by = collections.defaultdict(list)
    for (i, kind, _), item in zip(paths, items):
        by[(i, kind)].append(item)
    t1 = time.perf_counter()
    verdicts = {}
    for i in sorted(fleet):
        vid = f"bus-{seeds[i]}"
        vibmode.fleet.store_features(db, vid, by[(i, "baseline")], condition="nominal")
        vibmode.fleet.baseline(db, vid)
    t_baseline = time.perf_counter() - t1
    t2 = time.perf_counter()
    for i in sorted(fleet):
        vid = f"bus-{seeds[i]}"
        verdicts[i] = vibmode.fleet.check(db, vid, fleet[i]["day"])
    t_check = time.perf_counter() - t2
    return {
        "workers": n_workers,
        "records": len(paths),
        "features_s": t_features,
        "records_per_s_per_worker": len(paths) / t_features / n_workers,
        "store_and_baseline_s": t_baseline,
        "check_s": t_check,
        "to_verdict_s": t_features + t_baseline + t_check,
        "verdicts": verdicts,
    }


def drive_verdict(check):
    """The day drive's verdict: the store's per-drive decision when it gives one (`drives`), else
    the most frequent class of the records; the corner named first (the first evidence's)."""
    classes = collections.Counter()
    corners = collections.Counter()
    for r in check.get("records", []):
        c = r.get("classification", "?")
        classes[c] += 1
        ev = r.get("evidence") or []
        if c in ("vehicle", "both") and ev and isinstance(ev[0], dict) and ev[0].get("corner"):
            corners[str(ev[0]["corner"]).lower()] += 1
    top = classes.most_common(1)[0][0] if classes else "?"
    corner = corners.most_common(1)[0][0] if corners else None
    drives = check.get("drives") or []
    if drives and isinstance(drives[0], dict) and drives[0].get("classification"):
        top = drives[0]["classification"]
        named = drives[0].get("corner")
        if named:
            corner = str(named).lower()
    return top, dict(classes), corner


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--buses", type=int, default=20)
    ap.add_argument("--records", type=int, default=8, help="records per drive (baseline and day)")
    ap.add_argument("--fs", type=float, default=2000.0)
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--seeds", default="", help="bus seeds to replay, comma-separated")
    ap.add_argument("--out", default=None, help="also write the figures as JSON here")
    a = ap.parse_args()
    if a.seeds:
        os.environ["VIBMODE_BUS_SEEDS"] = a.seeds
    seeds = harness.draw_bus_seeds(a.buses, "fleet")
    rng = random.Random(sum(seeds))
    damper_bus, road_bus = rng.sample(range(len(seeds)), 2)
    damper_corner = rng.choice(CORNERS)
    print(f"worn damper (50 %): bus-{seeds[damper_bus]} {damper_corner.upper()}; "
          f"class D road: bus-{seeds[road_bus]}; day scaled to {a.records} records "
          f"({a.records * RECORD_S:.0f} s) of {DAY_RECORDS_8H} in 8 h; records at {a.fs:g} Hz", flush=True)
    t0 = time.perf_counter()
    fleet = simulate_fleet(seeds, a.records, a.fs, damper_bus, damper_corner, road_bus)
    print(f"simulated {2 * a.records * len(seeds)} records in {time.perf_counter() - t0:.0f} s", flush=True)
    results = []
    with tempfile.TemporaryDirectory() as work:
        for w in a.workers:
            r = run(fleet, seeds, w, work)
            results.append(r)
            print(f"{w} worker(s): {r['records']} records, features {r['features_s']:.1f} s "
                  f"({r['records_per_s_per_worker']:.2f} records/s/worker), store + baselines "
                  f"{r['store_and_baseline_s']:.1f} s, checks {r['check_s']:.1f} s, "
                  f"to verdict {r['to_verdict_s']:.1f} s", flush=True)
    last = results[-1]
    print("\n| bus | day condition | verdict (most records) | classes | corner named first |")
    print("|---|---|---|---|---|")
    ok_damper = ok_road = False
    false_alarms = 0
    for i, s in enumerate(seeds):
        cond = ("damper " + damper_corner.upper() + " 50 %") if i == damper_bus else (
            "class D road" if i == road_bus else "healthy")
        top, classes, corner = drive_verdict(last["verdicts"][i])
        print(f"| bus-{s} | {cond} | {top} | {classes} | {corner.upper() if corner else '-'} |")
        if i == damper_bus:
            ok_damper = top in ("vehicle", "both") and corner == damper_corner
        elif i == road_bus:
            ok_road = top == "road"
        elif top != "normal":
            false_alarms += 1
    if len(results) >= 2:
        r1, r2 = results[0], results[1]
        print(f"\nscaling 1 -> {r2['workers']} workers: features {r1['features_s'] / r2['features_s']:.2f}x")
    rate = max(r["records_per_s_per_worker"] for r in results)
    need = 100 * DAY_RECORDS_8H / (rate * 8 * 3600)
    print(f"projection: 100 buses x 8 h = {100 * DAY_RECORDS_8H} records/day; at {rate:.2f} records/s/worker "
          f"that is {need:.1f} workers busy for 8 h (features only; records at {a.fs:g} Hz)")
    print(f"worn damper's bus and corner named: {'yes' if ok_damper else 'NO'}; rough road named: "
          f"{'yes' if ok_road else 'NO'}; healthy buses not normal: {false_alarms} of {len(seeds) - 2}")
    if a.out:
        with open(a.out, "w") as f:
            json.dump({"seeds": seeds, "damper": [seeds[damper_bus], damper_corner],
                       "road": seeds[road_bus], "runs": [{k: v for k, v in r.items() if k != "verdicts"} for r in results],
                       "ok_damper": ok_damper, "ok_road": ok_road, "false_alarms": false_alarms}, f, indent=1)


if __name__ == "__main__":
    main()
