# Outputs shared by every tool (docs/conventions.md; issues 20 and 22).
# Included from tests/apps/CMakeLists.txt.
#
# <tool>.all_or_nothing: a run whose LAST output cannot be written (its
#   folder is missing, or a folder stands where the file must go) exits 73
#   and leaves none of the run's outputs: every earlier output is checked to
#   be absent (run_app.cmake deletes them before the run).
# <tool>.out_dash_is_stdout: `--out -` prints the output on stdout and
#   leaves no file named "-" in the working folder.
# <tool>.summary_json: the new --summary JSONs, checked against the tool's
#   other output by check_summary.py.
set(O ${PROJECT_BINARY_DIR}/test_tmp/outputs)
set(CWD ${O}/cwd)  # working folder of the '-' tests: no file named '-' may appear here
file(MAKE_DIRECTORY ${CWD})
set(S ${PROJECT_SOURCE_DIR})
set(MACH ${S}/config/machine)
set(MDATA ${DATA}/machine)
set(PDATA ${DATA}/polishing)
set(CHECK_SUMMARY ${CMAKE_CURRENT_SOURCE_DIR}/check_summary.py)

function(dash_test name)
  robomach_app_test(${name} ${ARGN} NO_FILES ${CWD}/-)
  set_tests_properties(${name} PROPERTIES WORKING_DIRECTORY ${CWD})
endfunction()

# ---- frf-predict: --out, --modes, --summary, then --plot (missing folder)
robomach_app_test(frf-predict.all_or_nothing RC 73 CLEAN ${O}/frf_predict STDERR "missing"
  CMD $<TARGET_FILE:frf-predict> --robot ${ROBOT} --postures ${S}/config/postures_demo.csv --fmax-hz 5
      --out ${O}/frf_predict/frf.csv --modes ${O}/frf_predict/modes.csv --summary ${O}/frf_predict/summary.json
      --plot ${O}/frf_predict/missing/sheet.png
  NO_FILES ${O}/frf_predict/frf.csv ${O}/frf_predict/modes.csv ${O}/frf_predict/summary.json)
dash_test(frf-predict.out_dash_is_stdout RC 0 STDOUT "pose_id,response,excitation,freq_hz"
  CMD $<TARGET_FILE:frf-predict> --robot ${ROBOT} --postures ${S}/config/postures_demo.csv --fmax-hz 5 --out -)
# --details is the old name of --summary.
robomach_app_test(frf-predict.details_is_summary RC 0 CLEAN ${O}/frf_predict_details
  CMD $<TARGET_FILE:frf-predict> --robot ${ROBOT} --postures ${S}/config/postures_demo.csv --fmax-hz 5
      --out ${O}/frf_predict_details/frf.csv --details ${O}/frf_predict_details/details.json
  FILES ${O}/frf_predict_details/frf.csv ${O}/frf_predict_details/details.json)

# ---- drill-force-fit: --out, --plot, then --predictions
robomach_app_test(drill-force-fit.all_or_nothing RC 73 CLEAN ${O}/drill_force_fit STDERR "missing"
  CMD $<TARGET_FILE:drill-force-fit> --table ${S}/config/drilling/q235_hss.csv --drill ${S}/config/drilling/drill_5mm.yaml
      --out ${O}/drill_force_fit/q235.yaml --plot ${O}/drill_force_fit/forces.png
      --predict ${DATA}/drilling/predict_rows.csv --predictions ${O}/drill_force_fit/missing/pred.csv
  NO_FILES ${O}/drill_force_fit/q235.yaml ${O}/drill_force_fit/forces.png)
dash_test(drill-force-fit.out_dash_is_stdout RC 0 STDOUT "shear_stress"
  CMD $<TARGET_FILE:drill-force-fit> --table ${S}/config/drilling/q235_hss.csv
      --drill ${S}/config/drilling/drill_5mm.yaml --out -)

