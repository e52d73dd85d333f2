#!/usr/bin/env python3
"""The full-car model update on busgen's bus family (issue 30, items 1 and 4).

For each bus drawn at random: simulate 8 records (2 kHz), write a vibmode vehicle file holding the
bus's true geometry, masses and tyres with the generic suspension of examples/city_bus_flexible.toml
(springs, dampers, inertias, rear anti-roll bar; with and without its front bar), run
`vibmode analyze rec*.csv --vehicle bus.toml -o OUT` and compare the updated body pitch, heave and
roll (truth.json modes labelled 'body pitch' ...) and every fitted spring and damper (truth's ks_f,
ks_r, cs_f, cs_r times spring_scale / damper_scale per corner) with the truth.

    python tools/busgen/update.py --buses 6            # 6 buses drawn at random
    VIBMODE_BUS_SEEDS=0,17 python tools/busgen/update.py
    python tools/busgen/update.py --buses 3 --no-noise
    python tools/busgen/update.py --buses 3 --added-noise 0.0025,2.6e-4   # unsprung noise / 4

Prints one row per bus and file variant, then the rates. busgen needs numpy and scipy
(BUSGEN_PYTHON); the binary is VIBMODE_BIN or target/release/vibmode.
"""

from __future__ import annotations

import argparse
import json
import math
import random
import shutil
import sys
import tempfile
from pathlib import Path
from typing import Dict, List, Optional

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness  # noqa: E402

#: The acceptance goals of issue 30 item 4.
MODE_TOL = 0.03
PARAM_TOL = 0.10
MODE_RATE = 0.90
CORNERS = ("FL", "FR", "RL", "RR")
BODY = ("body pitch", "body heave", "body roll")

#: Generic suspension and inertias: examples/city_bus_flexible.toml.
GENERIC = dict(pitch_inertia_kgm2=115000.0, roll_inertia_kgm2=16000.0, cg_height_m=1.2,
               ks_f=127000.0, cs_f=7500.0, karb_f=340000.0,
               ks_r=203000.0, cs_r=12000.0, karb_r=500000.0)


def vehicle_toml(truth: Dict, front_bar: bool) -> str:
    """A vibmode vehicle file for a busgen truth.json: the bus's geometry, masses and tyres, the
    generic suspension and inertias (those are fitted), sensors named as busgen's channels.
    `front_bar`: keep the generic front anti-roll bar in the file (half of busgen's buses have
    none, and the update should find it absent there; the other half draw one of 0-200 kN m/rad,
    which a file without a bar cannot represent: `represents_bus`). No bending section: the update's band is below it."""
    b = truth["bus"]
    g = GENERIC
    lines = [
        f'name = "busgen bus {truth["bus_seed"]}, generic suspension'
        f'{", front bar" if front_bar else ""}"',
        "[body]",
        f"mass_kg = {b['ms']!r}",
        f"pitch_inertia_kgm2 = {g['pitch_inertia_kgm2']!r}",
        f"roll_inertia_kgm2 = {g['roll_inertia_kgm2']!r}",
        f"cg_height_m = {g['cg_height_m']!r}",
        "[geometry]",
        f"wheelbase_m = {b['a'] + b['b']!r}",
        f"cg_to_front_axle_m = {b['a']!r}",
        f"track_front_m = {b['tf']!r}",
        f"track_rear_m = {b['tr']!r}",
    ]
    for axle, s in (("front", "f"), ("rear", "r")):
        bar = g[f"karb_{s}"] if (axle == "rear" or front_bar) else 0.0
        lines += [
            f"[{axle}]",
            f"unsprung_mass_kg = {b['mu_' + s]!r}",
            f"spring_stiffness_n_per_m = {g['ks_' + s]!r}",
            f"damper_n_s_per_m = {g['cs_' + s]!r}",
            f"tyre_stiffness_n_per_m = {b['kt_' + s]!r}",
            f"tyre_damping_n_s_per_m = {b['ct_' + s]!r}",
            f"anti_roll_stiffness_nm_per_rad = {bar!r}",
        ]
    # The tyre faults are known to the file (the update fits the suspension only).
    for i, c in enumerate(CORNERS):
        ts = b["tyre_scale"][i]
        if ts != 1.0:
            lines += ["[[corner_condition]]", f'corner = "{c}"', f"tyre_stiffness_factor = {ts!r}"]
    for ch in ("unsprung_fl", "unsprung_fr", "unsprung_rl", "unsprung_rr",
               "sprung_fr", "sprung_rl", "sprung_rr"):
        kind, corner = ch.split("_")
        lines += ["[[sensors]]", f'name = "{ch}"', f'kind = "{kind}"', f'corner = "{corner.upper()}"']
    return "\n".join(lines) + "\n"


