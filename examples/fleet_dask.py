#!/usr/bin/env python3
"""Fleet-scale batch analysis on Dask: every recording of a folder (or an fsspec URL such as
s3://bucket/fleet/2026-11/) analysed on its own by vibmode on a dask.distributed cluster,
per-record results written to Parquet, and optionally the fleet store fed.

    pip install ./python "dask[distributed]" pandas pyarrow       # + s3fs/gcsfs for object storage
    python examples/fleet_dask.py RECORDS_DIR -o results/           # LocalCluster, 2 workers
    python examples/fleet_dask.py s3://bucket/fleet/ -o s3://bucket/results/ --scheduler tcp://host:8786
    python examples/fleet_dask.py RECORDS_DIR -o results/ --store fleet.db --vehicle bus-017

Outputs (any fsspec URL): OUT/modes/<record>-<digest>.parquet (one row per invariant mode of the record,
per channel and per role; written by the worker that analysed it), OUT/records.parquet (one row
per record: rate, length, fits, modes, seconds) and, with --store and --condition test,
OUT/checks.parquet (the store's classification of each record).

The fleet store is SQLite: one writer. The workers compute each record's store features
(vibmode.fleet.features, the expensive part); this process alone writes them
(vibmode.fleet.store_features). The workers use the store's settings (vibmode.fleet.settings,
read once by this process): initialise the store with `vibmode fleet init --db fleet.db --config
fleet.toml` first for other settings than the defaults. See docs/scaling.md.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import json
import os
import sys
import tempfile
import time
from typing import Any, Dict, Iterator, List, Optional

import pandas as pd

import vibmode

if __name__ != "__main__":
    # Imported (e.g. by the tests): ship this module's functions to the workers by value, as
    # they cannot import it by name.
    try:
        import cloudpickle

        cloudpickle.register_pickle_by_value(sys.modules[__name__])
    except (ImportError, AttributeError, ValueError):  # pragma: no cover
        pass

EXTENSIONS = (".wav", ".csv", ".txt", ".tsv", ".dat", ".f32", ".f64", ".bin", ".raw")


def _fs(url: str, storage_options: Dict[str, Any]):
    import fsspec

    return fsspec.core.url_to_fs(url, **storage_options)


def _is_local(fs) -> bool:
    proto = fs.protocol if isinstance(fs.protocol, (tuple, list)) else (fs.protocol,)
    return "file" in proto or "local" in proto


def list_records(source: str, pattern: str = "*", storage_options: Optional[Dict[str, Any]] = None) -> List[str]:
    """The recordings under `source` (a folder, a file or an fsspec URL), sorted by name."""
    so = storage_options or {}
    fs, root = _fs(source, so)
    if fs.isfile(root):
        return [source]
    files = sorted(f for f in fs.glob(root.rstrip("/") + "/" + pattern) if f.lower().endswith(EXTENSIONS))
    if _is_local(fs):
        # Named as the user gave the folder (relative stays relative), as `vibmode analyze`
        # and `vibmode fleet ingest` name records.
        return [os.path.join(source, os.path.relpath(f, root)) for f in files]
    return [fs.unstrip_protocol(f) for f in files]


@contextlib.contextmanager
def local_copy(url: str, storage_options: Dict[str, Any]) -> Iterator[str]:
    """A local path of `url`: the file itself, or a temporary download (with its sidecar)."""
    fs, path = _fs(url, storage_options)
    if _is_local(fs):
        yield path
        return
    with tempfile.TemporaryDirectory(prefix="vibmode-") as d:
        local = os.path.join(d, os.path.basename(path))
        fs.get(path, local)
        stem, ext = os.path.splitext(path)
        if ext.lower() in (".f32", ".f64", ".bin", ".raw"):
            for side in (path + ".json", stem + ".json"):
                if fs.exists(side):
                    fs.get(side, os.path.join(d, os.path.basename(side)))
        yield local


def _scalar(v: Any) -> Any:
    if v is None or isinstance(v, (bool, int, float, str)):
        return v
    return json.dumps(v)


def modes_table(record: str, res: Dict[str, Any]) -> pd.DataFrame:
    """One row per invariant mode of `res` (vibmode.analyze(..., as_frames=False)), per channel
    and per role pool; nested fields as JSON text (Parquet-friendly)."""
    rows = []
    for ch in res["channels"]:
        for m in ch["invariant_modes"]:
            rows.append({"record": record, "pool_kind": "channel", "pool": ch["name"], "role": ch["role"],
                         **{k: _scalar(v) for k, v in m.items()}})
    for ro in res["roles"]:
        for m in ro["invariant_modes"]:
            rows.append({"record": record, "pool_kind": "role", "pool": ro["role"], "role": ro["role"],
                         **{k: _scalar(v) for k, v in m.items()}})
    return pd.DataFrame(rows)


def analyze_record(
    url: str,
    out: str,
    analysis: Dict[str, Any],
    fs_hz: Optional[float] = None,
    with_features: bool = False,
    storage_options: Optional[Dict[str, Any]] = None,
    settings: Optional[Dict[str, Any]] = None,
    model: Optional[str] = None,
    content_hash: Optional[str] = None,
) -> Dict[str, Any]:
    """The per-record task: analyse one recording, write OUT/modes/<record>.parquet, return its
    summary row (and its fleet-store features when asked, computed with the store's `settings`,
    vibmode.fleet.settings(db), and the vehicle's registered model file, vibmode.fleet.model(db,
    vehicle), whose body equations `fleet ingest` keeps too, keyed by the store's content hash,
    vibmode.fleet.content_hash(db))."""
    so = storage_options or {}
    t0 = time.perf_counter()
    # The record is named by its path or URL as listed (as `vibmode analyze` and `vibmode fleet
    # ingest` name records: run1/record_01.wav and run2/record_01.wav stay apart), also when a
    # remote file is analysed from a temporary copy.
    name = url
    with local_copy(url, so) as path:
        res = vibmode.analyze(path, fs=fs_hz, as_frames=False, **analysis)
        feats = (
            vibmode.fleet.features(path, fs=fs_hz, settings=settings, model=model,
                                   content_hash=content_hash)
            if with_features
            else None
        )
    if feats is not None:
        # Stored under the record as the user named it (as `vibmode fleet ingest` does), not
        # under the temporary copy of a remote file.
        feats["file"] = url
    table = modes_table(name, res)
    # One file per record: its base name and a digest of the full name, as records of two
    # folders may share a base name.
    digest = hashlib.sha256(name.encode("utf-8")).hexdigest()[:12]
    stem = os.path.splitext(os.path.basename(name.rstrip("/")))[0]
    target = out.rstrip("/") + "/modes/" + f"{stem}-{digest}.parquet"
    ofs, opath = _fs(target, so)
    ofs.makedirs(opath.rsplit("/", 1)[0], exist_ok=True)
    with ofs.open(opath, "wb") as f:
        table.to_parquet(f, index=False)
    recs = res["records"]
    summary = {
        "record": name,
        "fs_hz": recs[0]["fs_hz"],
        "n_samples": sum(r["n_samples"] for r in recs),
        "duration_s": sum(r["duration_s"] for r in recs),
        "n_records": len(recs),
        "n_fits": res["n_fits"],
        "n_not_converged": res["n_not_converged"],
        "n_failed": res["n_failed"],
        "n_modes": len(table),
        "seconds": time.perf_counter() - t0,
    }
    return {"summary": summary, "features": feats}


def run(
    source: str,
    out: str,
    client=None,
    analysis: Optional[Dict[str, Any]] = None,
    fs_hz: Optional[float] = None,
    pattern: str = "*",
    store: Optional[str] = None,
    vehicle: Optional[str] = None,
    condition: str = "nominal",
    road: Optional[str] = None,
    storage_options: Optional[Dict[str, Any]] = None,
) -> pd.DataFrame:
    """Analyses every recording of `source` (on `client`'s cluster, or in this process when
    `client` is None) and writes the Parquet outputs under `out`; returns the records table."""
    analysis = dict(analysis or {})
    so = storage_options or {}
    files = list_records(source, pattern, so)
    if not files:
        raise FileNotFoundError(f"no recordings ({', '.join(EXTENSIONS)}) under {source}")
    if store is not None and not vehicle:
        raise ValueError("--store needs --vehicle ID")
    feats = store is not None
    settings = None
    model = None
    content_hash = None
    if store is not None:
        # The store's settings (`vibmode fleet init --config`, or the defaults), read once here and
        # shipped to every task: the workers' features are then the ones `fleet ingest` stores.
        vibmode.fleet.init(store)
        settings = vibmode.fleet.settings(store)
        model = vibmode.fleet.model(store, vehicle)
        content_hash = vibmode.fleet.content_hash(store)
    if client is None:
        results = [analyze_record(f, out, analysis, fs_hz, feats, so, settings, model, content_hash)
                   for f in files]
    else:
        # A lambda is shipped by value (cloudpickle), with analyze_record inside it: the workers
        # need vibmode installed, not this script.
        task = lambda url: analyze_record(  # noqa: E731
            url, out, analysis, fs_hz, feats, so, settings, model, content_hash)
        futures = client.map(task, files, pure=False)
        results = client.gather(futures)
    records = pd.DataFrame([r["summary"] for r in results])
    ofs, opath = _fs(out.rstrip("/") + "/records.parquet", so)
    with ofs.open(opath, "wb") as f:
        records.to_parquet(f, index=False)
    if store is not None:
        # One writer: the store is fed from this process only.
        stored = vibmode.fleet.store_features(store, vehicle, [r["features"] for r in results], condition, road)
        print(f"store {store}: {sum(not s['already_stored'] for s in stored)} new {condition} record(s) of {vehicle}",
              file=sys.stderr)
        if condition == "test":
            local = [f for f in files if os.path.exists(f)]
            if len(local) < len(files):
                print(f"{len(files) - len(local)} remote record(s) stored but not checked: run "
                      "vibmode.fleet.check on local copies", file=sys.stderr)
            checked = vibmode.fleet.check(store, vehicle, local, fs=fs_hz)["records"]
            table = pd.DataFrame([{k: _scalar(v) for k, v in c.items()} for c in checked])
            cfs, cpath = _fs(out.rstrip("/") + "/checks.parquet", so)
            with cfs.open(cpath, "wb") as f:
                table.to_parquet(f, index=False)
    return records


def _settings(items: List[str]) -> Dict[str, Any]:
    """`KEY=VALUE` analysis settings (flat keys of docs/analysis.md, e.g. order_max=12)."""
    out: Dict[str, Any] = {}
    for it in items:
        k, sep, v = it.partition("=")
        if not sep:
            raise SystemExit(f"--set {it!r}: use KEY=VALUE, e.g. --set order_max=12")
        try:
            out[k] = json.loads(v)
        except json.JSONDecodeError:
            out[k] = v
    return out


def main(argv: Optional[List[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("source", help="folder, file or fsspec URL of the recordings")
    ap.add_argument("-o", "--out", required=True, help="output folder or fsspec URL")
    ap.add_argument("--scheduler", help="address of a running dask scheduler (default: a LocalCluster)")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster workers (processes), default 2")
    ap.add_argument("--threads-per-worker", type=int, default=1,
                    help="tasks per worker at a time; vibmode's own threads follow it (RAYON_NUM_THREADS)")
    ap.add_argument("--memory-limit", default="auto", help="LocalCluster memory limit per worker, e.g. 2GiB")
    ap.add_argument("--single-process", action="store_true", help="no Dask: analyse in this process")
    ap.add_argument("--pattern", default="*", help="glob of the recordings under SOURCE (default all)")
    ap.add_argument("--fs", type=float, help="sampling rate (Hz) for files without a time column")
    ap.add_argument("--config", help="analysis settings (TOML file)")
    ap.add_argument("--preset", help="vibmode (default) or paper")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="analysis setting, e.g. order_max=12")
    ap.add_argument("--store", help="fleet store (SQLite file on this machine) to feed, with its own settings")
    ap.add_argument("--vehicle", help="vehicle id for --store")
    ap.add_argument("--condition", default="nominal", choices=["nominal", "test"])
    ap.add_argument("--road", help="road label for --store")
    ap.add_argument("--storage-option", action="append", default=[], metavar="KEY=VALUE",
                    help="fsspec storage option, e.g. anon=true")
    a = ap.parse_args(argv)
    analysis = _settings(a.set)
    if a.config:
        analysis["config"] = a.config
    if a.preset:
        analysis["preset"] = a.preset
    so = _settings(a.storage_option)
    t0 = time.perf_counter()
    if a.single_process:
        records = run(a.source, a.out, None, analysis, a.fs, a.pattern, a.store, a.vehicle, a.condition, a.road, so)
        where = "1 process"
    else:
        from dask.distributed import Client, LocalCluster

        if a.scheduler:
            client = Client(a.scheduler)
            cluster = None
        else:
            cluster = LocalCluster(
                n_workers=a.workers, threads_per_worker=a.threads_per_worker, processes=True,
                memory_limit=a.memory_limit, env={"RAYON_NUM_THREADS": str(a.threads_per_worker)},
                dashboard_address=None,
            )
            client = Client(cluster)
        try:
            t0 = time.perf_counter()
            records = run(a.source, a.out, client, analysis, a.fs, a.pattern, a.store, a.vehicle, a.condition, a.road, so)
            n = len(client.scheduler_info().get("workers", {}))
            where = f"{n} worker(s)"
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    dt = time.perf_counter() - t0
    print(f"{len(records)} record(s) in {dt:.1f} s on {where}: {len(records) / dt:.2f} records/s "
          f"(median {records['seconds'].median():.2f} s per record); results in {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
