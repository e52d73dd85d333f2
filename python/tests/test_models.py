"""AR / ARMA models against statsmodels and a known system; sweeps; round trips; errors."""

import json
import warnings

import numpy as np
import pytest
from statsmodels.regression.linear_model import burg, yule_walker
from statsmodels.tsa.arima_process import arma_generate_sample

import vibmode

FS = 200.0
F0, ZETA = 9.0, 0.05


def ar2_of_mode(f0=F0, zeta=ZETA, fs=FS):
    """A(z) of a continuous mode (f0 Hz, zeta) sampled at fs: poles z = exp(s / fs)."""
    w = 2 * np.pi * f0
    s = complex(-zeta * w, w * np.sqrt(1 - zeta**2))
    z = np.exp(s / fs)
    return np.real(np.poly([z, np.conj(z)]))


@pytest.fixture(scope="module")
def ar2_data():
    rng = np.random.default_rng(7)
    return arma_generate_sample(ar2_of_mode(), [1.0], 6000, scale=1.0, distrvs=rng.standard_normal)


@pytest.fixture(scope="module")
def arma21_data():
    rng = np.random.default_rng(8)
    return arma_generate_sample(ar2_of_mode(), [1.0, 0.4], 8000, scale=1.0, distrvs=rng.standard_normal)


def test_burg_equals_statsmodels(ar2_data):
    for p in (2, 5, 12):
        m = vibmode.fit_ar(ar2_data, FS, p)
        rho, sigma2 = burg(ar2_data, p)
        np.testing.assert_allclose(m.a, np.r_[1.0, -rho], rtol=0, atol=1e-9)
        assert m.noise_variance == pytest.approx(sigma2, rel=1e-9)
        assert m.c.tolist() == [1.0]


def test_yule_walker_equals_statsmodels_mle(ar2_data):
    m = vibmode.fit_ar(ar2_data, FS, 4, method="yule-walker")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        rho, sigma = yule_walker(ar2_data, 4, method="mle")[:2]
    np.testing.assert_allclose(m.a, np.r_[1.0, -rho], atol=1e-9)
    assert m.noise_variance == pytest.approx(sigma**2, rel=1e-9)


def test_known_mode_is_found(ar2_data):
    m = vibmode.fit_ar(ar2_data, FS, 2)
    assert m.frequency_hz.shape == (1,)
    assert m.frequency_hz[0] == pytest.approx(F0, abs=0.15)
    assert m.damping_ratio[0] == pytest.approx(ZETA, abs=0.01)
    # The poles are the roots of A.
    assert np.allclose(np.sort_complex(m.poles), np.sort_complex(np.roots(m.a)))


def test_arma_agrees_with_statsmodels_mle(arma21_data):
    from statsmodels.tsa.arima.model import ARIMA

    m = vibmode.fit_arma(arma21_data, FS, 2, 1, robust="off")
    r = ARIMA(arma21_data, order=(2, 0, 1), trend="n").fit()
    ar, ma, sigma2 = r.params[:2], r.params[2:3], r.params[3]
    # Conditional prediction-error estimate vs exact maximum likelihood: close, not equal.
    np.testing.assert_allclose(m.a, np.r_[1.0, -ar], atol=5e-3)
    np.testing.assert_allclose(m.c, np.r_[1.0, ma], atol=1e-2)
    assert m.noise_variance == pytest.approx(sigma2, rel=2e-2)
    assert m.converged
    # And the truth.
    np.testing.assert_allclose(m.a, ar2_of_mode(), atol=1e-2)
    assert m.c[1] == pytest.approx(0.4, abs=0.05)


def test_robust_default_and_q_default(arma21_data):
    m = vibmode.fit_arma(arma21_data, FS, 2)
    assert (m.p, m.q) == (2, 2)
    assert m.frequency_hz[0] == pytest.approx(F0, abs=0.2)


def test_model_psd_is_the_formula(ar2_data):
    m = vibmode.fit_ar(ar2_data, FS, 2)
    f = np.array([0.0, 5.0, 9.0, 50.0])
    zi = np.exp(-2j * np.pi * f / FS)
    a = m.a[0] + m.a[1] * zi + m.a[2] * zi**2
    expected = 2 * m.noise_variance / FS / np.abs(a) ** 2
    np.testing.assert_allclose(m.psd(f), expected, rtol=1e-12)
    # and it follows the Welch estimate near the peak (within the estimate's scatter)
    fw, pw = vibmode.welch(ar2_data, FS, nperseg=512)
    k = np.argmin(np.abs(fw - F0))
    assert m.psd(fw[k]) == pytest.approx(pw[k], rel=0.5)


def test_to_dict_round_trip(ar2_data):
    m = vibmode.fit_ar(ar2_data, FS, 6)
    d = json.loads(json.dumps(m.to_dict()))
    m2 = vibmode.ArmaModel.from_dict(d)
    np.testing.assert_array_equal(m.a, m2.a)
    np.testing.assert_array_equal(m.frequency_hz, m2.frequency_hz)
    assert m2.noise_variance == m.noise_variance
    assert d["fs_hz"] == FS and d["model"]["p"] == 6


