"""vibmode.fleet.register: a vehicle's model file for the suspension fitted per drive, as
`vibmode fleet register` (the CLI test tests/cli_fleet_suspension.rs checks the fit itself)."""

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
    with sqlite3.connect(str(db)) as c:
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
    with sqlite3.connect(str(db)) as c:
        assert c.execute("SELECT COUNT(*) FROM vehicle_models").fetchone()[0] == 0
        assert c.execute("SELECT COUNT(*) FROM vehicles").fetchone()[0] == 0
