"""Writes a long 7-channel raw f32 recording (+ JSON sidecar) for the streaming benchmarks:
filtered noise with suspension-like resonances (1.2, 1.6, 9.5, 11 Hz), an engine line at 27 Hz,
tones at 1-6 kHz and sensor noise, with stops (idling: engine line and noise only) of 30 s every
5 min. Written in chunks of 60 s, so memory stays small.

    python3 bench/make_long.py OUT.f32 --minutes 60 [--fs 20000] [--seed 1]
"""
import argparse
import json

import numpy as np
from scipy import signal


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--minutes", type=float, default=60.0)
    ap.add_argument("--fs", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    fs = a.fs
    names = ["FL", "FR", "RL", "RR", "S_FR", "S_RL", "S_RR"]
    rng = np.random.default_rng(a.seed)
    sos = []
    for f0, z in [(1.2, 0.2), (1.6, 0.2), (9.5, 0.1), (11.0, 0.1)]:
        w0 = 2 * np.pi * f0 / fs
        r = np.exp(-z * w0)
        sos.append([1.0, 0.0, 0.0, 1.0, -2 * r * np.cos(w0 * np.sqrt(1 - z * z)), r * r])
    sos = np.array(sos)
    zi = np.zeros((len(names), sos.shape[0], 2))
    chunk = 60 * fs
    total = int(a.minutes * 60 * fs)
    t0 = 0
    with open(a.out, "wb") as f:
        while t0 < total:
            n = min(chunk, total - t0)
            t = (t0 + np.arange(n)) / fs
            moving = ((t % 300.0) >= 30.0).astype(np.float64)
            out = np.empty((n, len(names)), dtype=np.float32)
            for c in range(len(names)):
                w = rng.standard_normal(n) * 2e-3
                y, zi[c] = signal.sosfilt(sos, w, zi=zi[c])
                y = y / 0.05 * moving
                y += 0.05 * np.sin(2 * np.pi * 27.0 * t + c)
                for k, ft in enumerate([1000.0, 2500.0, 6000.0]):
                    y += 0.2 * np.sin(2 * np.pi * ft * t + k + c)
                y += 0.01 * rng.standard_normal(n)
                out[:, c] = y
            f.write(out.tobytes())
            t0 += n
    side = {"fs_hz": fs, "dtype": "f32", "channels": names, "units": ["m/s^2"] * len(names)}
    with open(a.out + ".json", "w") as f:
        json.dump(side, f)


if __name__ == "__main__":
    main()