def test_iteration_settings_have_one_name_and_defaults_from_rust(arma21_data):
    """fit_arma and sweep name the iteration cap and tolerance alike; their defaults are read from
    Rust (a single fit: 100 and 1e-5; each fit of the analysis sweep: 20 and 1e-4)."""
    import inspect

    fit = inspect.signature(vibmode.fit_arma).parameters
    sw = inspect.signature(vibmode.sweep).parameters
    native = json.loads(vibmode._native.ident_defaults())
    for name in ("max_iterations", "tolerance", "robust"):
        assert fit[name].default == native["fit_arma"][name]
        assert sw[name].default == native["sweep"][name]
    assert fit["max_iterations"].default > sw["max_iterations"].default
    # Both are passed through under their one name: to a tolerance no step can reach, no fit
    # converges, and a cap of 1 iteration per start stops sooner than a cap of 3 (the iterations
    # of the fit's starts add up); the default tolerance is reachable.
    one = vibmode.fit_arma(arma21_data, FS, 2, 1, max_iterations=1, tolerance=1e-300)
    three = vibmode.fit_arma(arma21_data, FS, 2, 1, max_iterations=3, tolerance=1e-300)
    assert not one.converged and not three.converged
    assert one.iterations < three.iterations
    assert vibmode.fit_arma(arma21_data, FS, 2, 1).converged
    # The earlier names still work, with a DeprecationWarning, and mean the same.
    with pytest.warns(DeprecationWarning, match="max_iterations"):
        old = vibmode.fit_arma(arma21_data, FS, 2, 1, max_iter=1, tol=1e-300)
    assert old.iterations == one.iterations and not old.converged


def test_sweep_stabilises_on_the_mode(ar2_data):
    s = vibmode.sweep(ar2_data, FS, orders=range(2, 9), model="ar")
    modes = s.modes
    near = modes[np.abs(modes["frequency_hz"] - F0) < 0.3]
    assert sorted(set(near["order"])) == list(range(2, 9))
    assert len(s.fits) == 7
    # The clusters over the orders: one mode that stays, at the true frequency, in every order
    # (the CLI's `vibmode sweep` prints the same clusters).
    c = s.clusters
    stay = c[c["class"] != "spurious"]
    assert len(stay) == 1, c
    assert abs(stay["frequency_hz"].iloc[0] - F0) < 0.02 * F0, c
    assert stay["order_share"].iloc[0] == 1.0 and stay["class"].iloc[0] == "structural", c
    s2 = vibmode.sweep(ar2_data[:2000], FS, orders=[2, 4], robust="off", as_frame=False)
    assert isinstance(s2.modes, dict) and set(s2.modes["order"]) <= {2, 4}


def test_sweep_starts(arma21_data):
    """``starts``: 'multi' by default (the analysis config's); at a sweep's first order (no warm
    start) the multi-start keeps the lowest end point of the single start's candidates and more,
    so its loss is never above and its iterations are the single start's and more; ARMA(9, 9)
    (p + q = 18, one start either way) is the same with both; an unknown value is refused."""
    y = arma21_data[:2000]

    def same(a, b):
        return a.keys() == b.keys() and all(
            np.array_equal(np.asarray(a[k], dtype=object), np.asarray(b[k], dtype=object)) for k in a
        )

    assert vibmode.analysis_config()["sweep"]["starts"] == "multi"
    multi = vibmode.sweep(y, FS, orders=range(2, 6), as_frame=False).fits
    assert same(vibmode.sweep(y, FS, orders=range(2, 6), starts="multi", as_frame=False).fits, multi)
    single = vibmode.sweep(y, FS, orders=range(2, 6), starts="single", as_frame=False).fits
    assert single["loss"][0] >= multi["loss"][0]
    assert single["iterations"][0] <= multi["iterations"][0]
    assert sum(single["iterations"]) < sum(multi["iterations"])
    nine = [vibmode.sweep(y, FS, orders=[9], starts=s, as_frame=False).fits for s in ("multi", "single")]
    assert same(nine[0], nine[1])
    with pytest.raises(ValueError, match="starts"):
        vibmode.sweep(y, FS, orders=[2], starts="some")


@pytest.mark.parametrize(
    "call,match",
    [
        (lambda y: vibmode.fit_ar(y, FS, 0), "order"),
        (lambda y: vibmode.fit_ar(y, FS, 5000), "order|too"),
        (lambda y: vibmode.fit_ar(y, FS, 2, method="magic"), "magic"),
        (lambda y: vibmode.fit_ar(y, -1.0, 2), "fs"),
        (lambda y: vibmode.fit_arma(y, FS, 2, robust=-1), "robust"),
        (lambda y: vibmode.fit_arma(np.vstack([y, y]), FS, 2), "1-D"),
        (lambda y: vibmode.sweep(y, FS, orders=[]), "empty"),
        (lambda y: vibmode.sweep(y, FS, model="armax"), "armax"),
    ],
)
def test_errors(ar2_data, call, match):
    with pytest.raises(ValueError, match=match):
        call(ar2_data[:3000])
