"""Reference values for the model update on noisy records: bias-compensated least squares and the
jackknife (vibmode_vehicle::update), from numpy/scipy.

Writes tools/reference/data/body_fit_noise_input.json (the records) and
tools/reference/data/body_fit_noise.json (the fit). Run from the repository root:
python3 tools/reference/body_fit_noise.py

Versions: Python 3.11+, numpy and scipy as in tools/reference/requirements.txt (recorded in the
JSON's "versions" key).

Data: the changed rigid bus of tools/reference/body_fit.py (its numpy/scipy simulation) at
400 Hz, the first 12 s of its first 3 records, plus white noise from numpy.random.default_rng(SEED + 1):
standard deviation 0.5 m/s^2 per sample on the unsprung channels, 0.05 on the sprung ones; rounded
to 7 significant digits.

The fit (the algorithm of crates/vibmode-vehicle/src/update.rs, written again here with numpy)
* Equations as tools/reference/body_fit.py (numpy FFT derivatives, band, instants, rows).
* Noise density per channel and record: Hann window w_k = 1/2 - cos(2 pi k / n)/2 on the record
  (mean removed), numpy.fft.rfft; range [max(15 f_hi, fs/20), 0.4 fs], split in two at the
  bin nearest its geometric mean; the median (sorted ordinate len/2) of |X|^2 in each; if the larger is at most
  1.5 times the smaller, density = 2 mean(medians) / ln 2 / (sum w^2 fs), else 0.
* Noise share of each record's Z^T Z (Z = [X | y], all rows): the kernels h_k = irfft(G (i w)^k)
  on the padded length m = 2n; for each instant t, c_kl(t) = sum_{j<n} h_k[(t-j) mod m]
  h_l[(t-j) mod m] (directly, numpy indexing); the rows' linear map L_k of each channel's k-th
  signal (rows evaluated at unit inputs); share = sum_channels s^2 sum_kl sum_t c_kl(t) L_k^T L_l
  with s^2 = density fs / 2.
* The share taken out, lambda: with G = sum_r Z_r^T Z_r and N = sum_r N_r, the largest generalized
  eigenvalue mu of N v = mu G v (scipy.linalg.eigh(N, G)); lambda = 1 / mu when mu > 1, else 1
  (generalized total least squares, capped at the whole expected share).
* theta = solve(G - lambda N) (the unbounded solution; this case is feasible); the
  jackknife over the 3 records, lambda found again for each: sd = sqrt((R-1)/R sum (theta_(-r) -
  mean)^2) for every parameter and for the three body modes' frequency and damping
  (scipy.linalg.eigvals).

Rust tolerance (crates/vibmode-vehicle/tests/integration/reference.rs): densities, parameters, modes and
their standard deviations relative 1e-6 (same algorithm; different FFT, median selection and
linear solver).
"""

import json
import os
import platform
import sys
import tomllib

import numpy as np
import scipy
import scipy.linalg

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import body_fit as bf  # noqa: E402

bf.FS = 400.0
SECONDS = 12.0
RECORDS = 3
SIGMA = [0.5, 0.5, 0.5, 0.5, 0.05, 0.05, 0.05]


