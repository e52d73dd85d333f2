"""Reference values for vibmode-ssi's first-order (Döhler-style) pole uncertainty, from pyOMA2.

Writes tools/reference/data/ssi_uncertainty.json. Run from the repository root after
tools/reference/ssi.py (it reads that script's committed data, ssi_input.json):

    python3 -m pip install -r tools/reference/requirements.txt
    python3 tools/reference/ssi_uncertainty.py

Pinned versions (tools/reference/requirements.txt): Python 3.11.7, pyOMA2 (pip package
`pyoma-2`) 1.4.3, numpy 2.1.3, scipy 1.14.1.

What is compared
----------------
pyOMA2 1.4.3 implements Döhler & Mevel (2013), "Efficient multi-order uncertainty computation
for stochastic subspace identification" (MSSP 38): pyoma2.functions.ssi.SSI_poles(...,
calc_unc=True, H=H, T=T) propagates cov(vec H) = T T^T to the standard deviations of every
pole's frequency and damping with the closed-form sensitivities of the SVD, the shift-invariance
least squares and the eigenvalues. vibmode computes the same first-order quantity with
directional derivatives (crates/vibmode-ssi/src/perturb.rs). To compare the propagation alone,
H and T are built here from vibmode's estimator and handed to pyOMA2:

* the record (5 channels x 3000 samples at 50 Hz, ssi_input.json) cut into NB = 20 blocks of
  time: block b holds, at each lag k = 1..2br-1, the products y[t+k] y[t]^T of the t in
  [b N / NB, (b+1) N / NB) with t < N - k (every product of the record in one block);
* R_k = (sum of all blocks' products) / (their number) (= vibmode's whole-record estimate), each
  block's own R_k^(b) = its sum / its count, w_b(k) = its count / the total count;
* H: the R_k in pyOMA2's block Hankel layout (block (a, c) = R_{1+a+c}); vibmode's Toeplitz
  layout reverses the block columns, which changes neither the poles nor their sensitivities;
* T: column b = vec_F of the Hankel layout of sqrt(NB / (NB - 1)) w_b(k) (R_k^(b) - R_k), so
  that T T^T is the estimate of cov(vec H) (Döhler's (H_b - H) / sqrt(NB (NB - 1)) for equal
  blocks, which pyOMA2's own build_hank(..., calc_unc=True) forms).

pyOMA2 is run with step = 1: with step = 2 its loop over the singular vectors (`for ii in
trange(1, ordmax + 1, step)`) fills the sensitivities of every other singular vector only and
leaves the rest zero, which underestimates the standard deviations. br = 10, orders 2, 4, ...,
12 are stored. Rust tolerance (crates/vibmode-ssi/tests/integration/reference.rs): poles 1e-9 relative,
standard deviations 1e-4 relative (finite differences against closed form).
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

logging.disable(logging.CRITICAL)

BR = 10
ORDMAX = 12
NB = 20
HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data")


def hankel(r):
    return np.block([[r[1 + a + c] for c in range(BR)] for a in range(BR)])


def main():
    with open(os.path.join(HERE, "ssi_input.json")) as f:
        data = json.load(f)
    fs = data["fs_hz"]
    y = np.array(data["channels"])
    y = y - y.mean(axis=1, keepdims=True)
    l, n = y.shape
    lags = range(1, 2 * BR)
    sums = np.zeros((NB, 2 * BR, l, l))
    counts = np.zeros((NB, 2 * BR))
    for b in range(NB):
        t0, t1 = b * n // NB, (b + 1) * n // NB
        for k in lags:
            t_end = min(t1, n - k)
            if t_end <= t0:
                continue
            sums[b, k] = y[:, t0 + k : t_end + k] @ y[:, t0:t_end].T
            counts[b, k] = t_end - t0
    total = sums.sum(axis=0)
    count = counts.sum(axis=0)
    r_bar = [None] + [total[k] / count[k] for k in lags]
    h = hankel(r_bar)
    t = np.zeros((h.size, NB))
    for b in range(NB):
        d = [None] + [
            np.sqrt(NB / (NB - 1)) * counts[b, k] / count[k] * (sums[b, k] / counts[b, k] - r_bar[k])
            for k in lags
        ]
        t[:, b] = hankel(d).reshape(-1, order="F")
    obs, a, c, _ = pyssi.SSI_fast(h, BR, ORDMAX, step=1)
    fn, xi, _phi, lam, fn_std, xi_std, _ = pyssi.SSI_poles(
        obs, a, c, ORDMAX, 1 / fs, step=1, HC=True, xi_max=1.0, calc_unc=True, H=h, T=t
    )
    orders = []
    for order in range(2, ORDMAX + 1, 2):
        modes = []
        for j in np.nonzero(~np.isnan(fn[:, order]))[0]:
            modes.append(
                {
                    "frequency_hz": float(fn[j, order]),
                    "damping_ratio": float(xi[j, order]),
                    "frequency_std_hz": float(fn_std[j, order]),
                    "damping_std": float(xi_std[j, order]),
                }
            )
        modes.sort(key=lambda m: m["frequency_hz"])
        orders.append({"order": order, "modes": modes})
    result = {
        "description": "tools/reference/ssi_uncertainty.py: pyOMA2's Döhler propagation of "
        "vibmode's block scatter (ssi_input.json, %d blocks)" % NB,
        "versions": {
            "python": sys.version.split()[0],
            "pyoma2": importlib.metadata.version("pyoma-2"),
            "numpy": np.__version__,
            "scipy": scipy.__version__,
        },
        "block_rows": BR,
        "n_blocks": NB,
        "fs_hz": fs,
        "orders": orders,
    }
    with open(os.path.join(HERE, "ssi_uncertainty.json"), "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
