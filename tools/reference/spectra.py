"""Reference values for crates/vibmode-spectra from scipy.signal.

Writes tools/reference/data/spectra.json (run from anywhere):

    python3 tools/reference/spectra.py

Pinned versions (tools/reference/requirements.txt): Python 3.11, numpy 2.1.3,
scipy 1.14.1. The script records the versions it actually ran with in the JSON.

Contents
- "signals": seeded test inputs (numpy default_rng(20240601)): noise + sines +
  offset + trend so that the detrend options matter; even and odd lengths, and
  one record shorter than the default nperseg = 256.
- "windows": scipy.signal.get_window(name, n) (periodic, fftbins=True) for
  every window at several lengths.
- "cases": scipy.signal.welch / periodogram / csd / coherence outputs
  (frequencies and values; complex values as separate re/im lists) for every
  window, both scalings, both averages (median with even and odd segment
  counts), every detrend, nfft > nperseg (even and odd), odd nperseg,
  noverlap 0 and non-default, a short record (nperseg clamped), periodograms
  with and without window and with nfft larger and smaller than the record.

Tolerance used by the Rust tests (tests/integration/scipy_reference.rs): on every bin,
|rust - scipy| <= 1e-9 * max(|scipy bin|, 1e-12 * max_bins |scipy|);
frequencies to 1e-12 relative; windows to 1e-12 absolute.
"""

import json
import os
import sys

import numpy as np
import scipy
import scipy.signal as sig

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "data", "spectra.json")


def make_signals():
    rng = np.random.default_rng(20240601)

    def sig_of(n, fs, tones, offset, slope):
        t = np.arange(n) / fs
        x = rng.standard_normal(n)
        for amp, f in tones:
            x += amp * np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
        return x + offset + slope * t

    s = {}
    s["a1000"] = sig_of(1000, 100.0, [(3.0, 1.1), (1.0, 9.3)], 2.5, 0.4)
    s["b777"] = sig_of(777, 200.0, [(2.0, 13.0)], -1.0, 1.5)
    s["c200"] = sig_of(200, 50.0, [(1.5, 4.0)], 0.3, 0.0)
    s["d2000"] = sig_of(2000, 256.0, [(0.5, 20.0), (4.0, 60.5)], 0.0, -0.2)
    s["e513"] = sig_of(513, 10.0, [(1.0, 1.7)], 5.0, 0.1)
    # y correlated with a1000: smoothed a1000 plus independent noise.
    a = s["a1000"]
    y = np.convolve(a, [0.5, 0.3, 0.2], mode="same") + 0.5 * rng.standard_normal(a.size)
    s["y1000"] = y
    d = s["d2000"]
    s["y2000"] = 0.8 * np.roll(d, 3) + rng.standard_normal(d.size)
    return s


def scipy_window(w):
    if w.startswith("tukey:"):
        return ("tukey", float(w.split(":")[1]))
    return w


def scipy_detrend(d):
    return False if d == "none" else d


