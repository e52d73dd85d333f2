"""AR / ARMA prediction-error models and order sweeps."""

from __future__ import annotations

import copy
import json
import warnings
from typing import Any, Dict, Iterable, Optional

import numpy as np

from . import _native
from ._spectral import _check_fs
from ._tables import columns

# The defaults of fit_arma (a single fit) and sweep (the analysis sweep), from the Rust
# definitions (vibmode_ident::ArmaParams, vibmode_core::SweepParams): no number is copied here.
_DEFAULTS = json.loads(_native.ident_defaults())
_FIT = _DEFAULTS["fit_arma"]
_SWEEP = _DEFAULTS["sweep"]


def _signal(y: Any) -> np.ndarray:
    a = np.asarray(y)
    if np.iscomplexobj(a) or a.dtype.kind not in "fiub":
        raise ValueError(f"y has dtype {a.dtype}; give a real 1-D signal")
    a = np.squeeze(a) if a.ndim > 1 and sum(s > 1 for s in a.shape) <= 1 else a
    if a.ndim != 1:
        raise ValueError(f"y has shape {np.shape(y)}; give one signal (a 1-D array), e.g. x[0]")
    return np.ascontiguousarray(a, dtype=np.float64)


def _order(name: str, v: Any, minimum: int = 0) -> int:
    import operator

    try:
        i = operator.index(v)
    except TypeError:
        raise ValueError(f"{name} = {v!r} must be an integer") from None
    if i < minimum:
        raise ValueError(f"{name} = {i} must be >= {minimum}")
    return int(i)


def _robust(robust: Any) -> Optional[float]:
    """A Huber factor, or None for the quadratic criterion ('off', None, False or 0)."""
    if robust is None or robust is False:
        return None
    if isinstance(robust, str):
        if robust.strip().lower() in ("off", "none", "quadratic"):
            return None
        try:
            robust = float(robust)
        except ValueError:
            raise ValueError(
                f"robust = {robust!r}: use a Huber factor such as 1.6, or 'off'"
            ) from None
    r = float(robust)
    if r == 0:
        return None
    if not (np.isfinite(r) and r > 0):
        raise ValueError(f"robust = {robust!r}: use a positive Huber factor such as 1.6, or 'off'")
    return r


