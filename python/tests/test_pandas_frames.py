"""pandas users' frames and files: a DataFrame's time (a time column, a DatetimeIndex) gives the
rate and is not a channel; ``DataFrame.to_csv`` files (the row index as an unnamed first column, a
DatetimeIndex as date-time text) read as the frame they came from."""
import numpy as np
import pytest

import vibmode

pd = pytest.importorskip("pandas")

FS = 200.0


def _signals(n=4000, seed=3):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    a = np.sin(2 * np.pi * 1.3 * t) + 0.3 * rng.standard_normal(n)
    b = np.sin(2 * np.pi * 9.0 * t) + 0.3 * rng.standard_normal(n)
    return t, np.vstack([a, b])


def _analysis(x, **kw):
    r = vibmode.analyze(x, method="arma", order_max=8, as_frames=False, **kw)
    return [c["name"] for c in r["channels"]], r["records"][0]["fs_hz"], r["channels"][0]["welch_psd"]


def test_time_column_and_datetime_index_give_the_rate_and_are_not_channels():
    t, data = _signals()
    expected = _analysis((data, FS), channels=None)
    frames = {
        "time column": pd.DataFrame({"time": t, "acc_a": data[0], "acc_b": data[1]}),
        "Time (ms) column": pd.DataFrame({"Time (ms)": 1e3 * t, "acc_a": data[0], "acc_b": data[1]}),
        "DatetimeIndex": pd.DataFrame(
            {"acc_a": data[0], "acc_b": data[1]},
            index=pd.date_range("2026-11-27 05:00", periods=len(t), freq="5ms"),
        ),
        "TimedeltaIndex": pd.DataFrame(
            {"acc_a": data[0], "acc_b": data[1]}, index=pd.to_timedelta(t, unit="s")
        ),
        "DatetimeIndex with a zone": pd.DataFrame(
            {"acc_a": data[0], "acc_b": data[1]},
            index=pd.date_range("2026-03-29 01:59:50", periods=len(t), freq="5ms", tz="Europe/Bratislava"),
        ),
        "datetime column": pd.DataFrame(
            {"when": pd.date_range("2026-11-27", periods=len(t), freq="5ms"), "acc_a": data[0], "acc_b": data[1]}
        ),
    }
    for what, df in frames.items():
        names, fs, psd = _analysis(df)
        assert names == ["acc_a", "acc_b"], what
        assert fs == pytest.approx(FS, rel=1e-9), what
        np.testing.assert_array_equal(psd, expected[2], err_msg=what)
        # SSI-cov takes the same channels and rate.
        s = vibmode.ssi_cov(df, orders=(2, 8))
        assert list(s.channels) == ["acc_a", "acc_b"], what


def test_frames_with_a_bad_time_are_refused_in_one_line():
    t, data = _signals(1000)
    df = pd.DataFrame({"time": t, "acc_a": data[0], "acc_b": data[1]})
    with pytest.raises(ValueError, match="must agree within 1 %"):
        vibmode.analyze(df, fs=150.0)
    back = df.copy()
    back.loc[5, "time"] = 0.001
    with pytest.raises(ValueError, match="does not increase at row 5"):
        vibmode.analyze(back)
    jitter = df.copy()
    jitter["time"] = t + np.random.default_rng(1).uniform(-1e-3, 1e-3, len(t))
    jitter.loc[0, "time"] = 0.0
    with pytest.raises(ValueError, match="not uniform"):
        vibmode.analyze(jitter)
    words = df.assign(note="ok")
    with pytest.raises(ValueError, match="'note' are not numbers"):
        vibmode.analyze(words)
    with pytest.raises(ValueError, match="give fs"):
        vibmode.analyze(pd.DataFrame({"acc_a": data[0]}))
    with pytest.raises(ValueError, match="no channel besides its time column 'time'"):
        vibmode.analyze(df[["time"]])


def test_to_csv_files_read_as_their_frames(tmp_path):
    t, data = _signals(3000)
    df = pd.DataFrame({"time": t, "acc_a": data[0], "acc_b": data[1]})
    plain = tmp_path / "plain.csv"
    df.to_csv(plain)  # the RangeIndex as an unnamed first column
    rec = vibmode.read(plain)
    assert list(rec.channels) == ["acc_a", "acc_b"]
    assert rec.fs == pytest.approx(FS, rel=1e-9)
    np.testing.assert_allclose(rec.data, data, rtol=0, atol=1e-15)
    dated = tmp_path / "dated.csv"
    df.drop(columns="time").set_index(pd.date_range("2026-11-27 23:59:59", periods=len(t), freq="5ms")).to_csv(dated)
    rec = vibmode.read(dated)
    assert list(rec.channels) == ["acc_a", "acc_b"]
    assert rec.fs == pytest.approx(FS, rel=1e-9)
    np.testing.assert_allclose(rec.data, data, rtol=0, atol=1e-15)


def test_a_units_row_read_by_pandas_gives_names_and_units(tmp_path):
    """A file with a units row below its header, read as ``pandas.read_csv(path, header=[0,
    1])``, has two-level columns (name, unit): the time column (in ms here) gives the rate and
    is not a channel, the channels keep their names and units, and the analysis is that of the
    plain arrays; the same file read by vibmode directly agrees. Two-level columns that are not
    (name, unit), such as (sensor, axis), are joined."""
    t, data = _signals()
    expected = _analysis((data, FS), channels=None)
    path = tmp_path / "logger.csv"
    rows = "\n".join(f"{1e3 * ti:.3f},{float(a)!r},{float(b)!r}" for ti, a, b in zip(t, data[0], data[1]))
    path.write_text("time,acc_a,acc_b\nms,m/s^2,g\n" + rows + "\n")
    frame = pd.read_csv(path, header=[0, 1])
    assert isinstance(frame.columns, pd.MultiIndex)
    names, fs, psd = _analysis(frame)
    assert (names, fs) == (["acc_a", "acc_b"], expected[1])
    np.testing.assert_allclose(psd, expected[2], rtol=1e-9)
    rec = vibmode.read(path)
    assert rec.channels == ["acc_a", "acc_b"] and rec.units == ["m/s^2", "g"] and rec.fs == FS
    from vibmode._io import _as_recording

    assert _as_recording(frame, None).units == ["m/s^2", "g"]
    # An empty unit cell (pandas' "Unnamed: 1_level_1"): no unit.
    path.write_text("time,acc_a,acc_b\nms,,g\n" + rows + "\n")
    assert _as_recording(pd.read_csv(path, header=[0, 1]), None).units == ["", "g"]
    # (sensor, axis): not units; the names are joined.
    sensors = pd.DataFrame({("FL", "x"): data[0], ("FL", "z"): data[1]})
    assert _as_recording(sensors, FS).channels == ["FL_x", "FL_z"]