def main():
    signals = make_signals()
    fs_of = {"a1000": 100.0, "b777": 200.0, "c200": 50.0, "d2000": 256.0,
             "e513": 10.0, "y1000": 100.0, "y2000": 256.0}
    cases = []

    def add(name, func, x, y=None, **p):
        params = dict(window=None, nperseg=None, noverlap=None, nfft=None,
                      detrend="constant", scaling="density", average="mean")
        params.update(p)
        fs = fs_of[x]
        kw = dict(fs=fs, detrend=scipy_detrend(params["detrend"]))
        xv = signals[x]
        if func == "periodogram":
            params["window"] = params["window"] or "boxcar"
            f, v = sig.periodogram(xv, window=scipy_window(params["window"]),
                                   nfft=params["nfft"], scaling=params["scaling"], **kw)
        else:
            params["window"] = params["window"] or "hann"
            kw.update(window=scipy_window(params["window"]), nperseg=params["nperseg"],
                      noverlap=params["noverlap"], nfft=params["nfft"])
            if func == "welch":
                f, v = sig.welch(xv, scaling=params["scaling"], average=params["average"], **kw)
            elif func == "csd":
                f, v = sig.csd(xv, signals[y], scaling=params["scaling"],
                               average=params["average"], **kw)
            elif func == "coherence":
                f, v = sig.coherence(xv, signals[y], **kw)
            else:
                raise ValueError(func)
        v = np.asarray(v)
        case = dict(name=name, func=func, x=x, y=y, fs_hz=fs, params=params,
                    freq_hz=f.tolist(), re=np.real(v).tolist())
        if np.iscomplexobj(v):
            case["im"] = np.imag(v).tolist()
        cases.append(case)

    # Welch: defaults, every window, scalings, averages, detrends, sizes.
    add("welch default (6 segments)", "welch", "a1000")
    for w in ["hann", "hamming", "blackman", "boxcar", "flattop", "tukey:0.5", "tukey:0.25"]:
        add(f"welch window {w}", "welch", "b777", window=w, nperseg=200)
    add("welch spectrum scaling", "welch", "a1000", scaling="spectrum", window="flattop")
    add("welch median even (6 segments)", "welch", "a1000", average="median")
    add("welch median odd (7 segments)", "welch", "a1000", average="median", nperseg=250, noverlap=125)
    add("welch median odd spectrum linear", "welch", "d2000", average="median", nperseg=300,
        noverlap=100, scaling="spectrum", detrend="linear")
    add("welch detrend none", "welch", "a1000", detrend="none")
    add("welch detrend linear", "welch", "a1000", detrend="linear")
    add("welch nfft 512 > nperseg 200", "welch", "b777", nperseg=200, nfft=512)
    add("welch odd nfft 301 > odd nperseg 255", "welch", "d2000", nperseg=255, nfft=301)
    add("welch odd nperseg 255", "welch", "d2000", nperseg=255)
    add("welch noverlap 0", "welch", "d2000", nperseg=256, noverlap=0)
    add("welch noverlap 50", "welch", "b777", nperseg=128, noverlap=50, window="blackman")
    add("welch short record clamp", "welch", "c200")
    add("welch short record clamp odd", "welch", "e513", nperseg=600, window="hamming")
    add("welch nperseg 4096 clamp boxcar", "welch", "d2000", nperseg=4096, window="boxcar", detrend="none")
    # Periodogram.
    add("periodogram default", "periodogram", "a1000")
    add("periodogram odd default", "periodogram", "e513")
    add("periodogram hann", "periodogram", "b777", window="hann")
    add("periodogram flattop spectrum", "periodogram", "e513", window="flattop", scaling="spectrum")
    add("periodogram nfft 1024 > N", "periodogram", "a1000", nfft=1024, detrend="linear")
    add("periodogram nfft 333 < N", "periodogram", "e513", nfft=333)
    add("periodogram detrend none tukey", "periodogram", "d2000", detrend="none", window="tukey:0.25")
    # Cross-spectra and coherence.
    add("csd default", "csd", "a1000", y="y1000")
    add("csd median odd", "csd", "a1000", y="y1000", average="median", nperseg=250, noverlap=125)
    add("csd median even spectrum", "csd", "d2000", y="y2000", average="median", scaling="spectrum",
        window="hamming", nperseg=200, noverlap=100)
    add("csd odd nfft linear", "csd", "d2000", y="y2000", nperseg=255, nfft=301, detrend="linear")
    add("coherence default", "coherence", "a1000", y="y1000")
    add("coherence blackman 128", "coherence", "d2000", y="y2000", window="blackman", nperseg=128,
        noverlap=32, nfft=200)

    windows = []
    for w in ["hann", "hamming", "blackman", "boxcar", "flattop", "tukey:0.5", "tukey:0.25",
              "tukey:0.0", "tukey:1.0"]:
        for n in [1, 2, 7, 16, 33]:
            windows.append(dict(window=w, n=n,
                                values=sig.get_window(scipy_window(w), n).tolist()))

    out = dict(
        generator="tools/reference/spectra.py",
        versions=dict(python=sys.version.split()[0], numpy=np.__version__, scipy=scipy.__version__),
        tolerance="per bin: |rust - scipy| <= 1e-9 * max(|scipy|, 1e-12 * max|scipy|)",
        signals={k: v.tolist() for k, v in signals.items()},
        windows=windows,
        cases=cases,
    )
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as fh:
        json.dump(out, fh)
    print(f"wrote {OUT}: {len(cases)} cases, {os.path.getsize(OUT)} bytes")


if __name__ == "__main__":
    main()
