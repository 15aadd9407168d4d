#!/usr/bin/env bash
# The main job on the shipped default: installs what is missing, builds
# robomach (Release) and predicts the tool-tip FRFs of the default KUKA KR210
# milling system at the five demonstration postures.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
scripts/setup-deps.sh
build="${ROBOMACH_BUILD_DIR:-$root/build}"
jobs="$(nproc 2>/dev/null || echo 2)"
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --parallel "$jobs" --target frf-predict
out="$root/out/demo"
mkdir -p "$out"
"$build/apps/frf-predict" --robot config/kr210.yaml --postures config/postures_demo.csv \
  --out "$out/pred.csv" --modes "$out/modes.csv" --details "$out/details.json" \
  --plot "$out/frf.png" --plot-dir "$out/frf"
echo
echo "demo: outputs in $out"
echo "  pred.csv      tool-tip receptance H (m/N) per posture and direction pair"
echo "  modes.csv     natural frequencies, damping ratios, modal masses, tool-tip mode shapes"
echo "  details.json  J, cond(J), M_q, K_q, C_q, Cartesian M, K, C and static compliance per posture"
echo "  frf.png       magnitude and phase of Hxx, Hyy, Hzz at all postures (frf/ has one per posture)"
echo
head -n 13 "$out/modes.csv" | column -s, -t  # head first: with pipefail a closed pipe would fail the demo
