"""Reading and writing, resampling, the analysis, the full-car model and the fleet store."""

import json
import pathlib
import tomllib

import numpy as np
import pandas as pd
import pytest
import scipy.signal as ss

import vibmode


@pytest.fixture(scope="module")
def sim():
    # 4 records of 10.24 s at 200 Hz of the shipped city bus on a class B road (pure road response).
    return vibmode.simulate("city_bus", records=4, fs=200.0, effects="none", seed=3)


@pytest.mark.parametrize("ext", ["csv", "wav", "f64"])
def test_write_read_round_trip(tmp_path, rng, ext):
    data = rng.standard_normal((2, 500))
    rec = vibmode.Recording(data, 250.0, ["z", "y"], ["m/s^2", "m/s^2"])
    path = tmp_path / f"rec.{ext}"
    vibmode.write(path, rec)
    x, fs, names = vibmode.read(path)
    assert fs == pytest.approx(250.0, rel=1e-9)
    assert names == ["z", "y"]
    tol = 1e-6 if ext == "wav" else 1e-12  # WAV stores 32-bit floats
    np.testing.assert_allclose(x, data, atol=tol * 10, rtol=tol)


def test_read_as_frame_and_channel_selection(tmp_path):
    p = tmp_path / "semi.csv"
    lines = ["Time (ms);Z-Axis [m/s^2];X [g]"] + [f"{i};{np.sin(i / 5):.6f};{i % 7}".replace(".", ",") for i in range(400)]
    p.write_text("\n".join(lines) + "\n")
    df = vibmode.read(p, as_frame=True)
    assert list(df.columns) == ["Z-Axis", "X"]
    assert df.attrs["fs"] == pytest.approx(1000.0)
    assert df.attrs["units"]["Z-Axis"] == "m/s^2"
    assert df.index.name == "time_s"
    rec = vibmode.read(p, channels=["X"])
    assert rec.channels == ["X"] and rec.data.shape == (1, 400)
    rec = vibmode.read(p, channels=[0])
    assert rec.channels == ["Z-Axis"]


def test_the_first_samples_time_is_read_when_the_file_tells_it(tmp_path):
    import datetime

    # 2026-11-27 23:59:59 UTC (20784 days after 1970-01-01) at 200 Hz, across midnight, written as
    # ISO date-times, as a US date with a 12-hour clock, and as Unix milliseconds.
    t0 = 20784 * 86400 + 86399.0
    rows = range(400)
    stamp = lambda i: datetime.datetime.fromtimestamp(t0 + i / 200, tz=datetime.timezone.utc)
    files = {
        "iso.csv": ["time,z"] + [f"{stamp(i).strftime('%Y-%m-%d %H:%M:%S.%f')},{i % 5}" for i in rows],
        "us.csv": ["timestamp,z"] + [f"{stamp(i).strftime('%m/%d/%Y %I:%M:%S.%f %p')},{i % 5}" for i in rows],
        "epoch.csv": ["epoch_ms,z"] + [f"{round((t0 + i / 200) * 1000)},{i % 5}" for i in rows],
    }
    for name, lines in files.items():
        p = tmp_path / name
        p.write_text("\n".join(lines) + "\n")
        rec = vibmode.read(p)
        assert rec.fs == pytest.approx(200.0, rel=1e-6), name
        assert rec.start_unix_s == pytest.approx(t0, abs=1e-6), name
        assert rec.start == datetime.datetime(2026, 11, 27, 23, 59, 59, tzinfo=datetime.timezone.utc), name
        assert vibmode.read(p, as_frame=True).attrs["start_unix_s"] == pytest.approx(t0, abs=1e-6), name
    # Seconds from 0, and a slash date whose day and month cannot be told apart: no start.
    p = tmp_path / "relative.csv"
    p.write_text("\n".join(["time,z"] + [f"{i / 200},{i % 5}" for i in rows]) + "\n")
    p2 = tmp_path / "undecided.csv"
    p2.write_text("\n".join(["timestamp,z"] + [f"05/11/2026 08:00:{i / 200:06.3f},{i % 5}" for i in rows]) + "\n")
    for q in (p, p2):
        rec = vibmode.read(q)
        assert rec.fs == pytest.approx(200.0, rel=1e-9)
        assert rec.start_unix_s is None and rec.start is None
    with pytest.raises(ValueError, match="start_unix_s"):
        vibmode.Recording(np.zeros((1, 10)), 10.0, start_unix_s=float("nan"))