class ArmaModel:
    """A fitted model ``A(q) y_t = C(q) e_t`` of a signal sampled at ``fs_hz``.

    Attributes
    ----------
    a, c : ndarray, the A and C coefficients with the leading 1 (dimensionless).
    p, q : the orders (q = 0 for AR models).
    noise_variance : innovation variance lambda, signal units**2.
    frequency_hz, damping_ratio : ndarray, natural frequency (Hz) and damping ratio
        (dimensionless) of every stable complex pole pair, ascending in frequency.
    damped_frequency_hz : ndarray, Hz.
    fs_hz : sampling rate of the signal, Hz.
    loss, aic, bic, fpe, converged, iterations, estimator, n_samples, mean : as in the JSON
        of ``vibmode fit`` (see ``to_dict()``).
    """

    def __init__(self, d: Dict[str, Any]):
        self._d = copy.deepcopy(d)
        m = d["model"]
        self.fs_hz: float = float(d["fs_hz"])
        self.p: int = int(m["p"])
        self.q: int = int(m["q"])
        self.a = np.asarray(m["a"], dtype=float)
        self.c = np.asarray(m["c"], dtype=float)
        self.noise_variance: float = float(m["noise_variance"])
        self.loss: float = _num(m.get("loss"))
        self.aic: float = _num(m.get("aic"))
        self.bic: float = _num(m.get("bic"))
        self.fpe: float = _num(m.get("fpe"))
        self.converged: bool = bool(m.get("converged", True))
        self.iterations: int = int(m.get("iterations", 0))
        self.estimator: str = str(m.get("estimator"))
        self.n_samples: int = int(m.get("n_samples", 0))
        self.mean: float = _num(m.get("mean"))
        self.std_errors = np.asarray([_num(v) for v in m.get("std_errors", [])], dtype=float)
        modes = d.get("modes", {}).get("modes", [])
        self.frequency_hz = np.asarray([x["frequency_hz"] for x in modes], dtype=float)
        self.damping_ratio = np.asarray([x["damping_ratio"] for x in modes], dtype=float)
        self.damped_frequency_hz = np.asarray([x["damped_frequency_hz"] for x in modes], dtype=float)

    @property
    def poles(self) -> np.ndarray:
        """All discrete-time poles (roots of ``z**p + a1 z**(p-1) + ... + ap``), dimensionless."""
        return np.roots(self.a) if self.p > 0 else np.empty(0, dtype=complex)

    def psd(self, freq_hz: Any) -> np.ndarray:
        """One-sided model PSD ``2 lambda Ts |C/A|**2`` at ``freq_hz`` (Hz), in signal units**2/Hz,
        comparable with ``welch(..., scaling='density')``."""
        f = np.asarray(freq_hz, dtype=np.float64)
        out = _native.arma_psd(
            self.a.tolist(), self.c.tolist(), self.noise_variance,
            np.ascontiguousarray(f.ravel()), self.fs_hz,
        )
        return out.reshape(f.shape)

    def to_dict(self) -> Dict[str, Any]:
        """Everything, JSON-ready: ``{'fs_hz', 'model': {...}, 'modes': {...}}`` with the field
        names of the crate (``ArmaModel``, ``ModeSet``). ``ArmaModel.from_dict`` reads it back."""
        return copy.deepcopy(self._d)

    @classmethod
    def from_dict(cls, d: Dict[str, Any]) -> "ArmaModel":
        return cls(d)

    def __repr__(self) -> str:
        kind = f"ARMA({self.p}, {self.q})" if self.q else f"AR({self.p})"
        modes = ", ".join(f"{f:.3f} Hz/{z:.3f}" for f, z in zip(self.frequency_hz, self.damping_ratio))
        return f"<vibmode.ArmaModel {kind} at {self.fs_hz:g} Hz, lambda={self.noise_variance:.4g}, modes: [{modes}]>"


def _num(v: Any) -> float:
    return float("nan") if v is None else float(v)


def fit_arma(
    y: Any,
    fs: float,
    p: int,
    q: Optional[int] = None,
    robust: Any = _FIT["robust"],
    max_iterations: int = _FIT["max_iterations"],
    tolerance: float = _FIT["tolerance"],
    demean: bool = _FIT["demean"],
    *,
    max_iter: Optional[int] = None,
    tol: Optional[float] = None,
) -> ArmaModel:
    """ARMA(p, q) by prediction-error minimisation (Gauss-Newton, MATLAB ``armax``/``pem``'s
    method) of the signal ``y`` sampled at ``fs`` Hz.

    ``q`` defaults to ``p``. ``robust``: Huber factor of the robust criterion (default 1.6,
    with additive-outlier cleaning first), or ``'off'``/``None`` for least squares.
    ``max_iterations`` caps the Gauss-Newton iterations and ``tolerance`` is the relative
    stopping tolerance (the defaults of a single fit, ``vibmode fit``'s: 100 and 1e-5; the
    analysis sweep's are :func:`sweep`'s). ``max_iter`` and ``tol``, the names of earlier
    versions, are still accepted (a DeprecationWarning). Raises ValueError for bad orders or
    signals.
    """
    if max_iter is not None or tol is not None:
        warnings.warn(
            "fit_arma: max_iter and tol are now max_iterations and tolerance",
            DeprecationWarning,
            stacklevel=2,
        )
        max_iterations = max_iterations if max_iter is None else max_iter
        tolerance = tolerance if tol is None else tol
    fs = _check_fs(fs)
    p = _order("p", p, 0)
    q = p if q is None else _order("q", q, 0)
    s = _native.fit_arma(
        _signal(y), fs, p, q, _robust(robust), _order("max_iterations", max_iterations, 1),
        float(tolerance), bool(demean),
    )
    return ArmaModel(json.loads(s))


