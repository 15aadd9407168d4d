# Unit plausibility (issue #22 item 1): each wrong-unit case of the issue is
# made from a good shipped or test input by the mistake a user makes
# (wrong_units.py: a column x1000, mm/rev x rpm, two columns swapped, a
# receptance turned into a mobility), and the tool must flag it: exit 3 with
# every output written and the likely unit named on stderr (exit 65 with
# file:line: column for a table value outside drilling practice). The same
# tools on the good inputs exit 0 in their own smoke tests
# (axis-accuracy.hand_example, drill_force_fit_table1, drill_sim_default,
# axis_tools.end_to_end, stability_lobes_frf_csv,
# frf-calibrate.tiny_fixture_writes_config_and_report), plus
# plausibility.stability_lobes_uff_receptance_passes below.
set(WU ${CMAKE_CURRENT_SOURCE_DIR}/wrong_units.py)
set(PT ${PROJECT_BINARY_DIR}/test_tmp/plausibility)
file(MAKE_DIRECTORY ${PT})
set(S ${PROJECT_SOURCE_DIR})

# plausibility_input(<name> <wrong_units.py args>): a setup test that makes
# the wrong-unit input; the tests using it require fixture plaus_<name>.
function(plausibility_input name)
  add_test(NAME plausibility.make_${name} COMMAND python3 ${WU} ${ARGN})
  set_tests_properties(plausibility.make_${name} PROPERTIES FIXTURES_SETUP plaus_${name})
endfunction()
function(plausibility_test name input)
  robomach_app_test(plausibility.${name} ${ARGN})
  set_tests_properties(plausibility.${name} PROPERTIES FIXTURES_REQUIRED plaus_${input})
endfunction()

# axis-accuracy: the runs' measured positions in um under measured_mm
# (targets in mm): A came out as 10000 mm with exit 0.
plausibility_input(runs_um scale ${DATA}/machine/x_runs_hand.csv ${PT}/x_runs_um.csv measured_mm=1000)
plausibility_test(axis_accuracy_measured_in_um runs_um RC 3
  CMD $<TARGET_FILE:axis-accuracy> --runs ${PT}/x_runs_um.csv --out ${PT}/iso_um.json
  FILES ${PT}/iso_um.json
  STDERR "axis X: deviations up to [0-9.e+]+ mm are [0-9.e+]+ % of the targets' magnitude.*measured values in um \\(or targets in m\\) under the _mm headers")
# ... and targets and measured positions both in um (A = 10 "mm").
plausibility_input(runs_all_um scale ${DATA}/machine/x_runs_hand.csv ${PT}/x_runs_all_um.csv
                   target_mm=1000 measured_mm=1000)
plausibility_test(axis_accuracy_all_in_um runs_all_um RC 3
  CMD $<TARGET_FILE:axis-accuracy> --runs ${PT}/x_runs_all_um.csv --out ${PT}/iso_all_um.json
  FILES ${PT}/iso_all_um.json
  STDERR "axis X: deviations up to [0-9.]+ mm, more than the 1 mm a machine axis can be off: targets and measured values in um under the _mm headers")

# drill-force-fit: torque in N·mm under torque_Nm (the shipped table's
# source prints it so): K_TQ came out as 600 GPa with exit 0.
plausibility_input(torque_Nmm scale ${S}/config/drilling/q235_hss.csv ${PT}/q235_torque_Nmm.csv torque_Nm=1000)
plausibility_test(drill_force_fit_torque_in_Nmm torque_Nmm RC 3
  CMD $<TARGET_FILE:drill-force-fit> --table ${PT}/q235_torque_Nmm.csv --drill ${S}/config/drilling/drill_5mm.yaml
      --out ${PT}/q235_torque_Nmm.yaml
  FILES ${PT}/q235_torque_Nmm.yaml
  STDERR "median torque / \\(thrust x diameter\\) of the table is [0-9.]+.*torque is probably in N·mm under torque_Nm")