def test_file_errors_are_os_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        vibmode.read(tmp_path / "missing.csv")
    with pytest.raises(OSError):
        vibmode.analyze(str(tmp_path / "missing.wav"))
    bad = tmp_path / "bad.csv"
    bad.write_text("a,b\n1,2\n3,x\n")
    with pytest.raises(ValueError, match="not a number"):
        vibmode.read(bad, fs=10)
    nofs = tmp_path / "nofs.csv"
    nofs.write_text("a,b\n1,2\n3,4\n5,6\n")
    with pytest.raises(ValueError, match="sampling rate"):
        vibmode.read(nofs)


def test_resample_ideal_passes_a_tone_and_matches_scipy_for_fourier_ratios(rng):
    fs = 1000.0
    t = np.arange(2000) / fs
    x = np.stack([np.sin(2 * np.pi * 10 * t), np.sin(2 * np.pi * 10 * t + 1)])
    y = vibmode.resample_ideal(x, fs, 100.0, 25.0)
    assert y.shape == (2, 200)
    np.testing.assert_allclose(y[0], np.sin(2 * np.pi * 10 * np.arange(200) / 100.0), atol=1e-9)
    # axis=0 gives the transpose
    np.testing.assert_allclose(vibmode.resample_ideal(x.T, fs, 100.0, 25.0, axis=0), y.T, atol=1e-12)
    # A 300 Hz tone above the cutoff is removed.
    z = vibmode.resample_ideal(np.sin(2 * np.pi * 300 * t), fs, 100.0, 25.0)
    assert np.max(np.abs(z)) < 1e-9
    # Non-integer ratio without a cutoff: Fourier resampling, as scipy.signal.resample.
    w = rng.standard_normal(1000)
    np.testing.assert_allclose(vibmode.resample_ideal(w, 1000.0, 300.0), ss.resample(w, 300), atol=1e-9)
    with pytest.raises(ValueError):
        vibmode.resample_ideal(w, 1000.0, -5.0)


def test_fullcar_modes():
    modes = vibmode.fullcar("city_bus")
    assert isinstance(modes, pd.DataFrame)
    heave = modes[modes["label"] == "body_heave"]
    assert len(heave) == 1 and 0.8 < float(heave["frequency_hz"].iloc[0]) < 1.3
    assert ((modes["damping_ratio"] > 0) & (modes["damping_ratio"] < 1)).all()
    as_list = vibmode.fullcar("city_bus", as_frame=False)
    assert [m["frequency_hz"] for m in as_list] == list(modes["frequency_hz"])
    with pytest.raises(ValueError, match="missing field"):
        vibmode.fullcar("[body]\nmass_kg = -3\n")
    with pytest.raises(OSError):
        vibmode.fullcar("no_such_file.toml")


def test_simulate_is_deterministic(sim, tmp_path):
    again = vibmode.simulate("city_bus", records=4, fs=200.0, effects="none", seed=3, out_dir=tmp_path)
    assert len(again.records) == 4 and len(again.paths) == 4
    np.testing.assert_array_equal(again.records[2].data, sim.records[2].data)
    assert sim.records[0].channels[4] == "FR_sprung"
    assert json.load(open(tmp_path / "truth.json"))["modes"]


