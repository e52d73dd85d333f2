"""vibmode.ssi_cov: a hand case, pyOMA2's reference values (tools/reference/ssi.py, committed
JSON), and the true modes of a simulated system over seeds."""

import json
import pathlib

import numpy as np
import pytest

import vibmode

REF = pathlib.Path(__file__).resolve().parents[2] / "tools" / "reference" / "data"


def simulate(n, seed, fs=50.0, modes=((1.2, 0.05), (4.5, 0.02), (9.0, 0.1)), shapes=None, noise=0.1):
    """Modes in real modal form, each the exact discretisation of its continuous block, driven
    by white noise (unit stationary variance per mode), plus white measurement noise."""
    rng = np.random.default_rng(seed)
    shapes = np.asarray(
        shapes
        if shapes is not None
        else [[1.0, 0.8, 0.5, 0.2, -0.1], [0.3, -0.6, 1.0, 0.2, -0.8], [-0.5, 1.0, 0.1, -0.9, 0.4]]
    )
    burn = 2000
    y = np.zeros((shapes.shape[1], n))
    for (f, z), phi in zip(modes, shapes):
        w = 2 * np.pi * f
        r = np.exp(-z * w / fs)
        wd = w * np.sqrt(1 - z * z) / fs
        a = r * np.array([[np.cos(wd), -np.sin(wd)], [np.sin(wd), np.cos(wd)]])
        e = np.sqrt(1 - r * r) * rng.standard_normal((n + burn, 2))
        x = np.zeros(2)
        out = np.empty(n + burn)
        for t in range(n + burn):
            out[t] = x[0]
            x = a @ x + e[t]
        y += np.outer(phi, out[burn:])
    y += noise * y.std(axis=1, keepdims=True) * rng.standard_normal(y.shape)
    return y


def mac(a, b):
    return abs(np.vdot(a, b)) ** 2 / (np.vdot(a, a).real * np.vdot(b, b).real)


def test_one_channel_free_decay_by_hand():
    # y_t = r^t cos(theta t): its correlations decay with the same pole, so order 2 gives it
    # exactly: f = theta fs / 2 pi, damping = -ln r / sqrt(ln r^2 + theta^2).
    fs, f, z = 100.0, 5.0, 0.02
    w = 2 * np.pi * f
    r, theta = np.exp(-z * w / fs), w * np.sqrt(1 - z * z) / fs
    t = np.arange(4000)
    y = r**t * np.cos(theta * t)
    res = vibmode.ssi_cov(y, fs, block_rows=4, orders=range(2, 3), normalise=False, as_frame=False)
    assert list(res.poles["order"]) == [2]
    assert abs(res.poles["frequency_hz"][0] - f) < 1e-3
    assert abs(res.poles["damping_ratio"][0] - z) < 1e-3
    assert res.pole_shapes.shape == (1, 1)
    assert abs(res.pole_shapes[0, 0] - 1.0) < 1e-12


def test_against_pyoma2_reference():
    """pyOMA2 1.4.3's SSI (SSI_fast + SSI_poles) on vibmode's correlation estimator, br = 10,
    orders 2..20 (tools/reference/ssi.py, case "toeplitz"): frequencies and damping to 1e-9
    relative, shapes to 1 - MAC < 1e-9. The reference-based case (channels 0 and 2) the same."""
    ref = json.loads((REF / "ssi.json").read_text())
    inp = json.loads((REF / "ssi_input.json").read_text())
    data = np.asarray(inp["channels"], dtype=float)
    for case, refs in (("toeplitz", None), ("toeplitz_refs", ref["reference_channels"])):
        orders = [o["order"] for o in ref[case]]
        res = vibmode.ssi_cov(
            data, ref["fs_hz"], block_rows=ref["block_rows"], orders=range(min(orders), max(orders) + 1, 2),
            references=refs, normalise=False, as_frame=False,
        )
        compared = 0
        for o in ref[case]:
            rows = np.flatnonzero(res.poles["order"] == o["order"])
            ours = sorted(rows, key=lambda i: res.poles["frequency_hz"][i])
            theirs = sorted(o["modes"], key=lambda m: m["frequency_hz"])
            assert len(ours) == len(theirs), (case, o["order"])
            for i, m in zip(ours, theirs):
                assert abs(res.poles["frequency_hz"][i] / m["frequency_hz"] - 1) < 1e-9
                assert abs(res.poles["damping_ratio"][i] / m["damping_ratio"] - 1) < 1e-9
                shape = np.array([complex(a, b) for a, b in m["shape"]])
                assert 1 - mac(res.pole_shapes[i], shape) < 1e-9
                compared += 1
        assert compared > 20, (case, compared)


