"""Shared plumbing for the acceptance runs on the independent bus family (../shared/busgen).

The measurement scripts beside this file (one per area: lines, model update, fleet) draw buses at
random, simulate them with busgen, run the vibmode binary on the records and score the results
against busgen's truth.json. This module holds what they share:

- where busgen and the vibmode binary are (`busgen_dir`, `vibmode_bin`), and why a run must skip;
- drawing bus seeds (`draw_bus_seeds`: fresh every run, printed; `VIBMODE_BUS_SEEDS=1,2,3` replays);
- simulating a folder of records once per set of arguments (`simulate`, cached by its arguments);
- running a vibmode command and reading its JSON output (`run_vibmode`, `analyze`);
- reading a folder's truth (`truth`).

busgen needs numpy and scipy in the Python that runs it (`BUSGEN_PYTHON`, else this interpreter).
Nothing here writes outside the cache folder (`VIBMODE_BUSGEN_CACHE`, else a temporary folder).
"""

from __future__ import annotations

import hashlib
import json
import os
import random
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Dict, List, Optional, Sequence

REPO = Path(__file__).resolve().parents[2]
#: busgen's default place: beside the checkout, as the project's guide says.
DEFAULT_BUSGEN = REPO.parent / "shared" / "busgen"
#: Records per folder and the rate the acceptance runs use (busgen: 2 kHz keeps everything below
#: 1 kHz and is ten times faster than 20 kHz).
RECORDS = 8
FS_HZ = 2000.0


class Skip(Exception):
    """A resource the run needs is absent; the message says which and how to provide it."""


def busgen_dir() -> Path:
    """The busgen folder (`VIBMODE_BUSGEN`, else ../shared/busgen beside the checkout)."""
    d = Path(os.environ.get("VIBMODE_BUSGEN", DEFAULT_BUSGEN))
    if not (d / "simulate.py").is_file():
        raise Skip(f"busgen not found at {d} (set VIBMODE_BUSGEN to the folder holding simulate.py)")
    return d


def busgen_python() -> str:
    """A Python with numpy and scipy for busgen (`BUSGEN_PYTHON`, else this interpreter)."""
    py = os.environ.get("BUSGEN_PYTHON", sys.executable)
    probe = subprocess.run([py, "-c", "import numpy, scipy"], capture_output=True)
    if probe.returncode != 0:
        raise Skip(f"{py} lacks numpy or scipy, which busgen needs (set BUSGEN_PYTHON)")
    return py


def vibmode_bin() -> str:
    """The vibmode binary (`VIBMODE_BIN`, else target/release/vibmode of this checkout)."""
    b = os.environ.get("VIBMODE_BIN") or str(REPO / "target" / "release" / "vibmode")
    if not Path(b).is_file():
        raise Skip(f"vibmode binary not found at {b} (build it, or set VIBMODE_BIN)")
    return b


def check_tools() -> None:
    """Raises :class:`Skip` unless the vibmode binary, busgen and busgen's Python are all found."""
    vibmode_bin()
    busgen_dir()
    busgen_python()


def required() -> bool:
    """True when CI says busgen is present and the run must not skip (VIBMODE_REQUIRE has busgen)."""
    return "busgen" in os.environ.get("VIBMODE_REQUIRE", "").split(",")


def draw_bus_seeds(n: int, label: str = "buses") -> List[int]:
    """`n` bus seeds, fresh every run (`VIBMODE_BUS_SEEDS=1,2,3` replays a draw); printed.

    Seed 0 is busgen's nominal bus; a random draw comes from 1..99999.
    """
    given = os.environ.get("VIBMODE_BUS_SEEDS", "").strip()
    if given:
        seeds = [int(s) for s in given.replace(" ", "").split(",") if s]
    else:
        rng = random.SystemRandom()
        seeds = rng.sample(range(1, 100000), n)
    print(f"{label}: bus seeds {','.join(str(s) for s in seeds)} "
          f"(replay with VIBMODE_BUS_SEEDS={','.join(str(s) for s in seeds)})", flush=True)
    return seeds


