#!/usr/bin/env bash
# Installs robomach from the build tree into a scratch prefix, builds the
# consumer project against it and checks its answer.
set -euo pipefail
build=$1; src=$2; work=$3
rm -rf "$work"; mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
cmake -S "$src/tests/cmake_consumer" -B "$work/consumer" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/consumer" >/dev/null
out=$("$work/consumer/consumer" "$src/config/kr210.yaml")
echo "consumer printed $out"
[ "$out" = "10.505871" ] || { echo "expected 10.505871"; exit 1; }
