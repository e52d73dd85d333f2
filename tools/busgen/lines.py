#!/usr/bin/env python3
"""Line recognition and structural-mode classing over buses drawn at random from busgen.

Usage (a vibmode binary and busgen's Python with numpy and scipy):

    VIBMODE_BIN=target/release/vibmode BUSGEN_PYTHON=/path/to/venv/bin/python \
        python3 tools/busgen/lines.py --buses 6 [--seed 1] [--jobs 2]

Draws `--buses` bus seeds at random (printed; `VIBMODE_BUS_SEEDS=1,2,3` replays a draw),
simulates 8 records of each (fs 2000 Hz, `--csv-only`, records seed `--seed`), runs
`vibmode analyze rec*.csv -q -o OUT` and scores OUT/results.json against truth.json.

What is reported (the analysis's pools, not its single channels): the line tracks of the role
pools (`roles[].lines`), of the SSI-cov pool (`ssi.lines`) and of the body-band SSI-cov
(`body_ssi.analysis.lines`), and every invariant mode of those pools classed
`periodic-disturbance`. Reports within `MERGE_REL` of each other are one reported line.

Scores per bus:
- recall: true lines (truth `periodic_lines`, `f0_hz`) at least `APART_REL` (3 %) away from every
  true mode, found when a report lies within `MATCH_REL` (2 %) of them. Lines within 2 % of a
  lightly damped mode (zeta < 0.1, the bending) or of a mode no sensor sees cannot be judged
  (busgen's README) and are left out of recall and precision; lines between 2 and 3 % from a
  broad mode are left out of recall only.
- recall of the lines the sensors show: the same over the judged lines whose oracle p-value
  (`line_evidence.py`: the harmonic F-test at the line's own frequency, Fisher-combined over the
  records, Bonferroni over the channels) is below `line_evidence.SEEN_P` (0.01). A line above it
  is shown by no sensor even to a test that knows its frequency; each missed line prints its p.
- recall of the lines the sensors show clearly: the same over the judged lines whose oracle
  p-value is below `line_evidence.search_level` (1.3e-5 at 10.24 s): what the analysis's own
  combined test, searching its band at 1 % per pool and analysis, could report (the acceptance
  asserts this one). Lines between that level and 0.01 are shown but weaker than a search at the
  stated rate reaches.
- false lines: reported lines matching no true line within `MATCH_REL` (precision's numerator of
  misses); a report on an unjudgeable line counts neither way.
- structural classed periodic: a false report (above) within max(2 %, zeta) of the bending or of
  a wheel-hop mode (group `unsprung`): that mode was called a line.
- bending structural: where a sensor sees the bending (`observable_in` non-empty), an invariant
  mode of a pool classed `structural` within `BENDING_REL` (2 %) of its frequency. Each row
  prints the bending's largest `visibility` over the sensors (busgen's truth: its modal peak in
  a channel over the strongest mode's peak there; `observable_in` takes 0.05 and up). Scored
  again over the buses where no true line lies within 2 % of the bending: busgen's README says
  a line that close to a lightly damped mode cannot be judged, and in 10 s records (resolution
  0.1 Hz) neither can the mode beside it; such a row says "not judged".
- the role pools' modes: per role pool (the ARMA order sweeps of the sprung and of the unsprung
  channels) and true mode its channels see, whether a structural invariant mode of the pool lies
  within max(`POOL_MODE_REL` (3 %), zeta/2) of it, with the median relative error, per mode
  label; and how many of the pools' structural modes lie within max(5 %, zeta) of no true mode
  and 2 % of no true line. The summary only; it is what a change of the order sweep moves.

Prints one row per bus and the summary; exit status 0 (it measures, it does not judge).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Dict, List, Tuple

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness  # noqa: E402
import line_evidence  # noqa: E402

APART_REL = 0.03
MATCH_REL = 0.02
MERGE_REL = 0.01
BENDING_REL = 0.02
LIGHT_ZETA = 0.1
POOL_MODE_REL = 0.03


def is_bending(m: Dict) -> bool:
    return "bending" in m.get("label", "")


def is_wheel_hop(m: Dict) -> bool:
    return m.get("group") == "unsprung"


def rel(a: float, b: float) -> float:
    return abs(a - b) / b


def pools(res: Dict) -> List[Tuple[str, Dict]]:
    """(name, pool) of the role pools, the SSI-cov pool and the body-band SSI-cov."""
    out = [(f"role:{r['role']}", r) for r in res.get("roles", [])]
    if res.get("ssi"):
        out.append(("ssi", res["ssi"]))
    if res.get("body_ssi"):
        out.append(("body_ssi", res["body_ssi"]["analysis"]))
    return out


def reports(res: Dict) -> List[Tuple[float, str]]:
    """Every reported line: (frequency Hz, where and how)."""
    out = []
    for name, p in pools(res):
        for t in p.get("lines", []):
            kind = "steady" if any(f is not None for f in t.get("record_hz", [])) else "swept"
            out.append((t["frequency_hz"], f"{name} {kind} track"))
        for m in p.get("invariant_modes", []):
            if m["class"] == "periodic-disturbance":
                out.append((m["frequency_hz"], f"{name} periodic mode (zeta {m['damping_ratio']:.3f})"))
    return sorted(out)


def merge(reps: List[Tuple[float, str]]) -> List[Tuple[float, List[str]]]:
    merged: List[Tuple[float, List[str]]] = []
    for f, w in sorted(reps):
        if merged and rel(f, merged[-1][0]) <= MERGE_REL:
            merged[-1][1].append(w)
        else:
            merged.append((f, [w]))
    return merged


def score(truth: Dict, res: Dict, evidence: Dict[float, float] = None,
          level: float = 1.0) -> Dict:
    """`evidence`: each judged line's oracle p-value (`line_evidence.evidence`), `level` the
    analysis's search level (`line_evidence.search_level`); without them every judged line counts
    as shown clearly by the sensors."""
    modes = truth["modes"]
    lines = [l["f0_hz"] for l in truth["periodic_lines"]]

    def unjudgeable(f: float) -> bool:
        return any(rel(f, m["f_n_hz"]) < MATCH_REL and (m["zeta"] < LIGHT_ZETA or not m["observable_in"])
                   for m in modes)

    apart = [f for f in lines if all(rel(f, m["f_n_hz"]) >= APART_REL for m in modes)]
    left_out = [f for f in lines if f not in apart]
    merged = merge(reports(res))
    found = [f for f in apart if any(rel(r, f) <= MATCH_REL for r, _ in merged)]
    evidence = evidence or {}
    seen = [f for f in apart if evidence.get(f, 0.0) < line_evidence.SEEN_P]
    clear = [f for f in apart if evidence.get(f, 0.0) < level]
    false = [(r, w) for r, w in merged
             if not any(rel(r, f) <= MATCH_REL for f in lines) and not unjudgeable(r)]
    structural = [m for m in modes if is_bending(m) or is_wheel_hop(m)]
    called_periodic = sorted({m["label"] for m in structural for r, _ in false
                              if rel(r, m["f_n_hz"]) <= max(MATCH_REL, m["zeta"])})
    bending = [m for m in modes if is_bending(m)]
    bend_seen = [m for m in bending if m["observable_in"]]
    bend_found = []
    for b in bend_seen:
        hits = [(name, m) for name, p in pools(res) for m in p.get("invariant_modes", [])
                if rel(m["frequency_hz"], b["f_n_hz"]) <= BENDING_REL]
        structural_hit = [h for h in hits if h[1]["class"] == "structural"]
        beside = [f for f in lines if rel(f, b["f_n_hz"]) < BENDING_REL]
        bend_found.append((b, structural_hit, hits, beside))
    return {
        "lines": lines, "apart": apart, "left_out": left_out, "found": found,
        "seen": seen, "clear": clear, "evidence": evidence, "level": level,
        "reported": merged, "false": false, "structural_periodic": called_periodic,
        "bending": bend_found, "role_modes": role_modes(truth, res),
    }


def role_modes(truth: Dict, res: Dict) -> Dict:
    """The role pools' (the ARMA order sweeps') structural modes against the true modes: per
    true mode and role pool whose channels see it (`observable_in`), whether a structural
    invariant mode of the pool lies within max(`POOL_MODE_REL`, zeta/2) of it (a broad wheel-hop
    mode's poles scatter about as its bandwidth), and its relative error; and the pool's
    structural modes within max(5 %, zeta) of no true mode and 2 % of no true line."""
    lines = [l["f0_hz"] for l in truth["periodic_lines"]]
    judged, found, errors, unmatched, n_structural = 0, 0, [], 0, 0
    per_label: Dict[str, List[int]] = {}
    for r in res.get("roles", []):
        chans = set(r.get("channels", []))
        structural = [m["frequency_hz"] for m in r.get("invariant_modes", [])
                      if m["class"] == "structural"]
        for m in truth["modes"]:
            if not chans & set(m["observable_in"]):
                continue
            f, tol = m["f_n_hz"], max(POOL_MODE_REL, m["zeta"] / 2)
            near = [rel(x, f) for x in structural if rel(x, f) <= tol]
            label = m["label"].split(" (")[0]
            counts = per_label.setdefault(label, [0, 0])
            judged += 1
            counts[1] += 1
            if near:
                found += 1
                counts[0] += 1
                errors.append(min(near))
        for x in structural:
            n_structural += 1
            if not (any(rel(x, m["f_n_hz"]) <= max(0.05, m["zeta"]) for m in truth["modes"])
                    or any(rel(x, f) <= MATCH_REL for f in lines)):
                unmatched += 1
    return {"judged": judged, "found": found, "errors": errors, "per_label": per_label,
            "structural": n_structural, "unmatched": unmatched}


def run_bus(bus: int, seed: int, keep: bool, extra: Tuple[str, ...] = ()) -> Tuple[int, Dict, Dict]:
    folder = harness.simulate(bus, seed)
    out = Path(tempfile.mkdtemp(prefix=f"vibmode-lines-bus{bus}-"))
    res = harness.analyze(folder, *extra, out=out)
    if not keep:
        import shutil
        shutil.rmtree(out, ignore_errors=True)
    t = harness.truth(folder)
    s0 = score(t, res)
    return bus, t, score(t, res, *line_evidence.evidence_and_level(folder, s0["apart"]))


def fmt_hz(v: List[float]) -> str:
    return ",".join(f"{f:.2f}" for f in v) or "-"


def row(bus: int, t: Dict, s: Dict) -> str:
    missed = [f for f in s["apart"] if f not in s["found"]]
    bend = "-"
    if s["bending"]:
        b, hit, hits, beside = s["bending"][0]
        if hit:
            bend = f"yes {hit[0][1]['frequency_hz']:.2f} ({hit[0][0]})"
        elif hits:
            bend = "no (" + "; ".join(f"{h[1]['frequency_hz']:.2f} {h[1]['class']} in {h[0]}" for h in hits) + ")"
        else:
            bend = "no (none within 2 %)"
        vis = max(b.get("visibility", {}).values(), default=float("nan"))
        bend = f"{b['f_n_hz']:.2f}/{b['zeta']:.3f} (visibility {vis:.2f}): {bend}"
        if beside:
            bend += f" [not judged: line at {fmt_hz(beside)} within 2 %]"
    ev = s.get("evidence", {})
    missed_ev = ",".join(f"{f:.2f} (p {ev[f]:.0e})" if f in ev else f"{f:.2f}" for f in missed) or "-"
    return (f"bus {bus:5d}: lines {fmt_hz(s['lines'])} | judged {fmt_hz(s['apart'])} found "
            f"{len(s['found'])}/{len(s['apart'])} missed {missed_ev} | false "
            f"{'; '.join(f'{r:.2f} [{w[0]}]' for r, w in s['false']) or '-'} | structural periodic "
            f"{', '.join(s['structural_periodic']) or '-'} | bending {bend}")


def summary(results: List[Tuple[int, Dict, Dict]]) -> Dict:
    n_apart = sum(len(s["apart"]) for _, _, s in results)
    n_found = sum(len(s["found"]) for _, _, s in results)
    n_seen = sum(len(s["seen"]) for _, _, s in results)
    n_seen_found = sum(len([f for f in s["seen"] if f in s["found"]]) for _, _, s in results)
    n_clear = sum(len(s["clear"]) for _, _, s in results)
    n_clear_found = sum(len([f for f in s["clear"] if f in s["found"]]) for _, _, s in results)
    n_rep = sum(len(s["reported"]) for _, _, s in results)
    n_false = sum(len(s["false"]) for _, _, s in results)
    n_clean = sum(1 for _, _, s in results if not s["structural_periodic"])
    seen = [s for _, _, s in results if s["bending"]]
    n_bend = sum(1 for s in seen if s["bending"][0][1])
    judged = [s for s in seen if not s["bending"][0][3]]
    n_bend_judged = sum(1 for s in judged if s["bending"][0][1])
    rm = [s["role_modes"] for _, _, s in results]
    errors = sorted(e for x in rm for e in x["errors"])
    labels: Dict[str, List[int]] = {}
    for x in rm:
        for k, (a, b) in x["per_label"].items():
            c = labels.setdefault(k, [0, 0])
            c[0] += a
            c[1] += b
    pool = {"judged": sum(x["judged"] for x in rm), "found": sum(x["found"] for x in rm),
            "median_error": errors[len(errors) // 2] if errors else None,
            "per_label": labels, "structural": sum(x["structural"] for x in rm),
            "unmatched": sum(x["unmatched"] for x in rm)}
    return {"role_modes": pool,
            "buses": len(results), "apart": n_apart, "found": n_found, "seen": n_seen,
            "seen_found": n_seen_found, "clear": n_clear, "clear_found": n_clear_found,
            "reported": n_rep,
            "false": n_false, "no_structural_periodic": n_clean, "bending_seen": len(seen),
            "bending_structural": n_bend, "bending_judged": len(judged),
            "bending_judged_structural": n_bend_judged,
            "left_out": sum(len(s["left_out"]) for _, _, s in results)}


def print_summary(sm: Dict) -> None:
    r = harness.rate
    print(f"recall of lines >= 3 % from every mode: {r(sm['found'], sm['apart'])}"
          f" ({sm['left_out']} lines within 3 % of a mode left out)")
    print(f"recall of those lines the sensors show (oracle F-test at the line's own frequency, "
          f"p < {line_evidence.SEEN_P} over the records): {r(sm['seen_found'], sm['seen'])}"
          f" ({sm['apart'] - sm['seen']} not shown by any sensor)")
    print(f"recall of the lines shown clearly enough for the analysis's search at its stated rate "
          f"(oracle p below the search's level, line_evidence.search_level): "
          f"{r(sm['clear_found'], sm['clear'])} ({sm['seen'] - sm['clear']} shown more weakly)")
    print(f"false lines (reported, matching no true line): {sm['false']} of {sm['reported']} reported")
    print(f"buses with no structural mode classed periodic: {r(sm['no_structural_periodic'], sm['buses'])}")
    print(f"bending found structural within 2 % where a sensor sees it: "
          f"{r(sm['bending_structural'], sm['bending_seen'])}; where no line lies within 2 % of it "
          f"(busgen's README: neither can be judged): {r(sm['bending_judged_structural'], sm['bending_judged'])}")
    pm = sm["role_modes"]
    med = "-" if pm["median_error"] is None else f"{100 * pm['median_error']:.1f} %"
    per = ", ".join(f"{k} {a}/{b}" for k, (a, b) in sorted(pm["per_label"].items()))
    print(f"true modes found structural by the role pools (ARMA sweeps) whose channels see them, "
          f"within max({100 * POOL_MODE_REL:.0f} %, zeta/2): {r(pm['found'], pm['judged'])}, "
          f"median error {med} ({per}); the pools' structural modes matching no true mode or "
          f"line: {pm['unmatched']} of {pm['structural']}")


def measure(n_buses: int, seed: int = 1, jobs: int = 2, keep: bool = False,
            extra: Tuple[str, ...] = ()) -> Dict:
    """`extra`: further `vibmode analyze` arguments, e.g. `("--config", "sweep.toml")`."""
    buses = harness.draw_bus_seeds(n_buses, "lines")
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        results = list(ex.map(lambda b: run_bus(b, seed, keep, extra), buses))
    for bus, t, s in results:
        print(row(bus, t, s), flush=True)
    sm = summary(results)
    print_summary(sm)
    sm["results"] = results
    return sm


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--buses", type=int, default=6, help="buses drawn at random (default 6)")
    ap.add_argument("--seed", type=int, default=1, help="busgen record seed (default 1)")
    ap.add_argument("--jobs", type=int, default=2, help="buses analysed at once (default 2)")
    ap.add_argument("--keep", action="store_true", help="keep the analysis folders")
    ap.add_argument("--config", help="an analysis settings file passed to `vibmode analyze --config`")
    ap.add_argument("--json", help="write the summary and the per-bus scores to this file")
    a = ap.parse_args()
    try:
        sm = measure(a.buses, a.seed, a.jobs, a.keep,
                     ("--config", a.config) if a.config else ())
        if a.json:
            with open(a.json, "w") as f:
                json.dump(sm, f, indent=1, default=str)
    except harness.Skip as e:
        print(f"skipped: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