def cache_dir() -> Path:
    d = os.environ.get("VIBMODE_BUSGEN_CACHE")
    if d:
        p = Path(d)
    else:
        p = Path(tempfile.gettempdir()) / "vibmode-busgen-cache"
    p.mkdir(parents=True, exist_ok=True)
    return p


def simulate(bus_seed: int, seed: int, *extra: str, records: int = RECORDS,
             fs_hz: float = FS_HZ) -> Path:
    """A folder of busgen records (`recNN.csv` + truth.json) for these arguments, made once.

    `extra` are busgen options as given on its command line, e.g. `"--damper", "rl=0.6"`.
    `VIBMODE_BUSGEN_EXTRA` (whitespace-separated busgen options, e.g. `--no-noise`) is added to
    every simulation, the baselines' too: what a figure depends on, measured by any of these
    scripts with one switch of the simulator off (part of the cache key).
    """
    args = ["--bus-seed", str(bus_seed), "--records", str(records), "--seed", str(seed),
            "--fs", repr(float(fs_hz)), "--csv-only", *extra,
            *os.environ.get("VIBMODE_BUSGEN_EXTRA", "").split()]
    key = hashlib.sha256(json.dumps(args).encode()).hexdigest()[:16]
    out = cache_dir() / f"bus{bus_seed}-{key}"
    if (out / "truth.json").is_file():
        return out
    tmp = out.with_name(out.name + ".part")
    shutil.rmtree(tmp, ignore_errors=True)
    cmd = [busgen_python(), str(busgen_dir() / "simulate.py"), *args, "--out", str(tmp)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"busgen failed ({' '.join(cmd)}): {r.stderr.strip()[-400:]}")
    shutil.rmtree(out, ignore_errors=True)
    tmp.rename(out)
    return out


def remove_store(path: Path) -> None:
    """Removes the SQLite store `path` with its write-ahead log and shared-memory files."""
    for f in (path, path.with_name(path.name + "-wal"), path.with_name(path.name + "-shm")):
        if f.exists():
            f.unlink()


def copy_store(src: Path, dst: Path) -> None:
    """Copies the SQLite store `src` (with what its write-ahead log holds) to `dst`, replacing
    it: SQLite's online backup."""
    import sqlite3

    remove_store(dst)
    a = sqlite3.connect(src)
    b = sqlite3.connect(dst)
    try:
        a.backup(b)
    finally:
        b.close()
        a.close()


def records(folder: Path) -> List[Path]:
    return sorted(folder.glob("rec*.csv"))


def truth(folder: Path) -> Dict:
    with open(folder / "truth.json") as f:
        return json.load(f)


def run_vibmode(args: Sequence[str], check: bool = True) -> subprocess.CompletedProcess:
    """Runs `vibmode ARGS` quietly; raises with its stderr when it fails and `check` is set."""
    cmd = [vibmode_bin(), *[str(a) for a in args]]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if check and r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd[:4])} ... exit {r.returncode}: {r.stderr.strip()[-600:]}")
    return r


def analyze(folder: Path, *extra: str, out: Optional[Path] = None) -> Dict:
    """`vibmode analyze` on a folder's records; returns results.json as a dict."""
    out = out or Path(tempfile.mkdtemp(prefix="vibmode-analyze-"))
    run_vibmode(["analyze", *records(folder), "-q", "-o", out, *extra])
    with open(out / "results.json") as f:
        return json.load(f)


def misses_probability(misses: int, n: int, goal: float) -> float:
    """P(X >= misses) for X ~ Binomial(n, 1 - goal): how likely that many misses among `n` are
    if the goal (a rate of successes) held. The acceptance tests fail a goal when it is below 5 %."""
    from math import comb

    q = 1.0 - goal
    return sum(comb(n, k) * q**k * (1 - q) ** (n - k) for k in range(misses, n + 1))


def rate(hits: int, total: int) -> str:
    """`hits/total (pct %)`, or `-` with nothing to count."""
    return f"{hits}/{total} ({100.0 * hits / total:.0f} %)" if total else "-"
