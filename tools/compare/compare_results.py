#!/usr/bin/env python3
"""Compares two trees of results.json files field by field.

usage: compare_results.py A_DIR B_DIR [--rtol 1e-9]

Every results.json under A_DIR is paired with the same relative path under B_DIR. Numbers are equal
when |a - b| <= rtol * max(|a|, |b|) (or both NaN/None); strings, booleans and list lengths must be
equal. The `timing` object (wall-clock seconds) is left out. Prints each difference with its JSON
path and exits 1 when there is any."""
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


def main():
    args = sys.argv[1:]
    rtol = 1e-9
    if "--rtol" in args:
        i = args.index("--rtol")
        rtol = float(args[i + 1])
        del args[i : i + 2]
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
        walk(json.loads(fa.read_text()), json.loads(fb.read_text()), "", rtol, out)
        for line in out[:40]:
            print(f"{rel}{line}")
        if len(out) > 40:
            print(f"{rel}: ... {len(out) - 40} more")
        diffs += len(out)
    print(f"{len(files)} files compared, {diffs} differences (rtol {rtol})")
    sys.exit(1 if diffs else 0)


if __name__ == "__main__":
    main()
