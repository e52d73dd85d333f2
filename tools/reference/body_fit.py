"""Reference values for vibmode_vehicle::update (the body-equation fit), from numpy/scipy.

Writes tools/reference/data/body_fit_input.json (the records) and tools/reference/data/body_fit.json
(the fit). Run from the repository root: python3 tools/reference/body_fit.py

Versions: Python 3.11+, numpy and scipy as in tools/reference/requirements.txt (the committed JSON
was written with the versions recorded in its "versions" key).

Data
----
The rigid bus of examples/city_bus.toml changed as a measured vehicle might differ from its file:
rear springs x 0.8, front dampers x 0.7, pitch and roll inertia x 1.15. Its 7-DOF model is built
here with numpy (deflection matrix T, K = T^T diag(k) T) and driven at its four wheels by four
independent road profiles (height spectrum falling as f^-2, as ISO 8608 roads at a steady speed:
white noise of numpy.random.default_rng(SEED), SEED = 20261124, summed, through a 1st-order
Butterworth high-pass at 0.1 Hz, scaled to 10 mm rms; road velocity by np.gradient).
scipy.signal.lsim (state [q, q'], linear interpolation of the input) gives the seven sensor
accelerations (default sensors: four unsprung, sprung at FR, RL, RR) at 400 Hz, brought to 50 Hz
by scipy.signal.decimate (FIR, zero phase): 10 s of warm-up, then 4 records of 30 s, rounded to
9 significant digits (as stored). Without the anti-alias filter the unsprung accelerations'
content above 25 Hz folds into the band and the equations miss by 7 %.

The fit (the algorithm of crates/vibmode-vehicle/src/update.rs, written again here)
--------------------------------------------------------------------------------
* Band [0.45 f_min, 1.6 f_max] over the *file's* three body modes (heave, pitch, roll: the three
  lowest of the rigid bus); cosine tapers over +-30 % of each edge frequency.
* Per channel: mean removed, zero-padded to twice its length, numpy.fft.rfft; multiplied by
  (i 2 pi f)^k times the band gain for k = 0, 1, 2; irfft; the first `len` samples.
* Body coordinates [z, theta, phi] = (P^T P)^-1 P^T s, P rows [1, x, y] of the sprung sensors.
* Equations at t = edge, edge + step, ... < len - edge, edge = round(1.0 s fs), step =
  max(1, floor(fs / (25 f_hi))): with g_c = z + x_c theta + y_c phi - w_c (k-th derivative),
  heave:  sum_c k_c g_c(a) + c_c g_c(a')                          = -z(a'')   (sprung mass 1)
  pitch: (I_p theta(a'') + sum_c x_c [k_c g_c(a) + c_c g_c(a')]) / r_p = 0
  roll:  (I_r phi(a'') + sum_c y_c [...] + sum_axles K_arb (phi - (w_L - w_R)/t))(a) / r_r = 0
  with r_p, r_r the file's radii of gyration; numpy.linalg.lstsq over every equation.
* The updated model (file masses and tyres, fitted springs, dampers, bars, inertias times the
  sprung mass): scipy.linalg.eigvals of its state matrix; the three lowest modes.

Rust tolerance (crates/vibmode-vehicle/tests/integration/reference.rs): parameters and mode frequencies and
damping ratios relative 1e-6 (same algorithm, different FFT and solver); and both within 1 % of
the changed bus's true parameters and modes (the physics).
"""

import importlib.metadata
import json
import os
import platform
import tomllib

import numpy as np
import scipy.linalg
import scipy.signal

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(ROOT, "tools", "reference", "data")
SEED = 20261124
FS = 50.0
CORNERS = ["FL", "FR", "RL", "RR"]
NAMES = ["FL_unsprung", "FR_unsprung", "RL_unsprung", "RR_unsprung", "FR_sprung", "RL_sprung", "RR_sprung"]
SPRUNG = ["FR", "RL", "RR"]


def positions(p):
    g = p["geometry"]
    a = g["cg_to_front_axle_m"]
    b = g["wheelbase_m"] - a
    return {"FL": (a, g["track_front_m"] / 2), "FR": (a, -g["track_front_m"] / 2),
            "RL": (-b, g["track_rear_m"] / 2), "RR": (-b, -g["track_rear_m"] / 2)}


