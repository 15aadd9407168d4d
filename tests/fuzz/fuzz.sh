#!/usr/bin/env bash
# Builds and runs the libFuzzer targets of tests/fuzz (issue #22 item 4).
#
#   tests/fuzz/fuzz.sh build [target ...]       # configure build-fuzz, build fuzz_all (or the targets)
#   tests/fuzz/fuzz.sh run <name> <seconds> [libFuzzer args ...]
#                                               # fuzz build-fuzz/tests/fuzz/fuzz_<name>
#
# Needs clang and libFuzzer (Debian: apt-get install --no-install-recommends
# clang libclang-rt-14-dev). The build is clang -O1 -g with libFuzzer's
# coverage instrumentation, ASan and UBSan (halting) on the whole library, and
# EIGEN_MALLOC_ALREADY_ALIGNED=1 as in scripts/check-sanitizers.sh (Debian's
# Ceres and OpenCASCADE are not instrumented; the define makes Eigen on both
# sides agree on malloc/free).
#
# `run` fuzzes with -timeout=1 (an input slower than a second is a finding),
# -rss_limit_mb=2048, -max_len=16384 (ROBOMACH_FUZZ_MAX_LEN; larger seeds are
# used truncated: a 1 MB seed would make every mutation of it slow) and
# -max_total_time=<seconds>, under nice 19. The working
# corpus is $ROBOMACH_FUZZ_WORK/<name> (default /tmp/robomach-fuzz; outside
# the repository); it starts from tests/fuzz/corpus/<name> and the target's
# seeds (the project's own files, listed in build-fuzz/tests/fuzz/fuzz_<name>.seeds,
# copied to $ROBOMACH_FUZZ_WORK/<name>-seeds).
# Findings are written to $ROBOMACH_FUZZ_WORK/<name>-artifacts/.
# Environment: ROBOMACH_FUZZ_BUILD_DIR (default build-fuzz in the checkout),
# CXX (default clang++), ROBOMACH_FUZZ_JOBS (default 2).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${ROBOMACH_FUZZ_BUILD_DIR:-$root/build-fuzz}"
work="${ROBOMACH_FUZZ_WORK:-/tmp/robomach-fuzz}"

usage() { sed -n '4,7p' "$0" >&2; exit 64; }
[ $# -ge 1 ] || usage

case "$1" in
  build)
    shift
    cxx="${CXX:-clang++}"
    san="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
    launcher=()
    if command -v ccache >/dev/null 2>&1; then
      export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(dirname "$root")}"
      launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
    fi
    # CMAKE_BUILD_TYPE=Sanitize has no flags of its own: everything is here.
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Sanitize -DBUILD_TESTING=ON \
      -DROBOMACH_BUILD_APPS=OFF -DROBOMACH_BUILD_BENCHMARKS=OFF -DROBOMACH_FUZZ=ON \
      -DCMAKE_CXX_COMPILER="$cxx" \
      -DCMAKE_CXX_FLAGS="-O1 -g $san -fsanitize=fuzzer-no-link -DEIGEN_MALLOC_ALREADY_ALIGNED=1" \
      -DCMAKE_EXE_LINKER_FLAGS="$san" "${launcher[@]}" >/dev/null
    targets=("$@")
    [ ${#targets[@]} -gt 0 ] || targets=(fuzz_all)
    nice -n 19 cmake --build "$build" --parallel "${ROBOMACH_FUZZ_JOBS:-2}" --target "${targets[@]}"
    ;;
  run)
    [ $# -ge 3 ] || usage
    name="$2" seconds="$3"
    shift 3
    exe="$build/tests/fuzz/fuzz_$name"
    [ -x "$exe" ] || { echo "fuzz.sh: $exe not built (tests/fuzz/fuzz.sh build fuzz_$name)" >&2; exit 66; }
    mkdir -p "$work/$name" "$work/$name-artifacts"
    # libFuzzer takes directories: the seeds are copied into one.
    rm -rf "$work/$name-seeds"; mkdir -p "$work/$name-seeds"
    while read -r seed; do [ -n "$seed" ] && cp "$seed" "$work/$name-seeds/"; done < "$build/tests/fuzz/fuzz_$name.seeds"
    asan="detect_leaks=1:strict_string_checks=1"
    # OpenCASCADE has no frame pointers: only the slow unwinder gives its leak
    # stacks enough frames for scripts/lsan.supp to recognise them.
    [ "$name" = cad_face ] && asan="$asan:fast_unwind_on_malloc=0"
    export ASAN_OPTIONS="${ASAN_OPTIONS:-$asan}"
    export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
    export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$root/scripts/lsan.supp:print_suppressions=0}"
    cd "$work"
    exec nice -n 19 "$exe" -max_total_time="$seconds" -timeout=1 -rss_limit_mb=2048 -print_final_stats=1 \
      -max_len="${ROBOMACH_FUZZ_MAX_LEN:-16384}" \
      -artifact_prefix="$work/$name-artifacts/" "$@" "$work/$name" "$root/tests/fuzz/corpus/$name" "$work/$name-seeds"
    ;;
  *) usage ;;
esac
