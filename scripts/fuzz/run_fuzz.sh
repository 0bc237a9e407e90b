#!/usr/bin/env bash
# Runs the readers' libFuzzer targets (docs/fuzzing.md).
#
#   scripts/fuzz/run_fuzz.sh BUILD_DIR regression       every target over its regression corpus
#   scripts/fuzz/run_fuzz.sh BUILD_DIR fuzz SECONDS     every target on fresh mutations of its seeds
#                                                       for SECONDS in all, shared among the targets
#   scripts/fuzz/run_fuzz.sh BUILD_DIR fuzz SECONDS TARGET   one target (e.g. lti_toml) for SECONDS
#
# Limits of every run: 1 GB of RSS (-rss_limit_mb, also the largest single allocation), 20 s per
# input (-timeout), inputs of at most 64 KiB (-max_len; the regression corpus is replayed whole).
# A crash, a sanitizer report, a leak, a limit or an exception other than piezobench::Error (the
# CLI's exit 1) fails the run; libFuzzer writes the input to BUILD_DIR/fuzz-artifacts/.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:?usage: run_fuzz.sh BUILD_DIR regression|fuzz [SECONDS [TARGET]]}"
mode="${2:?usage: run_fuzz.sh BUILD_DIR regression|fuzz [SECONDS [TARGET]]}"
readers=(mat_timeseries mat_frf csv_timeseries csv_frf uff58 lti_toml campaign_toml two_dof_toml ansys_text calculix matrix_market)
if [ -n "${4:-}" ]; then readers=("$4"); fi
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:allocator_may_return_null=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
limits=(-rss_limit_mb=1024 -malloc_limit_mb=1024 -timeout=20)
artifacts="$build/fuzz-artifacts"
mkdir -p "$artifacts"

# The seeds of a reader: fuzz/seeds/READER, the fixture files of its format and its regression files.
seed_dirs() {
  local reader="$1"
  local dir="$build/fuzz-seeds/$reader"
  rm -rf "$dir"
  mkdir -p "$dir"
  [ -d "$root/fuzz/seeds/$reader" ] && cp "$root/fuzz/seeds/$reader"/* "$dir"/
  case "$reader" in
    mat_timeseries|mat_frf) find "$root/tests/fixtures" -name '*.mat' -size -64k -exec cp {} "$dir"/ \; ;;
    csv_timeseries|csv_frf) find "$root/tests/fixtures" -name '*.csv' -size -64k -exec cp {} "$dir"/ \; ;;
    uff58) find "$root/tests/fixtures" \( -name '*.uff' -o -name '*.unv' \) -size -64k -exec cp {} "$dir"/ \; ;;
  esac
  echo "$dir"
}

status=0
case "$mode" in
  regression)
    for r in "${readers[@]}"; do
      corpus="$root/fuzz/regression/$r"
      [ -d "$corpus" ] || continue
      echo "run_fuzz: $r over $(ls "$corpus" | wc -l) regression file(s)" >&2
      if ! "$build/fuzz/fuzz_$r" "${limits[@]}" -artifact_prefix="$artifacts/$r-" "$corpus"/* >"$build/fuzz-$r.log" 2>&1; then
        tail -30 "$build/fuzz-$r.log" >&2
        echo "run_fuzz: $r FAILED on its regression corpus (log $build/fuzz-$r.log)" >&2
        status=1
      fi
    done
    ;;
  fuzz)
    total="${3:?fuzz needs SECONDS}"
    each=$(( total / ${#readers[@]} ))
    [ "$each" -ge 1 ] || each=1
    for r in "${readers[@]}"; do
      seeds="$(seed_dirs "$r")"
      corpus="$build/fuzz-corpus/$r"   # what the fuzzer finds; kept between local runs
      mkdir -p "$corpus"
      echo "run_fuzz: $r for $each s" >&2
      if ! "$build/fuzz/fuzz_$r" "${limits[@]}" -max_len=65536 -max_total_time="$each" -print_final_stats=1 \
           -artifact_prefix="$artifacts/$r-" "$corpus" "$seeds" >"$build/fuzz-$r.log" 2>&1; then
        tail -40 "$build/fuzz-$r.log" >&2
        echo "run_fuzz: $r FAILED (log $build/fuzz-$r.log, input in $artifacts/)" >&2
        status=1
      else
        grep -E "^stat::number_of_executed_units" "$build/fuzz-$r.log" | sed "s/^/run_fuzz: $r /" >&2 || true
      fi
    done
    ;;
  *) echo "run_fuzz: unknown mode '$mode' (regression or fuzz)" >&2; exit 2 ;;
esac
exit "$status"