# ---- drill-sim: two controllers (--out and --summary each twice), then --plot
robomach_app_test(drill-sim.all_or_nothing RC 73 CLEAN ${O}/drill_sim STDERR "missing"
  CMD $<TARGET_FILE:drill-sim> --robot ${S}/config/drilling/planar3r.yaml --drill ${S}/config/drilling/drill_5mm.yaml
      --material ${S}/config/drilling/q235.yaml --controller pid,pd-tdc
      --out ${O}/drill_sim/run.csv --summary ${O}/drill_sim/summary.json --plot ${O}/drill_sim/missing/run.png
  NO_FILES ${O}/drill_sim/run_pid.csv ${O}/drill_sim/run_pd-tdc.csv ${O}/drill_sim/summary_pid.json
           ${O}/drill_sim/summary_pd-tdc.json)
dash_test(drill-sim.out_dash_is_stdout RC 0 STDOUT "^t_s,"
  CMD $<TARGET_FILE:drill-sim> --robot ${S}/config/drilling/planar3r.yaml --drill ${S}/config/drilling/drill_5mm.yaml
      --material ${S}/config/drilling/q235.yaml --out -)

# ---- kq-identify: --out, --residuals, --plot, then --summary (exit 3 otherwise: joint 6 weak)
robomach_app_test(kq-identify.all_or_nothing RC 73 CLEAN ${O}/kq STDERR "missing"
  CMD $<TARGET_FILE:kq-identify> --robot ${ROBOT} --tracker ${DATA}/tracker_campaign.csv
      --out ${O}/kq/kq.yaml --residuals ${O}/kq/residuals.csv --plot ${O}/kq/residuals.png
      --summary ${O}/kq/missing/result.json
  NO_FILES ${O}/kq/kq.yaml ${O}/kq/residuals.csv ${O}/kq/residuals.png)
dash_test(kq-identify.out_dash_is_stdout RC 3 STDOUT "Nm_per_rad"
  CMD $<TARGET_FILE:kq-identify> --robot ${ROBOT} --tracker ${DATA}/tracker_campaign.csv --out -)
# --json is the old name of --summary.
robomach_app_test(kq-identify.json_is_summary RC 3 CLEAN ${O}/kq_json
  CMD $<TARGET_FILE:kq-identify> --robot ${ROBOT} --tracker ${DATA}/tracker_campaign.csv
      --out ${O}/kq_json/kq.yaml --json ${O}/kq_json/result.json
  FILES ${O}/kq_json/kq.yaml ${O}/kq_json/result.json)

# ---- axis-synth: --capture, --machine-out, then --out. A successful run
# makes the capture axis-decode's tests read.
set(SYNTH_ARGS --machine ${MACH}/dmu80p.yaml --program ${MDATA}/cone_arc.csv --feed-mm-min 2000
               --sample-rate-hz 8000 --capture-every 100)
robomach_app_test(axis-synth.all_or_nothing RC 73 CLEAN ${O}/axis_synth STDERR "missing"
  CMD $<TARGET_FILE:axis-synth> ${SYNTH_ARGS} --capture ${O}/axis_synth/capture.bin
      --machine-out ${O}/axis_synth/machine.yaml --out ${O}/axis_synth/missing/counts.csv
  NO_FILES ${O}/axis_synth/capture.bin ${O}/axis_synth/machine.yaml)
robomach_app_test(axis-synth.capture_for_outputs RC 0 CLEAN ${O}/axis_capture
  CMD $<TARGET_FILE:axis-synth> ${SYNTH_ARGS} --capture ${O}/axis_capture/capture.bin
      --machine-out ${O}/axis_capture/machine.yaml --out ${O}/axis_capture/counts.csv
  FILES ${O}/axis_capture/capture.bin ${O}/axis_capture/machine.yaml ${O}/axis_capture/counts.csv)
set_tests_properties(axis-synth.capture_for_outputs PROPERTIES FIXTURES_SETUP outputs_axis_capture)
dash_test(axis-synth.out_dash_is_stdout RC 0 STDOUT "t_s,"
  CMD $<TARGET_FILE:axis-synth> ${SYNTH_ARGS} --machine-out ${O}/axis_synth_dash.yaml --out -)