def matrices(p, springs, dampers, bars, inertia):
    """M, C, K, Kt, Ct of the rigid 7-DOF model with per-corner springs and dampers."""
    pos = positions(p)
    ax = {c: p["front"] if c[0] == "F" else p["rear"] for c in CORNERS}
    M = np.diag([p["body"]["mass_kg"], inertia[0], inertia[1]] + [ax[c]["unsprung_mass_kg"] for c in CORNERS])
    rows, kk, cc = [], [], []
    for i, c in enumerate(CORNERS):
        t = np.zeros(7)
        x, y = pos[c]
        t[0], t[1], t[2], t[3 + i] = 1.0, x, y, -1.0
        rows.append(t); kk.append(springs[i]); cc.append(dampers[i])
    for i, c in enumerate(CORNERS):
        t = np.zeros(7); t[3 + i] = 1.0
        rows.append(t); kk.append(ax[c]["tyre_stiffness_n_per_m"]); cc.append(ax[c].get("tyre_damping_n_s_per_m", 0.0))
    g = p["geometry"]
    for j, ((l, r), tr) in enumerate((((0, 1), g["track_front_m"]), ((2, 3), g["track_rear_m"]))):
        t = np.zeros(7); t[2] = 1.0; t[3 + l] = -1.0 / tr; t[3 + r] = 1.0 / tr
        rows.append(t); kk.append(bars[j]); cc.append(0.0)
    T = np.array(rows)
    K = T.T @ np.diag(kk) @ T
    C = T.T @ np.diag(cc) @ T
    Kt = np.zeros((7, 4)); Ct = np.zeros((7, 4))
    for i, c in enumerate(CORNERS):
        Kt[3 + i, i] = ax[c]["tyre_stiffness_n_per_m"]
        Ct[3 + i, i] = ax[c].get("tyre_damping_n_s_per_m", 0.0)
    return M, C, K, Kt, Ct


def params_of(p, spring_f=(1, 1, 1, 1), damper_f=(1, 1, 1, 1), inertia_f=1.0):
    ax = [p["front"] if c[0] == "F" else p["rear"] for c in CORNERS]
    return dict(
        springs=[a["spring_stiffness_n_per_m"] * f for a, f in zip(ax, spring_f)],
        dampers=[a["damper_n_s_per_m"] * f for a, f in zip(ax, damper_f)],
        bars=[p["front"].get("anti_roll_stiffness_nm_per_rad", 0.0), p["rear"].get("anti_roll_stiffness_nm_per_rad", 0.0)],
        inertia=[p["body"]["pitch_inertia_kgm2"] * inertia_f, p["body"]["roll_inertia_kgm2"] * inertia_f],
    )


def modes(M, C, K, count=3):
    n = M.shape[0]
    Mi = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ K, -Mi @ C]])
    ev = scipy.linalg.eigvals(A)
    ev = ev[ev.imag > 1e-9 * np.abs(ev)]
    w = np.abs(ev)
    order = np.argsort(w)[:count]
    return (w[order] / (2 * np.pi)).tolist(), (-ev.real[order] / w[order]).tolist()


def simulate(p, q):
    M, C, K, Kt, Ct = matrices(p, q["springs"], q["dampers"], q["bars"], q["inertia"])
    Mi = np.linalg.inv(M)
    A = np.block([[np.zeros((7, 7)), np.eye(7)], [-Mi @ K, -Mi @ C]])
    B = np.block([[np.zeros((7, 8))], [Mi @ Kt, Mi @ Ct]])
    pos = positions(p)
    O = np.zeros((7, 7))
    for j, name in enumerate(NAMES):
        corner, kind = name.split("_")
        if kind == "unsprung":
            O[j, 3 + CORNERS.index(corner)] = 1.0
        else:
            x, y = pos[corner]
            O[j, 0], O[j, 1], O[j, 2] = 1.0, x, y
    # Sensor accelerations: O q'' = O (A x + B u)[7:].
    Cy = O @ A[7:, :]
    Dy = O @ B[7:, :]
    warm, rec, nrec = 10.0, 30.0, 4
    # Simulated 8 times faster, then decimated with a zero-phase FIR anti-alias filter (the same
    # linear filter on every channel keeps the equations of motion).
    up = 8
    fs_sim = FS * up
    n = int(round((warm + rec * nrec) * fs_sim))
    rng = np.random.default_rng(SEED)
    # A road's height spectrum falls as f^-2 (ISO 8608 at a steady speed): integrated white
    # noise, the drift below 0.1 Hz removed.
    bb, aa = scipy.signal.butter(1, 0.1 / (fs_sim / 2), btype="high")
    r = scipy.signal.lfilter(bb, aa, np.cumsum(rng.standard_normal((n, 4)), axis=0), axis=0)
    r *= 0.01 / r.std(axis=0)
    rd = np.gradient(r, 1.0 / fs_sim, axis=0)
    t = np.arange(n) / fs_sim
    _, y, _ = scipy.signal.lsim((A, B, Cy, Dy), np.hstack([r, rd]), t, interp=True)
    y = scipy.signal.decimate(y, up, ftype="fir", axis=0, zero_phase=True)
    y = np.array([[float(f"{v:.9g}") for v in row] for row in y])
    w0 = int(round(warm * FS))
    m = int(round(rec * FS))
    return [y[w0 + i * m: w0 + (i + 1) * m].T.tolist() for i in range(nrec)]


