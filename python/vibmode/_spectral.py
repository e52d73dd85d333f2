"""Periodogram, Welch, CSD and coherence with scipy.signal's names, defaults and return
conventions, computed by vibmode's Rust core (rows in parallel, GIL released)."""

from __future__ import annotations

import operator
import warnings
from typing import Any, Callable, Dict, Optional, Tuple, Union

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
    "kaiser": "kaiser", "ksr": "kaiser",
}
_VALID_WINDOWS = "hann, hamming, blackman, boxcar, flattop, tukey, ('tukey', alpha) or ('kaiser', beta)"


def _unsupported(window: Any) -> ValueError:
    return ValueError(
        f"window {window!r} is not supported by vibmode; use {_VALID_WINDOWS}, or pass its "
        f"coefficients as an array, e.g. window=scipy.signal.get_window({window!r}, nperseg)"
    )


def _window_name(window: Any) -> str:
    """The crate's window name for scipy's `window` argument (a name or a (name, param) tuple)."""
    if isinstance(window, str):
        key = window.strip().lower()
        if key.startswith("tukey:"):
            return key
        if _WINDOW_ALIASES.get(key) == "kaiser":
            raise ValueError(f"window '{window}' needs its beta (as scipy): give ('kaiser', beta), e.g. ('kaiser', 8.6)")
        if key in _WINDOW_ALIASES:
            return _WINDOW_ALIASES[key]
        raise _unsupported(window)
    if isinstance(window, tuple) and window and isinstance(window[0], str):
        name = _WINDOW_ALIASES.get(window[0].strip().lower())
        if name in ("tukey", "kaiser") and len(window) == 2:
            try:
                param = float(window[1])
            except (TypeError, ValueError):
                raise ValueError(f"window {window!r}: the {name} parameter must be a number") from None
            return f"{name}:{param!r}"
        if name is not None and name != "kaiser" and len(window) == 1:
            return name
        raise _unsupported(window)
    raise ValueError(
        f"window of type {type(window).__name__} is not a window name; give one of {_VALID_WINDOWS}"
    )


def _window_arg(window: Any) -> Union[str, np.ndarray]:
    """scipy's `window`: a name or (name, parameter) tuple (the crate's name), or an array of
    coefficients (1-D float64; the crate checks them: non-empty, finite, not all zero)."""
    if isinstance(window, (str, tuple)):
        return _window_name(window)
    try:
        a = np.asarray(window)
    except (TypeError, ValueError):
        a = np.asarray(None)
    if a.dtype.kind not in "fiub":
        raise ValueError(
            f"window of type {type(window).__name__} is not supported; give a name ({_VALID_WINDOWS}) "
            "or a 1-D array of real coefficients"
        )
    if a.ndim != 1:
        raise ValueError(
            f"window must be 1-D: got an array of shape {a.shape}; give one coefficient per sample of a segment"
        )
    return np.ascontiguousarray(a, dtype=np.float64)


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


def _back(p: np.ndarray, lead: Tuple[int, ...], axis: int, ndim: int) -> np.ndarray:
    out = p.reshape(lead + (p.shape[-1],))
    return np.moveaxis(out, -1, axis if axis >= 0 else ndim + axis)


def _warn(notes: list) -> None:
    for n in notes:
        warnings.warn(n, UserWarning, stacklevel=4)


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


def _segment_args(
    window: Any,
    nperseg: Any = None,
    noverlap: Any = None,
    nfft: Any = None,
    detrend: Any = "constant",
    scaling: Any = "density",
    average: Any = "mean",
) -> Dict[str, Any]:
    """scipy's segment arguments, checked and translated for the native functions (one dict,
    read by the extension in one place). An array window sets ``nperseg`` to its length; a
    different ``nperseg`` is a ValueError (both checked by the extension, as scipy)."""
    return {
        "window": _window_arg(window),
        "nperseg": _opt_count("nperseg", nperseg, 1),
        "noverlap": _opt_count("noverlap", noverlap, 0),
        "nfft": _opt_count("nfft", nfft, 1),
        "detrend": _detrend_name(detrend),
        "scaling": str(scaling),
        "average": str(average),
    }


def _pair(x: Any, y: Any, axis: int):
    a = _real_input(x, "x")
    b = _real_input(y, "y")
    ax = np.moveaxis(a, axis, -1)  # AxisError is a ValueError
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


