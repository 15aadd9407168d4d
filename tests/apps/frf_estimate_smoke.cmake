# frf-estimate (issue #18, item 4), run as a new user would: records made by
# a plain-Python simulation (make_hammer_records.py, independent of
# robomach), the defaults, a double and a clipped hit, too few hits, bad and
# missing input. Included from tests/apps/CMakeLists.txt.
set(EST_TMP ${PROJECT_BINARY_DIR}/test_tmp/frf_estimate)
add_test(NAME frf_estimate.make_records
         COMMAND python3 ${CMAKE_CURRENT_SOURCE_DIR}/make_hammer_records.py ${EST_TMP}/records)
set_tests_properties(frf_estimate.make_records PROPERTIES FIXTURES_SETUP frf_estimate_records)

robomach_app_test(frf_estimate.help RC 0 CMD $<TARGET_FILE:frf-estimate> --help STDOUT "--exp-window-tau-s")
# Defaults: hits 1-3 averaged; 4 (rebound) and 5 (accelerometer clipped at
# 12 m/s²) rejected by name; FRF CSV, summary and plot written.
robomach_app_test(frf_estimate.defaults RC 0 CLEAN ${EST_TMP}/defaults
  CMD $<TARGET_FILE:frf-estimate> ${EST_TMP}/records/hits.csv --out ${EST_TMP}/defaults/frf.csv
      --summary ${EST_TMP}/defaults/summary.json --plot ${EST_TMP}/defaults/frf.png
  FILES ${EST_TMP}/defaults/frf.csv ${EST_TMP}/defaults/summary.json ${EST_TMP}/defaults/frf.png
  STDERR "hit 4 \\([^)]*hits.csv:1539[^)]*\\) rejected: double hit.*hit 5 \\([^)]*\\) rejected: overload: response acc_y is clipped.*3 of 5 hits averaged")
add_test(NAME frf_estimate.summary_names_rejected_hits
  COMMAND python3 -c "import json,sys; d=json.load(open(sys.argv[1])); s={h['id']:h['status'] for h in d['hits']}; print(s, d['averages']); sys.exit(0 if s=={'1':'accepted','2':'accepted','3':'accepted','4':'double hit','5':'overload'} and d['averages']==3 else 1)"
          ${EST_TMP}/defaults/summary.json)
set_tests_properties(frf_estimate.summary_names_rejected_hits PROPERTIES DEPENDS frf_estimate.defaults)
# The output reads back as formats.md §3 with its averages and coherence.
add_test(NAME frf_estimate.output_is_formats_section_3
  COMMAND python3 -c "import csv,sys; L=open(sys.argv[1]).read().splitlines(); m=dict(l[2:].split(': ',1) for l in L if l.startswith('# ') and ': ' in l); r=list(csv.DictReader(l for l in L if not l.startswith('#'))); k={(x['response'],x['excitation']) for x in r}; print(m, len(r), k); sys.exit(0 if m['averages']=='3' and m['quantity']=='receptance' and k=={('x','x'),('y','x')} and len(r)==400 and all(0<=float(x['coherence'])<=1 for x in r) else 1)"
          ${EST_TMP}/defaults/frf.csv)
set_tests_properties(frf_estimate.output_is_formats_section_3 PROPERTIES DEPENDS frf_estimate.defaults)
# One file per hit, two hits: fewer than --min-hits 3, flagged (exit 3),
# written anyway.
robomach_app_test(frf_estimate.too_few_hits RC 3 CLEAN ${EST_TMP}/two
  CMD $<TARGET_FILE:frf-estimate> ${EST_TMP}/records/hit_a.csv ${EST_TMP}/records/hit_b.csv
      --out ${EST_TMP}/two/frf.csv --quantity accelerance --estimator h2
  FILES ${EST_TMP}/two/frf.csv
  STDERR "fewer than --min-hits 3")
# Every hit over a 50 N force range: nothing to average, exit 65, no FRF
# file, the summary says why.
robomach_app_test(frf_estimate.all_rejected RC 65 CLEAN ${EST_TMP}/none
  CMD $<TARGET_FILE:frf-estimate> ${EST_TMP}/records/hits.csv --out ${EST_TMP}/none/frf.csv
      --summary ${EST_TMP}/none/summary.json --force-range-N 50
  FILES ${EST_TMP}/none/summary.json NO_FILES ${EST_TMP}/none/frf.csv
  STDERR "every hit was rejected")
