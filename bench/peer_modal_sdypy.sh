#!/usr/bin/env bash
# Runs bench/peer_modal_sdypy.py in a scratch virtual environment with
# sdypy-EMA from PyPI (issue #34 §8). Not a test; needs a build (frf-modes).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="${ROBOMACH_PEER_VENV:-$root/build/peer-venv}"
if [ ! -x "$venv/bin/python" ]; then
  /usr/bin/python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet numpy sdypy-EMA
fi
exec "$venv/bin/python" "$root/bench/peer_modal_sdypy.py" "$@"
