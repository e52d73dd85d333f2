"""Reference scatter of the fleet's per-record estimates, by Monte Carlo with scipy.signal, for
vibmode_fleet::model::{welch_band_cells, noise_free_level_variance, h1_log_variance} (the
variance a record's own estimate gives its level ratios and transmissibility).

Writes tools/reference/data/estimate_variance.json. Run from the repository root:
python3 tools/reference/estimate_variance.py

Versions: numpy and scipy as in tools/reference/requirements.txt (recorded in the JSON).

The fleet's spectra: one 10.24 s record at 50 Hz (512 samples), scipy.signal.welch / csd with a
Hann window, nperseg 256, half overlap (3 segments), density scaling. Seeded numpy generator
(PCG64, seed 20261129); per case 4000 draws:

- "band_sum": white noise; the relative variance var(S) / mean(S)^2 of the PSD summed over the
  bins of a band (edges included);
- "noise_free_level": one fixed wheel signal (white, drawn once) plus fresh white sensor noise
  of standard deviation `noise_sd` per draw; the level sqrt(sum psd df over 8-20 Hz - N (20 - 8))
  with N = 2 noise_sd^2 / 50 the noise's one-sided density; the variance of its ln over the
  draws (draws where the noise is more than half the band power are skipped, as the fleet
  skips them), and the mean of the measured band power's ln-level with the noise in it;
- "h1": u white, y = 0.5 u + e with e white of standard deviation `e_sd` (coherence 0.25 /
  (0.25 + e_sd^2)); the variance over the draws of ln sqrt(sum |S_uy|^2 / S_uu / sum S_uu)
  over 2-20 Hz.

Rust tolerances (crates/vibmode-fleet/tests/integration/reference.rs): the formulas are
approximations (a band sum's bins and segments as independent cells with Hann's correlations;
first-order propagation of the noise); band sums within 10 %, noise-free levels and the H1
estimate within 15 %. The Monte Carlo's own standard error of a variance over 4000 draws is
about sqrt(2 / 4000) = 2.2 % (more for the heavier-tailed ln H1), well inside them.
"""
import json

import numpy as np
import scipy
import scipy.signal

FS = 50.0
N = 512
KW = dict(fs=FS, window="hann", nperseg=256)
DRAWS = 4000


def band(f, lo, hi):
    return (f >= lo) & (f <= hi)


def main():
    rng = np.random.default_rng(20261129)
    out = {
        "versions": {"numpy": np.__version__, "scipy": scipy.__version__},
        "fs_hz": FS,
        "samples": N,
        "nperseg": 256,
        "segments": 3,
        "draws": DRAWS,
        "band_sum": [],
        "noise_free_level": [],
        "h1": [],
    }
    for lo, hi in [(8.0, 20.0), (2.0, 5.0), (12.0, 20.0)]:
        sums = []
        for _ in range(DRAWS):
            f, p = scipy.signal.welch(rng.standard_normal(N), **KW)
            sums.append(p[band(f, lo, hi)].sum())
        sums = np.array(sums)
        out["band_sum"].append(
            {
                "band_hz": [lo, hi],
                "bins": int(band(f, lo, hi).sum()),
                "relative_variance": float(sums.var(ddof=1) / sums.mean() ** 2),
            }
        )
    wheel = rng.standard_normal(N)
    f, pw = scipy.signal.welch(wheel, **KW)
    df = f[1] - f[0]
    m = band(f, 8.0, 20.0)
    for noise_sd in [0.33, 0.7]:
        density = 2 * noise_sd**2 / FS
        pn = density * 12.0
        logs, levels = [], []
        for _ in range(DRAWS):
            _, p = scipy.signal.welch(wheel + noise_sd * rng.standard_normal(N), **KW)
            power = p[m].sum() * df
            levels.append(0.5 * np.log(power))
            if pn <= 0.5 * power:
                logs.append(0.5 * np.log(power - pn))
        out["noise_free_level"].append(
            {
                "noise_sd": noise_sd,
                "noise_power": pn,
                "wheel_power": float(pw[m].sum() * df),
                "mean_measured_power": float(np.mean(np.exp(2 * np.array(levels)))),
                "log_level_variance": float(np.var(logs, ddof=1)),
                "kept": len(logs),
            }
        )
    for e_sd in [1.0, 0.25]:
        logs = []
        for _ in range(DRAWS):
            u = rng.standard_normal(N)
            y = 0.5 * u + e_sd * rng.standard_normal(N)
            f, puu = scipy.signal.welch(u, **KW)
            _, puy = scipy.signal.csd(u, y, **KW)
            b = band(f, 2.0, 20.0)
            logs.append(0.5 * np.log((np.abs(puy[b]) ** 2 / puu[b]).sum() / puu[b].sum()))
        out["h1"].append(
            {
                "coherence": 0.25 / (0.25 + e_sd**2),
                "bins": int(band(f, 2.0, 20.0).sum()),
                "log_variance": float(np.var(logs, ddof=1)),
            }
        )
    with open("tools/reference/data/estimate_variance.json", "w") as fh:
        json.dump(out, fh, indent=1)
        fh.write("\n")


if __name__ == "__main__":
    main()
