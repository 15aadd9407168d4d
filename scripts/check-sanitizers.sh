#!/usr/bin/env bash
# Builds robomach with AddressSanitizer + UndefinedBehaviorSanitizer (and
# LeakSanitizer) in a separate build directory and runs ctest there. Any
# sanitizer report, in a test or in a tool a test runs, fails the script.
#
# Usage: scripts/check-sanitizers.sh [ctest arguments]
#   scripts/check-sanitizers.sh                    # the whole suite (about 2 h on 2 cores)
#   scripts/check-sanitizers.sh -L readers         # the readers' tests only
#   scripts/check-sanitizers.sh -R 'FrfCsv|Uff58'  # a subset by name
# Environment:
#   ROBOMACH_SAN_BUILD_DIR  build directory (default: build-asan in the checkout)
#   ROBOMACH_SAN_TARGETS    space-separated targets to build (default: all)
#   ROBOMACH_SAN_JOBS       parallel build and test jobs (default: 2)
#   ROBOMACH_SAN_NICE       nice level of the build and the tests (default: 5)
#   ROBOMACH_SAN_TIMEOUT    per-test timeout [s] (default: 7200; CTest's own
#                           1500 s is too short here: the sanitized build runs
#                           10-15 times slower, and OptimisePlanLong.Saddle,
#                           160-260 s in a normal build, took 1514 s)
#   ROBOMACH_SAN_EXTRA_FLAGS  more compile flags (the fuzz build: -fsanitize=fuzzer-no-link)
#   ROBOMACH_SAN_CMAKE_ARGS   more cmake arguments (the fuzz build: -DROBOMACH_FUZZ=ON)
#   CXX                     compiler (default: clang++ when installed, else g++)
# Exit: 0 clean; 1 a test failed or a sanitizer reported something; 2 the
# build failed.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${ROBOMACH_SAN_BUILD_DIR:-$root/build-asan}"
jobs="${ROBOMACH_SAN_JOBS:-2}"
nice_level="${ROBOMACH_SAN_NICE:-5}"
if [ -z "${CXX:-}" ]; then
  if command -v clang++ >/dev/null 2>&1; then CXX=clang++; else CXX=g++; fi
fi

# -O1 keeps the stacks readable and the suite tolerable; no NDEBUG, so
# ROBOMACH_ASSERT and Eigen's own range checks are on as well.
#
# EIGEN_MALLOC_ALREADY_ALIGNED=1: Eigen decides from __SANITIZE_ADDRESS__
# whether malloc's 16-byte alignment can be trusted. Debian's Ceres was built
# without ASan, so inside Ceres Eigen frees with plain free() while our code,
# under ASan, would allocate with Eigen's handmade_aligned_malloc (an offset
# pointer): a matrix allocated on one side and freed on the other (Ceres'
# covariance hands its results back this way) is a bad free. The define makes
# both sides use malloc/free, which is what the uninstrumented Ceres does.
san_flags="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
cxx_flags="-O1 -g $san_flags -DEIGEN_MALLOC_ALREADY_ALIGNED=1 ${ROBOMACH_SAN_EXTRA_FLAGS:-}"
read -r -a extra_cmake_args <<<"${ROBOMACH_SAN_CMAKE_ARGS:-}"

launcher=()
if command -v ccache >/dev/null 2>&1; then
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(dirname "$root")}"
  [ -d /work/.ccache ] && export CCACHE_DIR="${CCACHE_DIR:-/work/.ccache}"
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi

echo "check-sanitizers: configuring $build with $CXX ($cxx_flags)" >&2
# CMAKE_BUILD_TYPE=Sanitize has no flags of its own: everything is above.
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Sanitize -DBUILD_TESTING=ON \
  -DROBOMACH_BUILD_BENCHMARKS=OFF -DCMAKE_CXX_COMPILER="$CXX" \
  -DCMAKE_CXX_FLAGS="$cxx_flags" \
  -DCMAKE_EXE_LINKER_FLAGS="$san_flags" -DCMAKE_SHARED_LINKER_FLAGS="$san_flags" \
  "${launcher[@]}" "${extra_cmake_args[@]}" >/dev/null

# ASan and LSan reports go to files, so that a report in a tool whose test
# expects a non-zero exit (or swallows stderr) is not missed. UBSan cannot
# share that (with ASan's log_path set, gcc's runtime prints a halting UBSan
# report on stderr only), so its reports are found in the tests' output
# (Testing/Temporary/LastTest.log holds every test's output, passed or not).
logs="$build/sanitizer-logs"
rm -rf "$logs"; mkdir -p "$logs"
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:check_initialization_order=1:log_path=$logs/asan"
export LSAN_OPTIONS="suppressions=$root/scripts/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

targets=()
if [ -n "${ROBOMACH_SAN_TARGETS:-}" ]; then
  read -r -a names <<<"$ROBOMACH_SAN_TARGETS"
  targets=(--target "${names[@]}")
fi
echo "check-sanitizers: building ${ROBOMACH_SAN_TARGETS:-everything} (-j$jobs, nice $nice_level)" >&2
if ! nice -n "$nice_level" cmake --build "$build" --parallel "$jobs" "${targets[@]}"; then
  echo "check-sanitizers: the build failed" >&2
  exit 2
fi

status=0
cd "$build"
rm -f Testing/Temporary/LastTest*.log
nice -n "$nice_level" ctest --output-on-failure --parallel "$jobs" --timeout "${ROBOMACH_SAN_TIMEOUT:-7200}" "$@" || status=1

pattern='runtime error:|ERROR: AddressSanitizer|ERROR: LeakSanitizer|SUMMARY: UndefinedBehaviorSanitizer'
for f in Testing/Temporary/LastTest*.log; do
  [ -f "$f" ] || continue
  if grep -qE "$pattern" "$f"; then
    echo "check-sanitizers: sanitizer report(s) in the tests' output ($build/$f):" >&2
    grep -nE -A12 "$pattern" "$f" | head -200 >&2
    status=1
  fi
done

# Any log file means a sanitizer spoke, whatever the test concluded.
shopt -s nullglob
reports=("$logs"/*)
if [ ${#reports[@]} -gt 0 ]; then
  echo "check-sanitizers: ${#reports[@]} sanitizer report(s):" >&2
  for f in "${reports[@]}"; do
    echo "==== $f" >&2
    sed -n '1,60p' "$f" >&2
  done
  status=1
fi
if [ $status -eq 0 ]; then
  echo "check-sanitizers: clean" >&2
else
  echo "check-sanitizers: FAILED (test failures or sanitizer reports above)" >&2
fi
exit $status
