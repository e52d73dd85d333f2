"""The whole analysis, the full-car model and the simulator."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, NamedTuple, Optional, Sequence, Union

import numpy as np

from . import _native
from ._io import Recording, _as_recording, write
from ._spectral import _check_fs
from ._tables import frames, has_pandas, require_pandas

_BUILTIN_VEHICLES = ("city_bus", "city_bus_flexible", "passenger_car")

# simulate()'s defaults, from the Rust definition (SimParams::default, as `vibmode simulate`'s).
_SIM = json.loads(_native.simulate_defaults())


def _deep_merge(base: Dict[str, Any], extra: Dict[str, Any]) -> Dict[str, Any]:
    out = dict(base)
    for k, v in extra.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = _deep_merge(out[k], v)
        else:
            out[k] = v
    return out


def _toml_dict(text: str) -> Dict[str, Any]:
    try:
        import tomllib  # Python >= 3.11
    except ImportError:  # pragma: no cover
        try:
            import tomli as tomllib  # type: ignore[no-redef]
        except ImportError:
            raise ImportError("merging a TOML config with keyword settings needs Python >= 3.11 or `pip install tomli`") from None
    try:
        return tomllib.loads(text)
    except Exception as e:
        raise ValueError(f"config is not valid TOML: {e}") from None


def _config_toml(config: Any, settings: Dict[str, Any]) -> Optional[str]:
    """TOML text of `config` (dict, TOML file path or TOML text) with `settings` merged over it."""
    text: Optional[str] = None
    d: Dict[str, Any] = {}
    if config is None:
        pass
    elif isinstance(config, dict):
        d = config
    elif isinstance(config, (str, os.PathLike)):
        s = os.fspath(config)
        if "\n" in s or "=" in s:
            text = s
        else:
            with open(s, encoding="utf-8") as f:  # OSError for a missing file
                text = f.read()
    else:
        raise ValueError(f"config of type {type(config).__name__}: give a dict, a TOML file or TOML text")
    if text is not None and not settings and not d:
        return text
    if text is not None:
        d = _toml_dict(text)
    d = _deep_merge(d, settings)
    if not d:
        return None
    return _native.json_to_toml(json.dumps(d, default=_jsonable))


def _jsonable(v: Any) -> Any:
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (np.floating,)):
        return float(v)
    if isinstance(v, (np.ndarray, range, tuple)):
        return list(v)
    raise TypeError(f"{type(v).__name__} is not a setting value")


def analysis_config(config: Any = None, preset: Optional[str] = None, **settings: Any) -> Dict[str, Any]:
    """The analysis settings in force for ``config`` / ``preset`` / keyword settings (the same
    merging as :func:`analyze`), as a dict with one section per stage (docs/analysis.md)."""
    toml = _config_toml(config, settings)
    return json.loads(_native.analysis_config(toml, preset))


def _vehicle_spec(vehicle: Any):
    """(kind, value) of a vehicle given as a shipped name, TOML path, TOML text or dict."""
    if isinstance(vehicle, dict):
        return "toml", _native.json_to_toml(json.dumps(vehicle, default=_jsonable))
    if isinstance(vehicle, os.PathLike):
        return "path", os.fspath(vehicle)
    if isinstance(vehicle, str):
        if vehicle in _BUILTIN_VEHICLES:
            return "builtin", vehicle
        if "\n" in vehicle or "=" in vehicle:
            return "toml", vehicle
        return "path", vehicle
    raise ValueError(
        f"vehicle of type {type(vehicle).__name__}: give {', '.join(_BUILTIN_VEHICLES)}, a TOML file, TOML text or a dict"
    )


def analyze(
    inputs: Any,
    fs: Optional[float] = None,
    *,
    config: Any = None,
    preset: Optional[str] = None,
    vehicle: Any = None,
    channels: Optional[Sequence[Union[str, int]]] = None,
    unit: Optional[str] = None,
    scale: float = 1.0,
    allow_nonuniform: bool = False,
    time_unit: Optional[str] = None,
    as_frames: Optional[bool] = None,
    **settings: Any,
) -> Dict[str, Any]:
    """The whole analysis of ``vibmode analyze``: for every record and channel the ideal
    anti-alias resampling, Welch spectra and an ARMA order sweep; poles pooled per channel and
    per role into invariant modes (frequency in Hz, damping ratio), lines tracked, optionally
    SSI-cov and the full-car model's modes matched.

    ``inputs``: a file path, a folder (its recordings, sorted by name, as ``vibmode analyze
    DIR``), a :class:`Recording`, an array (n_channels, n_samples) with ``fs``
    (Hz), a ``(data, fs)`` tuple, a DataFrame from ``read(..., as_frame=True)``, or a list of these (one or more records
    each; long recordings are cut into records of ``record_length_s``).
    ``config``: a dict, a TOML file or TOML text (docs/analysis.md); ``preset``: 'vibmode'
    (default) or 'paper'; keyword ``settings`` are merged over both, as sections
    (``sweep={'order_max': 12}``) or the flat keys (``order_max=12``, ``cutoff_hz=20``).
    ``vehicle``: full-car parameters (shipped name, TOML file/text or dict) whose modes are
    matched and whose suspension is fitted to the records' body equations: ``model_update`` in
    the result holds the updated vehicle, its modes and the file's (docs/model_update.md), or
    ``not_updated`` with the reason. ``channels``: names or indices to analyse. Files are read
    with ``scale``, ``unit``, ``time_unit`` and ``allow_nonuniform`` as :func:`read` reads them.

    Returns the structure of ``results.json`` as a dict; with pandas installed (and
    ``as_frames`` not False) every table (list of flat records: poles, fits, invariant modes,
    records, matches, ...) is a DataFrame.
    """
    items = inputs if isinstance(inputs, (list, tuple)) and not _is_array_tuple(inputs) else [inputs]
    native_items: List[Any] = []
    for i, it in enumerate(items):
        if isinstance(it, (str, os.PathLike)):
            native_items.append(os.fspath(it))
        else:
            native_items.append(_as_recording(it, fs, name=f"record {i + 1:02d}")._native_tuple())
    toml = _config_toml(config, settings)
    vk, vv = _vehicle_spec(vehicle) if vehicle is not None else (None, None)
    sel = None if channels is None else [str(c) for c in channels]
    text = _native.analyze(
        native_items, toml, preset, None if fs is None else _check_fs(fs), float(scale), unit, sel, vk, vv,
        bool(allow_nonuniform), time_unit,
    )
    res = json.loads(text)
    use = has_pandas() if as_frames is None else bool(as_frames)
    if use:
        require_pandas("as_frames=True")
        return frames(res)
    return res


def _is_array_tuple(x: Any) -> bool:
    return isinstance(x, tuple) and len(x) == 2 and isinstance(x[0], np.ndarray)


def fullcar(params: Any = "city_bus", as_frame: Optional[bool] = None):
    """Modes of the 7-DOF full-car model (docs/vehicle.md): natural frequency (Hz), damping
    ratio, damped frequency (Hz), label, shapes. ``params``: 'city_bus', 'city_bus_flexible',
    'passenger_car', a TOML file, TOML text or a dict of the same keys. Returns a DataFrame (with
    pandas, unless ``as_frame=False``) or a list of dicts."""
    kind, value = _vehicle_spec(params)
    modes = json.loads(_native.fullcar_modes(kind, value))
    use = has_pandas() if as_frame is None else bool(as_frame)
    if use:
        return require_pandas("as_frame=True").DataFrame(modes)
    return modes


class SimRecord(Recording):
    """A simulated record: a :class:`Recording` with ``start_time_s`` (s) and
    ``mean_speed_kmh`` (km/h)."""

    start_time_s: float = 0.0
    mean_speed_kmh: float = 0.0


class Simulation(NamedTuple):
    records: List[SimRecord]
    truth: Dict[str, Any]
    paths: List[str]


def simulate(
    vehicle: Any = "city_bus",
    road: str = _SIM["road"],
    speed_kmh: float = _SIM["speed_kmh"],
    duration_s: float = _SIM["duration_s"],
    records: int = _SIM["records"],
    fs: float = _SIM["fs"],
    seed: int = _SIM["seed"],
    effects: str = "in-service",
    out_dir: Optional[Union[str, "os.PathLike[str]"]] = None,
    format: str = "wav",
) -> Simulation:
    """In-service acceleration records of a vehicle (``vibmode simulate``): ISO 8608 ``road``
    class A-H at ``speed_kmh`` (km/h), ``records`` successive records of ``duration_s`` (s) at
    ``fs`` (Hz); ``effects``: 'in-service' (engine lines, sensor noise, tones, manoeuvres),
    'none' (pure road response) or 'demo'. The same seed gives the same numbers.

    Returns ``Simulation(records, truth, paths)``; with ``out_dir`` the records are also written
    there as ``record_01.<format>`` (wav, csv or f32) with ``truth.json``.
    """
    kind, value = _vehicle_spec(vehicle)
    recs, truth = _native.simulate(
        kind, value, str(road), float(speed_kmh), float(duration_s), int(records), _check_fs(fs), int(seed), str(effects),
    )
    out: List[SimRecord] = []
    for i, ((data, rate, names, units, placements, _start), t0, v) in enumerate(recs):
        r = SimRecord(data, rate, names, units, json.loads(placements), name=f"record_{i + 1:02d}")
        r.start_time_s = t0
        r.mean_speed_kmh = v
        out.append(r)
    truth_d = json.loads(truth)
    paths: List[str] = []
    if out_dir is not None:
        if format not in ("wav", "csv", "f32"):
            raise ValueError(f"format = {format!r}: use 'wav', 'csv' or 'f32'")
        d = os.fspath(out_dir)
        os.makedirs(d, exist_ok=True)
        for r in out:
            p = os.path.join(d, f"{r.name}.{format}")
            write(p, r)
            paths.append(p)
        with open(os.path.join(d, "truth.json"), "w", encoding="utf-8") as f:
            json.dump(truth_d, f, indent=2)
    return Simulation(out, truth_d, paths)