def _spectra(
    native: Callable[..., Tuple[np.ndarray, np.ndarray, list]],
    x: Any,
    y: Any,
    fs: Any,
    axis: int,
    args: Dict[str, Any],
    complex_out: bool = False,
    onesided: bool = True,
    warn: bool = True,
) -> Tuple[np.ndarray, np.ndarray]:
    """The shared path of welch, periodogram, csd and coherence: checks ``fs`` and the input(s)
    (``y`` None for auto-spectra), puts ``axis`` last as C-contiguous float64 rows (x and y
    broadcast), calls ``native(x_rows[, y_rows], fs, args)``, warns its notes, makes the
    spectrum two-sided if asked and restores the axis, in scipy's output dtype."""
    fs = _check_fs(fs)
    if y is None:
        a = _real_input(x, "x")
        arrays: Tuple[np.ndarray, ...] = (a,)
        moved = (np.moveaxis(a, axis, -1),)
        empty_shape = a.shape
    else:
        a, b, ax, bx = _pair(x, y, axis)
        arrays = (a, b)
        moved = (ax, bx)
        empty_shape = ax.shape
    cdt, rdt = _out_dtype(*arrays)
    if moved[0].size == 0:
        return np.empty(empty_shape), np.empty(empty_shape, dtype=cdt if complex_out else np.float64)
    n = moved[0].shape[-1]
    lead = moved[0].shape[:-1]
    rows = [np.ascontiguousarray(m.reshape(-1, n), dtype=np.float64) for m in moved]
    f, p, notes = native(*rows, fs, args)
    if warn:
        _warn(notes)
    if not onesided:
        f, p = _two_sided(f, p, fs, conj=complex_out)
    return f, _back(p, lead, axis, len(lead) + 1).astype(cdt if complex_out else rdt, copy=False)


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
    window : 'hann' (default), 'hamming', 'blackman', 'boxcar', 'flattop', 'tukey',
        ('tukey', alpha) or ('kaiser', beta); or a 1-D array of coefficients (dimensionless,
        e.g. ``np.hanning(256)`` or ``scipy.signal.get_window(('gaussian', 30), 256)``; no
        normalisation needed), whose length is the segment length. Other names raise
        ValueError (pass their coefficients).
    nperseg : segment length, samples (default 256, clamped to the record with a UserWarning;
        with an array window its length, and a different nperseg is a ValueError; an array
        window longer than the record is a ValueError, as scipy).
    noverlap : overlap, samples (default nperseg // 2).
    nfft : FFT length, samples, >= nperseg (default nperseg).
    detrend : 'constant' (default), 'linear' or False.
    return_onesided : True (default): ``nfft // 2 + 1`` bins from 0 Hz; False: scipy's
        two-sided spectrum, ``nfft`` bins in FFT order (``fftfreq``), each half the one-sided
        value but DC and Nyquist.
    scaling : 'density' (units**2/Hz, default; divides by ``fs * sum(w**2)``) or 'spectrum'
        (units**2; divides by ``sum(w)**2``).
    axis : axis of the samples (default -1).
    average : 'mean' (default) or 'median'.

    Returns
    -------
    f : ndarray, frequencies in Hz (``nfft // 2 + 1`` bins, or ``nfft`` two-sided).
    Pxx : ndarray, the shape of ``x`` with ``axis`` replaced by the bins; units**2/Hz or units**2.
    """
    args = _segment_args(window, nperseg, noverlap, nfft, detrend, scaling, average)
    return _spectra(_native.welch_rows, x, None, fs, axis, args, onesided=return_onesided)


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
    ``axis`` (window 'boxcar' by default; ``window=None`` is boxcar too; an array window needs
    one coefficient per sample used, else ValueError). ``nfft`` smaller than the record uses
    only its first ``nfft`` samples, larger zero-pads. Frequencies in Hz; Pxx in units**2/Hz
    ('density') or units**2 ('spectrum')."""
    args = _segment_args("boxcar" if window is None else window, None, None, nfft, detrend, scaling)
    return _spectra(_native.periodogram_rows, x, None, fs, axis, args, onesided=return_onesided, warn=False)


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
    :func:`welch`, including array windows; x and y broadcast against each other apart from
    ``axis`` and must have the same length along it). Returns frequencies in Hz and complex Pxy
    in units_x*units_y/Hz ('density') or units_x*units_y ('spectrum')."""
    args = _segment_args(window, nperseg, noverlap, nfft, detrend, scaling, average)
    return _spectra(_native.csd_rows, x, y, fs, axis, args, complex_out=True, onesided=return_onesided)


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
    :func:`scipy.signal.coherence` (arguments as :func:`welch`, including array windows; mean of
    the segments; NaN where Pxx Pyy is 0, as scipy). Returns frequencies in Hz and Cxy."""
    args = _segment_args(window, nperseg, noverlap, nfft, detrend)
    return _spectra(_native.coherence_rows, x, y, fs, axis, args)


def get_window(window: Any, nx: int) -> np.ndarray:
    """The periodic window of length ``nx`` (as ``scipy.signal.get_window(window, nx)``),
    dimensionless. Takes a window name, ('tukey', alpha) or ('kaiser', beta)."""
    n = _opt_count("nx", nx, 0)
    return _native.window_values(_window_name(window), n)
