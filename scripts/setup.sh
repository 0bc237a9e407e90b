#!/usr/bin/env bash
# Sets piezobench up on a Debian machine and runs one job.
#
#   scripts/setup.sh demo [--sanitize]   install what is missing, build, run the main job
#   scripts/setup.sh test [--sanitize]   install what is missing, build, run the whole test suite
#   scripts/setup.sh build [--sanitize]  install what is missing and build
#   scripts/setup.sh build --fuzz        install what is missing and build the fuzz targets (below)
#   scripts/setup.sh fuzz                install what is missing, build the readers' libFuzzer
#                                        targets in build-sanitize/, replay the regression
#                                        corpus (fatal) and fuzz for PIEZOBENCH_FUZZ_SECONDS
#                                        (default 88) in all, findings reported (docs/fuzzing.md)
#   scripts/setup.sh install             install what is missing, nothing else
#
# Installing is idempotent: packages already present are left alone, and nothing is installed
# (not even an `apt-get update`) when everything is there. --sanitize builds in build-sanitize/
# with clang, AddressSanitizer, UndefinedBehaviorSanitizer and libFuzzer's coverage instrumentation
# (the same tree holds the fuzz targets); the normal build (g++, Release) lives in build/.
set -euo pipefail

job="${1:-}"
shift || true
sanitize=0
fuzz_tree=0
for arg in "$@"; do
  case "$arg" in
    --sanitize) sanitize=1 ;;
    --fuzz) fuzz_tree=1 ;;
    *) echo "setup.sh: unknown option '$arg' (expected --sanitize or --fuzz)" >&2; exit 2 ;;
  esac
done
case "$job" in
  demo|test|build|fuzz|install) ;;
  *) echo "usage: scripts/setup.sh demo|test|build|fuzz|install [--sanitize]" >&2; exit 2 ;;
esac
if [ "$fuzz_tree" -eq 1 ] && [ "$job" != build ]; then
  echo "setup.sh: --fuzz goes with build (scripts/setup.sh fuzz builds and runs the fuzz targets)" >&2; exit 2
fi
[ "$job" = fuzz ] && fuzz_tree=1

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

# Build tools and every library piezobench links, all from Debian's archive.
packages=(
  g++ cmake ninja-build pkg-config
  libeigen3-dev libfftw3-dev libmatio-dev libhdf5-dev zlib1g-dev libsuitesparse-dev libspectra-dev
  libcli11-dev libfmt-dev nlohmann-json3-dev libtomlplusplus-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  # Data-acquisition cards through Comedi (the `measure` command's comedi backend).
  libcomedi-dev
  # The station's record store (`qualify`, `db`: SQLite) and the raw files' SHA-256 (nettle; also the
  # UDP protocol's HMAC-SHA256).
  libsqlite3-dev nettle-dev
  # The station's live web page (src/web): Boost.Beast, header-only.
  libboost-dev
  # An optimized BLAS under CHOLMOD (Debian's alternatives select it): the Craig-Bampton reduction
  # of a 150,000-DOF model takes 31 s of CPU with it and 83 s with the reference BLAS.
  libopenblas0-serial
  # External programs piezobench drives (`superelement from-step`) and the independent checks of
  # the test suite (scipy reads the virtual bench's files).
  gmsh calculix-ccx python3-scipy python3-h5py
  # The Python module (python/, pybind11) and its pytest suite, for Debian's python3.
  python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest
  # The fuzz job (docs/fuzzing.md): clang with libFuzzer and the sanitizer runtimes, and the
  # symbolizer of their stack traces.
  clang-14 libclang-rt-14-dev llvm-14
  # A one-node Slurm for the test of a campaign split over a cluster (tests/slurm, docs/cluster.md).
  slurm-wlm munge
  # The report's plotting library comes from npm (src/report/js); the browser tests run headless
  # Chromium, driven by npm's puppeteer-core (tests/js).
  nodejs chromium
)
# npm: Debian's package, unless the installed Node.js brings its own (NodeSource's conflicts with it).
if ! command -v npm >/dev/null 2>&1; then packages+=(npm); fi