def test_analyze_arrays_files_and_config(sim, tmp_path):
    r = vibmode.analyze(sim.records, order_max=8)
    assert r["schema_version"] == 3
    assert r["config"]["sweep"]["order_max"] == 8
    assert isinstance(r["records"], pd.DataFrame) and len(r["records"]) == 4
    assert isinstance(r["channels"][0]["poles"], pd.DataFrame)
    roles = {x["role"]: x for x in r["roles"]}
    assert "sprung" in roles
    inv = roles["sprung"]["invariant_modes"]
    # The body modes of the bus (about 1-1.3 Hz) are among the sprung pool's modes.
    assert ((inv["frequency_hz"] > 0.8) & (inv["frequency_hz"] < 1.5)).any()
    # Raw form: exactly json-like; the same numbers as from files written by the package.
    raw = vibmode.analyze(sim.records, sweep={"order_max": 8}, as_frames=False)
    assert isinstance(raw["records"], list)
    paths = vibmode.simulate("city_bus", records=4, fs=200.0, effects="none", seed=3, out_dir=tmp_path, format="f32").paths
    from_files = vibmode.analyze(paths, config="[sweep]\norder_max = 8\n", as_frames=False)
    a = [m["frequency_hz"] for m in raw["roles"][0]["invariant_modes"]]
    b = [m["frequency_hz"] for m in from_files["roles"][0]["invariant_modes"]]
    np.testing.assert_allclose(a, b, rtol=1e-5)  # f32 files: single precision samples
    cfg = vibmode.analysis_config(preset="paper")
    assert cfg["preprocess"]["analysis_fs_hz"] == 200.0
    with pytest.raises(ValueError, match="no_such_key|unknown"):
        vibmode.analyze(sim.records, no_such_key=1)
    with pytest.raises(ValueError):
        vibmode.analyze(sim.records, sweep={"order_max": -1})
    with pytest.raises(ValueError, match="fs"):
        vibmode.analyze(np.zeros((2, 100)))
    # An array with its rate, or a (data, fs) tuple, is the same record as the Recording.
    rec = sim.records[0]
    a1 = vibmode.analyze(rec, order_max=6, as_frames=False)
    a2 = vibmode.analyze((rec.data, rec.fs), channels=None, order_max=6, as_frames=False)
    assert [c["name"] for c in a2["channels"]] == [f"ch{i}" for i in range(7)]
    np.testing.assert_allclose(
        [m["frequency_hz"] for m in a1["channels"][0]["invariant_modes"]],
        [m["frequency_hz"] for m in a2["channels"][0]["invariant_modes"]],
    )


def test_analyze_with_vehicle_matches_modes(sim):
    r = vibmode.analyze(sim.records[:2], vehicle="city_bus", order_max=8, as_frames=False)
    assert len(r["reference_modes"]) > 0


def test_analyze_reports_the_body_band_ssi(sim):
    # SSI-cov of the body band, each record beyond its own front-to-rear wheel delay: the
    # delays are measured from the wheel channels (5.9 m at 30 km/h: 0.71 s).
    r = vibmode.analyze(sim.records[:2], order_max=8, as_frames=False)
    b = r["body_ssi"]
    assert len(b["delay_pairs"]) == 2
    assert len(b["delays"]) == 2
    for d in b["delays"]:
        if d["delay_s"] is not None:
            assert abs(d["delay_s"] - 5.9 / (30 / 3.6)) < 0.03, d
    # the [body_ssi] section as a keyword; switched off, the result says so
    r = vibmode.analyze(sim.records[:2], order_max=8, body_ssi={"enabled": False}, as_frames=False)
    assert "body_ssi" not in r
    assert "enabled = false" in r["body_ssi_not_run"]


def test_analyze_with_vehicle_updates_the_model():
    # A bus whose springs are 25 % softer than its file says: the model update's body heave and
    # pitch are the changed bus's (within 3 %), where the file's are not.
    text = (pathlib.Path(__file__).resolve().parents[2] / "examples" / "city_bus.toml").read_text()
    bus = tomllib.loads(text)
    bus["front"]["spring_stiffness_n_per_m"] *= 0.75
    bus["rear"]["spring_stiffness_n_per_m"] *= 0.75
    s = vibmode.simulate(bus, records=3, duration_s=20.0, fs=100.0, effects="none", seed=3)
    r = vibmode.analyze(s.records, vehicle="city_bus", order_max=8, as_frames=False)
    u = r["model_update"]
    assert u["records"] == 3

    truth = vibmode.fullcar(bus, as_frame=False)
    for label in ("body_heave", "body_pitch"):
        def f(modes):
            return next(m["frequency_hz"] for m in modes if m["label"] == label)

        assert abs(f(u["modes"]) / f(truth) - 1) < 0.03, label
        assert abs(f(u["nominal_modes"]) / f(truth) - 1) > 0.03, label
    # Without the wheels' channels the update says why, and the analysis stands.
    r = vibmode.analyze(s.records[:1], vehicle="city_bus", order_max=8,
                        channels=["FR_sprung", "RL_sprung", "RR_sprung"], as_frames=False)
    assert "no unsprung channel at FL, FR, RL, RR" in r["model_update"]["not_updated"]
    # The fit's band is the config's [model_update] section, here as a keyword.
    r = vibmode.analyze(s.records[:1], vehicle="city_bus", order_max=8,
                        model_update={"band_hz": [0.5, 2.0]}, as_frames=False)
    assert r["model_update"]["band_hz"] == [0.5, 2.0]
    with pytest.raises(ValueError, match=r"band_hz = \[2, 0.5\]"):
        vibmode.analyze(s.records[:1], vehicle="city_bus", model_update={"band_hz": [2.0, 0.5]})


