"""Reference values for the numeric helpers of crates/vibmode-report (module `axes`).

Writes tools/reference/data/report_plot.json (run from anywhere):

    python3 tools/reference/report_plot.py

Pinned versions (tools/reference/requirements.txt): Python 3.11, numpy 2.1.3.
The script records the versions it actually ran with in the JSON. No plotting
library is installed (matplotlib is not pinned), so the references are
independent numpy formulations of the documented rules, written without looking
at the Rust code paths:

Non-finite inputs are stored as the strings "nan", "inf", "-inf".

- "decimate": peak-preserving M4 decimation. Vectorised numpy: pixel column
  floor((x - lo) / (hi - lo) * n_columns) clipped to [-1, n_columns]; runs of
  consecutive finite points in one column found with np.diff/cumsum; per run the
  first, last, argmin and argmax (first occurrence, via np.lexsort) are kept;
  non-finite points are kept as their own runs. Seeded inputs (default_rng(7)):
  noise + sine + isolated spikes, NaN/Inf holes, uniform and jittered x, and an
  x range narrower than the data. Compared exactly (index lists).
- "nice_ticks": brute force over the candidate steps {1, 2, 5} x 10^k,
  k = -20..20, in increasing order; the first step giving at most max_ticks
  multiples inside [lo, hi] (tolerance 1e-9 step) wins. Tolerance in Rust:
  1e-12 * step absolute per tick, equal counts.
- "auto_range": np.nanmin/np.nanmax over the finite (and, for log, positive)
  values, 5 % padding of the span on each side (in log10 for log axes), the
  documented singular/empty cases. Tolerance in Rust: 1e-12 relative.
- "rescale": affine map of the valid values (log10 for log) onto a target
  range; invalid values -> NaN (stored as null). Tolerance: 1e-12 absolute
  relative to the target span.
"""

import json
import os
import platform

import numpy as np

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "report_plot.json")


def m4(x, y, lo, hi, ncol):
    n = len(x)
    valid = np.isfinite(x) & np.isfinite(y)
    with np.errstate(invalid="ignore", over="ignore"):
        col = np.clip(np.floor((x - lo) / (hi - lo) * ncol), -1, ncol)
    start = np.ones(n, dtype=bool)
    start[1:] = (~valid[1:]) | (~valid[:-1]) | (col[1:] != col[:-1])
    run = np.cumsum(start) - 1
    starts = np.flatnonzero(start)
    ends = np.r_[starts[1:], n] - 1
    keep = set(starts.tolist()) | set(ends.tolist())
    idx = np.arange(n)
    yy = np.where(valid, y, 0.0)
    order_min = np.lexsort((idx, yy, run))
    order_max = np.lexsort((idx, -yy, run))
    first_min = np.ones(n, dtype=bool)
    first_min[1:] = run[order_min][1:] != run[order_min][:-1]
    first_max = np.ones(n, dtype=bool)
    first_max[1:] = run[order_max][1:] != run[order_max][:-1]
    keep |= set(order_min[first_min].tolist())
    keep |= set(order_max[first_max].tolist())
    return sorted(int(i) for i in keep)


def decimate_cases(rng):
    cases = []
    for n, ncol, jitter, holes, narrow in [
        (5000, 300, False, False, False),
        (12000, 800, True, True, False),
        (9876, 1000, False, True, True),
        (3000, 50, True, False, True),
    ]:
        t = np.arange(n, dtype=float) * 0.005
        if jitter:
            t = np.sort(t + rng.uniform(0, 0.004, n))
        y = np.sin(2 * np.pi * 1.1 * t) + 0.2 * rng.standard_normal(n)
        spikes = rng.choice(n, 12, replace=False)
        y[spikes] += rng.choice([-1.0, 1.0], 12) * rng.uniform(5, 20, 12)
        # exact ties, so the "first occurrence" rule matters
        y[100:110] = 3.0
        if holes:
            y[rng.choice(n, 15, replace=False)] = np.nan
            y[rng.choice(n, 3, replace=False)] = np.inf
            t[rng.choice(n, 3, replace=False)] = np.nan
        # 7 significant digits keep the JSON small; the rounded values are the inputs.
        t = np.array([float(f"{v:.7g}") for v in t])
        y = np.array([float(f"{v:.7g}") for v in y])
        finite_t = t[np.isfinite(t)]
        lo, hi = float(finite_t.min()), float(finite_t.max())
        if narrow:
            lo, hi = lo + 0.3 * (hi - lo), lo + 0.6 * (hi - lo)
        kept = m4(t, y, lo, hi, ncol)
        cases.append(
            {
                "x": enc(t),
                "y": enc(y),
                "x_lo": lo,
                "x_hi": hi,
                "n_columns": ncol,
                "kept": kept,
            }
        )
    return cases


