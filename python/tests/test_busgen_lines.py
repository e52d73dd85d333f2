"""Acceptance on the independent bus family (../shared/busgen), issue 30 items 2-4: periodic lines
and the structural modes beside them, over buses drawn at random every run.

Runs tools/busgen/lines.py (see its docstring for the scoring) on BUSES buses (printed; replay
with VIBMODE_BUS_SEEDS=1,2,3) and asserts the issue's figures:
- recall >= 95 % of the true lines at least 3 % away from every mode;
- no structural mode (bending, wheel hop) classed periodic on >= 95 % of the buses;
- the bending found as structural within 2 % on >= 90 % of the buses where a sensor sees it.
The three goals are not met on every draw yet (issue 30 open): each is marked xfail (not
strict) with the figures measured on 2026-11-27 (docs/analysis.md, "Lines on busgen"); the test still runs, prints every bus and fails loudly on an
error in the scoring. Remove the marks once the figures hold.
Skips ("skipped: ...") without busgen or without VIBMODE_BIN; fails instead when VIBMODE_REQUIRE
contains "busgen". 5 buses of 8 records: 73 s in all with a release binary on the shared two
cores (busgen about 2 s per bus; the test-profile binary is optimised too, not timed here).
"""

import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools" / "busgen"))

import harness  # noqa: E402
import lines  # noqa: E402

BUSES = 5


def _ready():
    try:
        if not (ROOT.parent / "shared" / "busgen" / "simulate.py").is_file() and not os.environ.get(
                "VIBMODE_BUSGEN"):
            raise harness.Skip(f"busgen not found at {ROOT.parent / 'shared' / 'busgen'}")
        harness.busgen_dir()
        if not os.environ.get("VIBMODE_BIN"):
            raise harness.Skip("VIBMODE_BIN (the vibmode binary to test) is not set")
        harness.vibmode_bin()
        harness.busgen_python()
    except harness.Skip as e:
        if harness.required():
            pytest.fail(f"VIBMODE_REQUIRE has busgen but: {e}")
        pytest.skip(f"skipped: {e}")


@pytest.fixture(scope="module")
def measured():
    _ready()
    return lines.measure(BUSES, seed=1, jobs=2)


@pytest.mark.xfail(reason="issue 30 goal met over 50 buses of two draws on 2026-11-27 (129/134 = "
                          "96 %; 95 % on the draw of 30), but a draw of 5 buses holds ~13 lines, so "
                          "one miss (a 10-11.6 Hz order on the wheel-hop flank) fails it: about "
                          "one run in four; docs/analysis.md, 'Lines on busgen'",
                   strict=False)
def test_lines_apart_from_modes_are_recalled(measured):
    assert measured["apart"] > 0
    assert measured["found"] >= 0.95 * measured["apart"], measured


@pytest.mark.xfail(reason="issue 30 goal met over two draws on 2026-11-27 (48/50 buses, 96 %: "
                          "19/20, 29/30), but a lightly damped cluster beside the bending (bus "
                          "8788) can still be called a line, so a draw of 5 fails about one run "
                          "in five; docs/analysis.md",
                   strict=False)
def test_no_structural_mode_is_classed_periodic(measured):
    assert measured["no_structural_periodic"] >= 0.95 * measured["buses"], measured


@pytest.mark.xfail(reason="issue 30 item 3 not met: 22/48 buses (46 %) over two draws on 2026-11-27 "
                          "(10/18, 12/30): weak bending peaks (5-45 % of a sensor's strongest), "
                          "a line within 2 % of the bending, or its SSI-cov poles split or in "
                          "fewer than half the orders; docs/analysis.md, third step",
                   strict=False)
def test_bending_is_found_structural(measured):
    if measured["bending_seen"] == 0:
        pytest.skip("skipped: no bus drawn has a bending mode a sensor sees")
    assert measured["bending_structural"] >= 0.9 * measured["bending_seen"], measured
