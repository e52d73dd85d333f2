"""The shared reading options (the command line's --resample-nonuniform and --time-unit) in
read, analyze and the fleet functions: a 100 Hz file with a jittery Time_ms column."""
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