def gain(f, lo, hi, w=0.3):
    g = np.ones_like(f)
    g[(f <= lo * (1 - w)) | (f >= hi * (1 + w))] = 0.0
    m = (f > lo * (1 - w)) & (f < lo * (1 + w))
    u = (f[m] - lo * (1 - w)) / (2 * w * lo)
    g[m] = 0.5 - 0.5 * np.cos(np.pi * u)
    m = (f > hi * (1 - w)) & (f < hi * (1 + w))
    u = (hi * (1 + w) - f[m]) / (2 * w * hi)
    g[m] = 0.5 - 0.5 * np.cos(np.pi * u)
    return g


def derivatives(x, band):
    n = len(x)
    m = 2 * n
    spec = np.fft.rfft(np.asarray(x) - np.mean(x), n=m)
    f = np.arange(len(spec)) * FS / m
    g = gain(f, *band)
    iw = 2j * np.pi * f
    return [np.fft.irfft(spec * iw ** k * g, n=m)[:n] for k in range(3)]


def fit(p, records):
    pos = positions(p)
    nominal = params_of(p)
    fn, _ = modes(*matrices(p, nominal["springs"], nominal["dampers"], nominal["bars"], nominal["inertia"])[:3])
    band = (0.45 * min(fn), 1.6 * max(fn))
    bars = [b > 0 for b in nominal["bars"]]
    ms = p["body"]["mass_kg"]
    rp = np.sqrt(p["body"]["pitch_inertia_kgm2"] / ms)
    rr = np.sqrt(p["body"]["roll_inertia_kgm2"] / ms)
    P = np.array([[1.0, *pos[c]] for c in SPRUNG])
    Pinv = np.linalg.inv(P.T @ P) @ P.T
    tracks = [p["geometry"]["track_front_m"], p["geometry"]["track_rear_m"]]
    X, Y = [], []
    for rec in records:
        d = [derivatives(ch, band) for ch in rec]  # d[channel][k]
        wheel = [d[i] for i in range(4)]
        body = [[sum(Pinv[b, j] * d[4 + j][k] for j in range(3)) for k in range(3)] for b in range(3)]
        n = len(rec[0])
        edge = int(round(1.0 * FS))
        step = max(1, int(np.floor(FS / (25.0 * band[1]))))
        for t in range(edge, n - edge, step):
            rows = np.zeros((3, 10 + sum(bars)))
            for ci, c in enumerate(CORNERS):
                x, y = pos[c]
                g0 = body[0][0][t] + x * body[1][0][t] + y * body[2][0][t] - wheel[ci][0][t]
                g1 = body[0][1][t] + x * body[1][1][t] + y * body[2][1][t] - wheel[ci][1][t]
                for row, lever in ((0, 1.0), (1, x), (2, y)):
                    rows[row, 2 + ci] = lever * g0
                    rows[row, 6 + ci] = lever * g1
            rows[1, 0] = body[1][2][t]
            rows[2, 1] = body[2][2][t]
            col = 10
            for a, (l, r) in enumerate(((0, 1), (2, 3))):
                if bars[a]:
                    rows[2, col] = body[2][0][t] - (wheel[l][0][t] - wheel[r][0][t]) / tracks[a]
                    col += 1
            rows[1] /= rp
            rows[2] /= rr
            X.extend(rows)
            Y.extend([-body[0][2][t], 0.0, 0.0])
    th, *_ = np.linalg.lstsq(np.array(X), np.array(Y), rcond=None)
    th = th * ms
    q = dict(inertia=th[0:2].tolist(), springs=th[2:6].tolist(), dampers=th[6:10].tolist(), bars=[0.0, 0.0])
    col = 10
    for a in range(2):
        if bars[a]:
            q["bars"][a] = float(th[col])
            col += 1
    f, z = modes(*matrices(p, q["springs"], q["dampers"], q["bars"], q["inertia"])[:3])
    return dict(band_hz=list(band), equations=len(Y), params=q, body_frequency_hz=f, body_damping_ratio=z)


def main():
    with open(os.path.join(ROOT, "examples", "city_bus.toml"), "rb") as fh:
        p = tomllib.load(fh)
    truth = params_of(p, spring_f=(1, 1, 0.8, 0.8), damper_f=(0.7, 0.7, 1, 1), inertia_f=1.15)
    records = simulate(p, truth)
    tf, tz = modes(*matrices(p, truth["springs"], truth["dampers"], truth["bars"], truth["inertia"])[:3])
    with open(os.path.join(DATA, "body_fit_input.json"), "w") as fh:
        json.dump(dict(fs_hz=FS, channels=NAMES, records=records), fh)
    out = dict(
        versions={"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__},
        seed=SEED,
        vehicle_file="examples/city_bus.toml",
        truth=dict(params=truth, body_frequency_hz=tf, body_damping_ratio=tz),
        fit=fit(p, records),
    )
    with open(os.path.join(DATA, "body_fit.json"), "w") as fh:
        json.dump(out, fh, indent=1)
        fh.write("\n")
    print(json.dumps(dict(truth=out["truth"], fit=out["fit"]), indent=1))


if __name__ == "__main__":
    main()
