"""Reference values for crates/vibmode-ssi (covariance-driven SSI) from pyOMA2.

Writes tools/reference/data/ssi_input.json (the data) and tools/reference/data/ssi.json (pyOMA2's
poles). Run from the repository root:

    python3 -m pip install -r tools/reference/requirements.txt
    python3 tools/reference/ssi.py

Pinned versions (tools/reference/requirements.txt): Python 3.11.7, pyOMA2 (pip package
`pyoma-2`) 1.4.3, numpy 2.1.3, scipy 1.14.1.

Data
----
A 5-channel, 3000-sample record at 50 Hz of three modes (1.2 Hz / 0.05, 4.5 Hz / 0.02,
9.0 Hz / 0.1; real mode shapes below) in real modal form, each mode the exact discretisation
exp(A_c / fs) of its continuous block, driven by white noise scaled to unit stationary variance
per mode, plus 10 % white measurement noise: numpy.random.default_rng(SEED), SEED = 20261123.
Each channel's mean is removed, then the values are rounded to 9 significant digits; the
rounded values (as stored in ssi_input.json) are what pyOMA2 is given.

pyOMA2's definitions and the mapping to vibmode's
-------------------------------------------------
pyOMA2 1.4.3, pyoma2.functions.ssi (used by its `SSI` class with method "cov"):
* build_hank(Y, Yref, br, "cov"): p = br - 1, q = br, N = Ndat - p - q;
  Yf = [Y[:, q+i : N+q+i] for i = 0..p], Yp = [Y[:, q-1+i : N+q-1+i] for i = 0, -1, ..., -(q-1)],
  H = Yf Yp^T / N. Block (a, b) of H is (1/N) sum_t y_{t+q+a} y_{t+q-1-b}^T: an estimate of
  R_{1+a+b}, so H is the block *Hankel* matrix of the lags 1..2br-1, (br l) x (br l): the same
  lags and size as vibmode's block Toeplitz matrix with block_rows = br. The Hankel layout
  [R_{1+a+b}] is vibmode's Toeplitz layout [R_{i+a-b}] with the block columns reversed, which
  leaves the left singular vectors and singular values (hence O, A, C and the poles) unchanged.
  The *estimator* differs: every block of H averages exactly N products over its own window,
  where vibmode's R_k = 1/(Ndat - k) sum_{t=0}^{Ndat-1-k} y_{t+k} y_t^T uses all products of the
  record. ("cov_R" uses the lags 0..2br-2 and is not vibmode's definition.)
* SSI_fast(H, br, ordmax, step): U, S from numpy.linalg.svd(H); O = U[:, :n] S^{1/2};
  A = R_n^{-1} (Q^T O_down)[:n, :n] from a QR of O_up: the least-squares solution of
  O_up A = O_down, as vibmode's; C = the first l rows of O.
* SSI_poles(..., HC=True, xi_max=1.0): scipy.linalg.eig(A), lam_c = ln(lam_d) / dt,
  fn = |lam_c| / 2 pi, xi = -Re(lam_c) / |lam_c|, phi = C psi normalised by its entry of largest
  modulus; keeps one pole of each conjugate pair and 0 < xi < 1 (so real and unstable poles are
  dropped, as vibmode does). Which member of a pair is kept follows eig's order: shapes of kept
  poles with Im(lam_c) < 0 are conjugated here to vibmode's Im > 0 convention.

Two cases are stored, at orders 2, 4, ..., 20 with br = 10:
* "toeplitz": pyOMA2's SSI_fast + SSI_poles applied to the block Hankel matrix built here in
  numpy from vibmode's estimator (means removed, R_k = 1/(Ndat-k) ..., lags 1..2br-1). Same
  definitions end to end. Rust tolerance: 1e-9 relative on frequency and damping, 1 - MAC < 1e-9
  on shapes (achieved 4e-13, 2e-12 and 6e-16: crates/vibmode-ssi/tests/integration/reference.rs).
* "toeplitz_refs": the same with channels 0 and 2 as the references (reference-based SSI-cov;
  pyOMA2's build_hank(Y, Yref, ...) correlates every channel with Yref = Y[ref_ind]): the block
  Hankel matrix is (br l) x (br r), r = 2. Same tolerance.
* "pyoma2_cov": pyOMA2's own pipeline (build_hank "cov" + SSI_fast + SSI_poles) on the same
  data. Only the estimator of the correlations differs (edge windows of 2br - 1 samples out of
  3000); the Rust test compares the three physical modes at order 6 (tolerances there).
"""

import importlib.metadata
import json
import logging
import os
import sys

import numpy as np

os.environ.setdefault("TQDM_DISABLE", "1")  # pyOMA2 draws progress bars
import scipy

