"""Covariance-driven stochastic subspace identification (SSI-cov) of one multichannel record."""

from __future__ import annotations

import copy
import json
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

from . import _native
from ._io import Recording, frame_channels
from ._models import _num, _order
from ._spectral import _check_fs, _real_input
from ._tables import columns

_DEFAULTS = json.loads(_native.ssi_defaults())


def _shape(entries: List[List[float]]) -> np.ndarray:
    a = np.asarray(entries, dtype=np.float64).reshape(-1, 2)
    return a[:, 0] + 1j * a[:, 1]


def _orders(orders: Any) -> Dict[str, int]:
    """order_min, order_max, order_step from a range or an evenly spaced sequence."""
    if isinstance(orders, range):
        ords = list(orders)
        step = orders.step
    else:
        ords = sorted(_order("orders", o, 1) for o in orders)
        steps = {b - a for a, b in zip(ords, ords[1:])}
        if len(steps) > 1 or 0 in steps:
            raise ValueError(
                f"orders {ords} are not evenly spaced; give a range such as range(2, 61, 2)"
            )
        step = steps.pop() if steps else 1
    if not ords:
        raise ValueError("orders is empty; give e.g. range(2, 61, 2)")
    lo = _order("orders", min(ords), 1)
    if lo < 2:
        raise ValueError(f"orders start at {lo}; the lowest order is 2 (one mode)")
    return {"order_min": lo, "order_max": int(max(ords)), "order_step": int(step)}


