"""Python's `analyze` and the command line's `vibmode analyze` are one library run
(`vibmode_run::Run`): on the same files with the same settings their results.json are equal,
field by field, apart from the run time. The binary is the one `cargo test` built
(`VIBMODE_BIN`, as `.ci/run` sets it); without it the test is skipped with the reason."""

import json
import os
import pathlib
import subprocess

import pytest

import vibmode

ROOT = pathlib.Path(__file__).resolve().parents[2]


def binary():
    given = os.environ.get("VIBMODE_BIN")
    for p in ([pathlib.Path(given)] if given else []) + [
        ROOT / "target" / "debug" / "vibmode",
        ROOT / "target" / "release" / "vibmode",
    ]:
        if p.is_file():
            return p
    return None


def differences(a, b, at=""):
    """Every path where two JSON values differ (type, keys, lengths or values)."""
    if type(a) is not type(b):
        return [f"{at}: {type(a).__name__} vs {type(b).__name__}"]
    if isinstance(a, dict):
        out = [f"{at}.{k}: only in one" for k in sorted(set(a) ^ set(b))]
        for k in sorted(set(a) & set(b)):
            out += differences(a[k], b[k], f"{at}.{k}")
        return out
    if isinstance(a, list):
        if len(a) != len(b):
            return [f"{at}: {len(a)} vs {len(b)} items"]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in differences(x, y, f"{at}[{i}]")]
    return [] if a == b else [f"{at}: {str(a)[:60]} vs {str(b)[:60]}"]


def test_python_and_cli_give_the_same_results_json(tmp_path):
    exe = binary()
    if exe is None:
        pytest.skip("no vibmode binary (set VIBMODE_BIN or run cargo build first)")
    paths = vibmode.simulate("city_bus", records=3, fs=200.0, effects="in-service", seed=5,
                             out_dir=tmp_path / "recs", format="f32").paths
    paths = [str(p) for p in paths]
    config = "[sweep]\norder_max = 8\n"
    (tmp_path / "cfg.toml").write_text(config)
    py = vibmode.analyze(paths, config=config, as_frames=False)
    subprocess.run([str(exe), "analyze", "-q", "--config", str(tmp_path / "cfg.toml"),
                    "-o", str(tmp_path / "out"), *paths], check=True, capture_output=True)
    cli = json.loads((tmp_path / "out" / "results.json").read_text())
    for r in (py, cli):
        r.pop("timing")
    diffs = differences(py, cli)
    assert diffs == [], "\n".join(diffs[:20])
    # Something was found, so the comparison compared results, not two empty lists.
    assert any(m["class"] == "structural" for role in cli["roles"] for m in role["invariant_modes"])


def test_fleet_check_and_status_print_as_the_cli(tmp_path):
    """`print(vibmode.fleet.check(...))` shows the table `vibmode fleet check` prints (the same
    library text, `vibmode_fleet::text`), and the result stays the JSON dict; the same for the
    ingest, the baseline and the status. Two copies of one store, checked once by each."""
    exe = binary()
    if exe is None:
        pytest.skip("no vibmode binary (set VIBMODE_BIN or run cargo build first)")
    vibmode.simulate("city_bus", records=6, fs=200.0, effects="none", seed=21, out_dir=tmp_path / "nominal")
    vibmode.simulate("city_bus", records=3, fs=200.0, effects="none", seed=41, out_dir=tmp_path / "today")
    nominal = sorted(str(p) for p in (tmp_path / "nominal").glob("record_*.wav"))
    today = sorted(str(p) for p in (tmp_path / "today").glob("record_*.wav"))
    db = tmp_path / "a.db"
    vibmode.fleet.init(db)
    # An empty store: a state both say, the same way (not an error, not an empty table).
    empty = vibmode.fleet.status(db)
    assert str(empty).startswith("no vehicle in the store yet")
    cli = subprocess.run([str(exe), "fleet", "status", "--db", str(db)], check=True,
                         capture_output=True, text=True)
    assert str(empty) == cli.stdout
    done = vibmode.fleet.ingest(db, "bus-1", nominal)
    assert len(done) == 6 and done[0]["file"] == nominal[0]
    assert str(done).splitlines()[0] == f"{nominal[0]}: stored as nominal record 1 of vehicle bus-1"
    set_ = vibmode.fleet.baseline(db, "bus-1")
    assert set_["vehicle"] == "bus-1" and str(set_).startswith("vehicle bus-1: model set version 1")
    copy = tmp_path / "b.db"
    copy.write_bytes(db.read_bytes())

    py = vibmode.fleet.check(db, "bus-1", today)
    cli = subprocess.run([str(exe), "fleet", "check", "--db", str(copy), "--vehicle", "bus-1", *today],
                         check=True, capture_output=True, text=True)
    assert str(py) == cli.stdout
    assert py["drives"][0]["drive"] == str(tmp_path / "today")
    assert str(tmp_path / "today") in str(py)
    assert json.loads(json.dumps(py)) == dict(py)

    st = vibmode.fleet.status(db)
    assert str(st).startswith("vehicle          latest drive verdict")
    assert st[0]["vehicle"] == "bus-1" and "bus-1" in str(st).splitlines()[1]
    cli = subprocess.run([str(exe), "fleet", "status", "--db", str(db)], check=True, capture_output=True,
                         text=True)
    assert str(st) == cli.stdout


def test_info_statistics_agree_with_numpy(tmp_path):
    """`vibmode info --json` against numpy (the independent implementation) on arrays numpy
    writes: min and max exactly; mean, population std (`ddof=0`) and RMS per channel within
    1e-12 relative, times the channel's condition |mean| / std for the std (both sides round
    each sample at |mean|: a channel at 1e5 with std 1e-3 agrees to about 1e-12 x 1e8; a naive
    sum of squares would lose it entirely, 1e-16 x 1e16). Over seeds, lengths across the
    reader's 65 536-frame blocks; a dead channel is marked."""
    np = pytest.importorskip("numpy")
    exe = binary()
    if exe is None:
        pytest.skip("no vibmode binary (set VIBMODE_BIN or run cargo build first)")
    for seed, n in [(1, 5), (2, 65_536), (3, 65_537), (4, 200_003)]:
        rng = np.random.default_rng(seed)
        a = rng.standard_normal((n, 3)) * [1.0, 1e-3, 50.0] + [0.0, 1e5, -7.0]
        a[:, 0] = 0.0 if seed == 1 else a[:, 0]
        path = tmp_path / f"a{seed}.npy"
        np.save(path, a)
        out = subprocess.run([str(exe), "info", "--json", "--fs", "2000", str(path)],
                             check=True, capture_output=True, text=True).stdout
        (s,) = json.loads(out)
        assert (s["frames"], s["fs_hz"], len(s["channels"])) == (n, 2000.0, 3)
        assert s["duration_s"] == pytest.approx(n / 2000.0, rel=1e-15)
        for c, x in zip(s["channels"], a.T):
            assert (c["min"], c["max"]) == (x.min(), x.max())
            cond = max(1.0, abs(x.mean()) / max(x.std(), 1e-300))
            for key, ref, rel in [("mean", x.mean(), 1e-12), ("std", x.std(), 1e-12 * cond),
                                  ("rms", np.sqrt(np.mean(x * x)), 1e-12)]:
                assert c[key] == pytest.approx(ref, rel=rel, abs=1e-300), (seed, key)
        assert s["channels"][0]["constant"] == (0.0 if seed == 1 else None)
