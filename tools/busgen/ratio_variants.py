"""Front/rear level ratio of a track's wheels, three ways, over drives of one busgen bus: the
band-power ratio (what the fleet's level ratio is), and the median and the mean over the Welch
bins of the per-bin log ratio. Both wheels of a track roll over the same road, so per bin their
power ratio is |H_front|^2 / |H_rear|^2 whatever the speed and the road; the band sum weighs the
bins by the input's power, whose shape moves with speed and road (docs/fleet.md, "Tried since
(2026-11-29, not kept): the speed from the front/rear delay").

    python tools/busgen/ratio_variants.py REF_FOLDER FOLDER...

Each folder holds busgen's recNN.csv of one drive (e.g. `python ../shared/busgen/simulate.py
--bus-seed 32225 --records 8 --seed 6000 --fs 2000 --csv-only --road-class B --speed-kmh 30
--out REF_FOLDER`). Per record: the unsprung channels' white-noise density from the median of
their 1 s Welch spectrum in 300-900 Hz at the file's rate, then the channels brought to 50 Hz
(scipy.signal.resample_poly) and Welch with 256-sample Hann segments (the fleet's grid), 8-20
Hz, the noise density taken off every bin; per-bin ratios only where both bins keep more than
half their power after it. Lines are not left out (the median is robust to a few line bins; the
band sum is not). Printed per folder: each variant's drive median less REF_FOLDER's and its
standard deviation over the records (ln of the amplitude ratio; left track FL/RL, right FR/RR).
Needs numpy and scipy.
"""
import glob
import os
import sys

import numpy as np
from scipy.signal import resample_poly, welch

BAND_HZ = (8.0, 20.0)
NOISE_RANGE_HZ = (300.0, 900.0)
FS_HZ = 50.0
NPERSEG = 256
NAMES = ["band FL/RL", "median FL/RL", "mean FL/RL", "band FR/RR", "median FR/RR", "mean FR/RR"]


def record_ratios(path):
    """The six ratios of one record (see NAMES)."""
    with open(path) as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    fs = 1.0 / (data[1, 0] - data[0, 0])
    x = data[:, 1:].T
    idx = {name: i for i, name in enumerate(header[1:])}
    freq, p = welch(x, fs=fs, nperseg=int(fs))
    floor = (freq >= NOISE_RANGE_HZ[0]) & (freq <= NOISE_RANGE_HZ[1])
    noise = np.median(p[:, floor], axis=1)
    y = resample_poly(x, 1, int(round(fs / FS_HZ)), axis=1)
    f50, p50 = welch(y, fs=FS_HZ, nperseg=NPERSEG)
    band = (f50 >= BAND_HZ[0]) & (f50 <= BAND_HZ[1])
    out = []
    for front, rear in (("fl", "rl"), ("fr", "rr")):
        ia, ib = idx["unsprung_" + front], idx["unsprung_" + rear]
        pa, pb = p50[ia, band], p50[ib, band]
        ca, cb = pa - noise[ia], pb - noise[ib]
        out.append(0.5 * np.log(ca.sum() / cb.sum()))
        kept = (ca > 0.5 * pa) & (cb > 0.5 * pb)
        r = 0.5 * np.log(ca[kept] / cb[kept]) if kept.sum() > 5 else np.array([np.nan])
        out += [np.median(r), np.mean(r)]
    return out


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    drives = {}
    for folder in sys.argv[1:]:
        files = sorted(glob.glob(os.path.join(folder, "rec*.csv")))
        if not files:
            sys.exit(f"{folder}: no recNN.csv")
        drives[folder] = np.array([record_ratios(f) for f in files])
    ref = np.nanmedian(drives[sys.argv[1]], axis=0)
    print("drive (median less the reference's; sd over its records)")
    print("            " + "  ".join(f"{n:<20}" for n in NAMES))
    for folder, r in drives.items():
        med = np.nanmedian(r, axis=0) - ref
        sd = np.nanstd(r, axis=0)
        cells = "  ".join(f"{m:+.3f} (sd {s:.3f})    " for m, s in zip(med, sd))
        print(f"{os.path.basename(folder.rstrip('/')):<11} {cells}")


if __name__ == "__main__":
    main()
