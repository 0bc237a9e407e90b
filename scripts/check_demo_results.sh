#!/usr/bin/env bash
# Runs `piezobench demo --seed 1` and compares its results.json with the committed reference
# (scripts/compare_results.py: same values apart from the renames it documents).
#   scripts/check_demo_results.sh PIEZOBENCH OUT_DIR
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$1"
out="$2"
rm -rf "$out"
"$bin" demo --seed 1 --threads 2 --out "$out" >/dev/null 2>"$out.log" || { cat "$out.log" >&2; exit 1; }
python3 "$root/scripts/compare_results.py" "$root/tests/fixtures/campaign/demo_seed1_results.json" "$out/results.json"