def test_uncertainty_against_pyoma2_dohler():
    """First-order standard deviations (uncertainty_blocks=20) against pyOMA2 1.4.3's closed-form
    Döhler propagation of the same block scatter (tools/reference/ssi_uncertainty.py): orders
    2..12, br = 10, to 1e-4 relative (normalise=False: the reference is of the unscaled data;
    scaling the channels weights the SVD's truncation and moves poles and deviations)."""
    ref = json.loads((REF / "ssi_uncertainty.json").read_text())
    inp = json.loads((REF / "ssi_input.json").read_text())
    data = np.asarray(inp["channels"], dtype=float)
    res = vibmode.ssi_cov(
        data, ref["fs_hz"], block_rows=ref["block_rows"], orders=range(2, 13, 2),
        uncertainty_blocks=ref["n_blocks"], normalise=False, as_frame=False,
    )
    compared = 0
    for o in ref["orders"]:
        rows = np.flatnonzero(res.poles["order"] == o["order"])
        ours = sorted(rows, key=lambda i: res.poles["frequency_hz"][i])
        assert len(ours) == len(o["modes"]), o["order"]
        for i, m in zip(ours, o["modes"]):
            assert abs(res.poles["frequency_sd_hz"][i] / m["frequency_std_hz"] - 1) < 1e-4
            assert abs(res.poles["damping_sd"][i] / m["damping_std"] - 1) < 1e-4
            compared += 1
    assert compared == sum(len(o["modes"]) for o in ref["orders"]) > 15
    structural = [k for k, c in enumerate(res.modes["class"]) if c == "structural"]
    assert structural and all(np.isfinite(res.modes["frequency_sd_hz"][k]) for k in structural)
    with pytest.raises(ValueError, match="uncertainty_blocks"):
        vibmode.ssi_cov(data, ref["fs_hz"], uncertainty_blocks=1)
    with pytest.raises(ValueError, match="at most"):
        vibmode.ssi_cov(data, ref["fs_hz"], uncertainty_blocks=1000)


@pytest.mark.parametrize("seed", range(6))
def test_true_modes_recovered(seed):
    """The clusters over the default orders (2..60) hold every true mode: within 1.5 % in
    frequency, 0.02 in damping, MAC > 0.99 with the true shape (the Rust test measures the
    same over 8 other seeds: recall 24/24)."""
    y = simulate(20000, 500 + seed)
    res = vibmode.ssi_cov(y, 50.0, as_frame=False)
    struct = np.flatnonzero(res.modes["class"] == "structural")
    shapes = [[1.0, 0.8, 0.5, 0.2, -0.1], [0.3, -0.6, 1.0, 0.2, -0.8], [-0.5, 1.0, 0.1, -0.9, 0.4]]
    for (f, z), phi in zip(((1.2, 0.05), (4.5, 0.02), (9.0, 0.1)), shapes):
        hits = [
            i for i in struct
            if abs(res.modes["frequency_hz"][i] - f) < 0.015 * f
            and abs(res.modes["damping_ratio"][i] - z) < 0.02
            and mac(res.shapes[i], np.asarray(phi)) > 0.99
        ]
        assert hits, (seed, f, res.modes)


