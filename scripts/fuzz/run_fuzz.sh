#!/usr/bin/env bash
# Runs the readers' libFuzzer targets (docs/fuzzing.md).
#
#   scripts/fuzz/run_fuzz.sh BUILD_DIR regression       every target over its regression corpus
#   scripts/fuzz/run_fuzz.sh BUILD_DIR fuzz SECONDS     every target on fresh mutations of its seeds
#                                                       for SECONDS in all, shared among the targets
#                                                       (SECONDS / targets each, one target per core
#                                                       at a time: PIEZOBENCH_FUZZ_JOBS)
#   scripts/fuzz/run_fuzz.sh BUILD_DIR fuzz SECONDS TARGET   one target (e.g. lti_toml) for SECONDS
#
# Limits of every run: 1 GB of RSS (-rss_limit_mb, also the largest single allocation), 20 s per
# input (-timeout), inputs of at most 64 KiB (-max_len; the regression corpus is replayed whole).
# A crash, a sanitizer report, a leak, a limit or an exception other than piezobench::Error (the
# CLI's exit 1) is a finding; libFuzzer writes the input to BUILD_DIR/fuzz-artifacts/.
#
# The regression replay always fails (exit 1) on a finding: those inputs are known and fixed.
# Fuzzing fresh mutations fails on a finding too, unless PIEZOBENCH_FUZZ_FINDINGS=report (what CI
# sets): then a finding is reported and kept in BUILD_DIR/fuzz-artifacts/ and the run exits 0, so a
# new mutation found in a CI run never fails an unrelated change. Every target starts from
# -seed=PIEZOBENCH_FUZZ_SEED (default 1) plus its index, so a run can be repeated with the same
# mutation sequence (the number of inputs tried in SECONDS still depends on the machine).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:?usage: run_fuzz.sh BUILD_DIR regression|fuzz [SECONDS [TARGET]]}"
mode="${2:?usage: run_fuzz.sh BUILD_DIR regression|fuzz [SECONDS [TARGET]]}"
readers=(mat_timeseries mat_frf csv_timeseries csv_frf uff58 lti_toml campaign_toml two_dof_toml ansys_text calculix matrix_market
         udp_target station_toml answers_toml twin_toml http_request)
if [ -n "${4:-}" ]; then readers=("$4"); fi
findings="${PIEZOBENCH_FUZZ_FINDINGS:-fail}"
case "$findings" in fail|report) ;; *) echo "run_fuzz: PIEZOBENCH_FUZZ_FINDINGS must be fail or report" >&2; exit 2 ;; esac
seed="${PIEZOBENCH_FUZZ_SEED:-1}"
# Debian's llvm-14 installs the symbolizer as llvm-symbolizer-14 (llvm-symbolizer comes with 'llvm').
symbolizer="$(command -v llvm-symbolizer-14 || command -v llvm-symbolizer || true)"
sym_opt=""
[ -n "$symbolizer" ] && sym_opt=":external_symbolizer_path=$symbolizer"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:allocator_may_return_null=0$sym_opt}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1$sym_opt}"
for r in "${readers[@]}"; do
  [ -x "$build/fuzz/fuzz_$r" ] || { echo "run_fuzz: $build/fuzz/fuzz_$r is missing (scripts/setup.sh fuzz builds it)" >&2; exit 2; }
done
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

# The targets run PIEZOBENCH_FUZZ_JOBS at a time (default: one per core); each writes its own log
# and its outcome to BUILD_DIR/fuzz-READER.status.
jobs="${PIEZOBENCH_FUZZ_JOBS:-$(nproc 2>/dev/null || echo 1)}"
in_background() {
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
  "$@" &
}

# regress READER: its regression files, if any; any failure is fatal.
regress() {
  local r="$1" files=()
  [ -d "$root/fuzz/regression/$r" ] && files+=("$root/fuzz/regression/$r"/*)
  # The .mat reproducers of issue 21 are the io tests' fixtures (scripts/fixtures/make_io_hostile_fixtures.py).
  case "$r" in mat_timeseries|mat_frf) files+=("$root"/tests/fixtures/io/hostile/*.mat) ;; esac
  [ ${#files[@]} -gt 0 ] || { echo ok >"$build/fuzz-$r.status"; return 0; }
  echo "run_fuzz: $r over ${#files[@]} regression file(s)" >&2
  if "$build/fuzz/fuzz_$r" "${limits[@]}" -artifact_prefix="$artifacts/$r-" "${files[@]}" >"$build/fuzz-$r.log" 2>&1; then
    echo ok >"$build/fuzz-$r.status"
  else
    tail -30 "$build/fuzz-$r.log" >&2
    echo "run_fuzz: $r FAILED on its regression corpus (log $build/fuzz-$r.log)" >&2
    echo failed >"$build/fuzz-$r.status"
  fi
}

# fuzz_one READER INDEX SECONDS: fresh mutations of its seeds and its corpus.
fuzz_one() {
  local r="$1" index="$2" each="$3" seeds corpus
  seeds="$(seed_dirs "$r")"
  corpus="$build/fuzz-corpus/$r"   # what the fuzzer finds; kept between local runs
  mkdir -p "$corpus"
  echo "run_fuzz: $r for $each s (-seed=$((seed + index)))" >&2
  if "$build/fuzz/fuzz_$r" "${limits[@]}" -max_len=65536 -max_total_time="$each" -print_final_stats=1 \
       -seed=$((seed + index)) -artifact_prefix="$artifacts/$r-" "$corpus" "$seeds" >"$build/fuzz-$r.log" 2>&1; then
    grep -E "^stat::number_of_executed_units" "$build/fuzz-$r.log" | sed "s/^/run_fuzz: $r /" >&2 || true
    echo ok >"$build/fuzz-$r.status"
  else
    tail -40 "$build/fuzz-$r.log" >&2
    echo "run_fuzz: $r FOUND an input that fails (log $build/fuzz-$r.log, input in $artifacts/)" >&2
    echo failed >"$build/fuzz-$r.status"
  fi
}

# The readers whose status file says failed (every target must have written one).
failed_readers() {
  local r
  for r in "${readers[@]}"; do
    [ "$(cat "$build/fuzz-$r.status" 2>/dev/null)" = ok ] || echo "$r"
  done
}

status=0
for r in "${readers[@]}"; do rm -f "$build/fuzz-$r.status"; done
case "$mode" in
  regression)
    for r in "${readers[@]}"; do in_background regress "$r"; done
    wait
    [ -z "$(failed_readers)" ] || status=1
    ;;
  fuzz)
    total="${3:?fuzz needs SECONDS}"
    each=$(( total / ${#readers[@]} ))
    [ "$each" -ge 1 ] || each=1
    index=0
    for r in "${readers[@]}"; do
      index=$((index + 1))
      in_background fuzz_one "$r" "$index" "$each"
    done
    wait
    mapfile -t found < <(failed_readers)
    if [ ${#found[@]} -gt 0 ]; then
      echo "run_fuzz: FINDINGS in ${found[*]}: inputs kept in $artifacts/ (reproduce: $build/fuzz/fuzz_READER FILE;" \
           "once fixed, add the file to fuzz/regression/READER/)" >&2
      if [ "$findings" = fail ]; then
        status=1
      else
        echo "run_fuzz: PIEZOBENCH_FUZZ_FINDINGS=report: reported, not failed" >&2
      fi
    else
      echo "run_fuzz: no findings" >&2
    fi
    ;;
  *) echo "run_fuzz: unknown mode '$mode' (regression or fuzz)" >&2; exit 2 ;;
esac
exit "$status"