missing=()
for p in "${packages[@]}"; do
  if [ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null)" != "install ok installed" ]; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup.sh: installing ${missing[*]}" >&2
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
  "${sudo_cmd[@]}" apt-get update -q
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The plotting library inlined into report.html, at the versions package-lock.json pins; again
# whenever the lock file is newer than the installed tree.
report_js="$root/src/report/js"
if [ ! -f "$report_js/node_modules/.package-lock.json" ] || \
   [ "$report_js/package-lock.json" -nt "$report_js/node_modules/.package-lock.json" ]; then
  echo "setup.sh: installing the report's plotting library with npm ci" >&2
  npm ci --prefix "$report_js" --no-audit --no-fund --loglevel=error >/dev/null
fi
# The browser tests' puppeteer-core (tests/js), the same way (the ctest fixture browser.npm_ci runs
# the same script, a no-op once installed).
bash "$root/tests/js/install.sh" >/dev/null
[ "$job" = install ] && exit 0

if [ "$fuzz_tree" -eq 1 ] || [ "$sanitize" -eq 1 ]; then
  # One tree for the sanitizers and the fuzz targets: clang with AddressSanitizer, UBSan and
  # libFuzzer's coverage instrumentation on the modules (PIEZOBENCH_FUZZ, cmake/PiezobenchTargets.cmake).
  # The test programs run on it (--sanitize), the fuzz targets link the same objects (fuzz, --fuzz:
  # only the target `fuzzers` and what it links). One clang tree instead of a g++ sanitizer tree and
  # a clang fuzz tree: about a third less compile CPU in CI (docs/performance.md, "Build time").
  # clang-14 is in the packages list above, so a missing compiler is an error, never a skip.
  command -v clang++-14 >/dev/null || { echo "setup.sh: clang++-14 not found (package clang-14)" >&2; exit 1; }
  build_dir="$root/build-sanitize"
  # No Python module there: python3 would need the sanitizer runtime preloaded to load it.
  # -O1 -g1: line tables for the sanitizers' stack traces at about half the compile time of -O2 -g.
  config=(-DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=RelWithDebInfo
          "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=${PIEZOBENCH_FUZZ_CXXFLAGS:--O1 -g1 -DNDEBUG}"
          -DPIEZOBENCH_FUZZ=ON -DPIEZOBENCH_BUILD_BENCHMARKS=OFF -DPIEZOBENCH_BUILD_PYTHON=OFF)
  targets=()
  if [ "$fuzz_tree" -eq 1 ]; then targets=(--target fuzzers); fi
else
  build_dir="$root/build"
  # The Python module is built for Debian's interpreter (where apt puts numpy, scipy and pytest),
  # not for another python3 that may come first on PATH.
  config=(-DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3)
  targets=()
fi
jobs="$(nproc 2>/dev/null || echo 2)"

echo "setup.sh: configuring and building in $build_dir" >&2
cmake -S "$root" -B "$build_dir" -G Ninja "${config[@]}" >/dev/null
cmake --build "$build_dir" -j "$jobs" "${targets[@]}"

case "$job" in
  fuzz)
    # The regression corpus: known inputs, any failure fails the job.
    bash "$root/scripts/fuzz/run_fuzz.sh" "$build_dir" regression
    # Fresh mutations: a finding is reported and kept in build-sanitize/fuzz-artifacts/, not fatal (a
    # new mutation must not fail CI for an unrelated change); PIEZOBENCH_FUZZ_FINDINGS=fail makes it fatal.
    PIEZOBENCH_FUZZ_FINDINGS="${PIEZOBENCH_FUZZ_FINDINGS:-report}" \
      bash "$root/scripts/fuzz/run_fuzz.sh" "$build_dir" fuzz "${PIEZOBENCH_FUZZ_SECONDS:-88}"
    ;;
  demo)
    # The main job: the report's 7-unit campaign simulated on the virtual bench, then analysed;
    # prints where report.html is.
    "$build_dir/app/piezobench" demo --out "$root/piezobench-demo"
    ;;
  test)
    export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
    export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
    # The longest tests start first (tests/ctest_costs.txt: each test's larger cost of a Release and a sanitizer run),
    # so that no long test runs alone at the end of a fresh build's suite; ctest keeps the file
    # up to date from then on.
    costs="$build_dir/Testing/Temporary/CTestCostData.txt"
    if [ ! -f "$costs" ]; then mkdir -p "$(dirname "$costs")" && cp "$root/tests/ctest_costs.txt" "$costs"; fi
    ctest --test-dir "$build_dir" --output-on-failure -j "$jobs"
    ;;
  build) ;;
esac
