"""Reference values for vibmode-signal's resampling (crates/vibmode-signal/tests/integration/resample.rs).

Writes tools/reference/data/resample.json. Run from the repository root:
    python3 tools/reference/resample.py

Library versions (pinned in tools/reference/requirements.txt): Python 3.11, numpy 2.1.3,
scipy 1.14.1.

Two kinds of case:
- "scipy": y = scipy.signal.resample(x_f, num), num = round(N * to_hz / fs_in), where x_f is x
  itself (cutoff_hz null = output Nyquist) or x with every rfft bin above cutoff_hz zeroed
  (numpy.fft). Covers even/odd N, down- and upsampling, integer ratios with D dividing N, and
  rational ratios (1000->300, 999 samples, 425.08->50).
- "ideal_decimate": the paper's steps written with numpy.fft: X = fft(x), zero every bin with
  |f_k| > cutoff_hz, x_f = real(ifft(X)), y = x_f[::D]. Used where D does not divide N (scipy
  differs there, see the crate docs) and for cutoffs below the output Nyquist frequency.

Tolerance used by the Rust tests: max|y_rust - y_ref| / max|y_ref| <= 1e-9.
"""
import json
import os

import numpy as np
import scipy
import scipy.signal as ss

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "data", "resample.json")


def signal(rng, n, fs):
    t = np.arange(n) / fs
    x = rng.standard_normal(n)
    x += 2.0 * np.sin(2 * np.pi * 0.07 * fs * t + 0.3)
    x += 0.5 * np.cos(2 * np.pi * 0.31 * fs * t)
    return x


def lowpass(x, fs, cutoff):
    if cutoff is None:
        return x
    n = len(x)
    X = np.fft.rfft(x)
    f = np.arange(len(X)) * fs / n
    X[f > cutoff] = 0.0
    return np.fft.irfft(X, n)


def ideal_decimate(x, fs, d, cutoff):
    n = len(x)
    X = np.fft.fft(x)
    f = np.fft.fftfreq(n, 1.0 / fs)
    X[np.abs(f) > cutoff] = 0.0
    return np.real(np.fft.ifft(X))[::d]


def main():
    rng = np.random.default_rng(20240611)
    cases = []
    scipy_cases = [
        # name, n, fs_in, to_hz, cutoff_hz
        ("even_down_rational_1000_to_300", 1000, 1000.0, 300.0, None),
        ("odd_999_down_rational_1000_to_300", 999, 1000.0, 300.0, None),
        ("even_down_integer_1000_to_200", 1000, 1000.0, 200.0, None),
        ("even_down_integer_even_num_1000_to_250", 1000, 1000.0, 250.0, None),
        ("odd_down_integer_1001_7000_to_1000", 1001, 7000.0, 1000.0, None),
        ("even_up_100_to_250", 100, 100.0, 250.0, None),
        ("odd_up_101_to_250", 101, 100.0, 250.0, None),
        ("odd_up_integer_ratio_101_100_to_300", 101, 100.0, 300.0, None),
        ("smartphone_425p08_to_50", 2000, 425.08, 50.0, None),
        ("smartphone_odd_2001_425p08_to_50", 2001, 425.08, 50.0, None),
        ("even_down_rational_2048_1000_to_333", 2048, 1000.0, 333.0, None),
        ("rational_with_cutoff_1000_to_300_cut_90", 1000, 1000.0, 300.0, 90.0),
    ]
    for name, n, fs, to, cut in scipy_cases:
        x = signal(rng, n, fs)
        num = int(round(n * to / fs))
        y = ss.resample(lowpass(x, fs, cut), num)
        cases.append(dict(name=name, kind="scipy", fs_in=fs, to_hz=to, cutoff_hz=cut,
                          x=x.tolist(), y=y.tolist()))
    dec_cases = [
        ("odd_999_integer_1000_to_200", 999, 1000.0, 5, None),
        ("paper_like_cut_25_2000_to_200", 4000, 2000.0, 10, 25.0),
        ("d_not_dividing_1003_cut_13", 1003, 1000.0, 10, 13.0),
        ("even_1000_d4_default_cut", 1000, 1000.0, 4, None),
    ]
    for name, n, fs, d, cut in dec_cases:
        x = signal(rng, n, fs)
        to = fs / d
        c = to / 2 if cut is None else cut
        y = ideal_decimate(x, fs, d, c)
        cases.append(dict(name=name, kind="ideal_decimate", fs_in=fs, to_hz=to, cutoff_hz=cut,
                          x=x.tolist(), y=y.tolist()))
    doc = dict(
        generator="tools/reference/resample.py",
        numpy=np.__version__,
        scipy=scipy.__version__,
        tolerance_rel=1e-9,
        cases=cases,
    )
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        json.dump(doc, f)
    print(f"wrote {OUT}: {len(cases)} cases, {os.path.getsize(OUT)} bytes")


if __name__ == "__main__":
    main()
