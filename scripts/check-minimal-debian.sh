#!/usr/bin/env bash
# Checks that the README's two commands need nothing else: makes a minimal
# Debian 12 root from Debian's packages (debootstrap --variant=minbase, plus
# git to clone), clones this repository into it and runs scripts/demo.sh and
# scripts/test.sh there, as a new user on a fresh machine would. Needs root
# (debootstrap, chroot, mounts) and Debian's package mirror.
#
# Usage: scripts/check-minimal-debian.sh [ROOT_DIR] [ctest arguments...]
#   ROOT_DIR  where the minimal system goes (default /var/tmp/robomach-minbase;
#             reused if it exists, so a second run skips the bootstrap)
# Environment: MIRROR (default http://deb.debian.org/debian),
#   KEEP_BUILD=1 keeps the clone's build folder between runs.
# Exit status: that of the first failing step (0 = both commands passed).
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
target="${1:-/var/tmp/robomach-minbase}"
shift || true
mirror="${MIRROR:-http://deb.debian.org/debian}"

if [ "$(id -u)" -ne 0 ]; then
  echo "check-minimal-debian: needs root (debootstrap, chroot)" >&2
  exit 1
fi
if ! command -v debootstrap >/dev/null 2>&1; then
  echo "check-minimal-debian: installing debootstrap" >&2
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq debootstrap >/dev/null
fi

if [ ! -x "$target/usr/bin/apt-get" ]; then
  echo "check-minimal-debian: bootstrapping a minbase Debian 12 in $target" >&2
  # git only to clone, as a user would have it; everything else must come from setup-deps.
  debootstrap --variant=minbase --include=git,ca-certificates bookworm "$target" "$mirror" >&2
fi

mounted=()
cleanup() {
  for m in "${mounted[@]}"; do umount -l "$m" 2>/dev/null || true; done
}
trap cleanup EXIT
for fs in proc sys dev; do
  if ! mountpoint -q "$target/$fs"; then
    mount --rbind "/$fs" "$target/$fs"
    mounted+=("$target/$fs")
  fi
done
cp /etc/resolv.conf "$target/etc/resolv.conf" 2>/dev/null || true

# The committed state of this repository, as a clone sees it, and ../shared
# beside it as in CI (read-only bind mount, when it exists here).
work="$target/work"
mkdir -p "$work"
rm -rf "$work/main.git"
git clone -q --bare "$repo" "$work/main.git"
if [ "${KEEP_BUILD:-0}" != 1 ]; then rm -rf "$work/main"; fi
if [ -d "$work/main/.git" ]; then
  git -C "$work/main" fetch -q "$work/main.git" && git -C "$work/main" reset -q --hard FETCH_HEAD
else
  rm -rf "$work/main"
  chroot "$target" git clone -q /work/main.git /work/main
fi
if [ -d "$repo/../shared" ]; then
  mkdir -p "$work/shared"
  if ! mountpoint -q "$work/shared"; then
    mount --bind "$repo/../shared" "$work/shared"
    mount -o remount,bind,ro "$work/shared"
    mounted=("$work/shared" "${mounted[@]}")
  fi
fi

run() {
  echo "check-minimal-debian: $*" >&2
  chroot "$target" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    LANG=C.UTF-8 bash -c "cd /work/main && $*"
}
start=$(date +%s)
run scripts/demo.sh
demo_done=$(date +%s)
run scripts/test.sh "$@"
end=$(date +%s)
echo "check-minimal-debian: both commands passed in a minbase Debian 12 root (demo incl. set-up $((demo_done - start)) s, tests $((end - demo_done)) s)" >&2
