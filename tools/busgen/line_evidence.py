#!/usr/bin/env python3
"""How strongly the sensors show a line whose frequency is known: an oracle for acceptance.

busgen's README leaves out of recall a line that cannot be judged (within 2 % of a lightly
damped mode, or of a mode no sensor sees). A line no sensor shows is of the same kind: no
detector with a stated false-alarm rate can find it. This module measures that from the records
themselves, with the truth's frequency given, so it bounds what any method could find:

- each record's channels are brought to 50 Hz, vibmode's analysis rate, and Thomson's harmonic
  F-test with K = 7 Slepian tapers of NW = 4 (the test vibmode's analysis uses, docs/analysis.md
  "Periodic lines") is computed as `f_test_variants.py` computes it (the one F-test of these
  tools), and read at the line's own frequency only (no search: the F(2, 12) law holds there);
- per channel the records' p-values are combined by Fisher's method (chi-square with 2R degrees
  of freedom) and the smallest over the channels is multiplied by their number (Bonferroni).

`evidence(folder, f_hz)` returns that p-value. A line with `p >= SEEN_P` (0.01) is not shown by
the sensors even to a test that knows its frequency. vibmode's analysis does not know it: it
searches the grid of its band (4 points per 1/T, some 750 frequencies at 10.24 s) at a 1 %
false-alarm rate per pool and analysis, so its combined test reports a line where the combined
p-value falls below `search_level` (`f_test_combined_alpha` over those frequencies, 1.3e-5 at
10.24 s). A line with `p < search_level` is shown clearly enough for that search; a line between
the two levels is shown, but weaker than the search's stated rate can reach (on 30 buses of
2026-11-28: found at 1.4e-5, missed at 1.1e-4 and 1.4e-4, every line below 1e-8 found).

Needs numpy, scipy and pandas (as f_test_variants.py; the Python that runs the acceptance has them).
Run alone: `python3 tools/busgen/line_evidence.py FOLDER F_HZ [F_HZ ...]`.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Dict, List, Tuple

#: The Fisher-combined p-value (smallest channel's, times the channels) below which a sensor
#: shows the line.
SEEN_P = 0.01
#: Thomson's tapers: vibmode's defaults (`f_test_nw`, `f_test_tapers`).
NW, TAPERS = 4.0, 7
#: vibmode's false-alarm rate of the combined test per pool and analysis (`f_test_combined_alpha`).
SEARCH_ALPHA = 0.01


def search_level(n_samples: int) -> float:
    """The per-frequency level of vibmode's combined test on records of `n_samples` at 50 Hz:
    `SEARCH_ALPHA` over the points of the 4x zero-padded grid in the band it searches,
    `max(2 W, min_frequency_hz)` to the cutoff minus `W` with `W = NW / T` (as
    `combined_lines` in crates/vibmode-analysis/src/lines.rs)."""
    from f_test_variants import CUTOFF_HZ, FS_HZ, MIN_FREQUENCY_HZ

    t = n_samples / FS_HZ
    w = NW / t
    lo, hi = max(2.0 * w, MIN_FREQUENCY_HZ), CUTOFF_HZ - w
    return SEARCH_ALPHA / max(1.0, 4.0 * t * (hi - lo))


def f_test_ps(y, fs: float, freqs_hz: List[float]) -> List[float]:
    """The harmonic F-test's p-values for one record `y` (sampled at `fs`, which must be
    f_test_variants.FS_HZ) at the points of its 4x-padded grid nearest each of `freqs_hz`
    (within 1/(8 T), far inside the tapers' +-W)."""
    import numpy as np
    from f_test_variants import FS_HZ, ln_p_f_test

    assert fs == FS_HZ, (fs, FS_HZ)
    freq, ln_p = ln_p_f_test(np.asarray(y, dtype=float), NW, TAPERS)
    return [float(np.exp(ln_p[int(np.argmin(np.abs(freq - f)))])) for f in freqs_hz]


def f_test_p(y, fs: float, f_hz: float) -> float:
    """[`f_test_ps`] at one frequency."""
    return f_test_ps(y, fs, [f_hz])[0]


def _fisher(ps: List[float]) -> float:
    from scipy.stats import chi2

    x = -2.0 * sum(math.log(max(p, 1e-300)) for p in ps)
    return float(chi2.sf(x, 2 * len(ps)))


def evidence(folder: Path, freqs_hz: List[float]) -> Dict[float, float]:
    """{frequency: Fisher-combined p over the records, smallest channel's, times the channels}."""
    return evidence_and_level(folder, freqs_hz)[0]


def evidence_and_level(folder: Path, freqs_hz: List[float]) -> Tuple[Dict[float, float], float]:
    """[`evidence`] and the analysis's [`search_level`] for the folder's shortest record."""
    from f_test_variants import FS_HZ, records_at_50_hz

    chans = records_at_50_hz(Path(folder))
    if not chans:
        return {f: 1.0 for f in freqs_hz}, 0.0
    level = search_level(min(len(x) for recs in chans.values() for x in recs))
    # ps[channel][record][i]: the p-value at freqs_hz[i].
    ps = {c: [f_test_ps(x, FS_HZ, freqs_hz) for x in recs] for c, recs in chans.items()}
    out = {}
    for i, f in enumerate(freqs_hz):
        best = min(_fisher([r[i] for r in recs]) for recs in ps.values())
        out[f] = min(1.0, len(chans) * best)
    return out, level


def main() -> int:
    folder = Path(sys.argv[1])
    ev, level = evidence_and_level(folder, [float(a) for a in sys.argv[2:]])
    for f, p in ev.items():
        shown = "shown clearly" if p < level else "shown" if p < SEEN_P else "not shown"
        print(f"{f:.3f} Hz: p = {p:.2e} ({shown}; the search's level {level:.1e})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
