# Helpers for the app smoke tests: expect_exit CODE CMD... runs CMD, checks its
# exit code and keeps stdout/stderr in $out/$err for expect_in.
set -u
fails=0
expect_exit() {
  local want=$1; shift
  "$@" >"$work/stdout" 2>"$work/stderr"
  local got=$?
  if [ "$got" -ne "$want" ]; then
    echo "FAIL: expected exit $want, got $got: $*"; sed 's/^/  stderr: /' "$work/stderr"; fails=$((fails + 1))
  fi
}
expect_in() {  # expect_in FILE TEXT
  if ! grep -qF -- "$2" "$1"; then
    echo "FAIL: '$2' not in $1:"; sed 's/^/  /' "$1" | head -5; fails=$((fails + 1))
  fi
}
expect_file() { [ -s "$1" ] || { echo "FAIL: missing or empty $1"; fails=$((fails + 1)); }; }
expect_no_file() { [ ! -e "$1" ] || { echo "FAIL: $1 exists but must not"; fails=$((fails + 1)); }; }
finish() {
  if [ "$fails" -ne 0 ]; then echo "$fails check(s) failed"; exit 1; fi
  echo "all checks passed"
}
