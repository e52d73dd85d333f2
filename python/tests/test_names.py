"""Records are named by the path as given (relative stays relative), not by the base name:
vibmode.read, vibmode.analyze, vibmode.fleet and the Dask example's workers agree."""

import importlib.util
import os
import sqlite3
import sys
from pathlib import Path

import pandas as pd
import pytest

import vibmode

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fleet_dask.py"


def two_runs(root):
    """runs/a/record_01.wav and runs/b/record_01.wav (two drives, one base name) under `root`."""
    for sub, seed in (("a", 21), ("b", 22)):
        vibmode.simulate("city_bus", records=1, fs=200.0, effects="none", seed=seed,
                         out_dir=root / "runs" / sub)
    return [os.path.join("runs", "a", "record_01.wav"), os.path.join("runs", "b", "record_01.wav")]


def stored_names(db):
    with sqlite3.connect(str(db)) as c:
        return sorted(r[0] for r in c.execute("SELECT file_name FROM records"))


def test_read_analyze_fleet_name_records_by_the_given_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    paths = two_runs(tmp_path)
    assert vibmode.read(paths[0]).name == paths[0]
    assert vibmode.read(Path(paths[1])).name == paths[1]
    res = vibmode.analyze(paths, order_max=6, as_frames=False)
    assert [r["name"] for r in res["records"]] == paths
    # A recording read first keeps its name through the analysis.
    res = vibmode.analyze(vibmode.read(paths[1]), order_max=6, as_frames=False)
    assert [r["name"] for r in res["records"]] == [paths[1]]
    assert vibmode.fleet.features(paths[0])["file"] == paths[0]
    vibmode.fleet.init("fleet.db")
    got = vibmode.fleet.ingest("fleet.db", "bus-1", paths)
    assert sorted(g["file"] for g in got) == paths
    assert stored_names("fleet.db") == paths


def test_dask_workers_name_records_as_one_process(tmp_path, monkeypatch):
    distributed = pytest.importorskip("dask.distributed")
    pytest.importorskip("pyarrow")
    spec = importlib.util.spec_from_file_location("fleet_dask_names", EXAMPLE)
    fd = importlib.util.module_from_spec(spec)
    sys.modules["fleet_dask_names"] = fd
    spec.loader.exec_module(fd)
    monkeypatch.chdir(tmp_path)
    paths = two_runs(tmp_path)
    settings = {"order_max": 6}
    single = fd.run("runs", "single", None, settings, pattern="*/*.wav", store="single.db", vehicle="bus-1")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  env={"RAYON_NUM_THREADS": "1"}, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        dist = fd.run("runs", "dask", client, settings, pattern="*/*.wav", store="dask.db", vehicle="bus-1")
    assert list(single["record"]) == paths and list(dist["record"]) == paths
    cols = [c for c in single.columns if c != "seconds"]
    pd.testing.assert_frame_equal(single[cols], dist[cols])
    # One modes file per record although the base names are the same.
    for out in ("single", "dask"):
        assert len(list((tmp_path / out / "modes").glob("*.parquet"))) == 2
        assert sorted(set(pd.read_parquet(tmp_path / out / "modes")["record"])) == paths
    # The workers store what `ingest` stores, under the same names.
    vibmode.fleet.init("ingest.db")
    vibmode.fleet.ingest("ingest.db", "bus-1", paths)
    assert stored_names("dask.db") == stored_names("single.db") == stored_names("ingest.db") == paths


def test_a_folder_stands_for_its_recordings(tmp_path, monkeypatch):
    """A folder given to analyze, fleet.ingest or fleet.check is its recordings sorted by name,
    each named by its path (the folder joined with the file name), as `vibmode analyze DIR`."""
    monkeypatch.chdir(tmp_path)
    vibmode.simulate("city_bus", records=3, fs=200.0, effects="none", seed=5, out_dir="recs")
    (tmp_path / "recs" / "notes.txt.json").write_text("{}")
    files = sorted(os.path.join("recs", f) for f in os.listdir("recs") if f.endswith(".wav"))
    assert len(files) == 3
    by_folder = vibmode.analyze("recs", order_max=6, as_frames=False)
    by_files = vibmode.analyze(files, order_max=6, as_frames=False)
    assert [r["name"] for r in by_folder["records"]] == files
    by_folder.pop("timing", None)
    by_files.pop("timing", None)
    assert by_folder == by_files
    vibmode.fleet.init("fleet.db")
    got = vibmode.fleet.ingest("fleet.db", "bus-1", "recs")
    assert [g["file"] for g in got] == files
    os.mkdir("empty")
    with pytest.raises(ValueError, match="holds no recording"):
        vibmode.analyze("empty")