def test_layouts_agree_and_name_channels(rng):
    y = simulate(6000, 7)
    a = vibmode.ssi_cov(y, 50.0, orders=range(6, 7), as_frame=False)
    b = vibmode.ssi_cov(y.T, 50.0, axis=0, orders=range(6, 7), as_frame=False)
    np.testing.assert_array_equal(a.poles["frequency_hz"], b.poles["frequency_hz"])
    rec = vibmode.Recording(y, 50.0, channels=list("abcde"))
    c = vibmode.ssi_cov(rec, orders=range(6, 7), as_frame=False)
    assert c.channels == list("abcde")
    np.testing.assert_array_equal(a.poles["frequency_hz"], c.poles["frequency_hz"])
    # The lags' span by hand: 20 block rows from lag 1, lags 1..39 at 50 Hz: 0.78 s (1.28 Hz).
    assert a.lag_span_s == pytest.approx(39 / 50.0, rel=1e-12)
    assert "lags span 0.78 s: modes below about 1.28 Hz" in repr(a)
    assert vibmode.ssi_cov(y, 50.0, block_rows=10, first_lag=3, orders=range(6, 7)).lag_span_s == (
        pytest.approx(21 / 50.0, rel=1e-12))
    pd = pytest.importorskip("pandas")
    df = pd.DataFrame(y.T, columns=list("vwxyz"))
    df.attrs["fs"] = 50.0
    d = vibmode.ssi_cov(df, orders=range(6, 7))
    assert d.channels == list("vwxyz")
    assert isinstance(d.poles, pd.DataFrame) and isinstance(d.modes, pd.DataFrame)
    np.testing.assert_array_equal(a.poles["frequency_hz"], d.poles["frequency_hz"].to_numpy())
    # The mean shape is in the channels' units: scaling channel 2 scales its entry.
    y2 = y.copy()
    y2[2] *= 1000.0
    e = vibmode.ssi_cov(y2, 50.0, orders=range(6, 7), as_frame=False)
    np.testing.assert_allclose(e.poles["frequency_hz"], a.poles["frequency_hz"], rtol=1e-9)
    ratio = np.abs(e.pole_shapes[:, 2] / e.pole_shapes[:, 0]) / np.abs(a.pole_shapes[:, 2] / a.pole_shapes[:, 0])
    np.testing.assert_allclose(ratio, 1000.0, rtol=1e-6)


def test_defaults_are_the_cli_structs():
    d = vibmode.ssi_cov.defaults
    assert d["ssi"]["block_rows"] == 20 and d["ssi"]["order_max"] == 60 and d["ssi"]["first_lag"] == 1
    assert d["stability"]["mac_min"] == 0.98
    res = vibmode.ssi_cov(simulate(3000, 1), 50.0, as_frame=False)
    assert res.params == d["ssi"] and res.stability_params == d["stability"]
    assert "structural" in repr(res)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(block_rows=0), "block_rows"),
        (dict(orders=[2, 4, 8]), "evenly spaced"),
        (dict(orders=range(1, 4)), "lowest order is 2"),
        (dict(orders=range(200, 202, 2), block_rows=3), "highest is"),
        (dict(references=[9]), "reference channel 9"),
        (dict(first_lag=0), "first_lag"),
        (dict(mac_min=2.0), "mac_min"),
        (dict(axis=3), "axis = 3"),
        (dict(channels=["a"]), "1 channel names for 5 channels"),
    ],
)
def test_bad_arguments_are_value_errors(kwargs, message):
    y = simulate(2000, 3)
    with pytest.raises(ValueError, match=message):
        vibmode.ssi_cov(y, 50.0, **kwargs)


def test_bad_data_are_value_errors():
    y = simulate(2000, 3)
    y[1, 10] = np.nan
    with pytest.raises(ValueError, match="channel 1 sample 10"):
        vibmode.ssi_cov(y, 50.0)
    with pytest.raises(ValueError, match="fs"):
        vibmode.ssi_cov(np.zeros((2, 100)))
    with pytest.raises(ValueError, match="samples per channel are too few"):
        vibmode.ssi_cov(np.random.default_rng(0).standard_normal((2, 20)), 50.0)
    with pytest.raises(ValueError, match="complex"):
        vibmode.ssi_cov(np.ones((2, 100), dtype=complex), 50.0)