from pyoma2.functions import ssi as pyssi

logging.disable(logging.CRITICAL)  # pyOMA2 logs every step at INFO

SEED = 20261123
FS_HZ = 50.0
N = 3000
BR = 10
ORDMAX = 20
STEP = 2
REFS = [0, 2]  # reference channels of the reference-based case
MODES = [(1.2, 0.05), (4.5, 0.02), (9.0, 0.1)]
SHAPES = np.array(
    [
        [1.0, 0.8, 0.5, 0.2, -0.1],
        [0.3, -0.6, 1.0, 0.2, -0.8],
        [-0.5, 1.0, 0.1, -0.9, 0.4],
    ]
)
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data")


def simulate():
    rng = np.random.default_rng(SEED)
    burn = 2000
    blocks = []
    for f, z in MODES:
        w = 2 * np.pi * f
        sigma, wd = -z * w, w * np.sqrt(1 - z * z)
        r = np.exp(sigma / FS_HZ)
        c, s = np.cos(wd / FS_HZ), np.sin(wd / FS_HZ)
        blocks.append((r * np.array([[c, -s], [s, c]]), np.sqrt(1 - r * r)))
    x = np.zeros((len(MODES), 2))
    y = np.zeros((SHAPES.shape[1], N))
    for t in range(N + burn):
        if t >= burn:
            y[:, t - burn] = SHAPES.T @ x[:, 0]
        for m, (b, q) in enumerate(blocks):
            x[m] = b @ x[m] + q * rng.standard_normal(2)
    sd = np.sqrt((y**2).mean(axis=1))
    y += 0.1 * sd[:, None] * rng.standard_normal(y.shape)
    y -= y.mean(axis=1, keepdims=True)
    return np.array([[float(f"{v:.9g}") for v in ch] for ch in y])


def vibmode_hankel(y, br, refs=None):
    """vibmode's correlations in pyOMA2's block Hankel layout: block (a, b) = R_{1+a+b}, with
    R_k = E[y_{t+k} y_ref,t^T] (l x r) for the reference channels `refs` (all when None)."""
    l, n = y.shape
    y = y - y.mean(axis=1, keepdims=True)
    yr = y if refs is None else y[refs, :]
    r = [None] + [y[:, k:] @ yr[:, : n - k].T / (n - k) for k in range(1, 2 * br)]
    return np.block([[r[1 + a + b] for b in range(br)] for a in range(br)])


def poles(h):
    obs, a, c, _ = pyssi.SSI_fast(h, BR, ORDMAX, step=STEP)
    fn, xi, phi, lam, *_ = pyssi.SSI_poles(obs, a, c, ORDMAX, 1 / FS_HZ, step=STEP, HC=True, xi_max=1.0)
    out = []
    for col, order in enumerate(range(0, ORDMAX + 1, STEP)):
        if order == 0:
            continue
        keep = ~np.isnan(fn[:, col])
        modes = []
        for j in np.nonzero(keep)[0]:
            shape = phi[j, col, :]
            if lam[j, col].imag < 0:
                shape = np.conj(shape)
            modes.append(
                {
                    "frequency_hz": float(fn[j, col]),
                    "damping_ratio": float(xi[j, col]),
                    "shape": [[float(v.real), float(v.imag)] for v in shape],
                }
            )
        modes.sort(key=lambda m: m["frequency_hz"])
        out.append({"order": order, "modes": modes})
    return out


def main():
    y = simulate()
    with open(os.path.join(OUT, "ssi_input.json"), "w") as f:
        json.dump(
            {
                "description": "tools/reference/ssi.py: 5 channels x 3000 samples, seed %d" % SEED,
                "seed": SEED,
                "fs_hz": FS_HZ,
                "true_modes": [{"frequency_hz": f, "damping_ratio": z} for f, z in MODES],
                "true_shapes": SHAPES.tolist(),
                "channels": [[float(f"{v:.9g}") for v in ch] for ch in y],
            },
            f,
            separators=(",", ":"),
        )
    result = {
        "versions": {
            "python": sys.version.split()[0],
            "pyoma2": importlib.metadata.version("pyoma-2"),
            "numpy": np.__version__,
            "scipy": scipy.__version__,
        },
        "block_rows": BR,
        "fs_hz": FS_HZ,
        "toeplitz": poles(vibmode_hankel(y, BR)),
        "reference_channels": REFS,
        "toeplitz_refs": poles(vibmode_hankel(y, BR, REFS)),
        "pyoma2_cov": poles(pyssi.build_hank(y, y, BR, "cov")[0]),
    }
    with open(os.path.join(OUT, "ssi.json"), "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
