"""The shared reading options (the command line's --resample-nonuniform and --time-unit) in
read, analyze and the fleet functions: a 100 Hz file with a jittery Time_ms column."""
import os

import numpy as np
import pytest

import vibmode
from vibmode import fleet


def _jittery_csv(path, time_name="Time_ms", seconds=30.0):
    rng = np.random.default_rng(7)
    n = int(seconds * 100)
    t_ms = np.arange(n) * 10.0 + rng.uniform(-0.3, 0.3, n)
    t_ms[0] = 0.0
    t = t_ms / 1000.0
    x = np.sin(2 * np.pi * 1.3 * t) + 0.3 * rng.standard_normal(n)
    y = np.sin(2 * np.pi * 4.1 * t) + 0.3 * rng.standard_normal(n)
    z = np.sin(2 * np.pi * 9.7 * t) + 0.3 * rng.standard_normal(n)
    rows = [f"{time_name},x,y,z"] + [f"{a:.3f},{b:.6f},{c:.6f},{d:.6f}" for a, b, c, d in zip(t_ms, x, y, z)]
    path.write_text("\n".join(rows) + "\n")
    return path


def test_jittery_time_needs_and_takes_allow_nonuniform(tmp_path):
    p = _jittery_csv(tmp_path / "imu.csv")
    with pytest.raises(ValueError, match="uniform"):
        vibmode.read(p)
    rec = vibmode.read(p, allow_nonuniform=True)
    assert rec.fs == pytest.approx(100.0, rel=1e-3)
    assert list(rec.channels) == ["x", "y", "z"]
    with pytest.raises(ValueError, match="uniform"):
        vibmode.analyze(str(p), as_frames=False)
    res = vibmode.analyze(str(p), allow_nonuniform=True, as_frames=False)
    assert [c["name"] for c in res["channels"]] == ["x", "y", "z"]
    assert res["records"][0]["fs_hz"] == pytest.approx(100.0, rel=1e-3)
    with pytest.raises(ValueError, match="uniform"):
        fleet.features(p)


def test_time_unit_reads_a_timestamp_in_milliseconds(tmp_path):
    p = tmp_path / "ts.csv"
    n = 2000
    rows = ["Timestamp,a"] + [f"{k * 10},{np.sin(0.1 * k):.6f}" for k in range(n)]
    p.write_text("\n".join(rows) + "\n")
    assert vibmode.read(p).fs == pytest.approx(0.1)
    assert vibmode.read(p, time_unit="ms").fs == pytest.approx(100.0)
    with pytest.raises(ValueError, match="time_unit"):
        vibmode.read(p, time_unit="fortnights")


@pytest.mark.parametrize("dtype", ["float64", "float32", "int16", "int32"])
def test_wav_files_written_by_scipy_read_as_scipy_reads_them(tmp_path, dtype):
    """scipy.io.wavfile.write keeps the array's dtype: numpy's default float64 gives a 64-bit
    IEEE float WAV (which the hound crate refuses; vibmode reads its header itself). Every kind
    reads back to scipy's own values, integers scaled to full scale 1 (docs/formats.md)."""
    wavfile = pytest.importorskip("scipy.io.wavfile")
    rng = np.random.default_rng(3)
    x = rng.standard_normal((4000, 3)) * 0.2
    if dtype.startswith("int"):
        full = np.iinfo(dtype).max + 1
        data = np.round(x * full).astype(dtype)
    else:
        full = 1
        data = x.astype(dtype)
    path = tmp_path / f"{dtype}.wav"
    wavfile.write(path, 2000, data)
    fs, back = wavfile.read(path)
    rec = vibmode.read(path)
    assert rec.fs == fs == 2000
    assert rec.data.shape == (3, 4000)
    np.testing.assert_array_equal(rec.data, back.T.astype(np.float64) / full)
    scaled = vibmode.read(path, scale=19.62)
    np.testing.assert_allclose(scaled.data, 19.62 * rec.data, rtol=1e-15)