def nice_ticks(lo, hi, max_ticks):
    max_ticks = max(max_ticks, 2)
    steps = sorted(m * 10.0**k for k in range(-20, 21) for m in (1.0, 2.0, 5.0))
    for s in steps:
        first = np.ceil(lo / s - 1e-9)
        last = np.floor(hi / s + 1e-9)
        if last - first + 1 <= max_ticks:
            return s, [float(v * s) for v in np.arange(first, last + 1)]
    return None, []


def tick_cases(rng):
    cases = []
    fixed = [
        (0.0, 1.0, 5),
        (0.0, 10.24, 6),
        (-1.3, 1.3, 7),
        (0.0, 100.0, 10),
        (1e-6, 3.7e-6, 5),
        (-0.05, 25.05, 8),
        (123456.0, 123999.0, 4),
        (-3e5, 7e5, 6),
        (0.999, 1.001, 5),
        (2.0, 30.0, 2),
    ]
    for lo, hi, m in fixed:
        s, t = nice_ticks(lo, hi, m)
        cases.append({"lo": lo, "hi": hi, "max_ticks": m, "step": s, "ticks": t})
    for _ in range(40):
        c = rng.uniform(-1, 1) * 10.0 ** rng.integers(-6, 7)
        w = 10.0 ** rng.uniform(-7, 7)
        lo, hi = c - w * rng.uniform(0, 1), c + w * rng.uniform(0.01, 1)
        m = int(rng.integers(2, 11))
        s, t = nice_ticks(lo, hi, m)
        cases.append({"lo": float(lo), "hi": float(hi), "max_ticks": m, "step": s, "ticks": t})
    return cases


def auto_range(v, scale):
    v = np.asarray(v, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        ok = np.isfinite(v) & ((v > 0) if scale == "log" else True)
    t = v[ok]
    if scale == "log":
        t = np.log10(t)
    if t.size == 0:
        lo, hi = 0.0, 1.0
    else:
        a, b = float(np.min(t)), float(np.max(t))
        if b - a <= 1e-12 * max(abs(a), abs(b)):
            m = 0.5 * (a + b)
            d = 0.5 if scale == "log" else (1.0 if m == 0 else 0.1 * abs(m))
            lo, hi = m - d, m + d
        else:
            lo, hi = a - 0.05 * (b - a), b + 0.05 * (b - a)
    if scale == "log":
        lo, hi = 10.0**lo, 10.0**hi
    return lo, hi


def enc(v):
    return [float(x) if np.isfinite(x) else str(x) for x in v]


def range_cases(rng):
    cases = []
    inputs = [
        [1.0, 2.0, 3.0],
        [5.0],
        [0.0],
        [],
        [np.nan, np.inf, -np.inf],
        [-4.0, 0.0, 1e-3, 1e3, np.nan],
        list(rng.standard_normal(50) * 3 + 10),
        list(10.0 ** rng.uniform(-30, 2, 40)),
        list(np.r_[-1.0, 0.0, 10.0 ** rng.uniform(-3, 1, 20)]),
        [2.5, 2.5, 2.5],
    ]
    for v in inputs:
        for scale in ("linear", "log"):
            lo, hi = auto_range(v, scale)
            cases.append({"values": enc(v), "scale": scale, "lo": lo, "hi": hi})
    return cases


def rescale_cases(rng):
    cases = []
    for scale, v, target in [
        ("linear", [0.0, 5.0, 10.0, np.nan], (1.0, 3.0)),
        ("log", list(np.r_[10.0 ** rng.uniform(-8, 1, 30), 0.0, -1.0, np.inf]), (0.0, 30.0)),
        ("linear", list(rng.standard_normal(25)), (-2.0, 40.0)),
        ("log", [7.0, 7.0], (2.0, 4.0)),
    ]:
        v = np.asarray(v, dtype=float)
        with np.errstate(invalid="ignore", divide="ignore"):
            ok = np.isfinite(v) & ((v > 0) if scale == "log" else True)
            t = np.where(ok, np.log10(np.where(ok, v, 1.0)) if scale == "log" else v, np.nan)
        a, b = np.nanmin(t), np.nanmax(t)
        if b > a:
            out = target[0] + (t - a) / (b - a) * (target[1] - target[0])
        else:
            out = np.where(ok, 0.5 * (target[0] + target[1]), np.nan)
        cases.append(
            {
                "values": enc(v),
                "scale": scale,
                "target": list(target),
                "expected": [float(x) if np.isfinite(x) else None for x in out],
            }
        )
    return cases


def main():
    rng = np.random.default_rng(7)
    data = {
        "versions": {"python": platform.python_version(), "numpy": np.__version__},
        "decimate": decimate_cases(rng),
        "nice_ticks": tick_cases(rng),
        "auto_range": range_cases(rng),
        "rescale": rescale_cases(rng),
    }
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        json.dump(data, f, separators=(",", ":"))
    print(f"wrote {OUT} ({os.path.getsize(OUT)} bytes)")


if __name__ == "__main__":
    main()
