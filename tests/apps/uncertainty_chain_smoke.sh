#!/usr/bin/env bash
# Issue #37 as a user chains it: frf-calibrate --uncertainty-out, the file
# read by frf-predict (intervals, |H| band); model-audit --uncertainty says
# which part of a misfit the parameters' own uncertainty allows, and
# --uncertainty-out writes the named change's fit. Data from frf-synth with
# known truths (m6 +10 %, d6 -5 %; then kq2 -10 %), 1 % noise.
bin=$1; src=$2; work=$3
rm -rf "$work"; mkdir -p "$work"
. "$src/tests/apps/smoke_lib.sh"
cd "$src"
postures=tests/data/calibration/postures_two.csv

expect_exit 0 "$bin/frf-synth" --robot config/kr210.yaml --postures $postures --out "$work/hammer_cal.csv" \
  --set m6_kg=31.955 --set d6_m=0.5225 --noise-rel 0.01 --seed 5
expect_exit 0 "$bin/frf-synth" --robot config/kr210.yaml --postures $postures --out "$work/hammer_kq.csv" \
  --set kq2_Nm_per_rad=2.81862e6 --noise-rel 0.01 --seed 6

# frf-calibrate: the covariance of the four fitted parameters, on the log
# scale; the truth within 5 sigma of each estimate (sigma from the file).
expect_exit 0 "$bin/frf-calibrate" --robot config/kr210.yaml --postures $postures --measured "$work/hammer_cal.csv" \
  --out "$work/cal.yaml" --report "$work/cal" --uncertainty-out "$work/cal_unc.yaml" --summary "$work/cal.json"
