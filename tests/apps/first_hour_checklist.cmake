# Replays issue #35's checklist (first_hour_checklist.txt): for each row,
# runs the tool and checks its exit code, its stderr and the row's checks;
# reports every row that fails, then fails if any did.
#   cmake -DSRC=<source tree> -DBIN=<folder of the tools> -DWORK=<scratch folder>
#         -DTABLE=<checklist> [-DONLY=<row name regex>]
#         [-DPYTHON=<interpreter> -DPYTHONPATH=<folder of the robomach module>]
#         -P first_hour_checklist.cmake
# A row whose tool is `python` runs PYTHON with PYTHONPATH; without them
# (no Python module built) such rows are skipped and listed.
# The inputs are made here from shipped files, so the test needs nothing
# outside the source tree.
cmake_minimum_required(VERSION 3.16)  # CMP0053: "@SRC@" below is literal text
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/copy)

# A config copied to another folder without its URDF.
configure_file(${SRC}/config/kr210.yaml ${WORK}/copy/kr210.yaml COPYONLY)
# A machining region 0.6 m farther out than the demo's: most points out of reach.
file(READ ${SRC}/config/region_demo.yaml region)
string(REPLACE "origin_mm: [1900, -400, 800]" "origin_mm: [2500, -400, 800]" region "${region}")
file(WRITE ${WORK}/region_far.yaml "${region}")
# Posture files with the mistakes of a spreadsheet: ';' between the cells,
# a header name mistyped, an empty cell.
file(WRITE ${WORK}/semi.csv "pose_id;q1_deg;q2_deg;q3_deg;q4_deg;q5_deg;q6_deg\nP1;0;-90;90;0;45;0\n")
file(WRITE ${WORK}/typo.csv "pose_id,q1_deg,q2deg,q3_deg,q4_deg,q5_deg,q6_deg\nP1,0,-90,90,0,45,0\n")
file(WRITE ${WORK}/blank.csv "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\nP1,0,-90,90,0,45,0\nP2,0,-90,,0,45,0\n")
# A picture or document given as the robot config.
file(WRITE ${WORK}/report.pdf "%PDF-1.4\n%binary follows\n")
# The same config with a negative mass on line 38 (the URDF by absolute path).
file(READ ${SRC}/config/kr210.yaml cfg)
string(REPLACE "urdf: kr210_r2700_2.urdf" "urdf: ${SRC}/config/kr210_r2700_2.urdf" cfg "${cfg}")
string(REPLACE "mass_kg: 22.0" "mass_kg: -22.0" cfg "${cfg}")
file(WRITE ${WORK}/neg_mass.yaml "${cfg}")
# The joint stiffnesses in N·mm/rad (x1000), a drilling robot's rotor inertias in kg·cm².
string(REPLACE "mass_kg: -22.0" "mass_kg: 22.0" cfg "${cfg}")
string(REPLACE "[3.3479e+6, 3.1318e+6, 4.2895e+6, 2.4787e+5, 6.4292e+5, 1.8847e+5]"
               "[3.3479e+9, 3.1318e+9, 4.2895e+9, 2.4787e+8, 6.4292e+8, 1.8847e+8]" cfg "${cfg}")
file(WRITE ${WORK}/kq_Nmm.yaml "${cfg}")
# The joint stiffnesses per degree (N·m/deg: the values / 57.3).
string(REPLACE "[3.3479e+9, 3.1318e+9, 4.2895e+9, 2.4787e+8, 6.4292e+8, 1.8847e+8]"
               "[58432, 54660, 74866, 4326.2, 11221, 3289.4]" cfg "${cfg}")