def fit_ar(y: Any, fs: float, p: int, method: str = "burg") -> ArmaModel:
    """AR(p) of the signal ``y`` sampled at ``fs`` Hz; ``method``: 'burg' (default, equal to
    ``statsmodels.regression.linear_model.burg``), 'yule-walker' (equal to statsmodels'
    ``yule_walker(..., method='mle')``) or 'ls' (forward-backward least squares)."""
    fs = _check_fs(fs)
    s = _native.fit_ar(_signal(y), fs, _order("p", p, 0), str(method))
    return ArmaModel(json.loads(s))


class SweepResult:
    """An order sweep: ``fits`` (order, loss, noise_variance, aic, converged, iterations, error),
    ``modes`` (order, frequency_hz, damping_ratio: the stabilisation diagram),
    ``filtered_out`` (pole pairs the analysis' pole filters left out, with the reason) and
    ``clusters`` (the kept poles clustered over the orders, as the analysis clusters one
    record: frequency_hz, frequency_std_hz, damping_ratio, order_share, min_order, n_poles,
    class: ``structural`` or ``periodic-disturbance`` when in at least half the orders,
    ``spurious`` otherwise; ``vibmode sweep`` prints the first two). Tables are DataFrames when
    pandas is installed, else dicts of numpy arrays."""

    def __init__(self, d: Dict[str, Any], as_frame: Optional[bool]):
        self._d = d
        self.fs_hz = d["fs_hz"]
        self.model = d["model"]
        self.fits = columns(d["fits"], ["order", "loss", "noise_variance", "aic", "converged", "iterations", "error"], as_frame)
        self.modes = columns(d["modes"], ["order", "frequency_hz", "damping_ratio"], as_frame)
        self.filtered_out = columns(d["filtered_out"], ["order", "frequency_hz", "damping_ratio", "reason"], as_frame)
        self.clusters = columns(
            d["clusters"],
            ["frequency_hz", "frequency_std_hz", "damping_ratio", "order_share", "min_order", "n_poles", "class"],
            as_frame,
        )

    def to_dict(self) -> Dict[str, Any]:
        return copy.deepcopy(self._d)

    def __repr__(self) -> str:
        return f"<vibmode.SweepResult {self.model}, {len(self._d['fits'])} orders, {len(self._d['modes'])} pole pairs>"


def sweep(
    y: Any,
    fs: float,
    orders: Iterable[int] = range(_SWEEP["order_min"], _SWEEP["order_max"] + 1),
    model: str = "arma",
    method: str = "burg",
    robust: Any = _SWEEP["robust"],
    max_iterations: int = _SWEEP["max_iterations"],
    tolerance: float = _SWEEP["tolerance"],
    starts: str = _SWEEP["starts"],
    as_frame: Optional[bool] = None,
) -> SweepResult:
    """Fits every order of ``orders`` to ``y`` (sampled at ``fs`` Hz) and collects every mode:
    the stabilisation diagram of ``vibmode sweep``. ``model``: 'arma' (ARMA(p, p), warm-started
    from order to order) or 'ar' (with ``method``). ``starts``: 'multi' (models with p + q <= 16
    searched from every starting candidate) or 'single' (from the best-scored one only, as the
    fleet's records). Defaults are the analysis sweep's (p = 2..30, Huber 1.6, 20 iterations,
    tolerance 1e-4, 'multi')."""
    fs = _check_fs(fs)
    ords = [_order("order", o, 1) for o in orders]
    if not ords:
        raise ValueError("orders is empty; give e.g. range(2, 31)")
    if model not in ("arma", "ar"):
        raise ValueError(f"model = {model!r} is unknown; use 'arma' (ARMA(p, p)) or 'ar'")
    s = _native.sweep(
        _signal(y), fs, ords, model, str(method), _robust(robust),
        _order("max_iterations", max_iterations, 1), float(tolerance), str(starts),
    )
    return SweepResult(json.loads(s), as_frame)
