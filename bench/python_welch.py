#!/usr/bin/env python3
"""vibmode.welch (the Python package) against scipy.signal.welch, in one run, on the same arrays.

    pip install ./python scipy
    python bench/python_welch.py [--repeat 30]

Prints a Markdown table (medians of --repeat runs after one warm-up, wall-clock seconds) and
checks that the two agree to 1e-9 relative before timing anything.
"""

import argparse
import os
import platform
import statistics
import sys
import time

import numpy as np
import scipy
import scipy.signal as ss

import vibmode


def median_time(fn, repeat):
    fn()  # warm-up
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=30)
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    cases = [
        ("welch (3, 204800), nperseg 256", rng.standard_normal((3, 204800)), dict(fs=20000.0)),
        ("welch (3, 204800), nperseg 4096", rng.standard_normal((3, 204800)), dict(fs=20000.0, nperseg=4096)),
        ("welch (204800, 3), axis 0", rng.standard_normal((204800, 3)), dict(fs=20000.0, axis=0)),
        ("welch (7, 204800), median", rng.standard_normal((7, 204800)), dict(fs=20000.0, average="median")),
        ("welch (204800,), nperseg 256", rng.standard_normal(204800), dict(fs=20000.0)),
    ]
    print(
        f"python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
        f"vibmode {vibmode.__version__}, {os.cpu_count()} cores, load average "
        f"{os.getloadavg()[0]:.2f}, {args.repeat} repetitions"
    )
    print()
    print("| case | vibmode.welch [s] | scipy.signal.welch [s] | ratio vibmode/scipy | max rel. difference |")
    print("|---|---|---|---|---|")
    worst = 0.0
    for name, x, kw in cases:
        f1, p1 = vibmode.welch(x, **kw)
        f2, p2 = ss.welch(x, **kw)
        rel = float(np.max(np.abs(p1 - p2)) / np.max(np.abs(p2)))
        if not (np.allclose(f1, f2, rtol=1e-12) and rel < 1e-9):
            print(f"{name}: results differ (max relative difference {rel:.2e})", file=sys.stderr)
            sys.exit(1)
        tv = median_time(lambda: vibmode.welch(x, **kw), args.repeat)
        ts = median_time(lambda: ss.welch(x, **kw), args.repeat)
        worst = max(worst, tv / ts)
        print(f"| {name} | {tv:.5f} | {ts:.5f} | {tv / ts:.3f} | {rel:.1e} |")
    print()
    print(f"largest ratio vibmode/scipy: {worst:.3f}")


if __name__ == "__main__":
    main()