def density(x, band):
    fs = bf.FS
    n = len(x)
    w = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(n) / n)
    spec = np.fft.rfft(w * (np.asarray(x) - np.mean(x)))
    lo, hi = max(15 * band[1], 0.05 * fs), 0.4 * fs
    assert hi >= 4 * lo
    df = fs / n
    a, b = int(np.ceil(lo / df)), min(int(np.floor(hi / df)), len(spec) - 1)
    c = int(round(np.sqrt(lo * hi) / df))
    p = np.abs(spec) ** 2
    med = [np.sort(p[u:v])[(v - u) // 2] for u, v in ((a, c), (c, b + 1))]
    if max(med) > 1.5 * min(med):
        return 0.0
    return 2 * np.mean(med) / np.log(2) / (np.sum(w * w) * fs)


def rows_of(p, wheel, body, bars):
    """The 3 rows [x | y] from wheel[c][k], body[b][k] values (as body_fit.fit)."""
    pos = bf.positions(p)
    ms = p["body"]["mass_kg"]
    rp = np.sqrt(p["body"]["pitch_inertia_kgm2"] / ms)
    rr = np.sqrt(p["body"]["roll_inertia_kgm2"] / ms)
    tracks = [p["geometry"]["track_front_m"], p["geometry"]["track_rear_m"]]
    nu = 10 + sum(bars)
    z = np.zeros((3, nu + 1))
    for ci, c in enumerate(bf.CORNERS):
        x, y = pos[c]
        g = [body[0][k] + x * body[1][k] + y * body[2][k] - wheel[ci][k] for k in range(2)]
        for row, lever in ((0, 1.0), (1, x), (2, y)):
            z[row, 2 + ci] = lever * g[0]
            z[row, 6 + ci] = lever * g[1]
    z[1, 0] = body[1][2]
    z[2, 1] = body[2][2]
    col = 10
    for a, (l, r) in enumerate(((0, 1), (2, 3))):
        if bars[a]:
            z[2, col] = body[2][0] - (wheel[l][0] - wheel[r][0]) / tracks[a]
            col += 1
    z[0, nu] = -body[0][2]
    z[1] /= rp
    z[2] /= rr
    return z


def fit(p, records):
    pos = bf.positions(p)
    nominal = bf.params_of(p)
    fn, _ = bf.modes(*bf.matrices(p, nominal["springs"], nominal["dampers"], nominal["bars"], nominal["inertia"])[:3])
    band = (0.45 * min(fn), 1.6 * max(fn))
    bars = [b > 0 for b in nominal["bars"]]
    P = np.array([[1.0, *pos[c]] for c in bf.SPRUNG])
    Pinv = np.linalg.inv(P.T @ P) @ P.T
    grams, dens = [], []
    for rec in records:
        n = len(rec[0])
        m = 2 * n
        d = [bf.derivatives(ch, band) for ch in rec]
        edge = int(round(1.0 * bf.FS))
        step = max(1, int(np.floor(bf.FS / (25.0 * band[1]))))
        ts = np.arange(edge, n - edge, step)
        G = 0.0
        for t in ts:
            wheel = [[d[i][k][t] for k in range(3)] for i in range(4)]
            body = [[sum(Pinv[b, j] * d[4 + j][k][t] for j in range(3)) for k in range(3)] for b in range(3)]
            z = rows_of(p, wheel, body, bars)
            G = G + z.T @ z
        # Kernels and their covariance sums over the instants.
        f = np.arange(m // 2 + 1) * bf.FS / m
        g = bf.gain(f, *band)
        h = [np.fft.irfft(g * (2j * np.pi * f) ** k, n=m) for k in range(3)]
        lags = (ts[:, None] - np.arange(n)[None, :]) % m
        c = np.array([[np.sum(h[k][lags] * h[l][lags]) for l in range(3)] for k in range(3)])
        N = 0.0
        ds = []
        for ch in range(7):
            s = density(rec[ch], band)
            ds.append(s)
            var = s * bf.FS / 2
            L = []
            for k in range(3):
                wheel = [[0.0] * 3 for _ in range(4)]
                body = [[0.0] * 3 for _ in range(3)]
                if ch < 4:
                    wheel[ch][k] = 1.0
                else:
                    for b in range(3):
                        body[b][k] = Pinv[b, ch - 4]
                L.append(rows_of(p, wheel, body, bars))
            for k in range(3):
                for l in range(3):
                    N = N + var * c[k, l] * (L[k].T @ L[l])
        grams.append((G, N))
        dens.append(ds)
    ms = p["body"]["mass_kg"]

    def share(G, N):
        mu = scipy.linalg.eigh(N, G, eigvals_only=True).max()
        return 1.0 / mu if mu > 1.0 else 1.0

    def solve(Gs):
        G, N = sum(g for g, _ in Gs), sum(q for _, q in Gs)
        lam = share(G, N)
        Gt = G - lam * N
        nu = Gt.shape[0] - 1
        th = np.linalg.solve(Gt[:nu, :nu], Gt[:nu, nu])
        assert np.all(th > 0), th
        th = th * ms
        q = dict(inertia=th[0:2].tolist(), springs=th[2:6].tolist(), dampers=th[6:10].tolist(), bars=[0.0, 0.0])
        col = 10
        for a in range(2):
            if bars[a]:
                q["bars"][a] = float(th[col])
                col += 1
        fq, zq = bf.modes(*bf.matrices(p, q["springs"], q["dampers"], q["bars"], q["inertia"])[:3])
        return th, fq, zq, q, lam

    th, fq, zq, q, lam = solve(grams)
    loo = [solve([g for i, g in enumerate(grams) if i != r]) for r in range(len(grams))]
    R = len(grams)

    def jack(v):
        v = np.asarray(v)
        return np.sqrt((R - 1) / R * np.sum((v - v.mean(axis=0)) ** 2, axis=0)).tolist()

    return dict(band_hz=list(band), params=q, theta_si=th.tolist(), theta_sd=jack([l[0] for l in loo]),
                body_frequency_hz=fq, body_damping_ratio=zq,
                body_frequency_sd=jack([l[1] for l in loo]), body_damping_sd=jack([l[2] for l in loo]),
                noise_share=lam, noise_share_without_each=[l[4] for l in loo], density=dens)


def main():
    with open(os.path.join(bf.ROOT, "examples", "city_bus.toml"), "rb") as fh:
        p = tomllib.load(fh)
    truth = bf.params_of(p, spring_f=(1, 1, 0.8, 0.8), damper_f=(0.7, 0.7, 1, 1), inertia_f=1.15)
    clean = [[ch[: int(SECONDS * bf.FS)] for ch in rec] for rec in bf.simulate(p, truth)[:RECORDS]]
    rng = np.random.default_rng(bf.SEED + 1)
    records = []
    for rec in clean:
        noisy = [np.asarray(ch) + s * rng.standard_normal(len(ch)) for ch, s in zip(rec, SIGMA)]
        records.append([[float(f"{v:.7g}") for v in ch] for ch in noisy])
    with open(os.path.join(bf.DATA, "body_fit_noise_input.json"), "w") as fh:
        json.dump(dict(fs_hz=bf.FS, channels=bf.NAMES, sigma=SIGMA, records=records), fh)
    out = dict(
        versions={"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__},
        seed=bf.SEED + 1,
        vehicle_file="examples/city_bus.toml",
        truth=truth,
        fit=fit(p, records),
    )
    with open(os.path.join(bf.DATA, "body_fit_noise.json"), "w") as fh:
        json.dump(out, fh, indent=1)
        fh.write("\n")
    print(json.dumps(dict(truth=out["truth"], fit={k: v for k, v in out["fit"].items() if k != "density"}), indent=1))


if __name__ == "__main__":
    main()
