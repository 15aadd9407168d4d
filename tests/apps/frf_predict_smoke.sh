#!/usr/bin/env bash
# frf-predict as a user runs it: help, the shipped default, and bad input.
tool=$1; src=$2; work=$3
rm -rf "$work"; mkdir -p "$work"
. "$src/tests/apps/smoke_lib.sh"
cd "$src"

expect_exit 0 "$tool" --help
expect_in "$work/stdout" "--postures"
expect_in "$work/stdout" "Exit codes"

# The shipped default: all outputs, the modal table has 6 modes x 5 postures.
expect_exit 0 "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv \
  --out "$work/pred.csv" --modes "$work/modes.csv" --details "$work/d.json" --plot "$work/frf.png"
for f in pred.csv modes.csv d.json frf.png; do expect_file "$work/$f"; done
[ "$(grep -c '^P' "$work/modes.csv")" -eq 30 ] || { echo "FAIL: modes.csv rows"; fails=$((fails+1)); }
expect_in "$work/pred.csv" "# quantity: receptance"
expect_in "$work/modes.csv" "pose_id,mode,freq_hz,damping_ratio,modal_mass_kg,ux,uy,uz"
# The default model's first mode at P1 is 10.505871 Hz (kr210_reference.yaml check_values).
expect_in "$work/modes.csv" "P1,1,10.50587"

# Results on stdout when --out is omitted.
printf 'pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\nA,0,-90,90,0,45,0\n' > "$work/one.csv"
expect_exit 0 "$tool" --robot config/kr210.yaml --postures "$work/one.csv" --directions xx --fmin-hz 10 --fmax-hz 20 --df-hz 5
expect_in "$work/stdout" "A,x,x,15,"

# Bad input: exit 65, file:line on stderr, no output file.
printf 'pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\nP1,0,-90,90,0,45,0\nP2,0,-90,9O,0,45,0\n' > "$work/bad.csv"
expect_exit 65 "$tool" --robot config/kr210.yaml --postures "$work/bad.csv" --out "$work/bad_out.csv"
expect_in "$work/stderr" "bad.csv:3: column q3_deg: expected a number, got \"9O\""
expect_no_file "$work/bad_out.csv"
printf 'pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg\nP1,0,-90,90,0,45\n' > "$work/five.csv"
expect_exit 65 "$tool" --robot config/kr210.yaml --postures "$work/five.csv" --out "$work/five_out.csv"
expect_in "$work/stderr" "missing column q6_deg (or q6_rad): the robot has 6 joints"
expect_no_file "$work/five_out.csv"
printf '<robot name="x"><link name="a"></robot>\n' > "$work/broken.urdf"
sed "s|urdf: kr210_r2700_2.urdf|urdf: $work/broken.urdf|" config/kr210.yaml > "$work/broken.yaml"
expect_exit 65 "$tool" --robot "$work/broken.yaml" --postures config/postures_demo.csv --out "$work/u.csv"
expect_in "$work/stderr" "broken.urdf: not a valid URDF model"
expect_no_file "$work/u.csv"

# Missing input file: 66; bad option value: 64.
expect_exit 66 "$tool" --robot nothere.yaml --postures config/postures_demo.csv
expect_in "$work/stderr" "nothere.yaml: robot config not found"
expect_exit 64 "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv --directions xq
expect_exit 64 "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv --set m6_kg=-1
expect_in "$work/stderr" "outside its bounds"
expect_exit 64 "$tool" --robot config/kr210.yaml

# A wrist-singular posture (q5 = 0) and one outside the limits: outputs
# written, finite numbers, a clear warning each, exit 3 (flagged).
printf 'pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\nS,0,-90,90,0,0,0\nL,0,0,90,0,45,0\n' > "$work/flag.csv"
expect_exit 3 "$tool" --robot config/kr210.yaml --postures "$work/flag.csv" --out "$work/flag_out.csv" --details "$work/flag.json"
expect_in "$work/stderr" "posture S is near a singularity"
expect_in "$work/stderr" "posture L: joint 2 at 0 deg is outside its limits [-140, -5] deg"
expect_file "$work/flag_out.csv"
if grep -qiE "nan|inf" "$work/flag_out.csv"; then echo "FAIL: non-finite FRF"; fails=$((fails+1)); fi
expect_in "$work/flag.json" "\"cartesian\": null"

