#!/usr/bin/env python3
"""The paper's whole workload, timed: vibmode end to end, and statsmodels extrapolated.

Usage (from the repository root):
    python3 -m pip install -r tools/reference/requirements.txt
    python3 bench/workload.py [--sm-orders 2,4,6,8] [--skip-paper]

What it does, in one run:
1. builds the `vibmode` binary in release mode;
2. simulates the demo's 8 records x 7 channels of the city bus at 20 kHz (`vibmode simulate`);
3. times `vibmode analyze` on them end to end (read 20 kHz WAV, ideal anti-alias filter and
   resampling, Welch, ARMA(p,p) sweep, clustering, figures, HTML report), for
   a. the default preset (50 Hz, p = 2..30),
   b. the paper's model orders at vibmode's analysis rate (50 Hz, p = 2..60: 3304 fits),
   c. `--preset paper` (200 Hz, p = 2..60: 3304 fits);
4. times statsmodels' ARIMA(p,0,p) (exact likelihood) on one channel of one record at the same
   rates for a sample of orders, fits a power law t(p) = a p^b to the sample and extrapolates the
   sum over p = 2..60 and 56 channel-records;
5. prints a Markdown table for BENCHMARKS.md.
Wall-clock time on whatever machine runs it (`nproc` and the load average are printed).
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np


def run(cmd, **kw):
    t0 = time.perf_counter()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, **kw)
    return time.perf_counter() - t0, out.stdout + out.stderr


def load_f64(path, nch, ch):
    x = np.fromfile(path, dtype="<f8").reshape(-1, nch)
    return x[:, ch].copy()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sm-orders", default="2,4,6,8,10")
    ap.add_argument("--skip-paper", action="store_true")
    args = ap.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    subprocess.run(["cargo", "build", "--release", "--quiet", "--bin", "vibmode"], cwd=root, check=True)
    exe = os.path.join(root, "target", "release", "vibmode")
    print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()}", file=sys.stderr)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        sim = os.path.join(tmp, "sim")
        run([exe, "simulate", os.path.join(root, "examples", "city_bus.toml"), "--records", "8",
             "--output", sim])
        wavs = sorted(os.path.join(sim, f) for f in os.listdir(sim) if f.endswith(".wav"))
        cfg60 = os.path.join(tmp, "p60.toml")
        with open(cfg60, "w") as f:
            f.write("order_max = 60\n")
        cases = [("default preset: 50 Hz, p = 2..30", []),
                 ("paper's orders at 50 Hz: p = 2..60", ["--config", cfg60])]
        if not args.skip_paper:
            cases.append(("--preset paper: 200 Hz, p = 2..60", ["--preset", "paper"]))
        for label, extra in cases:
            out_dir = os.path.join(tmp, "out")
            dt, log = run([exe, "analyze", *wavs, "-q", "-o", out_dir, *extra])
            res = json.load(open(os.path.join(out_dir, "results.json")))
            summary = [l for l in log.splitlines() if "fits" in l][:1]
            print(f"{label}: {dt:.1f} s  {summary}", file=sys.stderr)
            rows.append((label, dt, summary[0] if summary else ""))
        # statsmodels sample on record 1, channel 0 (front-left wheel), at both rates.
        from statsmodels.tsa.arima.model import ARIMA
        import statsmodels
        sm_orders = [int(v) for v in args.sm_orders.split(",")]
        sm = {}
        for rate in ([50] if args.skip_paper else [50, 200]):
            raw = os.path.join(tmp, f"r{rate}.f64")
            run([exe, "resample", wavs[0], "--fs-out", str(rate), "--cutoff", "25", "-o", raw])
            y = load_f64(raw, 7, 0)
            times = []
            for p in sm_orders:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    t0 = time.perf_counter()
                    ARIMA(y, order=(p, 0, p), trend="c").fit()
                    times.append(time.perf_counter() - t0)
                print(f"statsmodels {statsmodels.__version__} ARIMA({p},0,{p}) N={len(y)}: "
                      f"{times[-1]:.2f} s", file=sys.stderr)
            b, log_a = np.polyfit(np.log(sm_orders), np.log(times), 1)
            est = sum(math.exp(log_a) * p ** b for p in range(2, 61)) * 56
            sm[rate] = (est, b, list(zip(sm_orders, times)))
    print("| workload | vibmode wall time (s) | fits |")
    print("|---|---|---|")
    for label, dt, summary in rows:
        print(f"| {label} | {dt:.1f} | {summary} |")
    print()
    print("| statsmodels ARIMA(p,0,p), one channel | sample (p: s) | power law exponent | "
          "extrapolated 56 x p = 2..60 (s) | (h) |")
    print("|---|---|---|---|---|")
    for rate, (est, b, sample) in sm.items():
        s = ", ".join(f"{p}: {t:.2f}" for p, t in sample)
        print(f"| {rate} Hz, N = {2048 if rate == 200 else 512} | {s} | {b:.2f} | {est:.0f} | "
              f"{est / 3600:.1f} |")


if __name__ == "__main__":
    main()
