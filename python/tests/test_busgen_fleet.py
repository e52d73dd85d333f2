"""Acceptance of `vibmode fleet` on the independent bus family (../shared/busgen), issue 31.

Buses drawn at random every run (seeds printed; `VIBMODE_BUS_SEEDS=1,2,3` replays), per bus a
baseline from 2 healthy drives of 8 records, then one drive each: healthy on another day
(20-40 km/h, load 0.85-1.20, road class A-C), damper at 60 % and 70 %, spring at 80 %, tyre at
75 % (each at a random corner), class D road (tools/busgen/fleet.py does the work).

Number of buses: `VIBMODE_FLEET_BUSES` (default 1: 64 records per bus; 2 buses took 3 min 52 s
with a release binary on the loaded 2-core machine, and CI's debug binary analyses more slowly,
so 1 bus keeps it under ~4 min). The issue's healthy
figure needs at least 20 buses: the full run is
`VIBMODE_FLEET_BUSES=20 VIBMODE_BIN=target/release/vibmode python -m pytest -s
python/tests/test_busgen_fleet.py` (docs/fleet.md states its figures).

Skips ("skipped: ...") without busgen or without VIBMODE_BIN, fails instead when
VIBMODE_REQUIRE contains busgen.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tools" / "busgen"))


def _need():
    import harness as h  # noqa: E402

    why = None
    if not (REPO.parent / "shared" / "busgen" / "simulate.py").is_file() and not os.environ.get(
        "VIBMODE_BUSGEN"
    ):
        why = f"busgen not found at {REPO.parent / 'shared' / 'busgen'}"
    elif not os.environ.get("VIBMODE_BIN"):
        why = "VIBMODE_BIN (the vibmode binary to test) is not set"
    else:
        try:
            h.busgen_dir()
            h.busgen_python()
            h.vibmode_bin()
        except h.Skip as e:
            why = str(e)
    if why:
        if h.required():
            pytest.fail(f"VIBMODE_REQUIRE has busgen, but {why}")
        pytest.skip(f"skipped: {why}")


@pytest.fixture(scope="module")
def measured():
    _need()
    import fleet  # tools/busgen/fleet.py

    n = int(os.environ.get("VIBMODE_FLEET_BUSES", "1"))
    seeds = fleet.h.draw_bus_seeds(n, "fleet acceptance")
    buses = fleet.measure(seeds)
    summary = fleet.summarise(buses)
    fleet.print_summary(summary)
    return summary


def _drive_rate(s):
    return s["drive_ok"] / s["drive_n"]


def test_healthy_drives_are_normal(measured):
    s = measured["healthy"]
    # >= 99 % normal: with fewer than 100 drives, every drive.
    assert s["drive_n"] > 0
    assert _drive_rate(s) >= 0.99, s


def test_damper_60_found_with_its_corner(measured):
    s = measured["damper60"]
    assert _drive_rate(s) >= 0.95, s


def test_tyre_75_found_with_its_corner(measured):
    s = measured["tyre75"]
    assert _drive_rate(s) >= 0.90, s


def test_road_d_is_road(measured):
    # A drive is right only when `road` (so never `both` without a fault); per record the
    # figures are printed, not asserted (the issue asks to state them).
    s = measured["roadD"]
    assert _drive_rate(s) >= 0.95, s


def test_found_faults_name_their_component(measured):
    # Of the damper (60 %) and tyre drives found with their corner, the component named
    # (`drives[].component`) is the fault's in >= 90 % (the bar for finding a fault).
    right = sum(measured[c]["drive_ok"] for c in ("damper60", "tyre75"))
    named = sum(measured[c]["component_ok"] for c in ("damper60", "tyre75"))
    assert right > 0, measured
    assert named >= 0.9 * right, measured


@pytest.mark.xfail(reason="issue 31 item 3 not met: a spring at 80 % at one corner is not "
                          "detected (0 of 9 drives on the 9 buses of docs/fleet.md; the body "
                          "response per drive does not separate it)", strict=False)
def test_spring_80_found_with_its_corner(measured):
    s = measured["spring80"]
    assert _drive_rate(s) >= 0.90, s