# An output on an input's path is refused, and the input survives.
cp config/postures_demo.csv "$work/same.csv"
expect_exit 64 "$tool" --robot config/kr210.yaml --postures "$work/same.csv" --out "$work/same.csv"
expect_in "$work/stderr" "is also the input of --postures"
cmp -s config/postures_demo.csv "$work/same.csv" || { echo "FAIL: input changed"; fails=$((fails+1)); }
expect_exit 64 "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv --out "$work/o.csv" --modes "$work/o.csv"
# A full disk on stdout is an error (exit 73), not a silent success.
if [ -w /dev/full ]; then
  "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv --directions xx > /dev/full 2>"$work/stderr"
  rc=$?; [ "$rc" -eq 73 ] || { echo "FAIL: /dev/full gave exit $rc"; fails=$((fails+1)); }
fi
# Duplicated direction pairs and absurd grids are usage errors.
expect_exit 64 "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv --directions xx,xx
expect_exit 64 "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv --df-hz 1e-17

# --uncertainty (issue #37), against a closed form: every joint stiffness
# scaled by one factor s with sigma(ln s) = 0.1 (a rank-one covariance in
# ln k) scales every undamped frequency by sqrt(s), so the first-order 95 %
# interval of each is f (1 -+ 1.959964 * 0.05); the shipped values are the
# estimates (no note of changed values).
{
  echo "parameter_uncertainty:"
  echo "  source: all joints scaled together"
  echo "  parameters:"
  for j in 1 2 3 4 5 6; do
    k=$(grep -o 'joint_stiffness_Nm_per_rad: \[[^]]*\]' config/kr210.yaml | sed 's/.*\[//; s/\]//' | cut -d, -f$j | tr -d ' ')
    echo "    - {name: kq${j}_Nm_per_rad, value: $k, scale: log}"
  done
  echo "  covariance:"
  for j in 1 2 3 4 5 6; do echo "    - [0.01, 0.01, 0.01, 0.01, 0.01, 0.01]"; done
} > "$work/common_scale.yaml"
expect_exit 0 "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv --modes "$work/umodes.csv" \
  --uncertainty "$work/common_scale.yaml" --uncertainty-method first-order
expect_in "$work/umodes.csv" "freq_hz_lower,freq_hz_upper,damping_ratio_lower,damping_ratio_upper,peak_receptance_m_per_N,"
expect_in "$work/stderr" "P1: 95 % intervals (first-order): mode 1 10.51 Hz"
if grep -q "estimates replace" "$work/stderr"; then echo "FAIL: the shipped values were called changed"; fails=$((fails+1)); fi
bad=$(awk -F, 'NR > 1 { lo = $3 * (1 - 1.959964 * 0.05); hi = $3 * (1 + 1.959964 * 0.05);
  if ((($9 - lo) / $3) ^ 2 > 1e-10 || (($10 - hi) / $3) ^ 2 > 1e-10 || $16 != "first-order") print }' "$work/umodes.csv")
[ -z "$bad" ] || { echo "FAIL: intervals off the closed form:"; echo "$bad" | head -3; fails=$((fails+1)); }
# The intervals go to --modes or --summary; one of them is needed.
expect_exit 64 "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv --out "$work/x.csv" \
  --uncertainty "$work/common_scale.yaml"
expect_in "$work/stderr" "give one of them"
# A parameter from the file and from --set: refused, naming both.
expect_exit 64 "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv --modes "$work/x.csv" \
  --uncertainty "$work/common_scale.yaml" --set kq2_Nm_per_rad=3e6
expect_in "$work/stderr" "--set kq2_Nm_per_rad and --uncertainty"
# A confidence typed as a percentage.
expect_exit 64 "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv --modes "$work/x.csv" \
  --uncertainty "$work/common_scale.yaml" --confidence 95
expect_in "$work/stderr" "a percentage? 95 % is 0.95"
# The robot config given as the uncertainty file.
expect_exit 65 "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv --modes "$work/x.csv" \
  --uncertainty config/kr210.yaml
expect_in "$work/stderr" "a robot config"
# A parameter the model does not have.
sed 's/kq6_Nm_per_rad/kq7_Nm_per_rad/' "$work/common_scale.yaml" > "$work/kq7.yaml"
expect_exit 65 "$tool" --robot config/kr210.yaml --postures config/postures_demo.csv --modes "$work/x.csv" \
  --uncertainty "$work/kq7.yaml"
expect_in "$work/stderr" "kq7_Nm_per_rad' (from $work/kq7.yaml (all joints scaled together)) is not a parameter of this model"
expect_no_file "$work/x.csv"
finish
