"""Reference values for vibmode-vehicle, from an independent numpy/scipy implementation.

Builds the 7-DOF (8 with bending) full-car model directly from the TOML files with numpy
(element-by-element, via a deflection matrix T: K = T^T diag(k) T), then computes
  * modes: eigenvalues of the 2n-state matrix (scipy.linalg.eig) -> frequency_hz, damping_ratio;
  * analytic one-sided sensor acceleration PSD for an ISO 8608 road (class C, Gd(n0) = 256e-6 m^3,
    n0 = 0.1 cycles/m, tyre envelope 1 / (1 + (n/3)^2), exponential coherence gamma = exp(-n/0.2),
    rear wheels delayed by wheelbase / v) at 40 km/h;
  * the time response of the sensor accelerations to a raised-cosine bump under the left
    wheels (scipy.signal.lsim, state x = [q, q'], input u = [r, r'] with analytic r').

Versions: Python 3.11, numpy 2.1.3, scipy 1.14.1 (tools/reference/requirements.txt).
Tolerances used by crates/vibmode-vehicle/tests/integration/reference.rs: modes and PSD relative 1e-6;
bump response max |error| <= 2e-3 * max |response| per channel (first-order-hold vs lsim's
linear interpolation and central-difference road velocity differ at O(dt^2)).

Run from the repository root: python3 tools/reference/vehicle.py
"""
import json
import os
import tomllib

import numpy as np
import scipy
import scipy.linalg
import scipy.signal

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "tools", "reference", "data", "vehicle.json")

BENDING_BUS = open(os.path.join(ROOT, "examples", "city_bus.toml")).read().replace(
    "# [bending]\n# frequency_hz = 11.0\n# damping_ratio = 0.02\n# modal_mass_kg = 3000.0\n# corner_shape = [-0.6, -0.6, 0.4, 0.4]",
    "[bending]\nfrequency_hz = 11.0\ndamping_ratio = 0.02\nmodal_mass_kg = 3000.0\ncorner_shape = [-0.6, -0.6, 0.4, 0.4]",
).replace('name = "RR_sprung"\nkind = "sprung"\ncorner = "RR"', 'name = "RR_sprung"\nkind = "sprung"\ncorner = "RR"\nbending_shape = 0.5')
assert "[bending]\nfrequency_hz" in BENDING_BUS and "bending_shape = 0.5" in BENDING_BUS

DEFAULT_SENSORS = [
    ("FL_unsprung", "unsprung", "FL"), ("FR_unsprung", "unsprung", "FR"),
    ("RL_unsprung", "unsprung", "RL"), ("RR_unsprung", "unsprung", "RR"),
    ("FR_sprung", "sprung", "FR"), ("RL_sprung", "sprung", "RL"), ("RR_sprung", "sprung", "RR"),
]
CORNERS = ["FL", "FR", "RL", "RR"]


def build(p):
    g = p["geometry"]
    a = g["cg_to_front_axle_m"]
    b = g["wheelbase_m"] - a
    pos = {"FL": (a, g["track_front_m"] / 2), "FR": (a, -g["track_front_m"] / 2),
           "RL": (-b, g["track_rear_m"] / 2), "RR": (-b, -g["track_rear_m"] / 2)}
    bend = p.get("bending")
    n = 8 if bend else 7
    masses = [p["body"]["mass_kg"], p["body"]["pitch_inertia_kgm2"], p["body"]["roll_inertia_kgm2"]]
    ax = {c: p["front"] if c[0] == "F" else p["rear"] for c in CORNERS}
    masses += [ax[c]["unsprung_mass_kg"] for c in CORNERS]
    if bend:
        masses.append(bend["modal_mass_kg"])
    M = np.diag(masses)
    # Elements: 4 suspension, 4 tyres (deflection relative to road), 2 anti-roll bars, bending.
    rows, kk, cc = [], [], []
    for i, c in enumerate(CORNERS):
        t = np.zeros(n)
        x, y = pos[c]
        t[0], t[1], t[2], t[3 + i] = 1.0, x, y, -1.0
        if bend:
            t[7] = bend["corner_shape"][i]
        rows.append(t); kk.append(ax[c]["spring_stiffness_n_per_m"]); cc.append(ax[c]["damper_n_s_per_m"])
    for i, c in enumerate(CORNERS):
        t = np.zeros(n); t[3 + i] = 1.0
        rows.append(t); kk.append(ax[c]["tyre_stiffness_n_per_m"]); cc.append(ax[c].get("tyre_damping_n_s_per_m", 0.0))
    for axle, (l, r), tr in (("front", (0, 1), g["track_front_m"]), ("rear", (2, 3), g["track_rear_m"])):
        t = np.zeros(n); t[2] = 1.0; t[3 + l] = -1.0 / tr; t[3 + r] = 1.0 / tr
        rows.append(t); kk.append(p[axle].get("anti_roll_stiffness_nm_per_rad", 0.0)); cc.append(0.0)
    if bend:
        w = 2 * np.pi * bend["frequency_hz"]
        t = np.zeros(n); t[7] = 1.0
        rows.append(t); kk.append(bend["modal_mass_kg"] * w * w); cc.append(2 * bend["damping_ratio"] * bend["modal_mass_kg"] * w)
    T = np.array(rows)
    K = T.T @ np.diag(kk) @ T
    C = T.T @ np.diag(cc) @ T
    Kt = np.zeros((n, 4)); Ct = np.zeros((n, 4))
    for i, c in enumerate(CORNERS):
        Kt[3 + i, i] = ax[c]["tyre_stiffness_n_per_m"]
        Ct[3 + i, i] = ax[c].get("tyre_damping_n_s_per_m", 0.0)
    sens = p.get("sensors") or [dict(name=s, kind=k, corner=c) for s, k, c in DEFAULT_SENSORS]
    O = np.zeros((len(sens), n))
    for j, s in enumerate(sens):
        if s["kind"] == "unsprung":
            O[j, 3 + CORNERS.index(s["corner"])] = 1.0
        else:
            x, y = pos[s["corner"]] if "corner" in s else (s["x_m"], s["y_m"])
            O[j, 0], O[j, 1], O[j, 2] = 1.0, x, y
            if bend:
                O[j, 7] = s.get("bending_shape", 0.0)
    return dict(M=M, C=C, K=K, Kt=Kt, Ct=Ct, O=O, n=n, wb=g["wheelbase_m"], names=[s["name"] for s in sens])