def true_params(truth: Dict) -> Dict[str, float]:
    """The bus's springs and dampers per corner (N/m, N s/m), faults applied."""
    b = truth["bus"]
    out = {}
    for i, c in enumerate(CORNERS):
        s = "f" if i < 2 else "r"
        out[f"spring {c}"] = b["ks_" + s] * b["spring_scale"][i]
        out[f"damper {c}"] = b["cs_" + s] * b["damper_scale"][i]
    return out


def fitted_params(mu: Dict) -> Dict[str, float]:
    """Springs and dampers per corner (N/m, N s/m) of the updated vehicle in results.json."""
    v = mu["vehicle"]
    out = {}
    for i, c in enumerate(CORNERS):
        ax = v["front"] if i < 2 else v["rear"]
        cc = [x for x in v.get("corner_condition", []) if x["corner"] == c]
        sf = 1.0
        df = 1.0
        for x in cc:
            sf *= x.get("spring_factor", 1.0)
            df *= x.get("damper_factor", 1.0)
        out[f"spring {c}"] = ax["spring_stiffness_n_per_m"] * sf
        out[f"damper {c}"] = ax["damper_n_s_per_m"] * df
    return out


def score(folder: Path, front_bar: bool, out: Path, config: Optional[Path] = None) -> Dict:
    """One update on one folder: its errors against the truth (or why it was not updated).
    `config`: an analysis config given to `vibmode analyze` (e.g. its `[model_update]`)."""
    t = harness.truth(folder)
    out.mkdir(parents=True, exist_ok=True)
    vf = out / "bus.toml"
    vf.write_text(vehicle_toml(t, front_bar))
    extra = ["--config", str(config)] if config else []
    res = harness.analyze(folder, "--vehicle", vf, *extra, out=out / "out")
    mu = res.get("model_update") or {}
    row: Dict = {"bus": t["bus_seed"], "front_bar": front_bar,
                 "bus_front_bar_nm_per_rad": t["bus"]["karb_f"],
                 "written": (out / "out" / "updated_vehicle.toml").is_file()}
    if "not_updated" in mu:
        row["not_updated"] = mu["not_updated"]
        # A fit the records do not support still leaves its figures in model_update.json.
        full = out / "out" / "model_update.json"
        if not full.is_file():
            return row
        mu = json.loads(full.read_text())
    if "vehicle" not in mu:
        row["not_updated"] = "no model_update in results.json"
        return row
    row["supported"] = mu.get("supported", True)
    sd_hz = {m["label"].replace("_", " "): m["frequency_hz_sd"] for m in mu.get("mode_sd", [])}
    # Whether a front bar was fitted: the file's, or any with `anti_roll_bars = "both"`.
    row["front_bar_fitted"] = any(p["name"] == "anti-roll bar front"
                                  for p in mu.get("parameters", []))
    row["param_sd"] = {p["name"]: p["sd"] / p["value"] for p in mu.get("parameters", [])
                       if p.get("sd") is not None and p["value"] > 0}
    truth_modes = {m["label"]: m for m in t["modes"]}
    errs = {}
    for lab in BODY:
        got = [m for m in mu["modes"] if m["label"] == lab.replace(" ", "_")]
        if lab in truth_modes and got:
            errs[lab] = got[0]["frequency_hz"] / truth_modes[lab]["f_n_hz"] - 1.0
            if lab in sd_hz:
                row.setdefault("mode_sd", {})[lab] = sd_hz[lab] / got[0]["frequency_hz"]
    row["modes"] = errs
    tp, fp = true_params(t), fitted_params(mu)
    row["params"] = {k: fp[k] / tp[k] - 1.0 for k in tp}
    row["absent"] = mu.get("absent", [])
    return row


#: A front bar below this (N m/rad) changes the bus's roll by well under 1 %: taken as none.
NEGLIGIBLE_BAR_NM_PER_RAD = 10e3


def represents_bus(r: Dict) -> bool:
    """Whether the row's fit can represent its bus: a front bar was fitted (the file's, or with
    `anti_roll_bars = "both"`, the default since 2026-11-29, whatever the file holds), or the bus
    has none (a fit of the file's bars alone cannot hold the roll moment of a bar it lacks)."""
    return (r.get("front_bar_fitted", r["front_bar"])
            or r.get("bus_front_bar_nm_per_rad", 0.0) < NEGLIGIBLE_BAR_NM_PER_RAD)