# ---- axis-decode: --out, then --summary
robomach_app_test(axis-decode.all_or_nothing RC 73 CLEAN ${O}/axis_decode STDERR "missing"
  CMD $<TARGET_FILE:axis-decode> --machine ${O}/axis_capture/machine.yaml --capture ${O}/axis_capture/capture.bin
      --sample-rate-hz 800000 --every 100 --out ${O}/axis_decode/counts.csv --summary ${O}/axis_decode/missing/decode.json
  NO_FILES ${O}/axis_decode/counts.csv)
dash_test(axis-decode.out_dash_is_stdout RC 0 STDOUT "t_s,"
  CMD $<TARGET_FILE:axis-decode> --machine ${O}/axis_capture/machine.yaml --capture ${O}/axis_capture/capture.bin
      --sample-rate-hz 800000 --every 100 --out -)
set_tests_properties(axis-decode.all_or_nothing axis-decode.out_dash_is_stdout PROPERTIES
  FIXTURES_REQUIRED outputs_axis_capture)

# ---- axis-acquire: --out, then --summary
robomach_app_test(axis-acquire.all_or_nothing RC 73 CLEAN ${O}/axis_acquire STDERR "missing"
  CMD $<TARGET_FILE:axis-acquire> --machine ${MACH}/dmu80p.yaml --counts ${MDATA}/counts_tiny.csv
      --out ${O}/axis_acquire/tcp.csv --summary ${O}/axis_acquire/missing/summary.json
  NO_FILES ${O}/axis_acquire/tcp.csv)
dash_test(axis-acquire.out_dash_is_stdout RC 0 STDOUT "x_mm"
  CMD $<TARGET_FILE:axis-acquire> --machine ${MACH}/dmu80p.yaml --counts ${MDATA}/counts_tiny.csv --out -)

# ---- axis-accuracy: --plot, then --out (the JSON; --summary is its other name)
robomach_app_test(axis-accuracy.all_or_nothing RC 73 CLEAN ${O}/axis_accuracy STDERR "missing"
  CMD $<TARGET_FILE:axis-accuracy> --runs ${MDATA}/x_runs_hand.csv --plot ${O}/axis_accuracy/iso.png
      --out ${O}/axis_accuracy/missing/iso.json
  NO_FILES ${O}/axis_accuracy/iso.png)
dash_test(axis-accuracy.out_dash_is_stdout RC 0 STDOUT "\"robomach_version\""
  CMD $<TARGET_FILE:axis-accuracy> --runs ${MDATA}/x_runs_hand.csv --out -)
robomach_app_test(axis-accuracy.summary_is_out RC 0 CLEAN ${O}/axis_accuracy_summary
  CMD $<TARGET_FILE:axis-accuracy> --runs ${MDATA}/x_runs_hand.csv --summary ${O}/axis_accuracy_summary/iso.json
  FILES ${O}/axis_accuracy_summary/iso.json)

# ---- tracker-synth: --out, then --summary (new)
robomach_app_test(tracker-synth.all_or_nothing RC 73 CLEAN ${O}/tracker_synth STDERR "missing"
  CMD $<TARGET_FILE:tracker-synth> --robot ${ROBOT} --num-postures 4 --seed 3
      --out ${O}/tracker_synth/tests.csv --summary ${O}/tracker_synth/missing/summary.json
  NO_FILES ${O}/tracker_synth/tests.csv)
dash_test(tracker-synth.out_dash_is_stdout RC 0 STDOUT "case_id,"
  CMD $<TARGET_FILE:tracker-synth> --robot ${ROBOT} --num-postures 4 --seed 3 --out -)
robomach_app_test(tracker-synth.summary_written RC 0 CLEAN ${O}/tracker_summary
  CMD $<TARGET_FILE:tracker-synth> --robot ${ROBOT} --num-postures 6 --outliers 2 --seed 9
      --out ${O}/tracker_summary/tests.csv --summary ${O}/tracker_summary/summary.json
  FILES ${O}/tracker_summary/tests.csv ${O}/tracker_summary/summary.json)
