"""examples/fleet_dask.py on a two-worker LocalCluster gives the single-process results."""

import importlib.util
import json
import os
import sqlite3
import sys
from pathlib import Path

import pandas as pd
import pytest

import vibmode

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fleet_dask.py"
CITY_BUS = Path(__file__).resolve().parents[2] / "examples" / "city_bus.toml"

distributed = pytest.importorskip("dask.distributed")
pytest.importorskip("pyarrow")


# Store settings other than the defaults (five bands 0.5-20 Hz): they change every band feature.
BANDS = [[1.0, 3.0], [3.0, 7.0], [7.0, 15.0]]
CONFIG_TOML = "bands_hz = [[1.0, 3.0], [3.0, 7.0], [7.0, 15.0]]\nfloor_level = 0.2\n"


def stored_features(db):
    """{file name: features} as the store keeps them (the features table's JSON)."""
    with sqlite3.connect(str(db)) as c:
        rows = c.execute(
            "SELECT r.file_name, f.json FROM records r JOIN features f ON f.record_id = r.id"
        ).fetchall()
    return {name: json.loads(j) for name, j in rows}


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
    # Both stores with non-default settings: the workers must use them, not the defaults.
    # And the vehicle's model file registered: the workers keep each record's body equations
    # (the suspension fitted per drive) as `ingest` does.
    for db in ("single.db", "dask.db", "ingest.db"):
        vibmode.fleet.init(tmp_path / db, config=CONFIG_TOML)
        assert vibmode.fleet.register(tmp_path / db, "bus-9", CITY_BUS) == "new"

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
    # Records are named by their path (the folder as given joined with the file), by the
    # workers as in one process.
    assert list(single["record"]) == [os.path.join(str(rec_dir), f"record_{i:02d}.wav") for i in range(1, 5)]
    a = pd.read_parquet(tmp_path / "single" / "modes").sort_values(["record", "pool_kind", "pool", "frequency_hz"]).reset_index(drop=True)
    b = pd.read_parquet(tmp_path / "dask" / "modes").sort_values(["record", "pool_kind", "pool", "frequency_hz"]).reset_index(drop=True)
    assert len(a) > 0 and set(a["record"]) == set(single["record"])
    pd.testing.assert_frame_equal(a, b)
    # The per-record table is the one-record analysis of each file.
    one = vibmode.analyze(str(rec_dir / "record_02.wav"), order_max=8, as_frames=False)
    expect = fd.modes_table(str(rec_dir / "record_02.wav"), one)
    got = a[a["record"] == str(rec_dir / "record_02.wav")].sort_values(["pool_kind", "pool", "frequency_hz"]).reset_index(drop=True)
    expect = expect.sort_values(["pool_kind", "pool", "frequency_hz"]).reset_index(drop=True)
    pd.testing.assert_frame_equal(got, expect, check_dtype=False)
    # The two stores hold the same records.
    assert vibmode.fleet.status(tmp_path / "single.db") == vibmode.fleet.status(tmp_path / "dask.db")
    assert vibmode.fleet.status(tmp_path / "dask.db")[0]["n_nominal"] == 4
    # The workers' features are those `ingest` computes with the store's settings.
    files = sorted(rec_dir.glob("record_*.wav"))
    vibmode.fleet.ingest(tmp_path / "ingest.db", "bus-9", files)
    by_ingest = stored_features(tmp_path / "ingest.db")
    by_workers = stored_features(tmp_path / "dask.db")
    assert len(by_ingest) == 4 and by_workers == by_ingest
    assert all("suspension" in f for f in by_ingest.values()), by_ingest
    default = vibmode.fleet.features(files[0])["features"]
    # Records are stored under the path as given (run1/record_01.wav and run2/record_01.wav
    # stay apart), by the workers as by `ingest`.
    assert default != by_ingest[str(files[0])]


def test_cli_single_process(tmp_path):
    fd = load_example()
    vibmode.simulate("city_bus", records=2, fs=200.0, effects="none", seed=12, out_dir=tmp_path / "r")
    assert fd.main([str(tmp_path / "r"), "-o", str(tmp_path / "o"), "--single-process", "--set", "order_max=6"]) == 0
    assert len(pd.read_parquet(tmp_path / "o" / "records.parquet")) == 2
    with pytest.raises(FileNotFoundError):
        fd.run(str(tmp_path / "empty"), str(tmp_path / "o2"))


