#!/usr/bin/env bash
# Issue 19 acceptance sweep, run by hand (long: ~10 min): every B-spline face
# of OpenCASCADE's test parts in ../shared/external/cad_freeform either plans
# within 60 s and 2 GB or is refused with a message naming the face, its size
# and the reason. Reads the files where they lie; writes only to OUT_DIR.
#   [FILES="occt_bearing.iges"] scripts/cad_face_sweep.sh [BUILD_DIR] [OUT_DIR] [extra polish-plan options...]
# e.g. FILES=occt_bearing.iges scripts/cad_face_sweep.sh build /tmp/s --cad-unit-scale 1000
# Prints one line per face (file, face, exit code, time_s, peak RSS MB, the
# last stderr line) and a table per file; times and RSS from /usr/bin/time.
set -u
HERE=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-$HERE/build}
OUT=${2:-/tmp/cad_face_sweep}
shift 2 2>/dev/null || shift $#
EXT=$HERE/../shared/external/cad_freeform
PLAN=$BUILD/apps/polish-plan
PROCESS=$HERE/config/polishing/belt_2N.yaml
if [ ! -d "$EXT" ]; then echo "cad_face_sweep: $EXT absent (../shared not here): nothing to sweep"; exit 0; fi
[ -x "$PLAN" ] || { echo "cad_face_sweep: $PLAN not built" >&2; exit 66; }
[ -x /usr/bin/time ] || { echo "cad_face_sweep: needs /usr/bin/time (Debian package time)" >&2; exit 69; }
mkdir -p "$OUT"
RESULTS=$OUT/sweep.csv
echo "file,face,rc,time_s,rss_mb,message" > "$RESULTS"
for f in ${FILES:-occt_linkrods.step occt_hammer.iges occt_bearing.iges}; do
  "$PLAN" --surface "$EXT/$f" --process "$PROCESS" --list-faces --out "$OUT/${f}_faces.csv" "$@" 2>"$OUT/${f}_list.err"
  for face in $(awk -F, 'NR > 1 && $2 == "bspline" {print $1}' "$OUT/${f}_faces.csv"); do
    err=$OUT/${f}_$face.err
    /usr/bin/time -f "%e %M" -o "$OUT/time.txt" timeout 120 "$PLAN" --surface "$EXT/$f" --face "$face" \
        --process "$PROCESS" --summary "$OUT/${f}_$face.json" "$@" >/dev/null 2>"$err"
    rc=$?
    read -r secs kb < <(tail -1 "$OUT/time.txt")
    msg=$(grep -v "warning: .*the file says\|^Command exited" "$err" | tail -1 | tr ',"' ';'"'" | cut -c1-300)
    line="$f,$face,$rc,$secs,$((kb / 1024)),\"$msg\""
    echo "$line" | tee -a "$RESULTS"
  done
done
echo
echo "file | B-spline faces | planned (exit 0/3) | refused (exit 65) | other | worst time [s] | worst RSS [MB]"
awk -F, 'NR > 1 {n[$1]++; if ($3 == 0 || $3 == 3) p[$1]++; else if ($3 == 65) r[$1]++; else o[$1]++;
         if ($4 > t[$1]) t[$1] = $4; if ($5 > m[$1]) m[$1] = $5}
         END {for (f in n) printf "%s | %d | %d | %d | %d | %.1f | %d\n", f, n[f], p[f], r[f], o[f], t[f], m[f]}' "$RESULTS"
