"""Recordings: reading, writing, and the ideal DFT resampling."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Iterator, List, Optional, Sequence, Union

import numpy as np

from . import _native
from ._spectral import _check_fs, _real_input
from ._tables import require_pandas

PathLike = Union[str, "os.PathLike[str]"]


class Recording:
    """A multichannel recording.

    Attributes
    ----------
    data : ndarray (n_channels, n_samples), float64, in each channel's unit.
    fs : sampling rate, Hz.
    channels : list of channel names (the time column of a text file is not a channel).
    units : list of units (e.g. 'm/s^2'; '' when unknown).
    placements : list of dicts (role, corner, direction) per channel.
    name : display name (the file name for files read).
    start_unix_s : the first sample's Unix time (s, UTC) when the file's time column told it
        (date-times, a date beside times of day, Unix time; docs/formats.md), else None.
        :attr:`start` gives it as a ``datetime``.

    ``data, fs, channels = recording`` unpacks the three main fields.
    """

    def __init__(
        self,
        data: Any,
        fs: float,
        channels: Optional[Sequence[str]] = None,
        units: Optional[Sequence[str]] = None,
        placements: Optional[List[Dict[str, Any]]] = None,
        name: str = "record",
        start_unix_s: Optional[float] = None,
    ):
        a = _real_input(data, "data")
        if a.ndim == 1:
            a = a[np.newaxis, :]
        if a.ndim != 2:
            raise ValueError(f"data has shape {a.shape}; give (n_channels, n_samples)")
        self.data = np.ascontiguousarray(a, dtype=np.float64)
        self.fs = _check_fs(fs)
        n = self.data.shape[0]
        self.channels = list(channels) if channels is not None else [f"ch{i}" for i in range(n)]
        self.units = list(units) if units is not None else [""] * n
        if len(self.channels) != n or len(self.units) != n:
            raise ValueError(
                f"{n} channels but {len(self.channels)} names and {len(self.units)} units; "
                "give one per row of data"
            )
        self.placements = placements
        self.name = name
        if start_unix_s is not None and not np.isfinite(start_unix_s):
            raise ValueError(f"start_unix_s = {start_unix_s!r}; give a finite Unix time in s, or None")
        self.start_unix_s = None if start_unix_s is None else float(start_unix_s)

    def __iter__(self) -> Iterator[Any]:
        return iter((self.data, self.fs, self.channels))

    def __len__(self) -> int:
        return self.data.shape[1]

    @property
    def duration_s(self) -> float:
        """Duration, s."""
        return self.data.shape[1] / self.fs

    @property
    def time_s(self) -> np.ndarray:
        """Sample times from 0, s."""
        return np.arange(self.data.shape[1]) / self.fs

    @property
    def start(self):
        """The first sample's time as a timezone-aware ``datetime`` (UTC), or None when the file
        did not tell it."""
        if self.start_unix_s is None:
            return None
        import datetime

        return datetime.datetime.fromtimestamp(self.start_unix_s, tz=datetime.timezone.utc)

    def to_frame(self):
        """A pandas DataFrame: one column per channel, index ``time_s`` (s); ``attrs`` holds
        ``fs`` (Hz), ``units``, ``name`` and ``start_unix_s`` (None when unknown)."""
        pd = require_pandas("Recording.to_frame")
        df = pd.DataFrame(self.data.T, columns=self.channels, index=pd.Index(self.time_s, name="time_s"))
        df.attrs.update(
            fs=self.fs, units=dict(zip(self.channels, self.units)), name=self.name, start_unix_s=self.start_unix_s
        )
        return df

    def _native_tuple(self):
        placements = json.dumps(self.placements) if self.placements else None
        return (self.name, self.data, self.fs, list(self.channels), list(self.units), placements)

    def __repr__(self) -> str:
        return (
            f"<vibmode.Recording {self.name!r}: {len(self.channels)} channels x "
            f"{self.data.shape[1]} samples at {self.fs:g} Hz>"
        )


def read(
    path: PathLike,
    fs: Optional[float] = None,
    channels: Optional[Sequence[Union[str, int]]] = None,
    scale: float = 1.0,
    unit: Optional[str] = None,
    allow_nonuniform: bool = False,
    format: Optional[str] = None,
    as_frame: bool = False,
    time_unit: Optional[str] = None,
):
    """Reads a recording: delimited text (separator, header, units, decimal commas and a time
    column detected), WAV (PCM or float), raw f32/f64 with a JSON sidecar, or a NumPy ``.npy``
    array of samples by channels (``numpy.save``; give ``fs``) (docs/formats.md).

    ``fs``: sampling rate in Hz for files without a time column. ``channels``: names or 0-based
    indices to keep. ``scale``: multiplier of WAV integer samples (full scale = 1.0).
    ``unit``: unit of channels whose file gives none. ``allow_nonuniform``: resample a jittery
    time column to its mean rate (the command line's ``--resample-nonuniform``). ``time_unit``:
    the time column's unit (``s``, ``ms``, ``us``, ``ns``, ``min``, ``h``) when its name and header
    do not say (``--time-unit``); :func:`analyze` and the fleet functions take the same options.

    Returns a :class:`Recording` (``data, fs, names = vibmode.read(path)`` unpacks it; its
    ``start`` is the first sample's UTC time when the time column told it), or with
    ``as_frame=True`` a pandas DataFrame (index ``time_s``, ``attrs['fs']`` in Hz,
    ``attrs['start_unix_s']``).
    Raises OSError (FileNotFoundError) for files that cannot be read, ValueError for contents.
    """
    sel = None if channels is None else [str(c) for c in channels]
    data, rate, names, units, placements, start = _native.read(
        os.fspath(path), None if fs is None else _check_fs(fs), float(scale), unit,
        bool(allow_nonuniform), format, sel, time_unit,
    )
    rec = Recording(data, rate, names, units, json.loads(placements), name=os.fspath(path), start_unix_s=start)
    return rec.to_frame() if as_frame else rec


def info(
    paths: Union[PathLike, Sequence[PathLike]],
    fs: Optional[float] = None,
    scale: float = 1.0,
    unit: Optional[str] = None,
    allow_nonuniform: bool = False,
    time_unit: Optional[str] = None,
    as_frame: bool = False,
):
    """What each recording file holds, read block by block (files of any length): the
    command line's ``vibmode info --json`` (docs/formats.md, "Checking a file").

    ``paths``: a file or folder, or a list of them (a folder stands for its recordings). The
    reading options are :func:`read`'s. Returns a list with one dict per file (``path``,
    ``format``, ``fs_hz``, ``frames``, ``duration_s``, ``start_s``, ``start_time`` and
    ``channels``: dicts with ``name``, ``unit``, ``min``, ``max``, ``mean``, ``std`` (population,
    ``ddof=0``), ``rms``, ``constant`` (the one value of a dead or stuck channel, else None),
    ``clipped_samples`` and ``clipped_value``, ``held_samples``, ``held_stretches`` and
    ``held_longest`` (samples) and ``refused_by_analysis``: the analysis's own sensor checks),
    or with ``as_frame=True`` a pandas DataFrame with one row per file and channel.
    Raises OSError (FileNotFoundError) for files that cannot be read, ValueError for contents.
    """
    if isinstance(paths, (str, bytes, os.PathLike)):
        paths = [paths]
    out = json.loads(_native.info(
        [os.fspath(p) for p in paths], None if fs is None else _check_fs(fs), float(scale), unit,
        bool(allow_nonuniform), time_unit,
    ))
    if not as_frame:
        return out
    pd = require_pandas("info(..., as_frame=True)")
    rows = [{"path": f["path"], "fs_hz": f["fs_hz"], "frames": f["frames"],
             "duration_s": f["duration_s"], **{("channel" if k == "name" else k): v
                                                 for k, v in c.items()}}
            for f in out for c in f["channels"]]
    return pd.DataFrame(rows)


def write(path: PathLike, recording: Any, fs: Optional[float] = None, channels=None, units=None) -> None:
    """Writes a recording (a :class:`Recording`, a DataFrame from ``read(..., as_frame=True)``
    or an array (n_channels, n_samples) with ``fs`` in Hz). The format follows the extension:
    .csv (with a time_s column), .wav (32-bit float) or .f32/.f64 (raw + JSON sidecar)."""
    rec = _as_recording(recording, fs, channels, units)
    placements = json.dumps(rec.placements) if rec.placements else None
    _native.write(os.fspath(path), rec.data, rec.fs, rec.channels, rec.units, placements)


#: Largest relative deviation of a DataFrame's time steps from their mean (the file reader's
#: ``max_jitter_rel`` default).
MAX_JITTER_REL = 0.01


def _frame_time(df: Any):
    """The DataFrame's time in seconds (from its first sample) and its column, or (None, None): a
    column named as the file reader names a time column (``time``, ``t``, ``timestamp``, ``Time
    (ms)``, ``t_s``, ...) or of a datetime/timedelta dtype, else the index when it is a
    ``DatetimeIndex``/``TimedeltaIndex`` or a numeric index so named (``read(..., as_frame=True)``'s
    ``time_s``)."""
    import pandas as pd
    from pandas.api import types

    def clock(values: Any) -> bool:
        return types.is_datetime64_any_dtype(values) or types.is_timedelta64_dtype(values)

    def seconds(values: Any, label: str):
        if clock(values):
            first = values[0] if isinstance(values, pd.Index) else values.iloc[0]
            ns = np.asarray(values - first, dtype="timedelta64[ns]").astype(np.int64)
            return ns.astype(np.float64) * 1e-9
        scale = _native.time_column_scale(label)
        v = np.asarray(values, dtype=np.float64)
        return (v - v[0]) * (1.0 if scale is None else scale)

    def is_time(values: Any, label: str) -> bool:
        return clock(values) or (types.is_numeric_dtype(values) and _native.time_column_scale(label) is not None)

    if len(df) == 0:
        return None, None
    for c in df.columns:
        if is_time(df[c], str(c)):
            return seconds(df[c], str(c)), c
    idx = df.index
    label = "" if idx.name is None else str(idx.name)
    if clock(idx) or (label and is_time(idx, label)):
        return seconds(idx, label), None
    return None, None


def _flat_columns(df: Any) -> Any:
    """``df`` with two-level columns made flat, as ``pandas.read_csv(path, header=[0, 1])``
    reads a file with a units row (``('time', 's'), ('acc', 'g')``): where the first level's
    names are distinct, the second level is the units, kept in ``attrs['units']`` (pandas'
    ``Unnamed: ...`` placeholders as no unit), and a time column keeps its unit in its name
    (``time [ms]``) so that it scales the time; else the levels are joined (``FL_z``). Other
    frames are returned as they are."""
    import pandas as pd

    cols = df.columns
    if not isinstance(cols, pd.MultiIndex):
        return df
    if cols.nlevels != 2:
        raise ValueError(
            f"the DataFrame's columns have {cols.nlevels} levels; give one level of channel names "
            "(and at most a second of units)"
        )

    def text(v: Any) -> str:
        v = "" if v is None else str(v).strip()
        return "" if v.startswith("Unnamed:") else v

    names = [text(a) for a, _ in cols]
    units = [text(b) for _, b in cols]
    out = df.copy(deep=False)
    if len(set(names)) == len(names) and all(names):
        flat = []
        for n, u in zip(names, units):
            labelled = f"{n} [{u}]"
            flat.append(labelled if u and _native.time_column_scale(labelled) is not None else n)
        out.columns = flat
        merged = dict(df.attrs.get("units", {}))
        for n, u in zip(names, units):
            if u:
                merged.setdefault(n, u)
        out.attrs = dict(df.attrs)
        out.attrs["units"] = merged
    else:
        out.columns = ["_".join(p for p in (n, u) if p) for n, u in zip(names, units)]
    return out


def frame_channels(df: Any, fs: Optional[float]):
    """A DataFrame's channels as an array (n_channels, n_samples), its rate (Hz) and the channel
    names. The rate is ``fs``, else ``attrs['fs']``, else its time (see :func:`_frame_time`:
    a time column, or a datetime/timedelta or time-named index), which must then be uniform
    within 1 % and agree with a given rate within 1 %; a time column is not a channel. Two-level
    columns (name, unit) are read as :func:`_flat_columns` says."""
    df = _flat_columns(df)
    t, time_col = _frame_time(df)
    cols = [c for c in df.columns if time_col is None or c != time_col]
    if not cols:
        only = "" if time_col is None else f" besides its time column {str(time_col)!r}"
        raise ValueError(f"the DataFrame has no channel{only}; give it one column per channel")
    from pandas.api import types

    bad = [str(c) for c in cols if not types.is_numeric_dtype(df[c]) or types.is_bool_dtype(df[c])]
    if bad:
        raise ValueError(
            f"DataFrame column(s) {', '.join(repr(b) for b in bad[:5])} are not numbers; "
            "drop them or make the time the index"
        )
    given = fs if fs is not None else df.attrs.get("fs")
    measured = None
    if t is not None and len(t) >= 2:
        what = f"the DataFrame's time ({'index' if time_col is None else repr(str(time_col))})"
        dt = np.diff(t)
        if not np.all(dt > 0):
            k = int(np.argmin(dt > 0)) + 1
            raise ValueError(f"{what} does not increase at row {k}; sort the rows (df.sort_index()) or drop duplicates")
        mean_dt = (t[-1] - t[0]) / (len(t) - 1)
        jitter = float(np.max(np.abs(dt - mean_dt)) / mean_dt)
        measured = 1.0 / mean_dt
        if jitter > MAX_JITTER_REL and given is None:
            raise ValueError(
                f"{what} is not uniform: its steps deviate by up to {jitter:.3g} of their mean "
                f"(limit {MAX_JITTER_REL}); resample it onto a uniform grid (df.resample) or give fs (Hz)"
            )
        if given is not None and abs(measured - float(given)) > 0.01 * float(given):
            raise ValueError(f"{what} gives {measured:.6g} Hz but fs is {float(given):.6g} Hz; they must agree within 1 %")
    rate = given if given is not None else measured
    if rate is None:
        raise ValueError(
            "the DataFrame has no time (a time column, or a DatetimeIndex/TimedeltaIndex) and no attrs['fs']; give fs (Hz)"
        )
    data = df[cols].to_numpy(dtype=np.float64).T
    return data, float(rate), [str(c) for c in cols]


def _as_recording(x: Any, fs: Optional[float], channels=None, units=None, name: str = "record") -> Recording:
    if isinstance(x, Recording):
        return x
    if isinstance(x, tuple) and len(x) == 2 and fs is None:  # (data, fs)
        return Recording(x[0], x[1], channels, units, name=name)
    if hasattr(x, "to_numpy") and hasattr(x, "columns"):  # a DataFrame
        x = _flat_columns(x)
        data, rate, cols = frame_channels(x, fs)
        u = x.attrs.get("units", {})
        return Recording(data, rate, cols, [u.get(c, "") for c in cols], name=x.attrs.get("name", name))
    if fs is None:
        raise ValueError("an array needs its sampling rate: give fs (Hz)")
    return Recording(x, fs, channels, units, name=name)


def resample_ideal(
    x: Any,
    fs: float,
    fs_out: float,
    cutoff_hz: Optional[float] = None,
    axis: int = -1,
    filter: bool = True,
) -> np.ndarray:
    """The paper's ideal anti-alias resampling along ``axis``: every DFT bin above
    ``cutoff_hz`` (Hz; default the output Nyquist frequency ``fs_out / 2``) is zeroed, then the
    signal is decimated (integer ``fs / fs_out``) or Fourier-resampled (other ratios, as
    ``scipy.signal.resample``). ``fs`` and ``fs_out`` in Hz. ``filter=False`` decimates without
    the filter (aliasing). Returns float64 samples at ``fs_out``."""
    fs = _check_fs(fs)
    fs_out = _check_fs(fs_out)
    a = _real_input(x, "x")
    moved = np.moveaxis(a, axis, -1)
    lead = moved.shape[:-1]
    rows = np.ascontiguousarray(moved.reshape(-1, moved.shape[-1]), dtype=np.float64)
    y, _ = _native.resample_rows(rows, fs, fs_out, None if cutoff_hz is None else float(cutoff_hz), bool(filter))
    out = y.reshape(lead + (y.shape[-1],))
    return np.moveaxis(out, -1, axis if axis >= 0 else a.ndim + axis)
