#!/usr/bin/env python3
"""Side-by-side benchmark: vibmode (Rust, release build) against scipy / numpy / pandas / statsmodels.

Usage (from the repository root):
    python3 -m pip install -r tools/reference/requirements.txt
    python3 bench/run.py [--quick] [--out bench-results.json] [--only ssi_cov] [--ssi-demo]

What it does, in one run:
1. builds `vibmode-bench` in release mode;
2. `vibmode-bench gen DIR` writes the shared inputs (a 7-channel 204 800-row CSV, the ARMA data);
3. `vibmode-bench run DIR` times vibmode's kernels and prints medians as JSON;
   (with --ssi-demo, SSI-cov also on `vibmode demo`'s 8 records brought to 50 Hz, see demo_ssi_input);
4. times the Python peers on the same inputs in this process;
5. prints a Markdown table (median seconds and vibmode/peer ratios) for BENCHMARKS.md.
Medians over repeated runs; wall-clock time on whatever machine runs it.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np
import scipy
import scipy.signal as ss


def median_time(fn, repeat, min_time=0.0):
    times = []
    t_start = time.perf_counter()
    while len(times) < repeat or (time.perf_counter() - t_start) < min_time:
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
        if len(times) >= 200:
            break
    return statistics.median(times)


# SSI inputs (file in the data folder, case name), as bench/src/main.rs's SSI_CASES: the generated
# case, and the demo's records at 50 Hz when --ssi-demo wrote them.
SSI_CASES = [("ssi_8x7x512.f64", "ssi_cov_8x7x512_br20_orders2-60"),
             ("ssi_demo50_8x7x512.f64", "ssi_cov_demo50_8x7x512_br20_orders2-60")]


def demo_ssi_input(root, target, data_dir):
    """The 8 records of `vibmode demo` (7 channels, 10.24 s at 20 kHz) brought to 50 Hz by
    `vibmode resample --fs-out 50` (the ideal DFT low-pass, as the analysis does): 512 samples each,
    written record-major, channel-major as data_dir/ssi_demo50_8x7x512.f64 (the layout of the
    generated SSI case)."""
    subprocess.run(["cargo", "build", "--release", "-q", "--bin", "vibmode"], cwd=root, check=True)
    exe = os.path.join(target, "release", "vibmode")
    demo = os.path.join(data_dir, "demo")
    subprocess.run([exe, "demo", "-q", "--keep-records", "-o", demo], check=True, capture_output=True)
    recs = sorted(f for f in os.listdir(os.path.join(demo, "records")) if f.endswith(".wav"))
    out = []
    for f in recs:
        dst = os.path.join(demo, f[:-4] + "_50hz.f64")
        subprocess.run([exe, "resample", "-q", os.path.join(demo, "records", f), "--fs-out", "50", "-o", dst],
                       check=True, capture_output=True)
        x = np.fromfile(dst, dtype="<f8").reshape(-1, 7)  # interleaved frames
        if x.shape != (512, 7):
            raise SystemExit(f"{f} at 50 Hz has shape {x.shape}, expected (512, 7)")
        out.append(x.T)
    if len(out) != 8:
        raise SystemExit(f"vibmode demo wrote {len(out)} records, expected 8")
    np.ascontiguousarray(np.stack(out)).astype("<f8").tofile(os.path.join(data_dir, SSI_CASES[1][0]))


def ssi_peer(data_dir, meta, quick):
    res = {}
    # SSI-cov: pyOMA2's functions (as its SSI class with method "cov" calls them) on the same
    # 8 records x 7 channels x 512 samples, block rows 20, orders 0..60 step 2, hard criterion
    # xi < 1 only (vibmode's filter). Skipped with a note when pyOMA2 is not installed.
    try:
        os.environ.setdefault("TQDM_DISABLE", "1")
        import logging
        from pyoma2.functions import ssi as pyssi
        logging.disable(logging.CRITICAL)
        m = meta["ssi"]
        br, om, st, dt = m["block_rows"], m["order_max"], m["order_step"], 1.0 / m["fs_hz"]
        for file, case in SSI_CASES:
            path = os.path.join(data_dir, file)
            if not os.path.exists(path):
                continue
            data = np.fromfile(path, dtype="<f8").reshape(m["records"], m["channels"], m["samples"])

            def pyoma2_ssi():
                n = 0
                for y in data:
                    h, _ = pyssi.build_hank(y, y, br, "cov")
                    obs, a, c, _ = pyssi.SSI_fast(h, br, om, step=st)
                    fn, *_ = pyssi.SSI_poles(obs, a, c, om, dt, step=st, HC=True, xi_max=1.0)
                    n += int(np.sum(~np.isnan(fn)))
                return n

            res[case] = {"pyOMA2 1.4 SSI-cov (build_hank cov + SSI_fast + SSI_poles)": median_time(pyoma2_ssi, 1 if quick else 3),
                         "_n_modes_pyoma2": pyoma2_ssi()}
        import importlib.metadata
        res.setdefault("_versions", {})["pyoma2"] = importlib.metadata.version("pyoma-2")
    except ImportError as e:
        print(f"note: SSI peer skipped, pyOMA2 is not importable ({e})", file=sys.stderr)
    return res


def npy_peer(data_dir, quick):
    """numpy.load of the .npy that vibmode-bench wrote (checked equal to the raw samples first)."""
    path = os.path.join(data_dir, "seven_channels.npy")
    raw = np.fromfile(os.path.join(data_dir, "raw7.f64"), dtype="<f8").reshape(-1, 7)
    if not np.array_equal(np.load(path), raw):
        raise SystemExit("seven_channels.npy does not load as raw7.f64: the bench's header is wrong")
    r = 3 if quick else 11
    # vibmode hands out each channel contiguous (the layout of `Recording`); numpy.load keeps the
    # file's frames, so the like-for-like peer also makes the channels contiguous.
    return {"read_npy_7x204800": {
        "numpy.load": median_time(lambda: np.load(path), r),
        "numpy.load + channels contiguous (ascontiguousarray(a.T))": median_time(
            lambda: np.ascontiguousarray(np.load(path).T), r),
    }}


def summarize_peer(data_dir, quick):
    """What `vibmode info` computes, by numpy and pandas: each channel's min, max, mean, std
    (ddof 0) and RMS after loading the .npy or reading the CSV (the sensor checks have no peer;
    vibmode's time includes them)."""
    npy = os.path.join(data_dir, "seven_channels.npy")
    csv = os.path.join(data_dir, "seven_channels.csv")

    def stats(a):
        return (a.min(axis=0), a.max(axis=0), a.mean(axis=0), a.std(axis=0),
                np.sqrt((a * a).mean(axis=0)))

    r = 3 if quick else 11
    out = {"summarize_npy_7x204800": {
        "numpy.load + min, max, mean, std, rms per column": median_time(lambda: stats(np.load(npy)), r)}}
    try:
        import pandas as pd

        def pandas_stats():
            df = pd.read_csv(csv)
            return df.min(), df.max(), df.mean(), df.std(ddof=0), np.sqrt((df * df).mean())

        out["summarize_csv_7x204800"] = {
            "pandas.read_csv + min, max, mean, std, rms per column": median_time(pandas_stats, 3 if quick else 7)}
    except ImportError as e:
        print(f"note: pandas peer skipped ({e})", file=sys.stderr)
    return out


def peers(data_dir, quick, only=None):
    res = {}
    meta = json.load(open(os.path.join(data_dir, "meta.json")))
    if only is not None:
        # One case's peers only (SSI-cov and the .npy reader are the ones worth timing alone).
        res = ssi_peer(data_dir, meta, quick) if "ssi_cov".startswith(only) or only.startswith("ssi_cov") else {}
        if "read_npy".startswith(only) or only.startswith("read_npy"):
            res.update(npy_peer(data_dir, quick))
        if "summarize".startswith(only) or only.startswith("summarize"):
            res.update(summarize_peer(data_dir, quick))
        res.setdefault("_versions", {}).update({"numpy": np.__version__, "scipy": scipy.__version__})
        return res
    csv_path = os.path.join(data_dir, "seven_channels.csv")
    x = np.fromfile(os.path.join(data_dir, "welch.f64"), dtype="<f8")
    r = 3 if quick else 7
    res["welch_204800_nperseg256"] = {"scipy.signal.welch": median_time(lambda: ss.welch(x, fs=20000.0, nperseg=256), r)}
    res["welch_204800_nperseg4096"] = {"scipy.signal.welch": median_time(lambda: ss.welch(x, fs=20000.0, nperseg=4096), r)}
    raw = np.fromfile(os.path.join(data_dir, "raw7.f64"), dtype="<f8").reshape(-1, 7)
    # Clustering: the independent scipy implementation of tools/reference/modal.py (cKDTree radius
    # queries + connected components) on the same pole cloud and settings.
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tools", "reference"))
    import modal as modal_ref
    cloud = json.load(open(os.path.join(data_dir, "poles.json")))
    cl_params = {k: v for k, v in cloud["params"].items() if v is not None}
    res["cluster_poles"] = {
        "scipy reference (tools/reference/modal.py)": median_time(
            lambda: modal_ref.cluster(cloud["poles"], cloud["n_records"], cloud["orders"], cl_params), 1 if quick else 3)
    }

    def ideal_numpy():
        X = np.fft.rfft(raw, axis=0)
        f = np.fft.rfftfreq(raw.shape[0], 1 / 20000.0)
        X[f > 100.0, :] = 0
        return np.fft.irfft(X, n=raw.shape[0], axis=0)[::100]

    res["resample_7x204800_20k_to_200"] = {
        "scipy.signal.resample": median_time(lambda: ss.resample(raw, 2048, axis=0), r),
        "numpy rfft ideal filter + decimate": median_time(ideal_numpy, r),
        "scipy.signal.resample_poly": median_time(lambda: ss.resample_poly(raw, 1, 100, axis=0), r),
    }
    rr = 1 if quick else 3
    csv = {"numpy.loadtxt": median_time(lambda: np.loadtxt(csv_path, delimiter=",", skiprows=1), rr)}
    try:
        import pandas as pd
        csv["pandas.read_csv"] = median_time(lambda: pd.read_csv(csv_path), rr)
    except ImportError:
        pass
    res["read_csv_7x204800"] = csv
    res.update(npy_peer(data_dir, quick))
    res.update(summarize_peer(data_dir, quick))
    res.update(ssi_peer(data_dir, meta, quick))
    # ARMA fits (statsmodels exact-likelihood ARIMA), same data as vibmode.
    try:
        import statsmodels
        from statsmodels.tsa.arima.model import ARIMA
        for p in meta["arma_orders"]:
            y = np.fromfile(os.path.join(data_dir, f"arma{p}.f64"), dtype="<f8")
            lam = {}

            def fit():
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    m = ARIMA(y, order=(p, 0, p), trend="n").fit()
                lam["sigma2"] = float(m.params[-1])
                lam["params"] = m.params
            t = median_time(fit, 1)
            # lambda of the statsmodels parameters evaluated by vibmode's predictor definition
            # (mean squared one-step error with zero initial conditions), computed here in numpy.
            ar = lam["params"][:p]
            ma = lam["params"][p:2 * p]
            a = np.r_[1.0, -ar]
            c = np.r_[1.0, ma]
            # vibmode's definition (docs/identification.md): demeaned y, conditional on the first
            # p samples: w_t = A(q) y_t for t >= p, eps = w / C with zero initial conditions.
            yd = y - y.mean()
            w = ss.lfilter(a, [1.0], yd)[p:]
            eps = ss.lfilter([1.0], c, w)
            res[f"arma_{p}_{p}_n2048"] = {"statsmodels ARIMA": t, "_lambda_statsmodels": float(np.mean(eps ** 2))}
        res.setdefault("_versions", {})["statsmodels"] = statsmodels.__version__
    except ImportError:
        pass
    res.setdefault("_versions", {}).update({"numpy": np.__version__, "scipy": scipy.__version__, "python": sys.version.split()[0]})
    return res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="fewer repetitions")
    ap.add_argument("--out", default=None, help="also write all figures to this JSON file")
    ap.add_argument("--ssi-demo", action="store_true",
                    help="also time SSI-cov on the 8 records of `vibmode demo` brought to 50 Hz (builds the vibmode binary)")
    ap.add_argument("--only", default=None,
                    help="only the cases whose name starts with this (e.g. ssi_cov): other peers are not run")
    args = ap.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    subprocess.run(["cargo", "build", "--release", "-q", "-p", "vibmode-bench"], cwd=root, check=True)
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(root, "target"))
    exe = os.path.join(target, "release", "vibmode-bench")
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([exe, "gen", d], check=True)
        if args.ssi_demo:
            demo_ssi_input(root, target, d)
        out = subprocess.run([exe, "run", d] + (["--quick"] if args.quick else []), check=True, capture_output=True, text=True)
        rust = json.loads(out.stdout)
        py = peers(d, args.quick, args.only)
    rows = []
    for case, rs in rust.items():
        if case.startswith("_") or (args.only and not case.startswith(args.only)):
            continue
        for impl_name, t in rs.items():
            if impl_name.startswith("_"):
                continue
            pe = {k: v for k, v in py.get(case, {}).items() if not k.startswith("_")}
            best = min(pe.items(), key=lambda kv: kv[1]) if pe else None
            for pname, pt in pe.items():
                rows.append((case, impl_name, t, pname, pt, t / pt, "fastest peer" if best and pname == best[0] else ""))
    print(f"| case | vibmode | median [s] | peer | median [s] | ratio vibmode/peer | |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]:.5f} | {r[3]} | {r[4]:.5f} | {r[5]:.4f} | {r[6]} |")
    extra = {k: v for k, v in rust.items() if k.startswith("_")}
    for case in py:
        if case.startswith("arma_"):
            lr = rust.get(case, {}).get("_lambda_vibmode")
            ls = py[case].get("_lambda_statsmodels")
            if lr is not None and ls is not None:
                print(f"\n{case}: lambda vibmode {lr:.6e}, statsmodels (evaluated by the same predictor) {ls:.6e}, ratio {lr / ls:.5f}")
    for case in rust:
        if case.startswith("ssi_cov") and "_n_modes" in rust[case]:
            print(f"\n{case}: {rust[case]['_n_modes']} modes (vibmode), "
                  f"{py.get(case, {}).get('_n_modes_pyoma2', 'n/a')} (pyOMA2, its own correlation estimator)")
    cl = rust.get("cluster_poles", {})
    if "_n_poles" in cl:
        print(f"\ncluster_poles: {cl['_n_poles']} poles, {cl['_invariant_modes']} invariant modes (vibmode)")
    print("\nversions:", json.dumps(py.get("_versions", {})), json.dumps(extra))
    if args.out:
        json.dump({"vibmode": rust, "peers": py}, open(args.out, "w"), indent=1, default=float)


if __name__ == "__main__":
    main()
