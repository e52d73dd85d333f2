"""Periodogram, Welch, CSD and coherence with scipy.signal's names, defaults and return
conventions, computed by vibmode's Rust core (rows in parallel, GIL released)."""

from __future__ import annotations

import operator
import warnings
from typing import Any, Optional, Tuple

import numpy as np

from . import _native

# scipy.signal.get_window's aliases of the windows vibmode has.
_WINDOW_ALIASES = {
    "hann": "hann", "han": "hann",
    "hamming": "hamming", "hamm": "hamming", "ham": "hamming",
    "blackman": "blackman", "black": "blackman", "blk": "blackman",
    "boxcar": "boxcar", "box": "boxcar", "ones": "boxcar", "rect": "boxcar",
    "rectangular": "boxcar",
    "flattop": "flattop", "flat": "flattop", "flt": "flattop",
    "tukey": "tukey", "tuk": "tukey",
}
_VALID_WINDOWS = "hann, hamming, blackman, boxcar, flattop, tukey or ('tukey', alpha)"


def _window_name(window: Any) -> str:
    """The crate's window name for scipy's `window` argument (a name or a (name, param) tuple)."""
    if isinstance(window, str):
        key = window.strip().lower()
        if key.startswith("tukey:"):
            return key
        if key in _WINDOW_ALIASES:
            return _WINDOW_ALIASES[key]
        raise ValueError(f"window '{window}' is not supported by vibmode; use {_VALID_WINDOWS}")
    if isinstance(window, tuple) and window and isinstance(window[0], str):
        name = _WINDOW_ALIASES.get(window[0].strip().lower())
        if name == "tukey" and len(window) == 2:
            alpha = float(window[1])
            return f"tukey:{alpha!r}"
        if name is not None and len(window) == 1:
            return name
        raise ValueError(f"window {window!r} is not supported by vibmode; use {_VALID_WINDOWS}")
    raise ValueError(
        f"window of type {type(window).__name__} is not supported by vibmode (window arrays are "
        f"not); give a window name: {_VALID_WINDOWS}"
    )


def _detrend_name(detrend: Any) -> str:
    if detrend is False or detrend is None:
        return "none"
    if isinstance(detrend, str) and detrend.strip().lower() in ("constant", "linear", "none"):
        return detrend.strip().lower()
    raise ValueError(
        f"detrend = {detrend!r} is not supported by vibmode; use 'constant', 'linear' or False "
        "(detrend functions are not)"
    )


def _opt_count(name: str, value: Any, minimum: int) -> Optional[int]:
    if value is None:
        return None
    try:
        v = operator.index(value)
    except TypeError:
        raise ValueError(f"{name} = {value!r} must be an integer") from None
    if v < minimum:
        raise ValueError(f"{name} = {v} must be >= {minimum}")
    return int(v)


def _check_fs(fs: Any) -> float:
    try:
        f = float(fs)
    except (TypeError, ValueError):
        raise ValueError(f"fs = {fs!r} must be a number (the sampling rate in Hz)") from None
    if not (np.isfinite(f) and f > 0):
        raise ValueError(f"fs = {fs!r} Hz is invalid: the sampling rate must be positive and finite")
    return f


def _real_input(x: Any, name: str) -> np.ndarray:
    a = np.asarray(x)
    if np.iscomplexobj(a):
        raise ValueError(
            f"{name} is complex: vibmode's spectra are of real signals (two-sided spectra of "
            "complex signals are not supported)"
        )
    if a.dtype.kind not in "fiub":
        raise ValueError(f"{name} has dtype {a.dtype}; give a real numeric array")
    if a.ndim == 0:
        raise ValueError(f"{name} is a scalar; give a 1-D or N-D array of samples")
    return a


def _out_dtype(*arrays: np.ndarray) -> Tuple[np.dtype, np.dtype]:
    """scipy's output types: complex = result_type(x, y, complex64), real = its real part."""
    c = np.result_type(*arrays, np.complex64)
    return np.dtype(c), np.dtype(np.finfo(c).dtype)


def _rows(a: np.ndarray, axis: int) -> Tuple[np.ndarray, Tuple[int, ...]]:
    """`a` with `axis` moved last, as C-contiguous float64 rows (copies only when needed)."""
    moved = np.moveaxis(a, axis, -1)  # AxisError is a ValueError
    lead = moved.shape[:-1]
    n = moved.shape[-1]
    rows = np.ascontiguousarray(moved.reshape(-1, n), dtype=np.float64)
    return rows, lead


def _back(p: np.ndarray, lead: Tuple[int, ...], axis: int, ndim: int) -> np.ndarray:
    out = p.reshape(lead + (p.shape[-1],))
    return np.moveaxis(out, -1, axis if axis >= 0 else ndim + axis)


