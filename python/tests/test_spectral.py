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
    dict(window=("kaiser", 8.6), nperseg=200, noverlap=150),
    dict(window=("ksr", 0.5), nperseg=128, scaling="spectrum", detrend="linear"),
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
        (dict(window=("gaussian", 7.0)), r"gaussian.*get_window\(\('gaussian', 7.0\), nperseg\)"),
        (dict(window="kaiser"), r"needs its beta.*\('kaiser', 8.6\)"),
        (dict(window=("kaiser", 800.0)), "kaiser beta"),
        (dict(window=("kaiser", "big")), "must be a number"),
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


# Window arrays (scipy's `window=` as coefficients): nperseg is the window's length.
ARRAY_WINDOWS = [
    ("np.hanning(256)", lambda: np.hanning(256), {}),
    ("get_window hann 200", lambda: ss.get_window("hann", 200), dict(noverlap=150, average="median")),
    ("kaiser 8 as list", lambda: list(ss.get_window(("kaiser", 8.0), 128)), dict(detrend="linear", nfft=300)),
    ("hamming 255 + nperseg", lambda: ss.get_window("hamming", 255), dict(nperseg=255, noverlap=100, scaling="spectrum")),
    ("random positive 100", lambda: np.random.default_rng(7).uniform(0.1, 2.0, 100), dict(detrend=False)),
]


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("shape,axis", SHAPES_AXES)
@pytest.mark.parametrize("name,make,params", ARRAY_WINDOWS, ids=[w[0] for w in ARRAY_WINDOWS])
def test_array_windows_match_scipy(seed, shape, axis, name, make, params):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(shape) * 2.0 + 0.7
    y = 0.6 * x + rng.standard_normal(shape)
    w = make()
    for ours, theirs, args, kw in [
        (vibmode.welch, ss.welch, (x,), params),
        (vibmode.csd, ss.csd, (x, y), params),
        (vibmode.coherence, ss.coherence, (x, y),
         {k: v for k, v in params.items() if k not in ("scaling", "average")}),
    ]:
        f, p = ours(*args, fs=256.0, window=w, axis=axis, **kw)
        f2, p2 = theirs(*args, fs=256.0, window=w, axis=axis, **kw)
        np.testing.assert_allclose(f, f2, rtol=1e-12)
        assert p.shape == p2.shape and p.dtype == p2.dtype, (ours.__name__, p.shape, p2.shape)
        assert rel_err(p, p2) < TOL, (ours.__name__, rel_err(p, p2))
    # Two-sided with an array window.
    f, p = vibmode.welch(x, fs=256.0, window=w, axis=axis, return_onesided=False, **params)
    f2, p2 = ss.welch(x, fs=256.0, window=w, axis=axis, return_onesided=False, **params)
    np.testing.assert_allclose(f, f2, rtol=1e-12, atol=1e-12)
    assert rel_err(p, p2) < TOL


@pytest.mark.parametrize("seed", [4, 5])
@pytest.mark.parametrize("shape,axis", SHAPES_AXES)
@pytest.mark.parametrize("nfft_less", [False, True])
def test_periodogram_array_window_matches_scipy(seed, shape, axis, nfft_less):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(shape)
    n = shape[axis]
    m = n - 300 if nfft_less else n  # nfft < n: the window covers the first nfft samples
    kw = dict(nfft=m) if nfft_less else {}
    for w in (ss.get_window(("kaiser", 6.0), m), rng.uniform(0.0, 1.0, m)):
        for scaling in ("density", "spectrum"):
            f, p = vibmode.periodogram(x, fs=50.0, window=w, axis=axis, scaling=scaling, **kw)
            f2, p2 = ss.periodogram(x, fs=50.0, window=w, axis=axis, scaling=scaling, **kw)
            np.testing.assert_allclose(f, f2, rtol=1e-12)
            assert p.shape == p2.shape
            assert rel_err(p, p2) < TOL


def test_array_window_equals_the_named_window_exactly(rng):
    x = rng.standard_normal((3, 5000))
    for name in ("hann", "flattop", ("tukey", 0.3)):
        for nperseg in (256, 333):
            w = vibmode.get_window(name, nperseg)
            np.testing.assert_array_equal(
                vibmode.welch(x, window=w)[1], vibmode.welch(x, window=name, nperseg=nperseg)[1]
            )
    # Any positive multiple of a window gives the same spectra (normalised by sum(w**2)).
    w = ss.get_window("hann", 128)
    assert rel_err(vibmode.welch(x, window=5.0 * w)[1], vibmode.welch(x, window=w)[1]) < 1e-14


@pytest.mark.parametrize(
    "kwargs,match",
    [
        # scipy's length rules (scipy refuses these too).
        (dict(window=np.hanning(128), nperseg=100), r"nperseg = 100 differs from the window's length 128"),
        (dict(window=np.ones(2000)), r"window has 2000 coefficients but the record only 1000 samples"),
        # Coefficients vibmode refuses (scipy gives NaN/inf spectra or errors of its own).
        (dict(window=np.array([])), "0 coefficients"),
        (dict(window=[1.0, np.nan, 1.0]), r"window\[1\] = NaN is not finite"),
        (dict(window=[1.0, np.inf]), r"window\[1\] = inf is not finite"),
        (dict(window=np.zeros(64)), "64 coefficients are all 0"),
        (dict(window=np.ones((8, 8))), r"1-D.*\(8, 8\)"),
        (dict(window=np.hanning(8) + 1j), "real coefficients"),
        (dict(window=["a", "b"]), "real coefficients"),
        (dict(window=None), "NoneType"),
        (dict(window=[1.0, -1.0, 1.0, -1.0], scaling="spectrum"), r"sum\(w\) is 0"),
    ],
)
def test_bad_array_windows_raise_value_error(rng, kwargs, match):
    x = rng.standard_normal((2, 1000))
    with pytest.raises(ValueError, match=match) as e:
        vibmode.welch(x, **kwargs)
    assert "\n" not in str(e.value)
    if "differs" in match or "record only" in match:
        with pytest.raises(ValueError):
            ss.welch(x, **kwargs)


def test_array_window_length_errors_in_every_function(rng):
    x = rng.standard_normal(1000)
    w = np.hanning(128)
    for fn, args in [(vibmode.welch, (x,)), (vibmode.csd, (x, x)), (vibmode.coherence, (x, x))]:
        with pytest.raises(ValueError, match="nperseg = 64 differs from the window's length 128"):
            fn(*args, window=w, nperseg=64)
    with pytest.raises(ValueError, match="128 coefficients but the periodogram uses 1000 samples"):
        vibmode.periodogram(x, window=w)
    with pytest.raises(ValueError):
        ss.periodogram(x, window=w)
    # get_window takes names only.
    with pytest.raises(ValueError, match="not a window name"):
        vibmode.get_window(w, 128)


@pytest.mark.parametrize("beta", [0.0, 1.5, 5.0, 8.6, 14.0, 40.0, -6.0])
@pytest.mark.parametrize("n", [1, 2, 7, 64, 255, 256])
def test_kaiser_matches_scipy_get_window(beta, n):
    got = vibmode.get_window(("kaiser", beta), n)
    want = ss.get_window(("kaiser", beta), n)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
