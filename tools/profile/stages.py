#!/usr/bin/env python3
"""Where a vibmode run's CPU goes, by stage: each sample of a `perf record --call-graph dwarf`
profile is given to the stage of the nearest frame (leaf first) that names one.

    perf record -F 999 --call-graph dwarf,16384 -o p.data -- target/release/vibmode analyze -q -o /tmp/o RECORDS
    python3 tools/profile/stages.py p.data [--by-function]

Rules, tried on each frame from the leaf up: a frame of a vibmode crate names its stage
(`STAGES`, first match); a few libraries name theirs wherever they are called from (CSV
numbers, BLAKE3, SQLite, the PNG and plot code); any other frame (vibmode-core's shared
arithmetic such as `stats::dot`, libm, libc, the kernel's page faults, rustfft, nalgebra,
matrixmultiply, rayon) is passed over, so its time goes to the
vibmode stage that called it. A sample with no such frame is "kernel, ..." when its leaf is in
the kernel, else "other". Prints a markdown table
of the stages' shares of all samples (and with `--by-function` the ten leaf functions of each
stage). Needs only `perf` and Python 3.
"""

from __future__ import annotations

import argparse
import collections
import re
import subprocess
import sys
from typing import Dict, List, Optional, Tuple

#: (stage, pattern on the frame's symbol), first match wins. Vibmode's crates by module, then
#: libraries that belong to one stage wherever they are called from.
STAGES: List[Tuple[str, str]] = [
    ("ARMA order sweep (fits, trial steps, roots)", r"^vibmode_ident::"),
    ("SSI-cov (SVD, eigenvalues, correlations)", r"^vibmode_ssi::"),
    ("resampling (ideal DFT filter)", r"^vibmode_signal::resample"),
    ("reading files (CSV text, WAV frames)", r"^vibmode_signal::|^fast_float2::|^<?csv"),
    ("spectra and line tests (Welch, multitaper F-test, kurtosis)",
     r"^vibmode_spectra::|^vibmode_analysis::lines|^vibmode_analysis::stops"),
    ("clustering and classing", r"^vibmode_modal::"),
    ("body-band stage (front/rear delay, body SSI records)", r"^vibmode_analysis::body"),
    ("body equations and model update", r"^vibmode_vehicle::update|^vibmode_run::update"),
    ("vehicle model (simulation, full-car model)", r"^vibmode_vehicle::|^vibmode_run::demo"),
    ("sensor checks (finite samples, dead, stuck, clipped channels)",
     r"^vibmode_core::stats::(HealthScan|channel_health)|^vibmode_core::recording::check_finite"),
    ("content hash", r"^vibmode_fleet::hash|blake3|^<?sha2"),
    ("fleet store (SQLite)", r"^vibmode_fleet::store|sqlite3|^rusqlite"),
    ("fleet features and scores", r"^vibmode_fleet::"),
    ("report (figures, HTML, JSON)",
     r"^vibmode_report::|^plotters|^png::|^<plotters|^<png|^serde_json|^vibmode_analysis::results"),
]

COMPILED = [(name, re.compile(p)) for name, p in STAGES]


def stage_of(frames: List[str]) -> Optional[str]:
    """The stage of a sample's stack (leaf first), or None."""
    for sym in frames:
        for name, pat in COMPILED:
            if pat.search(sym):
                return name
    return None


#: Where a sample that names no stage goes when its leaf is in the kernel (the kernel's stack
#: was not followed into the program's: a file read or a page fault, mostly).
KERNEL = "kernel, not traced to a stage (file reads, page faults)"


def samples(path: str):
    """(leaf symbol, leaf in the kernel, [symbols leaf first]) per sample of `perf script`."""
    out = subprocess.run(["perf", "script", "-i", path, "-F", "ip,sym,dso"],
                         capture_output=True, text=True, check=True).stdout
    frames: List[str] = []
    kernel = False
    for line in out.splitlines() + [""]:
        line = line.strip()
        if not line:
            if frames:
                yield frames[0], kernel, frames
            frames = []
            continue
        in_kernel = line.endswith("([kernel.kallsyms])")
        line = re.sub(r" \([^()]*\)$", "", line)
        parts = line.split(None, 1)
        sym = parts[1] if len(parts) > 1 else "[unknown]"
        sym = re.sub(r"\+0x[0-9a-f]+$", "", sym)
        sym = re.sub(r" \(inlined\)$", "", sym)
        if not frames:
            kernel = in_kernel
        frames.append(sym)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("data", help="a perf.data file recorded with --call-graph dwarf")
    ap.add_argument("--by-function", action="store_true",
                    help="also list the ten leaf functions of each stage")
    a = ap.parse_args()
    total = 0
    by_stage: Dict[str, int] = collections.Counter()
    leaves: Dict[str, Dict[str, int]] = collections.defaultdict(collections.Counter)
    for leaf, kernel, frames in samples(a.data):
        total += 1
        st = stage_of(frames) or (KERNEL if kernel else "other")
        by_stage[st] += 1
        leaves[st][leaf] += 1
    if total == 0:
        print(f"no samples in {a.data}", file=sys.stderr)
        return 2
    print(f"{total} samples\n")
    print("| stage | share of CPU |")
    print("|---|---|")
    for st, n in sorted(by_stage.items(), key=lambda kv: -kv[1]):
        print(f"| {st} | {100.0 * n / total:.1f} % |")
    if a.by_function:
        for st, n in sorted(by_stage.items(), key=lambda kv: -kv[1]):
            print(f"\n{st}:")
            for leaf, m in leaves[st].most_common(10):
                print(f"  {100.0 * m / total:5.1f} %  {leaf}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
