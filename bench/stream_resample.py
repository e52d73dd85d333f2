#!/usr/bin/env python3
"""Decimating an hours-long recording to 200 Hz: `vibmode resample --resampler fir` (streamed)
against scipy.signal.resample_poly and soxr on the same raw f32 file, in one run.

Usage (from the repository root; needs numpy, scipy, soxr and a release build):
    cargo build --release
    python3 -m pip install numpy scipy soxr
    python3 bench/stream_resample.py [--minutes 60] [--file PATH] [--keep]

Writes the 7-channel 20 kHz f32 input with bench/make_long.py when --file is not given (2 GB for
60 min; deleted afterwards unless --keep). Each tool runs in its own process under
/usr/bin/time -v: wall time (including reading the file) and peak resident memory. The Python
peers load the whole file (np.fromfile) and resample all channels at once:
- scipy.signal.resample_poly(x, 1, 100) with its default Kaiser filter (beta 5, 2001 taps:
  about 55 dB stop band), and with vibmode's filter taps (110 dB, 7109 taps) given as `window`;
- soxr.resample(x, 20000, 200, quality="VHQ") (soxr's very high quality, about 175 dB).
Prints a Markdown table for BENCHMARKS.md.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VIBMODE = os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")), "release", "vibmode")

PEER = r"""
import sys, numpy as np, scipy.signal as ss
path, which, taps = sys.argv[1], sys.argv[2], sys.argv[3]
x = np.fromfile(path, dtype='<f4').reshape(-1, 7)
if which == 'resample_poly':
    y = ss.resample_poly(x, 1, 100, axis=0)
elif which == 'resample_poly_110db':
    h = np.fromfile(taps, dtype='<f8')
    y = ss.resample_poly(x, 1, 100, axis=0, window=h)
elif which == 'soxr':
    import soxr
    y = soxr.resample(x, 20000, 200, quality='VHQ')
print(y.shape)
"""


def timed(cmd):
    r = subprocess.run(["/usr/bin/time", "-v"] + cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr[-2000:]}")
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", r.stderr).group(1)
    parts = [float(p) for p in wall.split(":")]
    secs = sum(p * 60 ** i for i, p in enumerate(reversed(parts)))
    rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", r.stderr).group(1))
    return secs, rss_kb / 1024.0, r.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--minutes", type=float, default=60.0)
    ap.add_argument("--file")
    ap.add_argument("--keep", action="store_true")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="vibmode-bench-")
    path = a.file
    made = False
    if path is None:
        path = os.path.join(tmp, "long.f32")
        subprocess.run([sys.executable, os.path.join(ROOT, "bench", "make_long.py"), path, "--minutes", str(a.minutes)], check=True)
        made = True
    n_frames = os.path.getsize(path) // (7 * 4)
    duration = n_frames / 20000.0
    # vibmode's filter taps, for resample_poly with the same filter.
    sys.path.insert(0, os.path.join(ROOT, "bench"))
    import numpy as np
    from scipy.special import i0
    n_taps = 7109
    d = (n_taps - 1) / 2
    k = np.arange(n_taps) - d
    fc = 90.0 / 20000.0
    h = 2 * fc * np.sinc(2 * fc * k) * i0(0.1102 * (110 - 8.7) * np.sqrt(1 - (k / d) ** 2)) / i0(0.1102 * (110 - 8.7))
    h /= h.sum()
    taps = os.path.join(tmp, "taps.f64")
    h.astype("<f8").tofile(taps)
    rows = []
    out = os.path.join(tmp, "out200.f32")
    secs, rss, err = timed([VIBMODE, "resample", path, "--fs-out", "200", "--resampler", "fir", "-q", "-o", out])
    rows.append(("vibmode resample --resampler fir (streamed, 110 dB, 7109 taps)", secs, rss))
    for f in [out, out + ".json"]:
        os.remove(f)
    peer = os.path.join(tmp, "peer.py")
    open(peer, "w").write(PEER)
    for which, label in [
        ("resample_poly", "scipy.signal.resample_poly(x, 1, 100), default Kaiser beta 5 (~55 dB)"),
        ("resample_poly_110db", "scipy.signal.resample_poly with vibmode's 110 dB taps"),
        ("soxr", "soxr.resample(x, 20000, 200, 'VHQ')"),
    ]:
        secs, rss, _ = timed([sys.executable, peer, path, which, taps])
        rows.append((label, secs, rss))
    print(f"\n{duration / 60:.0f} min of 7 channels at 20 kHz (raw f32, {os.path.getsize(path) / 1e9:.2f} GB) to 200 Hz; "
          f"{os.cpu_count()} cores; wall time includes reading the file.\n")
    print("| tool | wall [s] | x real time | peak RSS [MB] |")
    print("|---|---|---|---|")
    for label, secs, rss in rows:
        print(f"| {label} | {secs:.1f} | {duration / secs:.0f} | {rss:.0f} |")
    json.dump({"duration_s": duration, "rows": rows}, open(os.path.join(tmp, "result.json"), "w"))
    if made and not a.keep:
        os.remove(path)
        os.remove(path + ".json")


if __name__ == "__main__":
    main()