def fmt_row(r: Dict) -> str:
    head = f"bus {r['bus']:>5} {'front bar' if r['front_bar'] else 'no bar   '}"
    if r.get("bus_front_bar_nm_per_rad", 0.0) >= NEGLIGIBLE_BAR_NM_PER_RAD:
        head += f" (bus has a {r['bus_front_bar_nm_per_rad'] / 1e3:.0f} kN m/rad front bar)"
    if "modes" not in r:
        return f"{head}  NOT UPDATED: {r['not_updated'][:150]}"
    sds = r.get("param_sd", {})
    worst_sd = max(sds.items(), key=lambda kv: kv[1]) if sds else ("-", float("nan"))
    sd_txt = (f"  sd: modes <= {100 * max(r['mode_sd'].values()):.1f}%"
              if r.get("mode_sd") else "  sd: -")
    m = " ".join(f"{k.split()[1]} {100 * v:+6.2f}%" for k, v in r["modes"].items())
    worst = max(r["params"].items(), key=lambda kv: abs(kv[1]))
    sp = max(abs(v) for k, v in r["params"].items() if k.startswith("spring"))
    dp = max(abs(v) for k, v in r["params"].items() if k.startswith("damper"))
    return (f"{head}  {m}  springs <= {100 * sp:.1f}%  dampers <= {100 * dp:.1f}% "
            f"(worst {worst[0]} {100 * worst[1]:+.1f}%)  absent {r['absent'] or '-'}"
            f"{sd_txt}, worst parameter sd {worst_sd[0]} {100 * worst_sd[1]:.1f}%"
            f"{'' if r.get('supported', True) else '  [NOT UPDATED: ' + r.get('not_updated', '')[:90] + ']'}")


def summarize(rows: List[Dict]) -> Dict[str, float]:
    """Rates over the rows: all three body modes within 3 %; every spring and damper within 10 %."""
    n = len(rows)
    done = [r for r in rows if "modes" in r and r.get("supported", True)]
    modes_ok = sum(1 for r in done if len(r["modes"]) == 3
                   and all(abs(v) <= MODE_TOL for v in r["modes"].values()))
    params_ok = sum(1 for r in done if all(abs(v) <= PARAM_TOL for v in r["params"].values()))
    per_param = [abs(v) <= PARAM_TOL for r in done for v in r["params"].values()]
    return {"runs": n, "updated": len(done), "modes_within_3pct": modes_ok,
            "all_params_within_10pct": params_ok,
            "params_within_10pct": sum(per_param), "params": len(per_param)}


