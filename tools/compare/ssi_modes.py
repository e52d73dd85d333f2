#!/usr/bin/env python3
"""Compares two mode listings of the SSI-cov example `ssi_dump` (two builds on the same input):
per record and order the number of modes, and over the modes paired in frequency order the worst
relative frequency difference, the worst relative and absolute damping differences, and the worst
shape entry difference; lists the modes whose damping differs by more than 1e-9 relative.

    cargo run --release -p vibmode-ssi --example ssi_dump -- FILE.f64 > new.txt   # each build
    python3 tools/compare/ssi_modes.py old.txt new.txt
"""
import ast
import collections
import sys


def load(path):
    d = collections.defaultdict(list)
    for line in open(path):
        r, o, f, z, sh = line.split(" ", 4)
        d[(int(r), int(o))].append((float(f), float(z), [complex(a, b) for a, b in ast.literal_eval(sh)]))
    return d


def main():
    a, b = load(sys.argv[1]), load(sys.argv[2])
    wf = wz = wza = ws = 0.0
    counts, over = [], []
    for k in sorted(set(a) | set(b)):
        ma, mb = a.get(k, []), b.get(k, [])
        if len(ma) != len(mb):
            counts.append((k, len(ma), len(mb)))
            continue
        for (fa, za, sa), (fb, zb, sb) in zip(ma, mb):
            wf = max(wf, abs(fa - fb) / fa)
            wz = max(wz, abs(za - zb) / za)
            wza = max(wza, abs(za - zb))
            ws = max(ws, max(abs(x - y) for x, y in zip(sa, sb)))
            if abs(za - zb) / za > 1e-9:
                over.append((k, round(fa, 3), za))
    na, nb = sum(map(len, a.values())), sum(map(len, b.values()))
    print(f"{na} vs {nb} modes; (record, order)s with another mode count: {len(counts)} {counts[:5]}")
    print(f"worst: relative frequency {wf:.1e}, relative damping {wz:.1e} (absolute {wza:.1e}), shape entry {ws:.1e}")
    print(f"damping differing by > 1e-9 relative (record, order), Hz, damping: {over}")


if __name__ == "__main__":
    main()
