"""vibmode's spectra against scipy.signal on seeded inputs: shapes, axes and parameters."""

import concurrent.futures
import warnings

import numpy as np
import pytest
import scipy.signal as ss

import vibmode
from conftest import rel_err

TOL = 1e-9

SHAPES_AXES = [
    ((2000,), -1),
    ((3, 4096), -1),
    ((4096, 3), 0),
    ((2, 3, 1500), 2),
    ((2, 1500, 3), 1),
    ((2, 1500, 3), -2),
]

WELCH_PARAMS = [
    {},
    dict(window="hamming", nperseg=128, noverlap=100),
    dict(window="blackman", nperseg=200, nfft=512, detrend="linear"),
    dict(window="boxcar", nperseg=100, noverlap=0, detrend=False, scaling="spectrum"),
    dict(window="flattop", nperseg=333, average="median"),
    dict(window=("tukey", 0.25), nperseg=256, noverlap=64, scaling="spectrum", average="median"),
    dict(window="tukey", nperseg=255, nfft=300),
]


@pytest.mark.parametrize("shape,axis", SHAPES_AXES)
@pytest.mark.parametrize("params", WELCH_PARAMS)
def test_welch_matches_scipy(rng, shape, axis, params):
    x = rng.standard_normal(shape) * 3.0 + 1.5
    f, p = vibmode.welch(x, fs=512.0, axis=axis, **params)
    f2, p2 = ss.welch(x, fs=512.0, axis=axis, **params)
    np.testing.assert_allclose(f, f2, rtol=1e-12)
    assert p.shape == p2.shape and p.dtype == p2.dtype
    assert rel_err(p, p2) < TOL


@pytest.mark.parametrize("shape,axis", SHAPES_AXES)
@pytest.mark.parametrize(
    "params",
    [{}, dict(window="hann", nfft=5000), dict(nfft=1000, detrend="linear", scaling="spectrum"), dict(window=("tukey", 0.5))],
)
def test_periodogram_matches_scipy(rng, shape, axis, params):
    x = rng.standard_normal(shape)
    f, p = vibmode.periodogram(x, fs=100.0, axis=axis, **params)
    f2, p2 = ss.periodogram(x, fs=100.0, axis=axis, **params)
    np.testing.assert_allclose(f, f2, rtol=1e-12)
    assert p.shape == p2.shape
    assert rel_err(p, p2) < TOL


@pytest.mark.parametrize("shape,axis", SHAPES_AXES[:3])
@pytest.mark.parametrize(
    "params",
    [{}, dict(nperseg=255), dict(nperseg=200, nfft=301, scaling="spectrum"), dict(average="median")],
)
def test_two_sided_spectra_match_scipy(rng, shape, axis, params):
    x = rng.standard_normal(shape) + 0.5
    y = 0.7 * x + rng.standard_normal(shape)
    for ours, theirs, args in [
        (vibmode.welch, ss.welch, (x,)),
        (vibmode.csd, ss.csd, (x, y)),
    ]:
        f, p = ours(*args, fs=64.0, axis=axis, return_onesided=False, **params)
        f2, p2 = theirs(*args, fs=64.0, axis=axis, return_onesided=False, **params)
        np.testing.assert_allclose(f, f2, rtol=1e-12, atol=1e-12)
        assert p.shape == p2.shape and p.dtype == p2.dtype
        assert rel_err(p, p2) < TOL
    pp = {k: v for k, v in params.items() if k in ("nfft", "scaling")}
    f, p = vibmode.periodogram(x, fs=64.0, axis=axis, return_onesided=False, **pp)
    f2, p2 = ss.periodogram(x, fs=64.0, axis=axis, return_onesided=False, **pp)
    np.testing.assert_allclose(f, f2, rtol=1e-12, atol=1e-12)
    assert rel_err(p, p2) < TOL


@pytest.mark.parametrize("params", WELCH_PARAMS[:5])
def test_csd_matches_scipy(rng, params):
    x = rng.standard_normal((3, 3000))
    y = 0.5 * x + rng.standard_normal((3, 3000))
    f, p = vibmode.csd(x, y, fs=50.0, **params)
    f2, p2 = ss.csd(x, y, fs=50.0, **params)
    np.testing.assert_allclose(f, f2, rtol=1e-12)
    assert p.dtype == p2.dtype == np.complex128
    assert rel_err(p, p2) < TOL


def test_csd_broadcasts_and_axis(rng):
    x = rng.standard_normal((1500, 1))
    y = rng.standard_normal((1500, 4))
    f, p = vibmode.csd(x, y, nperseg=64, axis=0)
    f2, p2 = ss.csd(x, y, nperseg=64, axis=0)
    assert p.shape == p2.shape == (33, 4)
    assert rel_err(p, p2) < TOL


