#!/usr/bin/env python3
"""Compares two trees of results.json files field by field.

usage: compare_results.py A_DIR B_DIR [--rtol 1e-9] [--drop-stop-fits]

Every results.json under A_DIR is paired with the same relative path under B_DIR. Numbers are equal
when |a - b| <= rtol * max(|a|, |b|) (or both NaN/None); strings, booleans and list lengths must be
equal. The `timing` object (wall-clock seconds) is left out. Prints each difference with its JSON
path and exits 1 when there is any.

--drop-stop-fits: A is from before stop records were left unidentified (the sweep runs only on the
records used for the modes and on the first record): A's fits and poles of the other stop records
are dropped, and its fit counts recounted, before comparing."""
import json
import math
import pathlib
import sys


def walk(a, b, path, rtol, out):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted((set(a) | set(b)) - {"timing"}):
            if k not in a or k not in b:
                out.append(f"{path}.{k}: only in {'B' if k not in a else 'A'}")
            else:
                walk(a[k], b[k], f"{path}.{k}", rtol, out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{path}: length {len(a)} vs {len(b)}")
        for i, (x, y) in enumerate(zip(a, b)):
            walk(x, y, f"{path}[{i}]", rtol, out)
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        if math.isnan(a) and math.isnan(b):
            return
        if abs(a - b) > rtol * max(abs(a), abs(b)):
            out.append(f"{path}: {a!r} vs {b!r}")
    elif a != b:
        out.append(f"{path}: {str(a)[:80]!r} vs {str(b)[:80]!r}")


def drop_stop_fits(a):
    stops = {i for i, r in enumerate(a["records"]) if r["stationary"] and i != 0}
    for ch in a["channels"]:
        ch["fits"] = [f for f in ch["fits"] if f["record"] not in stops]
        ch["poles"] = [p for p in ch["poles"] if p["record"] not in stops]
    fits = [f for ch in a["channels"] for f in ch["fits"]]
    a["n_fits"] = len(fits)
    a["n_not_converged"] = sum(1 for f in fits if not f["converged"])
    a["n_failed"] = sum(1 for f in fits if f["failed"])
    return a


def main():
    args = sys.argv[1:]
    rtol = 1e-9
    if "--rtol" in args:
        i = args.index("--rtol")
        rtol = float(args[i + 1])
        del args[i : i + 2]
    drop = "--drop-stop-fits" in args
    if drop:
        args.remove("--drop-stop-fits")
    a_dir, b_dir = map(pathlib.Path, args)
    diffs = 0
    files = sorted(a_dir.rglob("results.json"))
    for fa in files:
        rel = fa.relative_to(a_dir)
        fb = b_dir / rel
        if not fb.exists():
            print(f"{rel}: missing in B")
            diffs += 1
            continue
        out = []
        a = json.loads(fa.read_text())
        if drop:
            a = drop_stop_fits(a)
        walk(a, json.loads(fb.read_text()), "", rtol, out)
        for line in out[:40]:
            print(f"{rel}{line}")
        if len(out) > 40:
            print(f"{rel}: ... {len(out) - 40} more")
        diffs += len(out)
    print(f"{len(files)} files compared, {diffs} differences (rtol {rtol})")
    sys.exit(1 if diffs else 0)


if __name__ == "__main__":
    main()
