#!/usr/bin/env python3
"""How much of the unsprung level ratios' change between a baseline and a test drive is sensor
noise: the front/rear and left/right ratios of the unsprung channels' band power (8-20 Hz, the
fleet's `ratio_band_hz`, the drive's true periodic lines +-0.4 Hz left out as the fleet's
line-free features do), before and after each channel's noise power in the band is subtracted.
The noise density is the mean Welch PSD over [300 Hz, 0.4 fs] (busgen's sensor noise is white;
the vehicle's response there is negligible). Prints per ratio the baseline's median and robust
spread (1.4826 MAD over its records), the test drive's median and its z, raw and corrected, and
each channel's noise share of its band power.

Usage (busgen folders of CSV records with truth.json, e.g. from VIBMODE_BUSGEN_CACHE):
    python3 tools/busgen/level_noise.py BASELINE_DIR [BASELINE_DIR...] TEST_DIR

Measures; judges nothing (docs/fleet.md, "A false alarm found by CI's random draw").
"""

import glob
import json
import sys

import numpy as np
from scipy.signal import welch

BAND_HZ = (8.0, 20.0)
LINE_HALF_WIDTH_HZ = 0.4
NOISE_FROM_HZ = 300.0
CHANNELS = ["unsprung_fl", "unsprung_fr", "unsprung_rl", "unsprung_rr"]
PAIRS = [("fl", "rl"), ("fr", "rr"), ("fl", "fr"), ("rl", "rr")]


def band_and_noise_power(folder):
    """Per record: {corner: (band power, noise power in the band)}, (m/s^2)^2."""
    lines = [l["f0_hz"] for l in json.load(open(f"{folder}/truth.json"))["periodic_lines"]]
    out = []
    for path in sorted(glob.glob(f"{folder}/rec*.csv")):
        with open(path) as fh:
            header = fh.readline().strip().split(",")
        x = np.loadtxt(path, delimiter=",", skiprows=1)
        fs = 1.0 / np.median(np.diff(x[:, 0]))
        row = {}
        for name in CHANNELS:
            i = next(k for k, h in enumerate(header) if h.startswith(name))
            f, p = welch(x[:, i], fs=fs, nperseg=4096)
            band = (f >= BAND_HZ[0]) & (f <= BAND_HZ[1])
            for f0 in lines:
                band &= np.abs(f - f0) > LINE_HALF_WIDTH_HZ
            df = f[1] - f[0]
            density = np.mean(p[(f >= NOISE_FROM_HZ) & (f <= 0.4 * fs)])
            row[name[-2:]] = (p[band].sum() * df, density * band.sum() * df)
        out.append(row)
    return out


def log_ratios(rows, a, b, corrected):
    out = []
    for row in rows:
        (pa, na), (pb, nb) = row[a], row[b]
        if corrected:
            pa, pb = max(pa - na, 1e-3 * pa), max(pb - nb, 1e-3 * pb)
        out.append(0.5 * np.log(pa / pb))
    return np.array(out)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    base = [r for d in sys.argv[1:-1] for r in band_and_noise_power(d)]
    test = band_and_noise_power(sys.argv[-1])
    for corrected in (False, True):
        print("noise subtracted" if corrected else "raw")
        for a, b in PAIRS:
            rb, rt = log_ratios(base, a, b, corrected), log_ratios(test, a, b, corrected)
            s = 1.4826 * np.median(np.abs(rb - np.median(rb)))
            z = (np.median(rt) - np.median(rb)) / s
            print(f"  {a}/{b}: baseline {np.exp(np.median(rb)):.3f} (spread {s:.3f}), test {np.exp(np.median(rt)):.3f}, z {z:+.1f}")
    for name, rows in (("baseline", base), ("test", test)):
        share = {c: np.median([r[c][1] / r[c][0] for r in rows]) for c in rows[0]}
        print(f"noise share of the band power, {name}: " + ", ".join(f"{c} {v:.2f}" for c, v in share.items()))


if __name__ == "__main__":
    main()