file(MAKE_DIRECTORY ${WORK}/copy_deg)
file(WRITE ${WORK}/copy_deg/kr210_deg.yaml "${cfg}")
# The spindle_toolholder_interface section with a taper diameter in mm, a
# drawbar force in kN, a zero diameter, a billion elements; hammer_test's
# sample rate in kHz. Each from the shipped config with one mistake (the
# URDF by absolute path).
file(READ ${SRC}/config/kr210.yaml cfg)
string(REPLACE "urdf: kr210_r2700_2.urdf" "urdf: ${SRC}/config/kr210_r2700_2.urdf" cfg "${cfg}")
string(REPLACE "taper_large_diameter_m: 0.024007" "taper_large_diameter_m: 24.007" c "${cfg}")
file(WRITE ${WORK}/taper_mm.yaml "${c}")
string(REPLACE "taper_large_diameter_m: 0.024007" "taper_large_diameter_m: 0" c "${cfg}")
file(WRITE ${WORK}/taper_zero.yaml "${c}")
string(REPLACE "drawbar_force_N: 5000 " "drawbar_force_N: 5 " c "${cfg}")
file(WRITE ${WORK}/drawbar_kN.yaml "${c}")
string(REPLACE "elements: 6 " "elements: 1000000000 " c "${cfg}")
file(WRITE ${WORK}/elements_huge.yaml "${c}")
string(REPLACE "sample_rate_hz: 5120" "sample_rate_hz: 5.12" c "${cfg}")
file(WRITE ${WORK}/fs_kHz.yaml "${c}")
file(READ ${SRC}/config/drilling/planar3r.yaml cfg)
string(REPLACE "rotor_inertia_kgm2: 1.98e-4" "rotor_inertia_kgm2: 1.98" cfg "${cfg}")
file(WRITE ${WORK}/planar3r_kgcm2.yaml "${cfg}")
# Cut files: a count beyond the limit, a diameter in um, ktc x1000.
file(READ ${SRC}/tests/data/stability/cut_benchmark_slot.yaml cut)
string(REPLACE "spindle_speed_count: 400" "spindle_speed_count: 2000000000" c "${cut}")
file(WRITE ${WORK}/cut_count.yaml "${c}")
string(REPLACE "diameter_mm: 20" "diameter_mm: 20000" c "${cut}")
file(WRITE ${WORK}/cut_diameter.yaml "${c}")
string(REPLACE "ktc_N_per_mm2: 600" "ktc_N_per_mm2: 1.8e6" c "${cut}")
file(WRITE ${WORK}/cut_ktc.yaml "${c}")
# A key mistyped (mm2 -> m2), and a cut file indented with a tab.
string(REPLACE "ktc_N_per_mm2: 600" "ktc_N_per_m2: 600" c "${cut}")
file(WRITE ${WORK}/cut_typo.yaml "${c}")
file(READ ${SRC}/config/cut_demo.yaml cut_demo)
string(REPLACE "\n  ktc_N_per_mm2:" "\n\tktc_N_per_mm2:" c "${cut_demo}")
file(WRITE ${WORK}/cut_tab.yaml "${c}")
# A machine file with the linear encoder resolutions in um (x1000).
file(READ ${SRC}/config/machine/dmu80p.yaml mach)
string(REPLACE "resolution_mm: 0.0005" "resolution_mm: 0.5" mach "${mach}")
file(WRITE ${WORK}/dmu80p_um.yaml "${mach}")
# Postures: an absurd angle, radians under _deg headers, degrees under _rad.
file(WRITE ${WORK}/huge.csv "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\nP1,1e308,-90,90,0,45,0\n")
file(WRITE ${WORK}/rad_as_deg.csv
     "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\nP1,0,-1.57,1.57,0,0.785,0\nP2,0.5,-1.2,1.3,0,0.6,0\n")
file(WRITE ${WORK}/deg_as_rad.csv
     "pose_id,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad\nP1,0,-90,90,0,45,0\n")

# Python: the demo posture in degrees passed where radians are expected;
# the glog level the module leaves (Ceres's log lines silenced).
file(WRITE ${WORK}/evaluate_degrees.py
     "import sys, numpy, robomach\n"
     "model = robomach.RobotConfig(sys.argv[1]).build()\n"
     "robomach.PostureEvaluator(model).evaluate(numpy.array([0.0, -90, 90, 0, 45, 0]))\n")
