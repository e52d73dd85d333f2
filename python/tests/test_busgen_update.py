"""Acceptance on busgen's bus family: the full-car model update from 8 records (issue 30 item 4).

Draws BUSES buses at random every run (printed; VIBMODE_BUS_SEEDS=1,2,3 replays), simulates 8
records each at 2 kHz, fits each twice (vehicle file with and without a front anti-roll bar;
half of the buses have none; a bus that has one cannot be represented by the file without it,
which the rows print) with `$VIBMODE_BIN analyze ... --vehicle bus.toml` and asserts the issue's
goals:
body pitch, heave and roll within 3 % on >= 90 % of the fits, every spring and damper within 10 %
(expected to fail today: marked xfail, see its reason), and that the fits reported as supported
meet them at the confidence the update states (95 %, judged as a binomial), over the draw's fits
and the first bus's fits without sensor noise. A fit the records do not support (reported, no
updated_vehicle.toml) counts as a failure of the goals.
About 25 s per bus on the 2-core machine with a release binary; 4 buses and the noise-free one
stay under 5 minutes with CI's debug binary (opt-level 2 dependencies).

Skips without ../shared/busgen or VIBMODE_BIN; fails instead when VIBMODE_REQUIRE has "busgen".
"""

import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools" / "busgen"))

BUSES = 4


def _skip_or_fail(why: str):
    if "busgen" in os.environ.get("VIBMODE_REQUIRE", "").split(","):
        pytest.fail(f"busgen required: {why}")
    pytest.skip(f"skipped: {why}")


@pytest.fixture(scope="module")
def fits(tmp_path_factory):
    import harness
    import update

    if not os.environ.get("VIBMODE_BIN"):
        _skip_or_fail("VIBMODE_BIN (the vibmode binary) is not set")
    try:
        harness.busgen_dir()
        harness.busgen_python()
        seeds = harness.draw_bus_seeds(BUSES, "model update")
    except harness.Skip as e:
        _skip_or_fail(str(e))
    rows = update.run(seeds, [], tmp_path_factory.mktemp("update"))
    print(update.summarize(rows))
    return rows


@pytest.fixture(scope="module")
def clean_fits(fits, tmp_path_factory):
    """The first drawn bus again without sensor noise (busgen `--no-noise`): fits the records
    determine to about 0.1 %, so that the supported path is judged on every run (on busgen's
    noisy records the update supports almost no fit). Without noise the fits measured so far
    were all supported and met the goals (buses 0, 68563, 66062, 52329, with and without a
    front bar in the file; docs/model_update.md)."""
    import update

    seed = fits[0]["bus"]
    print(f"model update without sensor noise: bus {seed} (the first drawn)")
    rows = update.run([seed], ["--no-noise"], tmp_path_factory.mktemp("update-clean"))
    for r in rows:
        r["noise"] = "none"
    print(update.summarize(rows))
    return rows


def test_a_fit_reported_as_supported_meets_the_goals(fits, clean_fits):
    """The model update writes a model only where the records support it: a fit it reports as
    supported has its body modes within 3 % and every spring and damper within 10 % of the bus's
    at 95 % confidence together (vibmode_vehicle::update::SUPPORT_CONFIDENCE: each quantity's
    jackknife interval of `support_factor` standard deviations inside its tolerance), so among
    the supported fits of a draw the misses are judged as a binomial with a 5 % miss rate, failed
    when that many would have probability below 5 % (one miss among 1-2 supported fits passes,
    two among 2-7 fail). A CI run on 2026-11-28 had one supported fit of 8 miss (bus 78749, heave
    -3.15 % at 3.3 of its standard deviations, dampers -11 %) under the gate of then, which
    asked for 2 standard deviations per quantity: at its edge, with 8 records (Student t, 7
    degrees of freedom), all 11 quantities inside together with probability 0.914^11 = 37 %.
    A fit it could not make (the records do not determine the suspension) says why and writes
    no vehicle file. The fits judged: the draw's (busgen's sensor noise) and the first bus's
    without sensor noise (`clean_fits`), where the records do support the fit."""
    import harness
    import update

    supported, missed = 0, []
    for r in fits + clean_fits:
        if "modes" not in r:
            assert r.get("not_updated"), f"bus {r['bus']}: no figures and no reason"
            assert not r["written"], f"bus {r['bus']}: not updated, yet updated_vehicle.toml written"
            continue
        if not r.get("supported", True):
            assert not r["written"], f"bus {r['bus']}: not supported, yet updated_vehicle.toml written"
            continue
        assert r["written"], f"bus {r['bus']}: supported, but no updated_vehicle.toml"
        supported += 1
        bad = {k: v for k, v in {**r["modes"], **r["params"]}.items()
               if abs(v) > (update.MODE_TOL if k.startswith("body") else update.PARAM_TOL)}
        if bad:
            missed.append(f"bus {r['bus']} (front bar {r['front_bar']}, sensor noise "
                          f"{r.get('noise', 'busgen')}): written with {bad}")
    p = harness.misses_probability(len(missed), supported, 0.95)
    assert p >= 0.05 - 1e-12, (
        f"{len(missed)} of {supported} supported fits miss the goals (P = {p:.3g} at a 5 % miss "
        f"rate): {missed}")


@pytest.mark.xfail(strict=False, reason=(
    "issue 30.1 not met yet: with busgen's unsprung noise the generalized total least squares fit "
    "is consistent but 8 records leave a jackknife spread of 0.4-2.5 % on the body modes (median "
    "1.2 % with the wide band where it is taken) and errors of 4-5 % (median) on springs and "
    "dampers (docs/model_update.md, 'Band' and 'Accuracy'), so the update reports most fits as "
    "not supported"))
def test_model_update_meets_the_issues_goals(fits):
    import update

    s = update.summarize(fits)
    assert s["modes_within_3pct"] >= update.MODE_RATE * s["runs"], (
        f"body modes within 3 % on {s['modes_within_3pct']} of {s['runs']} fits (goal >= 90 %)")
    assert s["all_params_within_10pct"] == s["runs"], (
        f"every spring and damper within 10 % on {s['all_params_within_10pct']} of "
        f"{s['runs']} fits")
