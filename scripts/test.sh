#!/usr/bin/env bash
# Installs what is missing, builds robomach (Release, with tests) and runs
# the whole ctest suite. Usage: scripts/test.sh [extra ctest arguments]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
scripts/setup-deps.sh
build="${ROBOMACH_BUILD_DIR:-$root/build}"
jobs="$(nproc 2>/dev/null || echo 2)"
# The Python module and its tests need an interpreter with numpy and pytest
# (Debian's python3-numpy, python3-pytest): when the first python3 on PATH
# lacks them (a pyenv or venv interpreter), Debian's /usr/bin/python3 is
# used, so that the Python tests run instead of being skipped.
py_args=()
if ! python3 -c 'import numpy, pytest' >/dev/null 2>&1 && [ -x /usr/bin/python3 ] &&
   /usr/bin/python3 -c 'import numpy, pytest' >/dev/null 2>&1; then
  py_args=(-DPython3_EXECUTABLE=/usr/bin/python3)
fi
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=ON "${py_args[@]}" >/dev/null
cmake --build "$build" --parallel "$jobs"
cd "$build"
ctest --output-on-failure --parallel "$jobs" "$@"