@pytest.mark.parametrize("kind", ["c", "fortran", "float32", "one_channel", "version2"])
def test_npy_files_written_by_numpy_read_as_their_arrays(tmp_path, kind):
    """numpy.save's files, as numpy (the independent implementation) writes them: a 2-D array
    (samples, channels) in C order, in Fortran order (pandas' ``DataFrame.to_numpy()`` of one
    dtype gives one), float32, a 1-D array, and format version 2.0 (``numpy.lib.format``).
    vibmode reads exactly the array (float32 widened), channels ch0, ch1, ..., at the given
    rate; without a rate, or transposed, or of integers, it refuses naming the value."""
    rng = np.random.default_rng(11)
    a = rng.standard_normal((3000, 4))
    path = tmp_path / f"{kind}.npy"
    if kind == "fortran":
        a = np.asfortranarray(a)
    elif kind == "float32":
        a = a.astype(np.float32)
    elif kind == "one_channel":
        a = a[:, 0].copy()
    if kind == "version2":
        with open(path, "wb") as f:
            np.lib.format.write_array(f, a, version=(2, 0))
    else:
        np.save(path, a)
    back = np.load(path)
    rec = vibmode.read(path, fs=500.0)
    want = back.reshape(len(back), -1).T.astype(np.float64)
    assert rec.fs == 500.0
    assert list(rec.channels) == [f"ch{i}" for i in range(want.shape[0])]
    np.testing.assert_array_equal(rec.data, want)
    with pytest.raises(ValueError, match="holds no sampling rate"):
        vibmode.read(path)


def test_npy_refusals_name_the_value(tmp_path):
    a = np.random.default_rng(2).standard_normal((2000, 3))
    np.save(tmp_path / "t.npy", a.T.copy())
    with pytest.raises(ValueError, match=r"shape \(3, 2000\) would be 2000 channels of 3 samples"):
        vibmode.read(tmp_path / "t.npy", fs=100.0)
    np.save(tmp_path / "i.npy", (a * 100).astype(np.int32))
    with pytest.raises(ValueError, match="data type '<i4' is not supported"):
        vibmode.read(tmp_path / "i.npy", fs=100.0)
    np.save(tmp_path / "b.npy", a.astype(">f8"))
    with pytest.raises(ValueError, match="data type '>f8'"):
        vibmode.read(tmp_path / "b.npy", fs=100.0)


def test_info_gives_what_the_cli_prints_and_numpy_agrees(tmp_path):
    """``vibmode.info`` is ``vibmode info --json`` (the same library call): per file its format,
    rate, frames and per channel min/max (exact), mean, std (ddof 0) and RMS against numpy; a
    folder stands for its files; ``as_frame`` gives one row per file and channel; a missing
    file raises OSError, a file without a rate ValueError naming it."""
    rng = np.random.default_rng(7)
    a = rng.standard_normal((5000, 2)) + [3.0, -1.0]
    np.save(tmp_path / "a.npy", a)
    (s,) = vibmode.info(tmp_path / "a.npy", fs=500.0)
    assert (s["format"], s["fs_hz"], s["frames"], s["duration_s"]) == ("Npy", 500.0, 5000, 10.0)
    for c, x in zip(s["channels"], a.T):
        assert (c["min"], c["max"], c["constant"]) == (x.min(), x.max(), None)
        assert c["mean"] == pytest.approx(x.mean(), rel=1e-13)
        assert c["std"] == pytest.approx(x.std(), rel=1e-12)
        assert c["rms"] == pytest.approx(np.sqrt(np.mean(x * x)), rel=1e-13)
    vibmode.write(tmp_path / "b.csv", a[:100].T, fs=500.0, channels=["x", "y"])
    both = vibmode.info([tmp_path], fs=500.0)
    assert [os.path.basename(f["path"]) for f in both] == ["a.npy", "b.csv"]
    pd = pytest.importorskip("pandas")
    df = vibmode.info(tmp_path, fs=500.0, as_frame=True)
    assert isinstance(df, pd.DataFrame) and len(df) == 4
    assert list(df["channel"]) == ["ch0", "ch1", "x", "y"]
    with pytest.raises(OSError):
        vibmode.info(tmp_path / "none.csv")
    with pytest.raises(ValueError, match="a.npy.*holds no sampling rate"):
        vibmode.info(tmp_path / "a.npy")