def modes(m):
    n = m["n"]
    Mi = np.linalg.inv(m["M"])
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ m["K"], -Mi @ m["C"]]])
    ev = scipy.linalg.eigvals(A)
    ev = ev[ev.imag > 1e-9 * np.abs(ev)]
    w = np.abs(ev)
    order = np.argsort(w)
    return (w[order] / (2 * np.pi)).tolist(), (-ev.real[order] / w[order]).tolist()


def psd(m, speed_kmh, freqs, gd0=256e-6, ne=3.0, nc=0.2):
    v = speed_kmh / 3.6
    tau = m["wb"] / v
    out = np.zeros((m["O"].shape[0], len(freqs)))
    for k, f in enumerate(freqs):
        w = 2 * np.pi * f
        D = m["K"] - w * w * m["M"] + 1j * w * m["C"]
        H = -w * w * m["O"] @ np.linalg.solve(D, m["Kt"] + 1j * w * m["Ct"])  # sensors x 4
        n = f / v
        G = gd0 * (n / 0.1) ** -2 / (1 + (n / ne) ** 2) / v
        gam = np.exp(-n / nc)
        track = np.array([0, 1, 0, 1])
        delay = np.array([0, 0, tau, tau])
        coh = np.where(track[:, None] == track[None, :], 1.0, gam)
        S = G * coh * np.exp(-1j * w * (delay[:, None] - delay[None, :]))
        out[:, k] = np.real(np.einsum("si,ij,sj->s", H, S, H.conj()))
    return out


def bump_response(m, fs, dur, speed_kmh=36.0, h=0.05, T=0.1, t0=0.2):
    v = speed_kmh / 3.6
    t = np.arange(int(round(dur * fs))) / fs
    r = np.zeros((len(t), 4)); rd = np.zeros((len(t), 4))
    for i, delay in ((0, 0.0), (2, m["wb"] / v)):  # left wheels only
        s = (t - t0 - delay) / T
        inside = (s >= 0) & (s <= 1)
        r[inside, i] = h / 2 * (1 - np.cos(2 * np.pi * s[inside]))
        rd[inside, i] = h / 2 * (2 * np.pi / T) * np.sin(2 * np.pi * s[inside])
    n = m["n"]
    Mi = np.linalg.inv(m["M"])
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ m["K"], -Mi @ m["C"]]])
    B = np.block([[np.zeros((n, 8))], [Mi @ m["Kt"], Mi @ m["Ct"]]])
    Cy = m["O"] @ np.hstack([-Mi @ m["K"], -Mi @ m["C"]])
    Dy = m["O"] @ np.hstack([Mi @ m["Kt"], Mi @ m["Ct"]])
    sys = scipy.signal.StateSpace(A, B, Cy, Dy)
    _, y, _ = scipy.signal.lsim(sys, np.hstack([r, rd]), t, interp=True)
    return r, y


def main():
    out = {"versions": {"numpy": np.__version__, "scipy": scipy.__version__}, "cases": []}
    freqs = np.concatenate([np.linspace(0.2, 3, 15), np.linspace(3.5, 30, 28)]).tolist()
    for name, text in (("city_bus", open(os.path.join(ROOT, "examples", "city_bus.toml")).read()),
                       ("passenger_car", open(os.path.join(ROOT, "examples", "passenger_car.toml")).read()),
                       ("city_bus_bending", BENDING_BUS)):
        m = build(tomllib.loads(text))
        f, z = modes(m)
        case = {"name": name, "toml": text, "sensor_names": m["names"], "frequency_hz": f, "damping_ratio": z,
                "psd_speed_kmh": 40.0, "psd_freq_hz": freqs, "psd_m2_s4_per_hz": psd(m, 40.0, freqs).tolist()}
        if name == "passenger_car":
            fs = 1000.0
            r, y = bump_response(m, fs, 2.0)
            case["bump"] = {"fs_hz": fs, "road_m": r.tolist(), "accel_m_s2": y.T.tolist()}
        out["cases"].append(case)
    with open(OUT, "w") as fh:
        json.dump(out, fh)
    print(OUT, os.path.getsize(OUT), "bytes")


if __name__ == "__main__":
    main()
