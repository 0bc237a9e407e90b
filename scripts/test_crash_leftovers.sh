#!/usr/bin/env bash
# Clean after a crash (issue 35): kill -9 (odd rounds) or SIGTERM (even rounds) `demo` and `run` at
# random moments, then run them again to the end; nothing of the killed runs may be left (no
# `.staging-*` folder, no `.*.tmp-*` file, no `.piezobench.lock`), and the results of the rerun are
# complete. It prints how many runs were killed mid-run and how many leftovers the reruns removed.
#
#   scripts/test_crash_leftovers.sh [BINARY] [ROUNDS]     (defaults: build/app/piezobench, 6)
#
# Each round takes a few seconds (a demo is ~2 s on an idle machine); the folders are in a private
# temporary folder removed at the end. Not part of every CI run (about 10 s per round on an idle
# machine); tests/io/output_dir_test.cpp checks the removal itself on every run.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${1:-$root/build/app/piezobench}"
rounds="${2:-6}"
[ -x "$bin" ] || { echo "test_crash_leftovers: $bin is not built" >&2; exit 2; }
work="$(mktemp -d "${TMPDIR:-/tmp}/piezobench-crash.XXXXXX")"
trap 'rm -rf "$work"' EXIT
RANDOM=$$

# Runs "$@" in the background and sends it $signal after a random 0.05 .. 2.5 s (or lets it end);
# counts a kill that found the process still running.
killed=0
kill_at_random() {
  "$@" >/dev/null 2>&1 &
  local pid=$!
  sleep "$(printf '0.%02d' $((RANDOM % 100)))"
  sleep $((RANDOM % 3))
  if kill "-$signal" "$pid" 2>/dev/null; then killed=$((killed + 1)); fi
  wait "$pid" 2>/dev/null || true
}

leftovers() {
  find "$1" \( -name '.staging-*' -o -name '.*.tmp-*' -o -name '.piezobench.lock' \) -print
}

fail=0
# A complete demo first: the campaign `run` analyses.
"$bin" demo --seed 1 --threads 2 --out "$work/demo" >/dev/null 2>&1
found=0
for round in $(seq 1 "$rounds"); do
  # SIGKILL in odd rounds, SIGTERM in even ones (issue 35: both left staging folders).
  signal=KILL
  [ $((round % 2)) -eq 0 ] && signal=TERM
  kill_at_random "$bin" demo --seed 1 --threads 2 --out "$work/demo"
  kill_at_random "$bin" run "$work/demo/campaign.toml" --threads 2 --out "$work/run"
  # What the killed runs left (the lock of a killed run included), before the reruns remove it.
  found=$((found + $(leftovers "$work" | wc -l)))
  # The next runs remove what the killed ones left, and finish.
  "$bin" demo --seed 1 --threads 2 --out "$work/demo" >/dev/null 2>&1 || { echo "round $round: demo rerun failed" >&2; fail=1; }
  "$bin" run "$work/demo/campaign.toml" --threads 2 --out "$work/run" >/dev/null 2>&1 || { echo "round $round: run rerun failed" >&2; fail=1; }
  left="$(leftovers "$work")"
  if [ -n "$left" ]; then
    echo "round $round: left behind:" >&2
    echo "$left" >&2
    fail=1
  fi
  for f in results.json results.mat report.html; do
    [ -s "$work/run/$f" ] || { echo "round $round: run/$f missing after the rerun" >&2; fail=1; }
  done
done
echo "test_crash_leftovers: $rounds rounds (SIGKILL and SIGTERM in turn), $killed of $((2 * rounds)) runs killed mid-run," \
     "$found leftovers found after the kills"
if [ "$fail" -eq 0 ]; then echo "test_crash_leftovers: every rerun completed and removed them: nothing left behind"; fi
exit "$fail"
