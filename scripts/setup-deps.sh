#!/usr/bin/env bash
# Installs robomach's build dependencies from Debian 12 packages when any is
# missing (as root, or through sudo). Safe to run again: it only installs
# what dpkg does not already have.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev liborocos-kdl-dev liburdfdom-dev
  libnlopt-cxx-dev libceres-dev libgoogle-glog-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev
  libyaml-cpp-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libocct-foundation-dev libocct-modeling-data-dev libocct-modeling-algorithms-dev
  libocct-data-exchange-dev libpolyclipping-dev
  python3          # demo.sh (index.html), polishing and frf-estimate tests
  pybind11-dev python3-dev python3-numpy python3-pytest  # the Python module (docs/python.md) and its tests
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup-deps: all ${#packages[@]} Debian packages are installed" >&2
  exit 0
fi

echo "setup-deps: installing ${missing[*]}" >&2
if [ "$(id -u)" -eq 0 ]; then
  sudo_cmd=()
elif command -v sudo >/dev/null 2>&1; then
  sudo_cmd=(sudo)
else
  echo "setup-deps: missing packages (${missing[*]}) and not root, no sudo; install them and retry" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
