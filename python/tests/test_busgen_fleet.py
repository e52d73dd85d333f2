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

Each goal ("at least 95 % of drives") is judged by what the drawn buses can tell: a test fails
when the drives it missed would be improbable if the goal held, P(at least that many misses |
miss rate 1 - goal) < 0.05 (one-sided binomial). With one bus a single missed healthy drive
(goal 99 %, P = 0.01) fails; a single missed damper drive (goal 95 %, P = 0.05) does not: one
drive cannot show a 95 % goal unmet. Every message names the bus seeds to replay.

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

import harness  # noqa: E402


@pytest.fixture(scope="module")
def measured(busgen):
    import fleet  # tools/busgen/fleet.py

    n = int(os.environ.get("VIBMODE_FLEET_BUSES", "1"))
    seeds = fleet.h.draw_bus_seeds(n, "fleet acceptance")
    # Each bus's model file registered (its true geometry, masses and tyres, generic
    # suspension): the suspension fitted per drive is part of what is accepted.
    buses = fleet.measure(seeds, model=True)
    summary = fleet.summarise(buses)
    fleet.print_summary(summary)
    summary["replay"] = "VIBMODE_BUS_SEEDS=" + ",".join(str(b) for b in seeds)
    return summary


ALPHA = 0.05


def _assert_goal(measured, condition, goal):
    s = measured[condition]
    assert s["drive_n"] > 0, (condition, measured["replay"])
    misses = s["drive_n"] - s["drive_ok"]
    p = harness.misses_probability(misses, s["drive_n"], goal)
    assert p >= ALPHA - 1e-12, (
        f"{condition}: {s['drive_ok']}/{s['drive_n']} drives right; {misses} missed would have "
        f"probability {p:.3g} if {goal:.0%} held; replay with {measured['replay']}; {s}"
    )


def test_the_goal_judgement_by_hand():
    # One drive missed of one: a 99 % goal is shown unmet (P = 0.01), a 95 % one is not (0.05).
    assert abs(harness.misses_probability(1, 1, 0.99) - 0.01) < 1e-12
    assert abs(harness.misses_probability(1, 1, 0.95) - 0.05) < 1e-12
    # 2 of 20 missed against 95 %: 1 - 0.95^20 - 20 * 0.05 * 0.95^19 = 0.2642.
    assert abs(harness.misses_probability(2, 20, 0.95) - 0.26416) < 1e-4
    assert abs(harness.misses_probability(0, 5, 0.9) - 1.0) < 1e-12


def test_healthy_drives_are_normal(measured):
    # >= 99 % normal.
    _assert_goal(measured, "healthy", 0.99)


def test_damper_60_found_with_its_corner(measured):
    _assert_goal(measured, "damper60", 0.95)


def test_tyre_75_found_with_its_corner(measured):
    _assert_goal(measured, "tyre75", 0.90)


def test_road_d_is_road(measured):
    # A drive is right only when `road` (so never `both` without a fault); per record the
    # figures are printed, not asserted (the issue asks to state them).
    _assert_goal(measured, "roadD", 0.95)


def test_found_faults_name_their_component(measured):
    # Of the damper (60 %) and tyre drives found with their corner, the component named
    # (`drives[].component`) is the fault's in >= 90 % (the bar for finding a fault).
    right = sum(measured[c]["drive_ok"] for c in ("damper60", "tyre75"))
    named = sum(measured[c]["component_ok"] for c in ("damper60", "tyre75"))
    assert right > 0, (measured["replay"], measured)
    p = harness.misses_probability(right - named, right, 0.9)
    assert p >= ALPHA - 1e-12, (f"component named in {named} of {right} found drives "
                                f"(P = {p:.3g} at 90 %); replay with {measured['replay']}")


@pytest.mark.xfail(reason="issue 31 item 3 not met: a spring at 80 % at one corner is found "
                          "by the suspension fitted per drive on 23 of 50 drives of 8 records "
                          "(10 buses, docs/fleet.md), none on class A roads; 90 % needs more "
                          "records per drive", strict=False)
def test_spring_80_found_with_its_corner(measured):
    s = measured["spring80"]
    assert s["drive_ok"] >= 0.90 * s["drive_n"], (measured["replay"], s)