def _warn(notes: list) -> None:
    for n in notes:
        warnings.warn(n, UserWarning, stacklevel=3)


def _two_sided(f: np.ndarray, p: np.ndarray, fs: float, conj: bool) -> Tuple[np.ndarray, np.ndarray]:
    """scipy's two-sided spectrum (``return_onesided=False``) of a real signal from vibmode's
    one-sided one along the last axis: the one-sided bins are doubled except DC and (even nfft)
    Nyquist, so the two-sided bins are halved back, and the negative frequencies mirror the
    positive ones (complex conjugate for a cross-spectrum). Frequencies in scipy's FFT order
    (``fftfreq(nfft, 1 / fs)``)."""
    m = f.shape[0]
    if m < 2:
        nfft = 1
    else:
        nfft = int(round(fs / (f[1] - f[0])))
    even = nfft % 2 == 0
    half = p.copy()
    hi = m - 1 if even else m
    half[..., 1:hi] = half[..., 1:hi] / 2.0
    out = np.empty(p.shape[:-1] + (nfft,), dtype=p.dtype)
    out[..., :m] = half
    k = np.arange(1, nfft - m + 1)  # positive bins whose mirror is a negative bin
    mirror = half[..., k]
    out[..., nfft - k] = np.conj(mirror) if conj else mirror
    return np.fft.fftfreq(nfft, 1.0 / fs), out


def welch(
    x: Any,
    fs: float = 1.0,
    window: Any = "hann",
    nperseg: Optional[int] = None,
    noverlap: Optional[int] = None,
    nfft: Optional[int] = None,
    detrend: Any = "constant",
    return_onesided: bool = True,
    scaling: str = "density",
    axis: int = -1,
    average: str = "mean",
) -> Tuple[np.ndarray, np.ndarray]:
    """Welch power spectral density, as :func:`scipy.signal.welch` (same arguments, defaults and
    results to ~1e-12 relative).

    Parameters
    ----------
    x : array_like of real numbers, any shape; the spectrum is taken along ``axis``.
    fs : sampling rate, Hz (default 1.0).
    window : 'hann' (default), 'hamming', 'blackman', 'boxcar', 'flattop', 'tukey' or
        ('tukey', alpha). Other windows and window arrays raise ValueError.
    nperseg : segment length, samples (default 256, clamped to the record with a UserWarning).
    noverlap : overlap, samples (default nperseg // 2).
    nfft : FFT length, samples, >= nperseg (default nperseg).
    detrend : 'constant' (default), 'linear' or False.
    return_onesided : True (default): ``nfft // 2 + 1`` bins from 0 Hz; False: scipy's
        two-sided spectrum, ``nfft`` bins in FFT order (``fftfreq``), each half the one-sided
        value but DC and Nyquist.
    scaling : 'density' (units**2/Hz, default) or 'spectrum' (units**2).
    axis : axis of the samples (default -1).
    average : 'mean' (default) or 'median'.

    Returns
    -------
    f : ndarray, frequencies in Hz (``nfft // 2 + 1`` bins, or ``nfft`` two-sided).
    Pxx : ndarray, the shape of ``x`` with ``axis`` replaced by the bins; units**2/Hz or units**2.
    """
    fs = _check_fs(fs)
    a = _real_input(x, "x")
    _, rdt = _out_dtype(a)
    if a.size == 0:
        return np.empty(a.shape), np.empty(a.shape)
    rows, lead = _rows(a, axis)
    f, p, notes = _native.welch_rows(
        rows, fs, _window_name(window), _opt_count("nperseg", nperseg, 1),
        _opt_count("noverlap", noverlap, 0), _opt_count("nfft", nfft, 1),
        _detrend_name(detrend), str(scaling), str(average),
    )
    _warn(notes)
    if not return_onesided:
        f, p = _two_sided(f, p, fs, conj=False)
    return f, _back(p, lead, axis, a.ndim).astype(rdt, copy=False)


def periodogram(
    x: Any,
    fs: float = 1.0,
    window: Any = "boxcar",
    nfft: Optional[int] = None,
    detrend: Any = "constant",
    return_onesided: bool = True,
    scaling: str = "density",
    axis: int = -1,
) -> Tuple[np.ndarray, np.ndarray]:
    """Periodogram, as :func:`scipy.signal.periodogram`: one segment of the whole record along
    ``axis`` (window 'boxcar' by default; ``window=None`` is boxcar too). ``nfft`` smaller than
    the record uses only its first ``nfft`` samples, larger zero-pads. Frequencies in Hz; Pxx in
    units**2/Hz ('density') or units**2 ('spectrum')."""
    fs = _check_fs(fs)
    a = _real_input(x, "x")
    _, rdt = _out_dtype(a)
    if a.size == 0:
        return np.empty(a.shape), np.empty(a.shape)
    rows, lead = _rows(a, axis)
    f, p, notes = _native.periodogram_rows(
        rows, fs, _window_name("boxcar" if window is None else window),
        _opt_count("nfft", nfft, 1), _detrend_name(detrend), str(scaling),
    )
    if not return_onesided:
        f, p = _two_sided(f, p, fs, conj=False)
    return f, _back(p, lead, axis, a.ndim).astype(rdt, copy=False)


