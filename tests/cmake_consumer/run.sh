#!/usr/bin/env bash
# Installs robomach from the build tree into a scratch prefix, builds the
# consumer projects against it and checks their answers: a full consumer
# (every component), and a dynamics-only one configured as if Ceres, NLopt,
# yaml-cpp, urdfdom, nlohmann_json and OpenCASCADE were not installed.
set -euo pipefail
build=$1; src=$2; work=$3
rm -rf "$work"; mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
# The consumers are compiled and linked with the build's own flags: in a
# sanitizer build (scripts/check-sanitizers.sh) the installed libraries are
# instrumented and link only into instrumented programs. Empty otherwise.
cxx_flags=$(sed -n 's/^CMAKE_CXX_FLAGS:STRING=//p' "$build/CMakeCache.txt")
ld_flags=$(sed -n 's/^CMAKE_EXE_LINKER_FLAGS:STRING=//p' "$build/CMakeCache.txt")
flags=(-DCMAKE_CXX_FLAGS="$cxx_flags" -DCMAKE_EXE_LINKER_FLAGS="$ld_flags")
cmake -S "$src/tests/cmake_consumer" -B "$work/consumer" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$work/prefix" "${flags[@]}" >/dev/null
cmake --build "$work/consumer" >/dev/null
out=$("$work/consumer/consumer" "$src/config/kr210.yaml")
echo "consumer printed $out"
[ "$out" = "10.505871" ] || { echo "expected 10.505871"; exit 1; }

disabled=()
for p in Ceres NLopt yaml-cpp urdfdom nlohmann_json OpenCASCADE; do
  disabled+=("-DCMAKE_DISABLE_FIND_PACKAGE_$p=ON")
done
cmake -S "$src/tests/cmake_consumer/dynamics_only" -B "$work/dynamics_only" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$work/prefix" "${disabled[@]}" "${flags[@]}" >/dev/null
if grep -E '^ROBOMACH_(OPENCV|CLIPPER)' "$work/dynamics_only/CMakeCache.txt"; then
  echo "a dynamics-only consumer looked for OpenCV or Clipper"; exit 1
fi
cmake --build "$work/dynamics_only" >/dev/null
read -r model closed < <("$work/dynamics_only/dynamics_consumer")
echo "dynamics-only consumer: natural frequency $model Hz, closed form $closed Hz"
# Both are the same formula up to the eigen-solver's rounding: 1e-9 relative.
awk -v a="$model" -v b="$closed" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= 1e-9 * b) }' \
  || { echo "expected the closed form"; exit 1; }
# A component that does not exist is refused by name.
mkdir -p "$work/bad"
cat > "$work/bad/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.22)
project(bad LANGUAGES CXX)
find_package(robomach 0.1 REQUIRED COMPONENTS dynamcs)
CM
if cmake -S "$work/bad" -B "$work/bad/build" -DCMAKE_PREFIX_PATH="$work/prefix" >"$work/bad.log" 2>&1; then
  echo "an unknown component was accepted"; exit 1
fi
grep -q "robomach has no component 'dynamcs'" "$work/bad.log" || { cat "$work/bad.log"; exit 1; }
echo "ok"
