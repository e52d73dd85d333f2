import numpy as np
import pytest


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


def rel_err(a, b):
    """Largest relative difference (relative to the largest |b|, so zero bins do not blow up)."""
    a = np.asarray(a)
    b = np.asarray(b)
    assert a.shape == b.shape, (a.shape, b.shape)
    scale = np.max(np.abs(b))
    return float(np.max(np.abs(a - b)) / scale) if scale > 0 else float(np.max(np.abs(a - b)))


@pytest.fixture(scope="module")
def busgen():
    """The busgen acceptance tests' tools (tools/busgen/harness.py, returned): busgen in
    ../shared/busgen (or VIBMODE_BUSGEN), its Python and VIBMODE_BIN. Skips ("skipped: ...")
    without one of them, fails instead when VIBMODE_REQUIRE contains busgen."""
    import os
    import sys
    from pathlib import Path

    repo = Path(__file__).resolve().parents[2]
    sys.path.insert(0, str(repo / "tools" / "busgen"))
    import harness as h

    why = None
    if not (repo.parent / "shared" / "busgen" / "simulate.py").is_file() and not os.environ.get(
        "VIBMODE_BUSGEN"
    ):
        why = f"busgen not found at {repo.parent / 'shared' / 'busgen'}"
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
    return h