def _pair(x: Any, y: Any, axis: int):
    a = _real_input(x, "x")
    b = _real_input(y, "y")
    ax = np.moveaxis(a, axis, -1)
    bx = np.moveaxis(b, axis, -1)
    if ax.shape[-1] != bx.shape[-1]:
        raise ValueError(
            f"x and y have {ax.shape[-1]} and {bx.shape[-1]} samples along axis {axis}; vibmode "
            "needs equal lengths (scipy zero-pads the shorter): trim or pad them yourself"
        )
    try:
        ax, bx = np.broadcast_arrays(ax, bx)
    except ValueError:
        raise ValueError(
            f"x and y shapes {a.shape} and {b.shape} do not broadcast (apart from axis {axis})"
        ) from None
    return a, b, ax, bx


def csd(
    x: Any,
    y: Any,
    fs: float = 1.0,
    window: Any = "hann",
    nperseg: Optional[int] = None,
    noverlap: Optional[int] = None,
    nfft: Optional[int] = None,
    detrend: Any = "constant",
    return_onesided: bool = True,
    scaling: str = "density",
    axis: int = -1,
    average: str = "mean",
) -> Tuple[np.ndarray, np.ndarray]:
    """Cross-spectral density ``Pxy = conj(X) Y``, as :func:`scipy.signal.csd` (arguments as
    :func:`welch`; x and y broadcast against each other apart from ``axis`` and must have the
    same length along it). Returns frequencies in Hz and complex Pxy in units_x*units_y/Hz
    ('density') or units_x*units_y ('spectrum')."""
    fs = _check_fs(fs)
    a, b, ax, bx = _pair(x, y, axis)
    cdt, _ = _out_dtype(a, b)
    n = ax.shape[-1]
    lead = ax.shape[:-1]
    if ax.size == 0:
        return np.empty(ax.shape), np.empty(ax.shape, dtype=cdt)
    xr = np.ascontiguousarray(ax.reshape(-1, n), dtype=np.float64)
    yr = np.ascontiguousarray(bx.reshape(-1, n), dtype=np.float64)
    f, p, notes = _native.csd_rows(
        xr, yr, fs, _window_name(window), _opt_count("nperseg", nperseg, 1),
        _opt_count("noverlap", noverlap, 0), _opt_count("nfft", nfft, 1),
        _detrend_name(detrend), str(scaling), str(average),
    )
    _warn(notes)
    if not return_onesided:
        f, p = _two_sided(f, p, fs, conj=True)
    return f, _back(p, lead, axis, len(lead) + 1).astype(cdt, copy=False)


def coherence(
    x: Any,
    y: Any,
    fs: float = 1.0,
    window: Any = "hann",
    nperseg: Optional[int] = None,
    noverlap: Optional[int] = None,
    nfft: Optional[int] = None,
    detrend: Any = "constant",
    axis: int = -1,
) -> Tuple[np.ndarray, np.ndarray]:
    """Magnitude-squared coherence ``|Pxy|**2 / (Pxx Pyy)`` (dimensionless, in [0, 1]), as
    :func:`scipy.signal.coherence` (mean of the segments; NaN where Pxx Pyy is 0, as scipy).
    Returns frequencies in Hz and Cxy."""
    fs = _check_fs(fs)
    a, b, ax, bx = _pair(x, y, axis)
    _, rdt = _out_dtype(a, b)
    n = ax.shape[-1]
    lead = ax.shape[:-1]
    if ax.size == 0:
        return np.empty(ax.shape), np.empty(ax.shape)
    xr = np.ascontiguousarray(ax.reshape(-1, n), dtype=np.float64)
    yr = np.ascontiguousarray(bx.reshape(-1, n), dtype=np.float64)
    f, c, notes = _native.coherence_rows(
        xr, yr, fs, _window_name(window), _opt_count("nperseg", nperseg, 1),
        _opt_count("noverlap", noverlap, 0), _opt_count("nfft", nfft, 1),
        _detrend_name(detrend),
    )
    _warn(notes)
    return f, _back(c, lead, axis, len(lead) + 1).astype(rdt, copy=False)


def get_window(window: Any, nx: int) -> np.ndarray:
    """The periodic window of length ``nx`` (as ``scipy.signal.get_window(window, nx)``),
    dimensionless."""
    n = _opt_count("nx", nx, 0)
    return _native.window_values(_window_name(window), n)
