#!/usr/bin/env python3
"""How far can Thomson's harmonic F-test go on busgen's lines? Variants of the test combined over
records, on the raw records of buses drawn at random, scored against truth.json.

    BUSGEN_PYTHON=/path/to/venv/bin/python VIBMODE_BUS_SEEDS=1,2,3 \
        /path/to/venv/bin/python tools/busgen/f_test_variants.py [--buses N]

Needs numpy, scipy and pandas (and busgen, through harness.py, for buses not yet cached; 8 records
of fs 2000 Hz, records seed 1: the folders tools/busgen/lines.py uses). No vibmode binary: the
test is recomputed here as vibmode computes it (each channel brought to 50 Hz with
scipy.signal.resample_poly 1/40, 10.24 s records, Slepian tapers, 4x zero-padded grid,
`F = (K-1) |mu|^2 sum U_k^2 / sum |y_k - mu U_k|^2` against F(2, 2K-2)), for time-half-bandwidths
NW = 4, 3, 2 with K = 2 NW - 1 tapers, and two ways of combining over the 8 records of a pool
(the three sprung channels, or the four unsprung):

- `chan`: Fisher's method over the records on each channel, the smallest over the pool's channels
  times their number (Bonferroni): vibmode's combined test (docs/analysis.md, "Periodic lines",
  step 2), without its per-record confirmation;
- `all`: Fisher's method over the records and the channels together (24 or 32 p-values). The
  channels of a pool are not independent (the road and the modes reach all of them), so this
  level is not a stated false-alarm rate; it shows what pooling everything could find.

A detection is a local minimum of the combined p-value over +-W below 0.01 / (B T) (B the band from
max(2 W, 3 Hz) to 21.6 Hz - W, T = 10.24 s), as in vibmode. Printed per bus and variant: the
detections labelled by truth (LINE, or the mode within max(3 %, zeta), or `other`); then per
variant the recall of the true lines at least 3 % from every mode (tools/busgen/lines.py's
judged lines; a detection within 2 % finds one), the missed lines and the detections on no line
(on a mode or on nothing).

    ... f_test_variants.py --at BUS:HZ [BUS:HZ ...]

prints instead, at NW = 4, for each frequency: the combined log10 p of each channel (Fisher over
the 8 records, smallest within +-2 grid points), and in each record where the test combined over
the pool's channels peaks within +-W (offset in grid points of 1/(4 T) = 0.024 Hz) and how many
records peak within one point of their median: a line at a steady frequency should peak at the
same point in most records, a mode anywhere in its band.

    ... f_test_variants.py --clusters OUT [OUT ...]

reads kept analyses (`tools/busgen/lines.py --keep` folders, `vibmode-lines-busN-*`) and prints
every cluster of the role pools and the SSI-cov pool damped below 0.05 above 3 Hz with the
combined log10 p at its frequency (Fisher over the records per channel of its pool, the smallest
times the number of channels) and what it is by truth.

    ... f_test_variants.py --tracks OUT [OUT ...]

reads kept analyses likewise and prints, over the line tracks of the role pools and the SSI-cov
pool seen in at least two records, the median absolute relative deviation of the track's record
frequencies from their median (busgen keeps each bus's engine speed, so a line's should be
small): its percentiles over the tracks on a true line (within 2 %), and each track on none.
Exit status 0 (it measures).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Dict, List, Tuple

import numpy as np
import pandas as pd
from scipy.signal import resample_poly, windows
from scipy.stats import chi2
from scipy.stats import f as fdist

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness  # noqa: E402

FS_HZ = 50.0
DECIMATE = 40  # 2000 Hz -> 50 Hz
CUTOFF_HZ = 21.6
MIN_FREQUENCY_HZ = 3.0
ALPHA = 0.01
VARIANTS = [(4.0, 7), (3.0, 5), (2.0, 3)]
APART_REL, MATCH_REL = 0.03, 0.02


def rel(a: float, b: float) -> float:
    return abs(a - b) / b


def ln_p_f_test(x: np.ndarray, nw: float, k: int) -> Tuple[np.ndarray, np.ndarray]:
    """Frequencies and ln p of the F-test of one record."""
    x = x - x.mean()
    tap = windows.dpss(len(x), nw, k)
    nfft = 4 * len(x)
    y = np.fft.rfft(tap * x, nfft, axis=1)
    u = tap.sum(axis=1)
    mu = (y * u[:, None]).sum(0) / np.sum(u**2)
    resid = np.sum(np.abs(y - mu[None, :] * u[:, None]) ** 2, 0)
    f_stat = (k - 1) * np.abs(mu) ** 2 * np.sum(u**2) / resid
    return np.fft.rfftfreq(nfft, 1 / FS_HZ), fdist.logsf(f_stat, 2, 2 * k - 2)


def records_at_50_hz(folder: Path) -> Dict[str, List[np.ndarray]]:
    out: Dict[str, List[np.ndarray]] = {}
    for fn in harness.records(folder):
        df = pd.read_csv(fn)
        for c in df.columns:
            if c != "time_s":
                out.setdefault(c, []).append(resample_poly(df[c].to_numpy(), 1, DECIMATE))
    return out


def label(f: float, truth: Dict) -> str:
    for line in truth["periodic_lines"]:
        if rel(f, line["f0_hz"]) <= MATCH_REL:
            return f"line {line['f0_hz']:.2f}"
    m = min(truth["modes"], key=lambda m: rel(f, m["f_n_hz"]))
    if rel(f, m["f_n_hz"]) <= max(APART_REL, m["zeta"]):
        return f"{m['label']} {m['f_n_hz']:.2f}/{m['zeta']:.3f}"
    return "other"


def detections(x: Dict[str, List[np.ndarray]], nw: float, k: int) -> Dict[str, List[float]]:
    """Detections of the two combinations (`chan`, `all`), over both pools."""
    w = nw / 10.24
    lo, hi = max(2 * w, MIN_FREQUENCY_HZ), CUTOFF_HZ - w
    ln_alpha = np.log(ALPHA / ((hi - lo) * 10.24))
    out: Dict[str, List[float]] = {"chan": [], "all": []}
    for pool in ("sprung", "unsprung"):
        chans = [c for c in x if c.startswith(pool)]
        fr = None
        lp = []
        for c in chans:
            rows = []
            for rec in x[c]:
                fr, l = ln_p_f_test(rec, nw, k)
                rows.append(l)
            lp.append(rows)
        a = np.array(lp)  # channels x records x frequencies
        n_ch, n_rec, _ = a.shape
        combined = {
            "chan": np.min(chi2.logsf(-2 * a.sum(1), 2 * n_rec), axis=0) + np.log(n_ch),
            "all": chi2.logsf(-2 * a.sum((0, 1)), 2 * n_ch * n_rec),
        }
        half = int(round(w / fr[1]))
        band = np.where((fr >= lo) & (fr <= hi))[0]
        for tag, p in combined.items():
            for j in band:
                if p[j] < ln_alpha and p[j] == p[max(0, j - half):j + half + 1].min():
                    out[tag].append(float(fr[j]))
    return out


def per_record_ln_p(x: Dict[str, List[np.ndarray]]) -> Tuple[np.ndarray, Dict[str, np.ndarray]]:
    """Frequencies and ln p (records x frequencies) per channel at NW = 4, K = 7."""
    out: Dict[str, np.ndarray] = {}
    fr = np.zeros(0)
    for c, recs in x.items():
        rows = []
        for rec in recs:
            fr, l = ln_p_f_test(rec, 4.0, 7)
            rows.append(l)
        out[c] = np.array(rows)
    return fr, out


def at_frequencies(items: List[str], seed: int) -> None:
    for item in items:
        bus_s, f_s = item.split(":")
        bus, f0 = int(bus_s), float(f_s)
        folder = harness.simulate(bus, seed)
        truth = harness.truth(folder)
        fr, lp = per_record_ln_p(records_at_50_hz(folder))
        j0 = int(np.argmin(np.abs(fr - f0)))
        per_channel = []
        for c, a in lp.items():
            v = min(chi2.logsf(-2 * a[:, j].sum(), 2 * a.shape[0]) for j in range(j0 - 2, j0 + 3))
            per_channel.append(f"{c} {v / np.log(10):.1f}")
        half = int(round(4.0 / 10.24 / fr[1]))
        for pool in ("sprung", "unsprung"):
            per_rec = -2 * sum(a for c, a in lp.items() if c.startswith(pool))
            off = [int(np.argmax(r[j0 - half:j0 + half + 1])) - half for r in per_rec]
            near = sum(1 for o in off if abs(o - np.median(off)) <= 1)
            per_channel.append(f"{pool} peak offsets {off} ({near} within 1 of the median)")
        print(f"bus {bus} {f0:.2f} Hz ({label(f0, truth)}): " + "; ".join(per_channel), flush=True)


def clusters(outs: List[str], seed: int) -> None:
    import re
    for out in outs:
        bus = int(re.search(r"bus(\d+)-", out).group(1))
        with open(Path(out) / "results.json") as f:
            res = json.load(f)
        folder = harness.simulate(bus, seed)
        truth = harness.truth(folder)
        fr, lp = per_record_ln_p(records_at_50_hz(folder))
        pools = [(f"role:{r['role']}", r) for r in res.get("roles", [])]
        if res.get("ssi"):
            pools.append(("ssi", res["ssi"]))
        for name, p in pools:
            role = name.split(":")[1] if name.startswith("role:") else ""
            chans = [c for c in lp if c.startswith(role)] if role else list(lp)
            for m in p.get("invariant_modes", []):
                f, z = m["frequency_hz"], m["damping_ratio"]
                if z >= 0.05 or f <= MIN_FREQUENCY_HZ:
                    continue
                j = int(np.argmin(np.abs(fr - f)))
                best = min(chi2.logsf(-2 * lp[c][:, j].sum(), 2 * lp[c].shape[0]) for c in chans)
                print(f"bus {bus} {name} {f:.2f} Hz zeta {z:.4f} {m['class']} order share "
                      f"{m['order_share']:.2f} log10 p {(best + np.log(len(chans))) / np.log(10):.1f}"
                      f" ({label(f, truth)})", flush=True)


def track_scatter(outs: List[str], seed: int) -> None:
    import re
    on_line: List[float] = []
    for out in outs:
        bus = int(re.search(r"bus(\d+)-", out).group(1))
        with open(Path(out) / "results.json") as f:
            res = json.load(f)
        truth = harness.truth(harness.simulate(bus, seed))
        pools = [(f"role:{r['role']}", r) for r in res.get("roles", [])]
        if res.get("ssi"):
            pools.append(("ssi", res["ssi"]))
        for name, p in pools:
            for t in p.get("lines", []):
                fs = np.array([f for f in t["record_hz"] if f])
                if len(fs) < 2:
                    continue
                mad = float(np.median(np.abs(fs / np.median(fs) - 1)))
                if label(t["frequency_hz"], truth).startswith("line"):
                    on_line.append(mad)
                else:
                    print(f"bus {bus} {name} track {t['frequency_hz']:.2f} Hz on no line "
                          f"({label(t['frequency_hz'], truth)}): {fs.min():.2f}-{fs.max():.2f} Hz "
                          f"in {len(fs)} records, scatter {100 * mad:.2f} %")
    if on_line:
        q = np.percentile(on_line, [50, 90, 99, 100]) * 100
        print(f"{len(on_line)} tracks on a true line: scatter percentiles 50/90/99/100 "
              + " ".join(f"{v:.2f} %" for v in q))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--buses", type=int, default=6, help="buses drawn at random (default 6)")
    ap.add_argument("--seed", type=int, default=1, help="busgen record seed (default 1)")
    ap.add_argument("--at", nargs="+", metavar="BUS:HZ", help="look at these frequencies only")
    ap.add_argument("--clusters", nargs="+", metavar="OUT", help="kept analyses to read")
    ap.add_argument("--tracks", nargs="+", metavar="OUT", help="kept analyses to read")
    a = ap.parse_args()
    try:
        if a.tracks:
            track_scatter(a.tracks, a.seed)
            return 0
        if a.at:
            at_frequencies(a.at, a.seed)
            return 0
        if a.clusters:
            clusters(a.clusters, a.seed)
            return 0
        buses = harness.draw_bus_seeds(a.buses, "f-test variants")
        score: Dict[Tuple[float, str], Dict[str, List[str]]] = {}
        n_judged = 0
        for bus in buses:
            folder = harness.simulate(bus, a.seed)
            truth = harness.truth(folder)
            judged = [l["f0_hz"] for l in truth["periodic_lines"]
                      if all(rel(l["f0_hz"], m["f_n_hz"]) >= APART_REL for m in truth["modes"])]
            n_judged += len(judged)
            x = records_at_50_hz(folder)
            for nw, k in VARIANTS:
                det = detections(x, nw, k)
                for tag, fs in det.items():
                    s = score.setdefault((nw, tag), {"found": [], "missed": [], "false": []})
                    for f0 in judged:
                        (s["found"] if any(rel(f, f0) <= MATCH_REL for f in fs)
                         else s["missed"]).append(f"{bus}:{f0:.2f}")
                    s["false"] += [f"{bus}:{f:.2f} ({label(f, truth)})" for f in fs
                                   if not label(f, truth).startswith("line")]
                    print(f"bus {bus} NW {nw:g} {tag}: "
                          + ", ".join(f"{f:.2f} ({label(f, truth)})" for f in fs), flush=True)
        for (nw, tag), s in sorted(score.items()):
            print(f"NW {nw:g} K {2 * nw - 1:g} {tag}: recall {harness.rate(len(s['found']), n_judged)}"
                  f"; missed {' '.join(s['missed']) or '-'}; not on a line {len(s['false'])}: "
                  f"{'; '.join(s['false']) or '-'}")
    except harness.Skip as e:
        print(f"skipped: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