# drill-force-fit: the feed in mm/min (feed per rev x rpm) under
# feed_mm_per_rev: exit 64 "shear_stress_thrust: expected > 0 Pa, got -nan"
# before; now the reader names the cell.
plausibility_input(feed_mm_min feedrate ${S}/config/drilling/q235_hss.csv ${PT}/q235_feed_mm_min.csv
                   feed_mm_per_rev speed_rpm)
plausibility_test(drill_force_fit_feed_in_mm_per_min feed_mm_min RC 65
  CMD $<TARGET_FILE:drill-force-fit> --table ${PT}/q235_feed_mm_min.csv --drill ${S}/config/drilling/drill_5mm.yaml
      --out ${PT}/q235_feed_mm_min.yaml
  NO_FILES ${PT}/q235_feed_mm_min.yaml
  STDERR "q235_feed_mm_min.csv:5: column feed_mm_per_rev: expected 0.005 to 1 mm/rev \\(twist-drilling practice\\), got 142.6: a feed in mm/min")
# drill-sim: the drill diameter in m typed in the mm field (0.005).
plausibility_input(drill_in_m yaml ${S}/config/drilling/drill_5mm.yaml ${PT}/drill_in_m.yaml diameter_mm=0.001)
plausibility_test(drill_sim_diameter_in_m drill_in_m RC 3
  CMD $<TARGET_FILE:drill-sim> --robot ${S}/config/drilling/planar3r.yaml --drill ${PT}/drill_in_m.yaml
      --material ${S}/config/drilling/q235.yaml --controller pid --out ${PT}/drill_in_m.csv
  FILES ${PT}/drill_in_m.csv
  STDERR "drill diameter_mm 0.005 mm is outside the 0.1 to 100 mm of twist drills: a diameter in m typed in the mm field")

# stability-lobes: a mobility under a UFF58 receptance header (the shipped
# test FRF times i omega): lobes at 1e-7 mm with exit 0 before.
plausibility_input(mobility mobility ${DATA}/kr210_P1_receptance.uff ${PT}/kr210_P1_mobility_as_receptance.uff)
plausibility_test(stability_lobes_mobility_as_receptance mobility RC 3
  CMD $<TARGET_FILE:stability-lobes> --frf ${PT}/kr210_P1_mobility_as_receptance.uff --cut ${S}/config/cut_demo.yaml
      --method zoa --out ${PT}/lobes_mobility.csv
  FILES ${PT}/lobes_mobility.csv
  STDERR "kr210_P1_mobility_as_receptance.uff: posture P1: the largest receptance is [0-9.e-]+ m/N, outside the plausible 1e-12 to 1e-03 m/N.*a mobility or accelerance was read as receptance")
robomach_app_test(plausibility.stability_lobes_uff_receptance_passes RC 0
  CMD $<TARGET_FILE:stability-lobes> --frf ${DATA}/kr210_P1_receptance.uff --cut ${S}/config/cut_demo.yaml
      --method zoa --out ${PT}/lobes_receptance.csv
  FILES ${PT}/lobes_receptance.csv)
# frf-calibrate: the response in mm under re/im of a receptance file (x1000).
plausibility_input(frf_mm scale ${DATA}/kr210_P1_receptance.csv ${PT}/kr210_P1_mm.csv re=1000 im=1000)
plausibility_test(frf_calibrate_response_in_mm frf_mm RC 3
  CMD $<TARGET_FILE:frf-calibrate> --robot ${S}/config/kr210.yaml --postures ${DATA}/calibration/postures_two.csv
      --measured ${PT}/kr210_P1_mm.csv --free m6_kg --only-free --out ${PT}/calibrated_mm.yaml --report ${PT}/report_mm
  FILES ${PT}/calibrated_mm.yaml
  STDERR "kr210_P1_mm.csv: pose P1, response x, excitation x: the largest receptance is [0-9.e-]+ m/N.*probably recorded in mm or um")