class SsiResult:
    """What :func:`ssi_cov` identified.

    Attributes
    ----------
    poles : table (DataFrame with pandas, else a dict of arrays), one row per identified mode
        of every order: ``order``, ``frequency_hz`` (Hz), ``damping_ratio``, ``mpc`` (modal
        phase collinearity, 0-1), ``stability`` (``new``, ``frequency``, ``frequency_damping``
        or ``stable`` against the previous order: the stabilisation diagram); with
        ``uncertainty_blocks`` also ``frequency_sd_hz`` and ``damping_sd``, the first-order
        standard deviations of the estimate (NaN where not computable).
    pole_shapes : complex ndarray (n_poles, n_channels), the mode shape of each row of
        ``poles``, in the channels' units, largest entry 1.
    modes : table, the poles clustered over the orders: ``frequency_hz``, ``frequency_std_hz``,
        ``damping_ratio``, ``order_share`` (share of the orders with a pole in the cluster),
        ``min_order``, ``n_poles``, ``class`` (``structural`` when in at least half the
        orders), ``mac_median``, ``mac_min`` (between the poles' shapes and the mean shape);
        structural modes first. ``frequency_std_hz`` is the spread of the poles over the
        orders; with ``uncertainty_blocks``, ``frequency_sd_hz`` and ``damping_sd`` are the
        standard deviations of the estimate (median over the mode's orders; NaN for
        non-structural clusters).
    shapes : complex ndarray (n_modes, n_channels), the mean shape of each row of ``modes``.
    channels : list of channel names.
    singular_values : ndarray, of the block Toeplitz matrix, largest first.
    lag_span_s : float, the span of the correlation lags in seconds (the largest lag over
        ``fs_hz``): a mode below ``1 / lag_span_s`` Hz completes less than one period within
        them and is seldom identified; resample to a lower rate or use more ``block_rows`` to
        reach lower (a 500 Hz record with the default 20 block rows spans 0.078 s: 12.8 Hz).
    fs_hz, n_samples, params, stability_params : the data and the parameters used.
    """

    def __init__(self, d: Dict[str, Any], channels: List[str], as_frame: Optional[bool]):
        self._d = d
        self.channels = channels
        self.fs_hz: float = float(d["fs_hz"])
        self.n_samples: int = int(d["n_samples"])
        self.params: Dict[str, Any] = d["params"]
        self.stability_params: Dict[str, Any] = d["stability_params"]
        self.lag_span_s: float = float(d["lag_span_s"])
        self.singular_values = np.asarray(d["result"]["singular_values"], dtype=np.float64)
        rows, shapes = [], []
        pole_std = d.get("pole_std")
        sd_cols = ["frequency_sd_hz", "damping_sd"] if pole_std is not None else []
        for k, (o, labels) in enumerate(zip(d["result"]["orders"], d["stability"])):
            for j, (m, label) in enumerate(zip(o["modes"], labels)):
                row = {
                    "order": o["order"],
                    "frequency_hz": m["frequency_hz"],
                    "damping_ratio": m["damping_ratio"],
                    "mpc": m["mpc"],
                    "stability": label,
                }
                if pole_std is not None:
                    sd = pole_std[k][j]
                    row["frequency_sd_hz"] = _num(sd[0])
                    row["damping_sd"] = _num(sd[1])
                rows.append(row)
                shapes.append(_shape(m["shape"]))
        n = len(channels)
        self.poles = columns(
            rows, ["order", "frequency_hz", "damping_ratio", "mpc", "stability"] + sd_cols, as_frame
        )
        self.pole_shapes = np.array(shapes).reshape(len(shapes), n)
        mrows, mshapes = [], []
        for m in d["modes"]:
            mac = m.get("shape_mac") or [None, None]
            unc = m.get("uncertainty") or {}
            mrow = {
                "frequency_hz": m["frequency_hz"],
                "frequency_std_hz": m["frequency_std_hz"],
                "damping_ratio": m["damping_ratio"],
                "order_share": m["order_share"],
                "min_order": m["min_order"],
                "n_poles": m["n_poles"],
                "class": m["class"],
                "mac_median": mac[0],
                "mac_min": mac[1],
            }
            if pole_std is not None:
                mrow["frequency_sd_hz"] = _num(unc.get("frequency_std_hz"))
                mrow["damping_sd"] = _num(unc.get("damping_std"))
            mrows.append(mrow)
            s = m.get("shape")
            mshapes.append(_shape(s) if s else np.full(n, np.nan + 0j))
        self.modes = columns(
            mrows,
            ["frequency_hz", "frequency_std_hz", "damping_ratio", "order_share", "min_order",
             "n_poles", "class", "mac_median", "mac_min"] + sd_cols,
            as_frame,
        )
        self.shapes = np.array(mshapes).reshape(len(mshapes), n)

    def to_dict(self) -> Dict[str, Any]:
        """The JSON of ``vibmode ssi --json`` (without ``source``) as a dict."""
        out = copy.deepcopy(self._d)
        out["channels"] = list(self.channels)
        return out

    def __repr__(self) -> str:
        n_struct = sum(1 for m in self._d["modes"] if m["class"] == "structural")
        return (
            f"<vibmode.SsiResult {len(self.channels)} channels, {len(self._d['result']['orders'])} "
            f"orders, {n_struct} structural modes; lags span {self.lag_span_s:.3g} s: modes below "
            f"about {1.0 / self.lag_span_s:.3g} Hz are seldom identified>"
        )