expect_in "$work/stderr" "wrote the covariance of 4 fitted parameters to $work/cal_unc.yaml"
expect_in "$work/cal.json" '"uncertainty_out"'
for truth in m6_kg=31.955 d6_m=0.5225; do
  name=${truth%%=*}; value=${truth#*=}
  line=$(grep -F "{name: $name," "$work/cal_unc.yaml")
  [ -n "$line" ] || { echo "FAIL: $name not in cal_unc.yaml"; fails=$((fails+1)); continue; }
  z=$(echo "$line" | sed 's/.*value: \([^,]*\), scale: log}  # \([^ ]*\) %.*/\1 \2/' |
      awk -v t="$value" '{ s = $1 * $2 / 100; d = ($1 - t) / s; print (d < 0 ? -d : d) }')
  awk -v z="$z" 'BEGIN { exit !(z < 5) }' || { echo "FAIL: $name truth $value is $z sigma off: $line"; fails=$((fails+1)); }
done
# The file feeds the predicting tools: intervals and the |H| band.
expect_exit 0 "$bin/frf-predict" --robot config/kr210.yaml --postures $postures --uncertainty "$work/cal_unc.yaml" \
  --modes "$work/modes.csv" --plot "$work/band.png"
expect_in "$work/stderr" "the uncertainty's estimates replace the config's values: m6_kg 29.05 -> 31.96"
expect_in "$work/stderr" "the plots show the 95 % band of |H|"
expect_in "$work/modes.csv" "freq_hz_lower,freq_hz_upper"
expect_file "$work/band.png"

# model-audit: kq2 10 % lower than configured, its uncertainty 8 %: the
# misfit is within it (Mahalanobis distance ~1.3 of 1.96).
cat > "$work/kq2_unc.yaml" <<'YAML'
parameter_uncertainty:
  source: kq2 known to 8 %
  parameters:
    - {name: kq2_Nm_per_rad, value: 3.1318e+6, scale: inverse}
  covariance:
    - [6.5254e-16]
YAML
expect_exit 0 "$bin/model-audit" --robot config/kr210.yaml --postures $postures --measured "$work/hammer_kq.csv" \
  --report "$work/audit" --candidates kq2_Nm_per_rad --uncertainty "$work/kq2_unc.yaml" \
  --uncertainty-out "$work/audit_unc.yaml"
expect_in "$work/stderr" "within the parameter uncertainty: with kq2_Nm_per_rad inside its 95 % confidence region"
expect_in "$work/audit/summary.json" '"covers_failure": true'
expect_in "$work/audit/index.html" "Parameter uncertainty:"
expect_in "$work/audit_unc.yaml" "{name: kq2_Nm_per_rad,"
# frf-calibrate's file holds only what the audit calibrates itself: asked
# for and not done, said and exit 3.
expect_exit 3 "$bin/model-audit" --robot config/kr210.yaml --postures $postures --measured "$work/hammer_kq.csv" \
  --report "$work/audit_cal" --candidates kq2_Nm_per_rad --uncertainty "$work/cal_unc.yaml"
expect_in "$work/stderr" "the parameter uncertainty was not used: it has no parameter the audit can move (m6_kg: calibrated by the audit"
expect_in "$work/audit_cal/summary.json" "the parameter uncertainty was not used"
# A confidence typed as a percentage, and the robot config as the file.
expect_exit 64 "$bin/model-audit" --robot config/kr210.yaml --postures $postures --measured "$work/hammer_kq.csv" \
  --report "$work/bad" --uncertainty "$work/kq2_unc.yaml" --confidence 95
expect_in "$work/stderr" "(0.95 for 95 %)"
expect_exit 65 "$bin/model-audit" --robot config/kr210.yaml --postures $postures --measured "$work/hammer_kq.csv" \
  --report "$work/bad" --uncertainty config/kr210.yaml
expect_in "$work/stderr" "a robot config"
expect_no_file "$work/bad"

# kq-identify --plan with a target (issue #37 §5): the safe depth at the
# demo postures (it depends on joint 6: load and target off the tool axis);
# a band out of reach is exit 3 with about how many postures would reach it
# (and the plan is still written); a band within reach names the first
# postures that reach it; with the default TCP joint 6 is unseen and the
# safe depth's band cannot close, which the warning says.
expect_exit 3 "$bin/kq-identify" --robot config/kr210.yaml --plan 4 --out "$work/plan.csv" \
  --target-postures config/postures_demo.csv --target-quantity safe-depth --cut config/cut_demo.yaml \
  --target-band-pct 1 --load-point-mm 150,0,100 --target-mm 0,120,50
expect_in "$work/stderr" "expected 95 % half-width of the smallest ZOA critical depth: target P1 ±"
expect_in "$work/stderr" "postures would reach it"
expect_file "$work/plan.csv"
expect_exit 3 "$bin/kq-identify" --robot config/kr210.yaml --plan 4 --out "$work/plan.csv" \
  --target-postures config/postures_demo.csv --target-quantity safe-depth --cut config/cut_demo.yaml \
  --target-band-pct 5
expect_in "$work/stderr" "a target depends on a joint these tests cannot determine (joint 6)"
expect_exit 0 "$bin/kq-identify" --robot config/kr210.yaml --plan 4 --out "$work/plan.csv" \
  --target-postures config/postures_demo.csv --target-band-pct 50
expect_in "$work/stderr" "of the plan ("
expect_in "$work/stderr" "bring every target within ±50 %"
expect_exit 64 "$bin/kq-identify" --robot config/kr210.yaml --plan 4 --out "$work/plan.csv" \
  --target-postures config/postures_demo.csv --target-quantity safe-depth
expect_in "$work/stderr" "--cut"
expect_exit 64 "$bin/kq-identify" --robot config/kr210.yaml --tracker tests/data/tracker_campaign.csv \
  --target-postures config/postures_demo.csv
expect_in "$work/stderr" "--target-postures is an option of --plan N"
expect_exit 64 "$bin/kq-identify" --robot config/kr210.yaml --plan 4 --out "$work/plan.csv" --cut config/cut_demo.yaml
expect_in "$work/stderr" "--cut describes the target of a targeted plan"
expect_exit 64 "$bin/kq-identify" --robot config/kr210.yaml --plan 4 --out config/postures_demo.csv \
  --target-postures config/postures_demo.csv
expect_in "$work/stderr" "is also the input of --target-postures"
finish
