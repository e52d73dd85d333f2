"""vibmode.fleet.register: a vehicle's model file for the suspension fitted per drive, as
`vibmode fleet register` (the CLI test tests/integration/cli_fleet_suspension.rs checks the fit itself)."""

import contextlib
import sqlite3
from pathlib import Path

import pytest

import vibmode

CITY_BUS = Path(__file__).resolve().parents[2] / "examples" / "city_bus.toml"


def test_register_stores_the_file_once(tmp_path):
    db = tmp_path / "fleet.db"
    vibmode.fleet.init(db)
    assert vibmode.fleet.register(db, "bus-1", CITY_BUS) == "new"
    assert vibmode.fleet.register(db, "bus-1", CITY_BUS) == "unchanged"
    other = tmp_path / "other.toml"
    other.write_text(CITY_BUS.read_text() + "\n# another revision\n")
    assert vibmode.fleet.register(db, "bus-1", other) == "replaced"
    assert vibmode.fleet.model(db, "bus-1") == other.read_text()
    assert vibmode.fleet.register(db, "bus-1", CITY_BUS) == "replaced"
    with contextlib.closing(sqlite3.connect(str(db))) as c:
        rows = c.execute(
            "SELECT v.name, m.toml FROM vehicle_models m JOIN vehicles v ON v.id = m.vehicle_id"
        ).fetchall()
    assert [r[0] for r in rows] == ["bus-1"]
    assert vibmode.fleet.model(db, "bus-2") is None
    assert rows[0][1] == CITY_BUS.read_text()


def test_a_bad_model_file_raises_and_stores_nothing(tmp_path):
    db = tmp_path / "fleet.db"
    vibmode.fleet.init(db)
    junk = tmp_path / "junk.toml"
    junk.write_text("this is = not [ a vehicle")
    with pytest.raises(ValueError, match="vehicle model"):
        vibmode.fleet.register(db, "bus-1", junk)
    with pytest.raises(ValueError, match="missing.toml"):
        vibmode.fleet.register(db, "bus-1", tmp_path / "missing.toml")
    with contextlib.closing(sqlite3.connect(str(db))) as c:
        assert c.execute("SELECT COUNT(*) FROM vehicle_models").fetchone()[0] == 0
        assert c.execute("SELECT COUNT(*) FROM vehicles").fetchone()[0] == 0


def _stored(db):
    """{file name: features} as the store keeps them. The connection is closed before vibmode
    writes again: Python's sqlite3 and vibmode's own SQLite are two copies of the library in one
    process, and a connection of one left open across the other's writes and checkpoints reads a
    stale WAL index ("database disk image is malformed"; docs/fleet.md, "Store")."""
    import contextlib
    import json

    with contextlib.closing(sqlite3.connect(str(db))) as c:
        rows = c.execute(
            "SELECT r.file_name, f.json FROM records r JOIN features f ON f.record_id = r.id"
        ).fetchall()
    return {name: json.loads(j) for name, j in rows}


def test_workers_add_equations_to_records_stored_before_registering(tmp_path):
    rec_dir = tmp_path / "records"
    vibmode.simulate("city_bus", records=3, fs=200.0, effects="none", seed=13, out_dir=rec_dir)
    files = sorted(rec_dir.glob("record_*.wav"))
    db = tmp_path / "workers.db"
    vibmode.fleet.init(db)
    settings = vibmode.fleet.settings(db)
    items = [vibmode.fleet.features(f, settings=settings) for f in files]
    out = vibmode.fleet.store_features(db, "bus-1", items)
    assert not any(o["already_stored"] for o in out)
    assert not any("suspension" in f for f in _stored(db).values())
    assert vibmode.fleet.register(db, "bus-1", CITY_BUS) == "new"
    model = vibmode.fleet.model(db, "bus-1")
    items = [vibmode.fleet.features(f, settings=settings, model=model) for f in files]
    out = vibmode.fleet.store_features(db, "bus-1", items)
    assert all(o["already_stored"] for o in out)
    assert all(any("body equations added" in n for n in o["notes"]) for o in out), out
    # The same as `ingest` into a store whose model file was registered first.
    first = tmp_path / "first.db"
    vibmode.fleet.init(first)
    vibmode.fleet.register(first, "bus-1", CITY_BUS)
    vibmode.fleet.ingest(first, "bus-1", files)
    assert _stored(db) == _stored(first)
    # Again: nothing to do.
    out = vibmode.fleet.store_features(db, "bus-1", items)
    assert all(o["already_stored"] and not o["notes"] for o in out), out


