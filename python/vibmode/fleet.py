"""Fleet monitoring on the embedded SQLite store (docs/fleet.md), as ``vibmode fleet``.

Per vehicle, a nominal model set from healthy runs; later records are classified ``normal``,
``road``, ``vehicle`` or ``both``. Every call opens the store file and closes it again; SQLite
allows one writer at a time (see docs/scaling.md for many writers).
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Optional, Sequence, Union

from . import _native

PathLike = Union[str, "os.PathLike[str]"]


def _paths(files: Union[PathLike, Sequence[PathLike]]) -> List[str]:
    if isinstance(files, (str, os.PathLike)):
        return [os.fspath(files)]
    return [os.fspath(f) for f in files]


def init(db: PathLike, config: Any = None) -> bool:
    """Creates the store ``db`` if it does not exist; returns True if it was created.

    ``config``: the store's settings (bands, floors, the per-record analysis; docs/fleet.md), as
    ``vibmode fleet init --config fleet.toml``: a dict, a TOML file or TOML text; None keeps the
    store's settings (the defaults for a new store). Settings are fixed once the store holds a
    record: other settings are then a ValueError, the same ones a no-op."""
    from ._analysis import _config_toml

    toml = None if config is None else _config_toml(config, {})
    return _native.fleet_init(os.fspath(db), toml)


def settings(db: PathLike) -> Dict[str, Any]:
    """The settings the store ``db`` analyses new records with (those given to :func:`init` /
    ``vibmode fleet init --config``, or the defaults), as a JSON-ready dict of plain values:
    pass it to :func:`features` (``settings=``), e.g. once to every Dask worker, so that their
    features are the ones :func:`ingest` would store."""
    return json.loads(_native.fleet_settings(os.fspath(db)))


def ingest(
    db: PathLike,
    vehicle: str,
    files: Union[PathLike, Sequence[PathLike]],
    condition: str = "nominal",
    road: Optional[str] = None,
    fs: Optional[float] = None,
    scale: float = 1.0,
    unit: Optional[str] = None,
    allow_nonuniform: bool = False,
    time_unit: Optional[str] = None,
) -> List[Dict[str, Any]]:
    """Stores the features of ``files`` (paths, or folders standing for their recordings,
    sorted by name) for ``vehicle`` (``condition`` 'nominal' or 'test');
    a file already stored is not stored twice. All or nothing: every file is read and analysed
    first, then all are stored in one transaction; an error stores none. Returns one dict per
    file (a :class:`FleetList`: ``print(result)`` shows what ``vibmode fleet ingest`` prints,
    also in ``result.text``)."""
    data, text = _native.fleet_ingest(
        os.fspath(db), vehicle, _paths(files), condition, road, fs, float(scale), unit,
        bool(allow_nonuniform), time_unit,
    )
    return FleetList(json.loads(data), text)


def register(db: PathLike, vehicle: str, model: PathLike) -> str:
    """Registers the vehicle's full-car model file (TOML, docs/vehicle.md), as `vibmode fleet
    register`: records ingested or checked afterwards keep their body equations, and the
    baseline and each checked drive fit the springs and dampers per corner to them
    (docs/fleet.md, "The suspension fitted per drive"). Returns ``"new"``, ``"unchanged"`` (the
    same text was registered) or ``"replaced"`` (another file was: records' equations made with
    it no longer count, and a new baseline is needed for the fit per drive)."""
    return _native.fleet_register(os.fspath(db), vehicle, os.fspath(model))


def content_hash(db: PathLike) -> str:
    """The hash function the store keys its records by, ``'blake3'`` (stores made since schema 4)
    or ``'sha256'`` (stores that held records before): pass it to every worker's
    :func:`features` (:func:`store_features` refuses features hashed with the other)."""
    return _native.fleet_content_hash(os.fspath(db))


def model(db: PathLike, vehicle: str) -> Optional[str]:
    """The vehicle's registered model file's text (:func:`register`), or None: read once by the
    client and passed to every worker's :func:`features` so that they keep the body equations
    `fleet ingest` keeps."""
    return _native.fleet_model(os.fspath(db), vehicle)


def baseline(db: PathLike, vehicle: str) -> Dict[str, Any]:
    """Builds the vehicle's nominal model set from its nominal records (at least 5); returns it
    (a dict, a :class:`FleetResult`: ``print(result)`` shows what ``vibmode fleet baseline``
    prints, the limits per feature kind, also in ``result.text``). Where the nominal records
    form two or more drives (days, else folders), ``result["held_out_drives"]`` holds each drive
    checked against a model set of the other nominal records: its ``classification`` (``normal``
    unless the drive rule would flag this vehicle's healthy drives), ``component`` and
    ``summary``."""
    data, text = _native.fleet_baseline(os.fspath(db), vehicle)
    return FleetResult(json.loads(data), text)


def check(
    db: PathLike,
    vehicle: str,
    files: Union[PathLike, Sequence[PathLike]],
    fs: Optional[float] = None,
    scale: float = 1.0,
    unit: Optional[str] = None,
    allow_nonuniform: bool = False,
    time_unit: Optional[str] = None,
    drive: Optional[str] = None,
) -> Dict[str, Any]:
    """Classifies ``files`` (paths, or folders standing for their recordings) against the
    vehicle's latest model set (``vibmode fleet check
    --json``): ``{'vehicle', 'model_version', 'records': [...], 'drives': [...]}``, each record
    with its ``assessment`` (classification: normal, road, vehicle, both, or sensor for a dead,
    stuck, clipped or held channel listed in ``sensor_faults``; scores, evidence). ``drive`` names the
    files as one drive (at least 3), classified from the medians of their features; without it
    files whose time column holds date-times form one drive per UTC day (``YYYY-MM-DD``, 3 files
    or more), and other files, 3 or more, one drive named by the folder they lie in (``all given
    records`` when they lie in several or none; docs/fleet.md, "Drives"). With a
    registered model file (:func:`register`) a drive also has ``suspension``: the springs and
    dampers fitted to its records and every corner's score against the reference (the
    baseline's fit pooled with the vehicle's first normal drives, listed in
    ``suspension['reference_drives']``): the ratio ``t``, Welch's ``df``, and ``z``, the normal
    score of its Behrens-Fisher fiducial tail (docs/fleet.md, "Scores by the fiducial tail"),
    and, from the vehicle's third drive against
    that baseline on, ``suspension['trend']``: each corner's spring pooled with the two drives
    before it (docs/fleet.md, "The spring trend"). All or nothing: an error in any file stores no
    record and no check.

    The result is a dict (a :class:`FleetResult`); ``print(result)`` shows the table
    ``vibmode fleet check`` prints, also in ``result.text``."""
    data, text = _native.fleet_check(
        os.fspath(db), vehicle, _paths(files), fs, float(scale), unit, bool(allow_nonuniform), time_unit,
        drive,
    )
    return FleetResult(json.loads(data), text)


def status(db: PathLike, last: int = 10) -> List[Dict[str, Any]]:
    """Status of every vehicle in the store, with its last ``last`` records: a list of dicts (a
    :class:`FleetList`); ``print(result)`` shows what ``vibmode fleet status`` prints (one
    row per vehicle with its latest drive verdict first), also in ``result.text``. A vehicle
    whose latest drive is not flagged ``vehicle`` or ``both`` while an earlier drive against the
    same baseline was has ``earlier_flag`` (that drive, ``later_drives``, ``flagged_drives``,
    ``baseline_drives``): a fault near the limits is not found on every drive."""
    data, text = _native.fleet_status(os.fspath(db), int(last))
    return FleetList(json.loads(data), text)


class FleetResult(dict):
    """The result of :func:`check` or :func:`baseline`: the command's JSON as a dict, printed as
    the command prints it (``text``)."""

    def __init__(self, data: Dict[str, Any], text: str) -> None:
        super().__init__(data)
        self.text = text

    def __str__(self) -> str:
        return self.text


class FleetList(list):
    """The result of :func:`ingest` or :func:`status`: one dict per file or vehicle, printed as
    the command prints it (``text``)."""

    def __init__(self, data: List[Dict[str, Any]], text: str) -> None:
        super().__init__(data)
        self.text = text

    def __str__(self) -> str:
        return self.text


def features(
    path: PathLike,
    fs: Optional[float] = None,
    scale: float = 1.0,
    unit: Optional[str] = None,
    settings: Optional[Dict[str, Any]] = None,
    allow_nonuniform: bool = False,
    time_unit: Optional[str] = None,
    model: Optional[str] = None,
    content_hash: Optional[str] = None,
) -> Dict[str, Any]:
    """What the store keeps of one file (band levels, transmissibility, modes), computed without
    a store: the expensive part of :func:`ingest`, to run on many workers (e.g. Dask). Returns a
    JSON-ready dict ``{'file', 'content_hash', 'content_hash_kind', 'metadata', 'features'}`` for
    :func:`store_features`;
    ``file`` is ``path`` as given (as :func:`ingest` names records: ``run1/record_01.wav`` and
    ``run2/record_01.wav`` stay apart). A worker that reads a temporary copy of a remote file
    sets ``file`` back to the file's URL before storing.

    ``settings``: the store's settings, :func:`settings` ``(db)`` (read once, passed to every
    worker); None computes with the default settings, which differ from a store initialised
    with other ones. ``model``: the vehicle's registered model file's text, :func:`model`
    ``(db, vehicle)``; with it the record's body equations for the suspension fitted per drive
    are kept, as `fleet ingest` keeps them. ``content_hash``: the store's, :func:`content_hash`
    ``(db)`` (None: that of every store made since schema 4, ``'blake3'``)."""
    if settings is not None and not isinstance(settings, dict):
        raise ValueError(
            f"settings of type {type(settings).__name__}: pass the dict vibmode.fleet.settings(db) returns, or None"
        )
    text = None if settings is None else json.dumps(settings)
    return json.loads(
        _native.fleet_features(
            os.fspath(path), fs, float(scale), unit, text, bool(allow_nonuniform), time_unit, model,
            content_hash,
        )
    )


def store_features(
    db: PathLike,
    vehicle: str,
    items: Sequence[Dict[str, Any]],
    condition: str = "nominal",
    road: Optional[str] = None,
) -> List[Dict[str, Any]]:
    """Stores features from :func:`features` for ``vehicle``, exactly as :func:`ingest` would
    (a file whose bytes are already stored is left alone). One writer: call it from one process."""
    return json.loads(_native.fleet_store_features(os.fspath(db), vehicle, json.dumps(list(items)), condition, road))