def ssi_cov(
    data: Any,
    fs: Optional[float] = None,
    *,
    axis: int = -1,
    channels: Optional[Sequence[str]] = None,
    block_rows: Optional[int] = None,
    orders: Any = None,
    first_lag: Optional[int] = None,
    references: Optional[Sequence[int]] = None,
    normalise: bool = True,
    valid_max_hz: Optional[float] = None,
    freq_tol_rel: Optional[float] = None,
    damping_tol_rel: Optional[float] = None,
    mac_min: Optional[float] = None,
    uncertainty_blocks: Optional[int] = None,
    as_frame: Optional[bool] = None,
) -> SsiResult:
    """Covariance-driven SSI of one multichannel record, as ``vibmode ssi``: output
    correlations at the lags ``first_lag .. first_lag + 2 block_rows - 2``, their block
    Toeplitz matrix and SVD, the poles and complex mode shapes of every order of ``orders``,
    the stabilisation labels, and the poles clustered over the orders (docs/ssi.md).

    ``data``: a :class:`Recording`, a pandas DataFrame (one column per channel, rows are
    samples; ``fs`` from ``attrs['fs']`` or the frame's time when not given, a time column not a
    channel: see :func:`vibmode.analyze`), or an array with time along ``axis``
    (default the last: ``(n_channels, n_samples)``; pyOMA2's ``(n_samples, n_channels)`` is
    ``axis=0``). ``fs``: sampling rate, Hz. ``orders``: a range of model orders (state
    dimensions, 2 per mode; default ``range(2, 61, 2)``). ``references``: 0-based channel
    indices for reference-based SSI-cov. ``normalise``: divide each channel by its RMS first
    (shapes are scaled back to the channels' units). ``valid_max_hz``: poles at or above it
    are not clustered (the top of the valid band after an anti-alias filter; default Nyquist).
    ``uncertainty_blocks``: cut the record into that many blocks of time and give every pole
    (and structural mode) the first-order standard deviations of its frequency and damping
    from the blocks' scatter (Döhler & Mevel 2013, as pyOMA2's ``calc_unc=True, nb=...``;
    20 to 50 are usual; default off).
    The defaults of every parameter are those of the CLI and the analysis' ``[ssi]`` TOML
    section (``vibmode.ssi_cov.defaults``)."""
    names: Optional[List[str]] = None
    if isinstance(data, Recording):
        arr, fs_given, names = data.data, data.fs, list(data.channels)
        fs = fs_given if fs is None else fs
    elif hasattr(data, "columns") and hasattr(data, "to_numpy"):  # pandas DataFrame
        arr, fs, names = frame_channels(data, fs)
        arr = _real_input(arr, "data")
    else:
        a = _real_input(data, "data")
        if a.ndim == 1:
            a = a[np.newaxis, :]
        if a.ndim != 2:
            raise ValueError(
                f"data has shape {a.shape}; give (n_channels, n_samples), or a 2-D array with time along axis"
            )
        ax = _order("axis", axis, -a.ndim)
        if ax >= a.ndim:
            raise ValueError(f"axis = {axis} is out of range for data of shape {a.shape}")
        arr = np.moveaxis(a, ax, -1)
    if fs is None:
        raise ValueError("fs is missing; give the sampling rate in Hz")
    fs = _check_fs(fs)
    arr = np.ascontiguousarray(arr, dtype=np.float64)
    n_ch = arr.shape[0]
    if channels is not None:
        names = [str(c) for c in channels]
        if len(names) != n_ch:
            raise ValueError(f"{len(names)} channel names for {n_ch} channels; give one per channel")
    if names is None:
        names = [f"ch{i}" for i in range(n_ch)]
    ssi: Dict[str, Any] = {}
    if block_rows is not None:
        ssi["block_rows"] = _order("block_rows", block_rows, 1)
    if orders is not None:
        ssi.update(_orders(orders))
    if first_lag is not None:
        ssi["first_lag"] = _order("first_lag", first_lag, 1)
    if references is not None:
        refs = [_order("references", r, 0) for r in references]
        ssi["reference_channels"] = refs
    stability: Dict[str, Any] = {}
    for key, v in (("freq_tol_rel", freq_tol_rel), ("damping_tol_rel", damping_tol_rel), ("mac_min", mac_min)):
        if v is not None:
            stability[key] = float(v)
    vmax = None if valid_max_hz is None else float(valid_max_hz)
    blocks = None if uncertainty_blocks is None else _order("uncertainty_blocks", uncertainty_blocks, 2)
    d = json.loads(
        _native.ssi_cov(arr, fs, json.dumps(ssi), json.dumps(stability), bool(normalise), vmax, blocks)
    )
    return SsiResult(d, names, as_frame)


ssi_cov.defaults = copy.deepcopy(_DEFAULTS)  # type: ignore[attr-defined]