add_test(NAME tracker-synth.summary_json
         COMMAND python3 ${CHECK_SUMMARY} tracker ${O}/tracker_summary/summary.json ${O}/tracker_summary/tests.csv)
set_tests_properties(tracker-synth.summary_json PROPERTIES DEPENDS tracker-synth.summary_written)

# ---- frf-synth: --out, then --summary (new)
robomach_app_test(frf-synth.all_or_nothing RC 73 CLEAN ${O}/frf_synth STDERR "missing"
  CMD $<TARGET_FILE:frf-synth> --robot ${ROBOT} --postures ${DATA}/calibration/postures_two.csv
      --out ${O}/frf_synth/hammer.csv --summary ${O}/frf_synth/missing/summary.json
  NO_FILES ${O}/frf_synth/hammer.csv)
dash_test(frf-synth.out_dash_is_stdout RC 0 STDOUT "pose_id,response,excitation,freq_hz"
  CMD $<TARGET_FILE:frf-synth> --robot ${ROBOT} --postures ${DATA}/calibration/postures_two.csv --fmax-hz 50 --out -)
robomach_app_test(frf-synth.summary_written RC 0 CLEAN ${O}/frf_synth_summary
  CMD $<TARGET_FILE:frf-synth> --robot ${ROBOT} --postures ${DATA}/calibration/postures_two.csv --noise-rel 0.01
      --seed 5 --directions xx,yy,xy --out ${O}/frf_synth_summary/hammer.csv
      --summary ${O}/frf_synth_summary/summary.json
  FILES ${O}/frf_synth_summary/hammer.csv ${O}/frf_synth_summary/summary.json)
add_test(NAME frf-synth.summary_json
         COMMAND python3 ${CHECK_SUMMARY} frf ${O}/frf_synth_summary/summary.json ${O}/frf_synth_summary/hammer.csv)
set_tests_properties(frf-synth.summary_json PROPERTIES DEPENDS frf-synth.summary_written)

# ---- frf-calibrate: --out, the --report folder (created by the run), then
# --summary. The folder must not remain either.
set(CAL_ARGS --robot ${ROBOT} --postures ${DATA}/calibration/postures_two.csv --measured ${tmp}/hammer.csv
             --free kq3_Nm_per_rad --only-free --free m6_kg --free d6_m)
robomach_app_test(frf-calibrate.all_or_nothing RC 73 CLEAN ${O}/frf_calibrate STDERR "missing"
  CMD $<TARGET_FILE:frf-calibrate> ${CAL_ARGS} --out ${O}/frf_calibrate/calibrated.yaml
      --report ${O}/frf_calibrate/report --summary ${O}/frf_calibrate/missing/summary.json
  NO_FILES ${O}/frf_calibrate/calibrated.yaml ${O}/frf_calibrate/report)
dash_test(frf-calibrate.out_dash_is_stdout RC 0 STDOUT "m6_kg"
  CMD $<TARGET_FILE:frf-calibrate> ${CAL_ARGS} --out - --report ${O}/frf_calibrate_dash_report)
set_tests_properties(frf-calibrate.all_or_nothing frf-calibrate.out_dash_is_stdout PROPERTIES
  FIXTURES_REQUIRED hammer_csv)

# ---- frf-estimate: --out, --plot, then --summary
robomach_app_test(frf-estimate.all_or_nothing RC 73 CLEAN ${O}/frf_estimate STDERR "missing"
  CMD $<TARGET_FILE:frf-estimate> ${EST_TMP}/records/hits.csv --out ${O}/frf_estimate/frf.csv
      --plot ${O}/frf_estimate/frf.png --summary ${O}/frf_estimate/missing/summary.json
  NO_FILES ${O}/frf_estimate/frf.csv ${O}/frf_estimate/frf.png)
dash_test(frf-estimate.out_dash_is_stdout RC 0 STDOUT "pose_id,response,excitation,freq_hz"
  CMD $<TARGET_FILE:frf-estimate> ${EST_TMP}/records/hits.csv --out -)