file(WRITE ${WORK}/glog_level.py
     "import ctypes, robomach\n"
     "path = next(l.split()[-1] for l in open('/proc/self/maps') if 'libglog' in l)\n"
     "print('minloglevel', ctypes.c_int.in_dll(ctypes.CDLL(path), '_ZN3fLI17FLAGS_minloglevelE').value)\n")

file(STRINGS ${TABLE} lines ENCODING UTF-8)
set(failed "")
set(count 0)
set(rows_seen 0)
# The rows of the file counted as text: a lone [ or ] in a row is a CMake
# list bracket that joins the rows after it into one list element, which
# would then be checked as one row (the rows compared below).
file(READ ${TABLE} table_text)
string(REGEX REPLACE "\n[ \t]*#[^\n]*" "" table_text "\n${table_text}")
string(REGEX REPLACE "\n[ \t]*[^ \t\n][^\n]*" "@ROW@" table_text "${table_text}")
string(REGEX MATCHALL "@ROW@" table_rows "${table_text}")
list(LENGTH table_rows table_row_count)
foreach(line IN LISTS lines)
  if(line MATCHES "^[ \t]*(#|$)")
    continue()
  endif()
  math(EXPR rows_seen "${rows_seen} + 1")
  string(REPLACE "@SRC@" "${SRC}" line "${line}")
  string(REPLACE "@WORK@" "${WORK}" line "${line}")
  # name | rc | regex | checks | command ("|" inside a regex is not used)
  if(NOT line MATCHES "^([^|]+)\\|([^|]+)\\|(.+)\\|([^|]+)\\|([^|]+)$")
    message(FATAL_ERROR "malformed checklist row: ${line}")
  endif()
  string(STRIP "${CMAKE_MATCH_1}" name)
  string(STRIP "${CMAKE_MATCH_2}" rc_expected)
  string(STRIP "${CMAKE_MATCH_3}" regex)
  string(STRIP "${CMAKE_MATCH_4}" checks)
  string(STRIP "${CMAKE_MATCH_5}" command)
  if(DEFINED ONLY AND NOT name MATCHES "${ONLY}")
    continue()
  endif()
  math(EXPR count "${count} + 1")
  separate_arguments(args UNIX_COMMAND "${command}")
  list(POP_FRONT args tool)
  if(tool STREQUAL "python")
    if(NOT PYTHON OR NOT PYTHONPATH)
      message(STATUS "skip ${name}: no Python module (python rows need -DPYTHON and -DPYTHONPATH)")
      math(EXPR count "${count} - 1")
      continue()
    endif()
    set(exe ${CMAKE_COMMAND} -E env --unset=GLOG_minloglevel PYTHONPATH=${PYTHONPATH} ${PYTHON})
  else()
    set(exe ${BIN}/${tool})
  endif()
  set(problems "")
  string(REPLACE "," ";" checks "${checks}")
  foreach(c IN LISTS checks)
    if(c MATCHES "^no=(.+)$")
      file(REMOVE ${CMAKE_MATCH_1})
    endif()
  endforeach()
  execute_process(COMMAND ${exe} ${args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                  TIMEOUT 300)
  if(NOT rc STREQUAL rc_expected)
    list(APPEND problems "exit code ${rc}, expected ${rc_expected}")
  endif()
  if(NOT err MATCHES "${regex}")
    list(APPEND problems "stderr does not match '${regex}'")
  endif()
  foreach(c IN LISTS checks)
    if(c STREQUAL "empty_stdout")
      string(LENGTH "${out}" n)
      if(n GREATER 0)
        list(APPEND problems "${n} characters on stdout, expected none")
      endif()
    elseif(c MATCHES "^stdout=(.+)$")
      set(want "${CMAKE_MATCH_1}")
      if(NOT out MATCHES "${want}")
        list(APPEND problems "stdout does not match '${want}'")
      endif()
    elseif(c MATCHES "^no=(.+)$")
      if(EXISTS ${CMAKE_MATCH_1})
        list(APPEND problems "${CMAKE_MATCH_1} was written")
      endif()
    elseif(c MATCHES "^file=([^~]+)~(.+)$")
      # file=PATH~REGEX: the file exists and its text matches (. matches
      # newlines in CMake's regex, so A.*B checks that A comes before B).
      set(f "${CMAKE_MATCH_1}")
      set(want "${CMAKE_MATCH_2}")
      if(NOT EXISTS ${f})
        list(APPEND problems "${f} was not written")
      else()
        file(READ ${f} text)
        if(NOT text MATCHES "${want}")
          list(APPEND problems "${f} does not match '${want}'")
        endif()
      endif()
    elseif(c MATCHES "^warnings_in=(.+)$")
      # warnings_in=SUMMARY: every "tool: warning: ..." line on stderr is in
      # the JSON summary's `warnings` (a warning printed after the summary
      # was written is missing from it).
      set(f "${CMAKE_MATCH_1}")
      if(NOT EXISTS ${f})
        list(APPEND problems "${f} was not written")
      else()
        file(READ ${f} text)
        string(JSON nw ERROR_VARIABLE jerr LENGTH "${text}" warnings)
        if(jerr)
          list(APPEND problems "${f}: no warnings list (${jerr})")
        else()
          set(listed "")
          if(nw GREATER 0)
            math(EXPR last "${nw} - 1")
            foreach(i RANGE ${last})
              string(JSON w GET "${text}" warnings ${i})
              string(REPLACE ";" "<semicolon>" w "${w}")
              list(APPEND listed "${w}")
            endforeach()
          endif()
          string(REPLACE ";" "<semicolon>" err_safe "${err}")
          string(REGEX MATCHALL "[a-z0-9-]+: warning: [^\n]*" printed "${err_safe}")
          set(nprinted 0)
          foreach(p IN LISTS printed)
            math(EXPR nprinted "${nprinted} + 1")
            string(REGEX REPLACE "^[a-z0-9-]+: warning: " "" m "${p}")
            list(FIND listed "${m}" at)
            if(at LESS 0)
              list(APPEND problems "printed but not in ${f}'s warnings: ${m}")
            endif()
          endforeach()
          if(nprinted EQUAL 0)
            list(APPEND problems "no warning printed (the row expects some)")
          endif()
        endif()
      endif()
    elseif(c MATCHES "^stderr_not=(.+)$")
      if(err MATCHES "${CMAKE_MATCH_1}")
        list(APPEND problems "stderr matches '${CMAKE_MATCH_1}'")
      endif()
    elseif(c STREQUAL "short_numbers")
      if(err MATCHES "[0-9]\\.[0-9][0-9][0-9][0-9][0-9][0-9][0-9][0-9][0-9]")
        list(APPEND problems "a number with 9 or more decimals on stderr")
      endif()
    elseif(NOT c STREQUAL "-")
      message(FATAL_ERROR "row ${name}: unknown check '${c}'")
    endif()
  endforeach()
  if(problems)
    string(REPLACE ";" "\n    " p "${problems}")
    message(STATUS "FAIL ${name}: ${tool} ${command}\n    ${p}\n  stderr:\n${err}")
    list(APPEND failed ${name})
  else()
    message(STATUS "ok   ${name}")
  endif()
endforeach()
if(NOT rows_seen EQUAL table_row_count)
  message(FATAL_ERROR "the table has ${table_row_count} rows but ${rows_seen} were read: a row with a [ or ] "
                      "without its pair joins the rows after it (write . for a lone bracket in a regex)")
endif()
if(count EQUAL 0)
  message(FATAL_ERROR "no checklist row ran")
endif()
if(failed)
  list(LENGTH failed nf)
  message(FATAL_ERROR "${nf} of ${count} checklist rows failed: ${failed}")
endif()
message(STATUS "all ${count} checklist rows pass")