def test_fleet_store(tmp_path):
    s = vibmode.simulate("city_bus", records=6, fs=200.0, effects="none", seed=5, out_dir=tmp_path)
    db = tmp_path / "fleet.db"
    assert vibmode.fleet.init(db) is True
    assert vibmode.fleet.init(db) is False
    with pytest.raises(ValueError, match="baseline|nominal"):
        vibmode.fleet.check(db, "bus-1", s.paths[5:]) if vibmode.fleet.ingest(db, "bus-1", s.paths[:1]) else None
    ing = vibmode.fleet.ingest(db, "bus-1", s.paths[1:5])
    assert [i["already_stored"] for i in ing] == [False] * 4
    assert vibmode.fleet.ingest(db, "bus-1", s.paths[0])[0]["already_stored"] is True
    b = vibmode.fleet.baseline(db, "bus-1")
    assert b["vehicle"] == "bus-1" and len(b["records"]) == 5
    c = vibmode.fleet_check(db, "bus-1", s.paths[5])
    assert c["records"][0]["classification"] in ("normal", "road", "vehicle", "both")
    assert vibmode.fleet.status(db)[0]["vehicle"] == "bus-1"
    with pytest.raises(OSError):
        vibmode.fleet.status(tmp_path / "nostore.db")


def test_fleet_features_then_store_equals_ingest(tmp_path):
    s = vibmode.simulate("city_bus", records=2, fs=200.0, effects="none", seed=9, out_dir=tmp_path)
    db1, db2 = tmp_path / "a.db", tmp_path / "b.db"
    vibmode.fleet.init(db1)
    vibmode.fleet.init(db2)
    direct = vibmode.fleet.ingest(db1, "bus-2", s.paths)
    feats = [json.loads(json.dumps(vibmode.fleet.features(p))) for p in s.paths]
    stored = vibmode.fleet.store_features(db2, "bus-2", feats)
    assert stored == direct
    assert vibmode.fleet.store_features(db2, "bus-2", feats[:1])[0]["already_stored"] is True
    a = vibmode.fleet.status(db1)[0]
    b = vibmode.fleet.status(db2)[0]
    assert a == b


def test_a_dead_or_stuck_channel_is_named_not_analysed(rng):
    # Before: the stuck channel's rounding noise after resampling gave "modes" and lines.
    fs = 100.0
    x = np.stack([rng.standard_normal(2048), np.full(2048, 9.81), np.zeros(2048)])
    with pytest.raises(ValueError, match=r"channel 'ch1' is constant \(every sample is 9.81\)"):
        vibmode.analyze(x, fs)
    with pytest.raises(ValueError, match=r"channel 'ch1' is constant \(every sample is 0\)"):
        vibmode.analyze(x[[0, 2]], fs)
    with pytest.raises(ValueError, match=r"constant \(every sample is 9.81\)"):
        vibmode.ssi_cov(x[:2], fs, block_rows=10, orders=[2, 4, 6])
    res = vibmode.analyze(x[:1], fs, as_frames=False)
    assert res["records"] and all("clipped" not in r for r in res["records"])
    # A saturated sensor is analysed and named per record.
    clip = np.clip(x[0], -1.0, 1.0)
    res = vibmode.analyze(clip, fs, as_frames=False)
    assert all(r["clipped"][0]["channel"] == "ch0" for r in res["records"])
    assert all(0.1 < r["clipped"][0]["share"] < 0.25 for r in res["records"])