set_tests_properties(frf-estimate.all_or_nothing frf-estimate.out_dash_is_stdout PROPERTIES
  FIXTURES_REQUIRED frf_estimate_records)

# ---- model-audit: the report folder exists and a folder stands where its
# last file, summary.json, must go: the commit fails (73) before any file
# of the report appears.
robomach_app_test(model-audit.all_or_nothing RC 73 CLEAN ${O}/model_audit STDERR "summary.json"
  MAKE_DIRS ${O}/model_audit/report/summary.json
  CMD $<TARGET_FILE:model-audit> --robot ${ROBOT} --postures ${DATA}/calibration/postures_two.csv
      --measured ${tmp}/hammer.csv --report ${O}/model_audit/report
  NO_FILES ${O}/model_audit/report/index.html ${O}/model_audit/report/errors.csv
           ${O}/model_audit/report/candidates.csv ${O}/model_audit/report/trends.csv
           ${O}/model_audit/report/trends.png ${O}/model_audit/report/overlay_P1.png
           ${O}/model_audit/report/overlay_P2.png)
set_tests_properties(model-audit.all_or_nothing PROPERTIES FIXTURES_REQUIRED hammer_csv)

# ---- stability-lobes: --out, --plot, then --summary (new)
set(LOBES_ARGS --modal-table ${DATA}/stability/modal_benchmark.csv --cut ${DATA}/stability/cut_benchmark_slot.yaml)
robomach_app_test(stability-lobes.all_or_nothing RC 73 CLEAN ${O}/lobes STDERR "missing"
  CMD $<TARGET_FILE:stability-lobes> ${LOBES_ARGS}
      --out ${O}/lobes/lobes.csv --plot ${O}/lobes/lobes.png --summary ${O}/lobes/missing/summary.json
  NO_FILES ${O}/lobes/lobes.csv ${O}/lobes/lobes.png)
dash_test(stability-lobes.out_dash_is_stdout RC 0 STDOUT "pose_id,spindle_speed_rpm,critical_depth_mm"
  CMD $<TARGET_FILE:stability-lobes> ${LOBES_ARGS} --out -)
robomach_app_test(stability-lobes.summary_written RC 0 CLEAN ${O}/lobes_summary
  CMD $<TARGET_FILE:stability-lobes> --modal-table ${DATA}/stability/modal_benchmark.csv
      --cut ${DATA}/stability/cut_benchmark_slot.yaml --method both --sd-speeds 3
      --out ${O}/lobes_summary/lobes.csv --summary ${O}/lobes_summary/summary.json
  FILES ${O}/lobes_summary/lobes.csv ${O}/lobes_summary/summary.json)
add_test(NAME stability-lobes.summary_json
         COMMAND python3 ${CHECK_SUMMARY} lobes ${O}/lobes_summary/summary.json ${O}/lobes_summary/lobes.csv)
set_tests_properties(stability-lobes.summary_json PROPERTIES DEPENDS stability-lobes.summary_written)

# ---- stability-map: --out, --plot, then --summary (new)
set(MAP_ARGS --robot ${ROBOT} --cut ${S}/config/cut_demo.yaml --region ${DATA}/stability/region_free_small.yaml)
robomach_app_test(stability-map.all_or_nothing RC 73 CLEAN ${O}/map STDERR "missing"
  CMD $<TARGET_FILE:stability-map> ${MAP_ARGS} --out ${O}/map/map.csv --plot ${O}/map/map.png
      --summary ${O}/map/missing/summary.json
  NO_FILES ${O}/map/map.csv ${O}/map/map.png)
dash_test(stability-map.out_dash_is_stdout RC 0 STDOUT "row,col,x_mm,y_mm"
  CMD $<TARGET_FILE:stability-map> ${MAP_ARGS} --out -)
robomach_app_test(stability-map.summary_written RC 0 CLEAN ${O}/map_summary
  CMD $<TARGET_FILE:stability-map> ${MAP_ARGS} --out ${O}/map_summary/map.csv --summary ${O}/map_summary/summary.json
  FILES ${O}/map_summary/map.csv ${O}/map_summary/summary.json)
