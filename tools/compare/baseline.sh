#!/usr/bin/env bash
# Runs the demo and `analyze` on the real files in ../shared/data/real/ with the binary given,
# writing each results.json under OUT. Used to compare two builds field by field
# (tools/compare/compare_results.py), e.g. before and after a refactor that must keep results.
# usage: tools/compare/baseline.sh path/to/vibmode OUT
set -euo pipefail
BIN="$1"; OUT="$2"
REAL="$(cd "$(dirname "$0")/../.." && pwd)/../shared/data/real"
mkdir -p "$OUT"
"$BIN" demo -q -o "$OUT/demo" >"$OUT/demo.txt"
if [ -d "$REAL" ]; then
  for f in "$REAL"/bratislava_transit/*.csv; do
    n="$(basename "$f" .csv)"
    "$BIN" analyze -q --fs 500 -c z -o "$OUT/$n" "$f" >"$OUT/$n.txt"
  done
  "$BIN" analyze -q -c Z-Axis -o "$OUT/slab" "$REAL/rc_slab_smartphone/Example02_Smartphone_Data.csv" >"$OUT/slab.txt"
else
  echo "skipped: $REAL not present (real files)"
fi