def accuracy(rows: List[Dict]) -> Dict[str, float]:
    """The fit's errors over every row with figures, supported or not (the estimator's accuracy,
    apart from whether it trusts itself): median absolute body-mode error, modes within 3 %, fits
    with all three, median absolute spring and damper error, parameters within 10 %, the range of
    the modes' relative standard deviations, and how many fits were supported."""
    def med(v: List[float]) -> float:
        v = sorted(v)
        return float("nan") if not v else 0.5 * (v[(len(v) - 1) // 2] + v[len(v) // 2])

    fig = [r for r in rows if "modes" in r]
    modes = [abs(v) for r in fig for v in r["modes"].values()]
    springs = [abs(v) for r in fig for k, v in r["params"].items() if k.startswith("spring")]
    dampers = [abs(v) for r in fig for k, v in r["params"].items() if k.startswith("damper")]
    sds = [v for r in fig for v in r.get("mode_sd", {}).values()]
    heave = [r["modes"]["body heave"] for r in fig if "body heave" in r["modes"]]
    return {"fits": len(rows), "with_figures": len(fig),
            "mode_error_median": med(modes),
            "modes_within_3pct": sum(v <= MODE_TOL for v in modes), "modes": len(modes),
            "fits_all_three_within_3pct": sum(
                1 for r in fig if len(r["modes"]) == 3
                and all(abs(v) <= MODE_TOL for v in r["modes"].values())),
            "spring_error_median": med(springs), "damper_error_median": med(dampers),
            "params_within_10pct": sum(v <= PARAM_TOL for v in springs + dampers),
            "params": len(springs) + len(dampers),
            "heave_error_mean": sum(heave) / len(heave) if heave else float("nan"),
            "mode_sd_min": min(sds) if sds else float("nan"),
            "mode_sd_max": max(sds) if sds else float("nan"),
            "mode_sd_median": med(sds),
            "supported": sum(1 for r in fig if r.get("supported", True))}


def with_noise(clean: Path, densities: List[float], out: Path, seed: int) -> Path:
    """A copy of a folder of noise-free records with white noise added: one-sided densities
    `densities` = [unsprung, sprung] in (m/s^2)^2/Hz on the channels named unsprung_* and
    sprung_* (variance density * fs / 2 per sample), from random.Random(seed)."""
    out.mkdir(parents=True, exist_ok=True)
    shutil.copy(clean / "truth.json", out / "truth.json")
    rng = random.Random(seed)
    for f in harness.records(clean):
        lines = f.read_text().splitlines()
        head = lines[0].split(",")
        rows = [[float(v) for v in ln.split(",")] for ln in lines[1:]]
        fs = 1.0 / (rows[1][0] - rows[0][0])
        sig = [math.sqrt(densities[0 if h.startswith("unsprung") else 1] * fs / 2)
               if h.split("_")[0] in ("unsprung", "sprung") else 0.0 for h in head]
        text = [lines[0]]
        for r in rows:
            text.append(",".join(repr(v + rng.gauss(0.0, g)) if g > 0 else repr(v)
                                 for v, g in zip(r, sig)))
        (out / f.name).write_text("\n".join(text) + "\n")
    return out


def run(seeds: List[int], extra: List[str], work: Optional[Path] = None,
        config: Optional[Path] = None, added_noise: Optional[List[float]] = None) -> List[Dict]:
    """Each bus simulated (busgen options `extra`) and fitted with and without a front bar; with
    `added_noise` ([unsprung, sprung] densities), its noise-free records with that noise added."""
    work = work or Path(tempfile.mkdtemp(prefix="vibmode-upd-"))
    rows = []
    for s in seeds:
        if added_noise is not None:
            folder = with_noise(harness.simulate(s, 1000 + s, "--no-noise", *extra), added_noise,
                                work / f"bus{s}-records", s)
        else:
            folder = harness.simulate(s, 1000 + s, *extra)
        for bar in (False, True):
            r = score(folder, bar, work / f"bus{s}-{'bar' if bar else 'nobar'}", config)
            print(fmt_row(r), flush=True)
            rows.append(r)
    return rows


def main(argv: Optional[List[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--buses", type=int, default=6, help="buses drawn at random (default 6)")
    ap.add_argument("--nominal", action="store_true", help="add busgen's nominal bus (seed 0)")
    ap.add_argument("--no-noise", action="store_true", help="simulate without sensor noise")
    ap.add_argument("--json", type=Path, help="write the rows and the summary here")
    ap.add_argument("--work", type=Path, help="keep each run's vehicle file and output here")
    ap.add_argument("--added-noise", metavar="UNSPRUNG,SPRUNG",
                    help="noise-free records with white noise of these one-sided densities, "
                         "(m/s^2)^2/Hz, added to the unsprung and sprung channels (busgen's own "
                         "noise measures about 0.01,2.6e-4): which sensors' noise limits the fit")
    ap.add_argument("--config", type=Path,
                    help="analysis config for every analyze (e.g. [model_update] edge_s = 0.5)")
    a = ap.parse_args(argv)
    try:
        seeds = harness.draw_bus_seeds(a.buses, "model update")
        if a.nominal and 0 not in seeds:
            seeds = [0] + seeds
        added = [float(v) for v in a.added_noise.split(",")] if a.added_noise else None
        if added is not None and (len(added) != 2 or not all(v >= 0 for v in added)):
            print(f"--added-noise {a.added_noise}: give two densities >= 0, e.g. 0.01,2.6e-4")
            return 2
        rows = run(seeds, ["--no-noise"] if a.no_noise and added is None else [], a.work,
                   a.config, added)
    except harness.Skip as e:
        print(f"skipped: {e}")
        return 0
    s = summarize(rows)
    print(f"body pitch, heave and roll within 3 %: {harness.rate(s['modes_within_3pct'], s['runs'])}"
          f" (goal >= 90 %); every spring and damper within 10 %: "
          f"{harness.rate(s['all_params_within_10pct'], s['runs'])}; single parameters within 10 %: "
          f"{harness.rate(s['params_within_10pct'], s['params'])}; updated "
          f"{harness.rate(s['updated'], s['runs'])}")
    for acc, what in ((accuracy(rows), "every fit"),
                      (accuracy([r for r in rows if represents_bus(r)]),
                       "the fits whose file can represent the bus")):
        print_accuracy(acc, what)
    if a.json:
        a.json.write_text(json.dumps({"rows": rows, "summary": s, "accuracy": accuracy(rows)},
                                     indent=1))
    return 0


def print_accuracy(acc: Dict, what: str) -> None:
    print(f"accuracy over {what} with figures (supported or not): "
          f"body-mode error median {100 * acc['mode_error_median']:.1f} %, "
          f"{acc['modes_within_3pct']}/{acc['modes']} modes within 3 %, "
          f"{acc['fits_all_three_within_3pct']}/{acc['fits']} fits with all three; "
          f"springs median {100 * acc['spring_error_median']:.1f} %, dampers "
          f"{100 * acc['damper_error_median']:.1f} %, {acc['params_within_10pct']}/{acc['params']} "
          f"springs and dampers within 10 %; heave mean {100 * acc['heave_error_mean']:+.1f} %; "
          f"mode sd {100 * acc['mode_sd_min']:.1f}-{100 * acc['mode_sd_max']:.1f} % "
          f"(median {100 * acc['mode_sd_median']:.1f} %); supported {acc['supported']}/{acc['fits']}")


if __name__ == "__main__":
    sys.exit(main())