@pytest.mark.parametrize("params", [{}, dict(nperseg=128, window="hamming"), dict(nperseg=100, detrend="linear", nfft=256)])
def test_coherence_matches_scipy(rng, params):
    x = rng.standard_normal((2, 4000))
    y = np.cumsum(x, axis=-1) * 0.01 + rng.standard_normal((2, 4000))
    f, c = vibmode.coherence(x, y, fs=10.0, **params)
    f2, c2 = ss.coherence(x, y, fs=10.0, **params)
    assert rel_err(c, c2) < TOL
    assert np.all((c >= 0) & (c <= 1 + 1e-12))


def test_float32_and_int_inputs_follow_scipy_dtypes(rng):
    x32 = rng.standard_normal(3000).astype(np.float32)
    _, p = vibmode.welch(x32)
    _, p2 = ss.welch(x32)
    assert p.dtype == p2.dtype == np.float32
    assert rel_err(p, p2) < 1e-5  # scipy computes in single precision
    xi = (rng.standard_normal(3000) * 1000).astype(np.int64)
    _, p = vibmode.welch(xi)
    _, p2 = ss.welch(xi)
    assert p.dtype == p2.dtype == np.float64
    assert rel_err(p, p2) < TOL
    xs = rng.standard_normal((3, 5000))[:, ::2]  # not contiguous
    assert rel_err(vibmode.welch(xs)[1], ss.welch(xs)[1]) < TOL


def test_short_record_clamps_with_a_warning_as_scipy(rng):
    x = rng.standard_normal(100)
    with pytest.warns(UserWarning, match="nperseg"):
        f, p = vibmode.welch(x)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f2, p2 = ss.welch(x)
    assert rel_err(p, p2) < TOL


def test_hand_checkable_sine():
    # A sine of amplitude 2 at a bin frequency: power A**2/2 = 2 at its peak (spectrum scaling),
    # and the density integrates to the mean square (Parseval), 2.0.
    fs = 100.0
    t = np.arange(1000) / fs
    x = 2.0 * np.sin(2 * np.pi * 5.0 * t)
    f, p = vibmode.periodogram(x, fs, scaling="spectrum")
    k = int(np.argmax(p))
    assert f[k] == pytest.approx(5.0, abs=1e-12)
    assert p[k] == pytest.approx(2.0, rel=1e-9)
    f, d = vibmode.periodogram(x, fs)
    assert np.sum(d) * (f[1] - f[0]) == pytest.approx(2.0, rel=1e-9)
    np.testing.assert_allclose(vibmode.get_window("hann", 4), [0.0, 0.5, 1.0, 0.5], atol=1e-15)


def test_empty_input_returns_empty_like_scipy():
    f, p = vibmode.welch(np.empty((3, 0)))
    assert f.shape == p.shape == (3, 0)


@pytest.mark.parametrize(
    "kwargs,match",
    [
        (dict(window="kaiser"), "kaiser"),
        (dict(window=np.hanning(256)), "window arrays"),
        (dict(nperseg=0), "nperseg"),
        (dict(nperseg=-5), "nperseg"),
        (dict(nperseg=64, noverlap=64), "noverlap"),
        (dict(nperseg=64, nfft=32), "nfft"),
        (dict(scaling="power"), "power"),
        (dict(average="mode"), "mode"),
        (dict(detrend="quadratic"), "quadratic"),
        (dict(fs=0.0), "fs"),
        (dict(fs=float("nan")), "fs"),
        (dict(axis=3), "axis"),
    ],
)
def test_bad_arguments_raise_value_error(rng, kwargs, match):
    x = rng.standard_normal((2, 1000))
    with pytest.raises(ValueError, match=match):
        vibmode.welch(x, **kwargs)


def test_bad_samples_raise_value_error(rng):
    x = rng.standard_normal(1000)
    x[10] = np.nan
    with pytest.raises(ValueError, match="NaN|finite|nan"):
        vibmode.welch(x)
    with pytest.raises(ValueError, match="complex"):
        vibmode.welch(np.ones(100, dtype=complex))
    with pytest.raises(ValueError, match="equal lengths"):
        vibmode.csd(np.ones(100), np.ones(90))
    # Errors are one line.
    try:
        vibmode.welch(np.ones(100), nperseg=10, noverlap=20)
    except ValueError as e:
        assert "\n" not in str(e)


def test_threads_give_the_same_results(rng):
    # The GIL is released in the native call; threads must not disturb the results.
    xs = [rng.standard_normal((3, 20000)) for _ in range(6)]
    expected = [vibmode.welch(x, nperseg=512)[1] for x in xs]
    with concurrent.futures.ThreadPoolExecutor(4) as ex:
        got = list(ex.map(lambda x: vibmode.welch(x, nperseg=512)[1], xs))
    for e, g in zip(expected, got):
        np.testing.assert_array_equal(e, g)


def test_coherence_of_a_silent_signal_is_nan_as_scipy(rng):
    x = np.zeros(1000)
    y = rng.standard_normal(1000)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        _, c2 = ss.coherence(x, y, nperseg=64)
    _, c = vibmode.coherence(x, y, nperseg=64)
    assert np.all(np.isnan(c)) and np.all(np.isnan(c2))
