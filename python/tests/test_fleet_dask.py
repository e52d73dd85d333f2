"""examples/fleet_dask.py on a two-worker LocalCluster gives the single-process results."""

import importlib.util
import sys
from pathlib import Path

import pandas as pd
import pytest

import vibmode

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fleet_dask.py"

distributed = pytest.importorskip("dask.distributed")
pytest.importorskip("pyarrow")


def load_example():
    spec = importlib.util.spec_from_file_location("fleet_dask", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["fleet_dask"] = mod
    spec.loader.exec_module(mod)
    return mod


def test_two_workers_equal_single_process(tmp_path):
    fd = load_example()
    rec_dir = tmp_path / "records"
    vibmode.simulate("city_bus", records=4, fs=200.0, effects="none", seed=11, out_dir=rec_dir)
    settings = {"order_max": 8}

    single = fd.run(str(rec_dir), str(tmp_path / "single"), None, settings,
                    store=str(tmp_path / "single.db"), vehicle="bus-9")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  env={"RAYON_NUM_THREADS": "1"}, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        dist = fd.run(str(rec_dir), str(tmp_path / "dask"), client, settings,
                      store=str(tmp_path / "dask.db"), vehicle="bus-9")

    cols = [c for c in single.columns if c != "seconds"]
    pd.testing.assert_frame_equal(single[cols], dist[cols])
    assert list(single["record"]) == [f"record_{i:02d}.wav" for i in range(1, 5)]
    a = pd.read_parquet(tmp_path / "single" / "modes").sort_values(["record", "pool_kind", "pool", "frequency_hz"]).reset_index(drop=True)
    b = pd.read_parquet(tmp_path / "dask" / "modes").sort_values(["record", "pool_kind", "pool", "frequency_hz"]).reset_index(drop=True)
    assert len(a) > 0 and set(a["record"]) == set(single["record"])
    pd.testing.assert_frame_equal(a, b)
    # The per-record table is the one-record analysis of each file.
    one = vibmode.analyze(str(rec_dir / "record_02.wav"), order_max=8, as_frames=False)
    expect = fd.modes_table("record_02.wav", one)
    got = a[a["record"] == "record_02.wav"].sort_values(["pool_kind", "pool", "frequency_hz"]).reset_index(drop=True)
    expect = expect.sort_values(["pool_kind", "pool", "frequency_hz"]).reset_index(drop=True)
    pd.testing.assert_frame_equal(got, expect, check_dtype=False)
    # The two stores hold the same records.
    assert vibmode.fleet.status(tmp_path / "single.db") == vibmode.fleet.status(tmp_path / "dask.db")
    assert vibmode.fleet.status(tmp_path / "dask.db")[0]["n_nominal"] == 4


def test_cli_single_process(tmp_path):
    fd = load_example()
    vibmode.simulate("city_bus", records=2, fs=200.0, effects="none", seed=12, out_dir=tmp_path / "r")
    assert fd.main([str(tmp_path / "r"), "-o", str(tmp_path / "o"), "--single-process", "--set", "order_max=6"]) == 0
    assert len(pd.read_parquet(tmp_path / "o" / "records.parquet")) == 2
    with pytest.raises(FileNotFoundError):
        fd.run(str(tmp_path / "empty"), str(tmp_path / "o2"))