def test_store_settings_reach_features(tmp_path):
    vibmode.simulate("city_bus", records=1, fs=200.0, effects="none", seed=13, out_dir=tmp_path / "r")
    path = tmp_path / "r" / "record_01.wav"
    db = tmp_path / "custom.db"
    assert vibmode.fleet.init(db, config={"bands_hz": BANDS, "floor_level": 0.2}) is True
    s = vibmode.fleet.settings(db)
    assert s["bands_hz"] == BANDS and s["floor_level"] == 0.2
    assert json.loads(json.dumps(s)) == s  # plain values: ships to workers as JSON or pickle
    # A default store's settings are the defaults.
    vibmode.fleet.init(tmp_path / "default.db")
    d = vibmode.fleet.settings(tmp_path / "default.db")
    assert len(d["bands_hz"]) == 5 and d != s
    # Features with the store's settings are what ingest stores; with the defaults they differ.
    vibmode.fleet.ingest(db, "bus-1", path)
    stored = stored_features(db)[str(path)]
    assert vibmode.fleet.features(path)["file"] == str(path)
    with_settings = vibmode.fleet.features(path, settings=s)
    assert with_settings["features"] == stored
    assert vibmode.fleet.features(path, settings=d)["features"] == vibmode.fleet.features(path)["features"]
    assert vibmode.fleet.features(path)["features"] != stored
    # The same features stored through store_features are a no-op on that store.
    assert vibmode.fleet.store_features(db, "bus-1", [with_settings])[0]["already_stored"] is True
    # The same settings again are a no-op; other settings once records exist are refused.
    assert vibmode.fleet.init(db, config=CONFIG_TOML) is False
    with pytest.raises(ValueError, match="already holds 1 record"):
        vibmode.fleet.init(db, config={"bands_hz": [[1.0, 2.0]]})


def test_bad_settings_raise(tmp_path):
    vibmode.simulate("city_bus", records=1, fs=200.0, effects="none", seed=14, out_dir=tmp_path / "r")
    path = tmp_path / "r" / "record_01.wav"
    vibmode.fleet.init(tmp_path / "s.db")
    good = vibmode.fleet.settings(tmp_path / "s.db")
    cases = [
        ("bands", "settings of type str"),
        ({**good, "bands_hz": [[5.0, 2.0]]}, "bands_hz"),
        ({**good, "no_such_key": 1}, "no_such_key"),
    ]
    for settings, match in cases:
        with pytest.raises(ValueError, match=match) as e:
            vibmode.fleet.features(path, settings=settings)
        assert "\n" not in str(e.value)
    with pytest.raises(ValueError, match="bands_hz"):
        vibmode.fleet.init(tmp_path / "bad.db", config={"bands_hz": [[1.0, 100.0]]})
    assert not (tmp_path / "bad.db").exists()  # checked before the store is created
    with pytest.raises(OSError):
        vibmode.fleet.settings(tmp_path / "missing.db")


def test_features_carry_the_stores_content_hash(tmp_path):
    """A store made now keys records by BLAKE3; features hashed with another function are
    refused by store_features with one line naming both, and nothing is stored."""
    vibmode.simulate("city_bus", records=1, fs=200.0, effects="none", seed=15, out_dir=tmp_path / "r")
    path = tmp_path / "r" / "record_01.wav"
    db = tmp_path / "h.db"
    vibmode.fleet.init(db)
    assert vibmode.fleet.content_hash(db) == "blake3"
    item = vibmode.fleet.features(path, content_hash=vibmode.fleet.content_hash(db))
    assert item["content_hash_kind"] == "blake3" and len(item["content_hash"]) == 64
    other = vibmode.fleet.features(path, content_hash="sha256")
    assert other["content_hash"] != item["content_hash"]
    with pytest.raises(ValueError, match="hashed with sha256, the store keys records by blake3") as e:
        vibmode.fleet.store_features(db, "bus-1", [other])
    assert "\n" not in str(e.value)
    assert stored_features(db) == {}
    with pytest.raises(ValueError, match="'md5' is not one of sha256, blake3"):
        vibmode.fleet.features(path, content_hash="md5")
    assert vibmode.fleet.store_features(db, "bus-1", [item])[0]["already_stored"] is False
    # The CLI's ingest of the same file keys it the same way: a no-op.
    assert vibmode.fleet.ingest(db, "bus-1", [path])[0]["already_stored"] is True


def test_a_record_of_another_vehicle_gets_the_same_note_from_workers_and_ingest(tmp_path):
    """A record whose content the store holds for another vehicle is stored with a note naming
    it, by store_features (the workers' path) exactly as by ingest (the CLI's)."""
    vibmode.simulate("city_bus", records=2, fs=200.0, effects="none", seed=17, out_dir=tmp_path / "r")
    first, second = (str(tmp_path / "r" / f"record_0{k}.wav") for k in (1, 2))
    db = tmp_path / "o.db"
    vibmode.fleet.init(db)
    vibmode.fleet.ingest(db, "bus-1", [first, second])
    kind = vibmode.fleet.content_hash(db)
    by_worker = vibmode.fleet.store_features(db, "bus-2", [vibmode.fleet.features(first, content_hash=kind)])
    by_ingest = vibmode.fleet.ingest(db, "bus-3", [second])
    note = "its content is stored for vehicle 'bus-1' too: a record is of one vehicle"
    assert [n for n in by_worker[0]["notes"] if n.startswith("its content")] == [
        n for n in by_ingest[0]["notes"] if n.startswith("its content")
    ]
    assert any(n.startswith(note) for n in by_worker[0]["notes"]), by_worker
    # Stored again: already stored, no note.
    again = vibmode.fleet.store_features(db, "bus-2", [vibmode.fleet.features(first, content_hash=kind)])
    assert again[0]["already_stored"] is True and again[0]["notes"] == []