def test_the_third_drive_pools_its_springs_with_the_two_before(tmp_path):
    # As `vibmode fleet check` (docs/fleet.md, "The spring trend"): the first two drives after
    # the baseline say why they have no trend; the third's pools the three, newest first.
    db = tmp_path / "fleet.db"
    vibmode.fleet.init(db)
    assert vibmode.fleet.register(db, "bus-1", CITY_BUS) == "new"
    nominal = tmp_path / "nominal"
    vibmode.simulate("city_bus", records=6, fs=200.0, seed=21, out_dir=nominal)
    vibmode.fleet.ingest(db, "bus-1", sorted(nominal.glob("record_*.wav")))
    base = vibmode.fleet.baseline(db, "bus-1")
    assert base["suspension"]["fit"]["records"] == 6
    drives = []
    for k, name in enumerate(["mon", "tue", "wed"]):
        folder = tmp_path / name
        vibmode.simulate("city_bus", records=3, fs=200.0, seed=31 + k, out_dir=folder)
        out = vibmode.fleet.check(db, "bus-1", sorted(folder.glob("record_*.wav")), drive=name)
        drives.append(out["drives"][0])
    for k, d in enumerate(drives[:2]):
        assert "trend" not in d["suspension"], d
        assert any(
            m.startswith("suspension fit: no spring trend over the last 3 drives yet: "
                         f"{k} of the 2 earlier drives")
            for m in d["missing"]
        ), d["missing"]
    trend = drives[2]["suspension"]["trend"]
    assert trend["drives"] == ["wed", "tue", "mon"]
    assert [s["corner"] for s in trend["scores"]] == ["FL", "FR", "RL", "RR"]
    assert all(s["part"] == "spring" for s in trend["scores"])
    # Each score's ratio t has Welch-Satterthwaite's degrees of freedom of its parts (three
    # drives of 3 records: 2 each, up to 6 with a drive's spring variances read as one scale
    # over the corners; the baseline of 6: 5), between the smallest and their sum, and its
    # normal score z is nearer 0 with the same sign (docs/fleet.md, "Scores of estimated
    # spread", "A drive's spring variances as one scale over the corners").
    for s in trend["scores"]:
        assert 2.0 <= s["df"] <= 23.0, s
        assert abs(s["z"]) <= abs(s["t"]) + 1e-12 and s["z"] * s["t"] >= 0, s
    # Phi^-1(1 - 0.01 / 8): the trend's half of the fit's 1 % over its 4 tests.
    assert abs(trend["limit"] - 3.0233414) < 1e-6


def test_baseline_holds_each_nominal_drive_out(tmp_path):
    """Nominal records of two folders are two drives: the baseline checks each against a model
    set of the other's records (`held_out_drives`, both `normal` on two healthy drives of the
    same road and speed), and the status states the measured rate per drive with its bound
    (0 of 2: 1 - 0.05^(1/2) = 77.6 %). The coherence gate's setting is read from the store's
    settings like every other key."""
    db = tmp_path / "fleet.db"
    vibmode.fleet.init(db, {"transmissibility_min_coherence": 0.1})
    assert vibmode.fleet.settings(db)["transmissibility_min_coherence"] == 0.1
    for name, seed in (("mon", 71), ("tue", 72)):
        vibmode.simulate("city_bus", records=5, fs=200.0, effects="none", seed=seed,
                         out_dir=tmp_path / name)
    stored = vibmode.fleet.ingest(db, "bus-1", [tmp_path / "mon", tmp_path / "tue"],
                                  condition="nominal")
    assert len(stored) == 10, str(stored)
    result = vibmode.fleet.baseline(db, "bus-1")
    held = result["held_out_drives"]
    assert [Path(h["drive"]).name for h in held] == ["mon", "tue"], held
    assert [h["classification"] for h in held] == ["normal", "normal"], held
    assert [h["reference_records"] for h in held] == [5, 5]
    assert "leave-one-drive-out: 2 nominal drive(s)" in str(result)
    status = vibmode.fleet.status(db)
    assert "a rate of at most 77.6 %" in str(status), str(status)
    with pytest.raises(ValueError, match="transmissibility_min_coherence"):
        vibmode.fleet.init(tmp_path / "bad.db", {"transmissibility_min_coherence": 1.5})


def test_status_keeps_an_earlier_flagged_drive(tmp_path):
    """A drive flagged `vehicle` (RL damper at 50 %) and a healthy drive after it: the status
    keeps the flagged drive as `earlier_flag` beneath the latest `normal`, as `fleet status`
    prints it (docs/fleet.md)."""
    db = tmp_path / "fleet.db"
    vibmode.fleet.init(db)
    vibmode.simulate("city_bus", records=6, fs=200.0, seed=11, out_dir=tmp_path / "nominal",
                     format="csv")
    vibmode.fleet.ingest(db, "bus-1", tmp_path / "nominal", condition="nominal")
    vibmode.fleet.baseline(db, "bus-1")
    bus = Path(__file__).resolve().parents[2] / "examples" / "city_bus.toml"
    worn = tmp_path / "worn.toml"
    worn.write_text(bus.read_text()
                    + '\n[[corner_condition]]\ncorner = "RL"\ndamper_factor = 0.5\n')
    vibmode.simulate(worn, records=4, fs=200.0, seed=21, out_dir=tmp_path / "worn", format="csv")
    first = vibmode.fleet.check(db, "bus-1", tmp_path / "worn", drive="day-1")
    assert first["drives"][0]["classification"] == "vehicle", str(first)
    vibmode.simulate("city_bus", records=4, fs=200.0, seed=22, out_dir=tmp_path / "ok",
                     format="csv")
    second = vibmode.fleet.check(db, "bus-1", tmp_path / "ok", drive="day-2")
    assert second["drives"][0]["classification"] == "normal", str(second)
    assert second["earlier_flag"]["drive"]["drive"] == "day-1", str(second)
    assert "note: earlier drive flagged vehicle (RL" in str(second), str(second)
    status = vibmode.fleet.status(db)
    flag = status[0]["earlier_flag"]
    assert flag["drive"]["drive"] == "day-1" and flag["later_drives"] == 1, flag
    assert (flag["flagged_drives"], flag["baseline_drives"]) == (1, 2), flag
    assert "earlier drive flagged vehicle (RL" in str(status), str(status)