robomach_app_test(frf_estimate.bad_number RC 65 CLEAN ${EST_TMP}/broken
  CMD $<TARGET_FILE:frf-estimate> ${EST_TMP}/records/broken.csv --out ${EST_TMP}/broken/frf.csv
  NO_FILES ${EST_TMP}/broken/frf.csv
  STDERR "broken.csv:9:4: column tip_x_m: expected a number, got \"nan\"")
robomach_app_test(frf_estimate.missing_file RC 66
  CMD $<TARGET_FILE:frf-estimate> ${EST_TMP}/records/no_such.csv --out ${EST_TMP}/missing.csv
  STDERR "no_such.csv: hammer record file not found")
robomach_app_test(frf_estimate.unknown_direction RC 64
  CMD $<TARGET_FILE:frf-estimate> ${EST_TMP}/records/hits.csv --out ${EST_TMP}/dir.csv --direction acc=z
  STDERR "--direction acc=z: no response channel 'acc'")
# Records too short for the decay: leakage, exit 3, with a proposed tau;
# with that exponential window the result is clean and records its tau.
robomach_app_test(frf_estimate.leakage RC 3 CLEAN ${EST_TMP}/short
  CMD $<TARGET_FILE:frf-estimate> ${EST_TMP}/records/short.csv --out ${EST_TMP}/short/frf.csv
  FILES ${EST_TMP}/short/frf.csv
  STDERR "response tip_x: has not decayed by the end of the record in 4 of 4.*tau = 0.0133 s")
robomach_app_test(frf_estimate.exponential_window RC 0 CLEAN ${EST_TMP}/short_exp
  CMD $<TARGET_FILE:frf-estimate> ${EST_TMP}/records/short.csv --out ${EST_TMP}/short_exp/frf.csv
      --exp-window-tau-s 0.0133
  FILES ${EST_TMP}/short_exp/frf.csv)
add_test(NAME frf_estimate.exponential_window_recorded
  COMMAND python3 -c "import sys; L=open(sys.argv[1]).read().splitlines(); print(L[:6]); sys.exit(0 if '# exponential_window_tau_s: 0.0133' in L else 1)"
          ${EST_TMP}/short_exp/frf.csv)
set_tests_properties(frf_estimate.exponential_window_recorded PROPERTIES DEPENDS frf_estimate.exponential_window)
set_tests_properties(frf_estimate.leakage frf_estimate.exponential_window
                     frf_estimate.defaults frf_estimate.too_few_hits frf_estimate.all_rejected
                     frf_estimate.bad_number frf_estimate.missing_file frf_estimate.unknown_direction
                     PROPERTIES FIXTURES_REQUIRED frf_estimate_records)
# Bad option values are bad command lines (64) named by their option, not
# "bad input: FrfEstimateOptions::..."; an fmax above the records' Nyquist
# frequency is refused as frf-synth refuses it (1e12 once overflowed the
# line count: "is below the line spacing"); an exponential window shorter
# than 4 sample periods is refused with the damping bias it would add.
set(est_option_tests "")
function(est_option_test name words)
  robomach_app_test(frf_estimate.option_${name} RC 64
    CMD $<TARGET_FILE:frf-estimate> ${EST_TMP}/records/hits.csv --out ${EST_TMP}/opt_${name}.csv ${ARGN}
    NO_FILES ${EST_TMP}/opt_${name}.csv
    STDERR "frf-estimate: ${words}")
  set(est_option_tests ${est_option_tests} frf_estimate.option_${name} PARENT_SCOPE)
endfunction()
est_option_test(fmax_1e12 "--fmax-hz 1e\\+12: above the Nyquist frequency 512 Hz of the records" --fmax-hz 1e12)
est_option_test(fmax_1e308 "--fmax-hz 1e\\+308: above the Nyquist frequency 512 Hz" --fmax-hz 1e308)
est_option_test(fmax_1e6 "--fmax-hz 1000000: above the Nyquist frequency 512 Hz" --fmax-hz 1e6)
est_option_test(fmax_negative "--fmax-hz -5: expected >= 0" --fmax-hz -5)
est_option_test(double_hit_fraction "--double-hit-fraction 10: expected in .--trigger-fraction" --double-hit-fraction 10)
est_option_test(tau_negative "--exp-window-tau-s -1: expected >= 0" --exp-window-tau-s -1)
est_option_test(tau_below_a_sample
  "--exp-window-tau-s 1e-09: shorter than 4 sample periods .*damping ratio 1/.tau omega. of [0-9.e+]+ even at 400 Hz"
  --exp-window-tau-s 1e-9)
set_tests_properties(${est_option_tests} PROPERTIES FIXTURES_REQUIRED frf_estimate_records)