add_test(NAME stability-map.summary_json
         COMMAND python3 ${CHECK_SUMMARY} map ${O}/map_summary/summary.json ${O}/map_summary/map.csv)
set_tests_properties(stability-map.summary_json PROPERTIES DEPENDS stability-map.summary_written)

# ---- polish-plan: --path, --removal, --plot (three pictures), then --summary
robomach_app_test(polish-plan.all_or_nothing RC 73 CLEAN ${O}/polish_plan STDERR "missing"
  CMD $<TARGET_FILE:polish-plan> --surface ${PDATA}/plane_80x50.yaml --process ${PDATA}/process_small_margin.yaml
      --pattern cycloid --guides parallel --target-removal-um 2 --path ${O}/polish_plan/path.csv
      --removal ${O}/polish_plan/removal.csv --plot ${O}/polish_plan/plane.png
      --summary ${O}/polish_plan/missing/summary.json
  NO_FILES ${O}/polish_plan/path.csv ${O}/polish_plan/removal.csv ${O}/polish_plan/plane.png
           ${O}/polish_plan/plane_histogram.png ${O}/polish_plan/plane_path.png)
dash_test(polish-plan.out_dash_is_stdout RC 0 STDOUT "face,surface_type"
  CMD $<TARGET_FILE:polish-plan> --surface ${S}/config/polishing/blade.step --process ${S}/config/polishing/belt_2N.yaml
      --list-faces --out -)

# ---- polish-sim: --removal, --plot (three pictures), then --summary
robomach_app_test(polish-sim.all_or_nothing RC 73 CLEAN ${O}/polish_sim STDERR "missing"
  CMD $<TARGET_FILE:polish-sim> --surface ${PDATA}/plane_80x50.yaml --process ${PDATA}/process_small_margin.yaml
      --path ${PDATA}/path_straight.csv --removal ${O}/polish_sim/removal.csv --plot ${O}/polish_sim/sim.png
      --summary ${O}/polish_sim/missing/summary.json
  NO_FILES ${O}/polish_sim/removal.csv ${O}/polish_sim/sim.png ${O}/polish_sim/sim_histogram.png
           ${O}/polish_sim/sim_path.png)

# frf-calibrate and model-audit: --summary FILE is a copy of the report's
# summary.json (which stays).
add_test(NAME model-audit.summary_copy
  COMMAND ${CMAKE_COMMAND}
    "-DCMD=$<TARGET_FILE:model-audit>;--robot;${ROBOT};--postures;${DATA}/calibration/postures_two.csv;--measured;${tmp}/hammer.csv;--report;${O}/audit_summary/report;--summary;${O}/audit_summary/summary.json"
    -DEXPECT_RC=0 "-DFILES=${O}/audit_summary/report/summary.json;${O}/audit_summary/summary.json"
    "-DJSON=${O}/audit_summary/summary.json" "-DJSON_KEYS=robomach_version;verdict.grade;postures.P1"
    "-DCLEAN=${O}/audit_summary" -P ${check})
add_test(NAME frf-calibrate.summary_copy
  COMMAND ${CMAKE_COMMAND}
    "-DCMD=$<TARGET_FILE:frf-calibrate>;${CAL_ARGS};--out;${O}/cal_summary/calibrated.yaml;--report;${O}/cal_summary/report;--summary;${O}/cal_summary/summary.json"
    -DEXPECT_RC=0 "-DFILES=${O}/cal_summary/report/summary.json;${O}/cal_summary/summary.json"
    "-DJSON=${O}/cal_summary/summary.json" "-DJSON_KEYS=robomach_version;misfit.calibrated;calibrated_config"
    "-DCLEAN=${O}/cal_summary/report;${O}/cal_summary/summary.json;${O}/cal_summary/calibrated.yaml" -P ${check})
file(MAKE_DIRECTORY ${O}/cal_summary)
set_tests_properties(model-audit.summary_copy frf-calibrate.summary_copy PROPERTIES FIXTURES_REQUIRED hammer_csv)
