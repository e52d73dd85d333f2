"""Thomson's harmonic F-test of one busgen bus, pooled over records and channels by Fisher's
method at each frequency: where a weak engine order would be found by pooling alone, and which
modes the same rule would call lines (the trade-off behind the per-record confirmation in
docs/analysis.md, "Periodic lines").

    python tools/busgen/pooled_f_test.py BUS_FOLDER

BUS_FOLDER holds busgen's truth.json and recNN.csv at 2 kHz (as tools/busgen/harness.py caches
them). Each channel is brought to 50 Hz (scipy.signal.resample_poly, 1/40), F computed with 7
Slepian tapers of NW = 4 on a 4x zero-padded grid (vibmode's defaults); per pool (sprung,
unsprung) X = -2 sum ln p over records and channels against chi-square with 2 R C degrees of
freedom; printed: the local maxima (+-0.39 Hz) in 5-25 Hz with p below 0.01 / 221 (the
pool's Bonferroni level), as frequency(log10 p). Needs numpy, scipy, pandas.
"""
import glob
import json
import os
import sys

import numpy as np
import pandas as pd
from scipy.signal import resample_poly
from scipy.stats import chi2

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from f_test_variants import FS_HZ, ln_p_f_test  # noqa: E402  (the one F-test of these tools)

NW, K = 4, 7
assert FS_HZ == 50.0  # the records brought from busgen's 2 kHz to 50 Hz (1 in 40)


def main(folder):
    t = json.load(open(os.path.join(folder, "truth.json")))
    print("modes above 5 Hz:", [(m["label"], round(m["f_n_hz"], 2), round(m["zeta"], 3))
                               for m in t["modes"] if m["f_n_hz"] > 5])
    print("lines:", [round(x["f0_hz"], 2) for x in t["periodic_lines"]])
    logp, fr = {}, None
    for fn in sorted(glob.glob(os.path.join(folder, "rec*.csv"))):
        df = pd.read_csv(fn)
        for c in (c for c in df.columns if c != "time_s"):
            fr, lp = ln_p_f_test(resample_poly(df[c].values, 1, 40), NW, K)
            logp.setdefault(c, []).append(lp)
    half = 4 * NW  # the tapers' half-bandwidth NW / T in points of the 4x padded grid (1 / 4T)
    for pool in ("sprung", "unsprung"):
        rows = np.array([lp for c in logp if c.startswith(pool) for lp in logp[c]])
        x = -2 * rows.sum(0)
        p = chi2.sf(x, 2 * rows.shape[0])
        band = np.where((fr > 5) & (fr < 25))[0]
        peaks = [j for j in band if x[j] == x[max(0, j - half):j + half + 1].max() and p[j] < 0.01 / 221]
        print(pool, f"({rows.shape[0]} record-channels):",
              " ".join(f"{fr[j]:.2f}({np.log10(max(p[j], 1e-300)):.0f})" for j in peaks))


if __name__ == "__main__":
    main(sys.argv[1])
