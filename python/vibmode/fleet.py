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


def init(db: PathLike) -> bool:
    """Creates the store ``db`` if it does not exist; returns True if it was created."""
    return _native.fleet_init(os.fspath(db))


def ingest(
    db: PathLike,
    vehicle: str,
    files: Union[PathLike, Sequence[PathLike]],
    condition: str = "nominal",
    road: Optional[str] = None,
    fs: Optional[float] = None,
    scale: float = 1.0,
    unit: Optional[str] = None,
) -> List[Dict[str, Any]]:
    """Stores the features of ``files`` for ``vehicle`` (``condition`` 'nominal' or 'test');
    a file already stored is not stored twice. Returns one dict per file."""
    return json.loads(
        _native.fleet_ingest(os.fspath(db), vehicle, _paths(files), condition, road, fs, float(scale), unit)
    )


def baseline(db: PathLike, vehicle: str) -> Dict[str, Any]:
    """Builds the vehicle's nominal model set from its nominal records (at least 5); returns it."""
    return json.loads(_native.fleet_baseline(os.fspath(db), vehicle))


def check(
    db: PathLike,
    vehicle: str,
    files: Union[PathLike, Sequence[PathLike]],
    fs: Optional[float] = None,
    scale: float = 1.0,
    unit: Optional[str] = None,
) -> Dict[str, Any]:
    """Classifies ``files`` against the vehicle's latest model set (``vibmode fleet check
    --json``): ``{'vehicle', 'model_version', 'records': [...]}``, each record with its
    ``assessment`` (classification, scores, evidence)."""
    return json.loads(_native.fleet_check(os.fspath(db), vehicle, _paths(files), fs, float(scale), unit))


def status(db: PathLike, last: int = 10) -> List[Dict[str, Any]]:
    """Status of every vehicle in the store, with its last ``last`` records."""
    return json.loads(_native.fleet_status(os.fspath(db), int(last)))


def features(path: PathLike, fs: Optional[float] = None, scale: float = 1.0, unit: Optional[str] = None) -> Dict[str, Any]:
    """What the store keeps of one file (band levels, transmissibility, modes), computed without
    a store: the expensive part of :func:`ingest`, to run on many workers (e.g. Dask). Returns a
    JSON-ready dict ``{'file', 'sha256', 'metadata', 'features'}`` for :func:`store_features`."""
    return json.loads(_native.fleet_features(os.fspath(path), fs, float(scale), unit))


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
