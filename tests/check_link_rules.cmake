# report and io_base may not link the domain modules (issue #21, style.md
# §2.1): report draws (figures, heat maps, HTML, JSON) with io_base's atomic
# files and number format; report_fits draws calibration and audit results
# and may link those (and report), not io or the other domain modules;
# io_base is CSV, YAML, atomic files and parallel rows on top of common.
# LINKS is a file of "target=link|link|..." lines written by
# tests/CMakeLists.txt at generate time.
cmake_minimum_required(VERSION 3.16)
set(forbidden_io robomach::workflows robomach::report robomach::report_fits)
set(forbidden_report robomach::workflows robomach::io robomach::kinematics robomach::dynamics
    robomach::identification robomach::calibration robomach::audit robomach::stability robomach::polishing
    robomach::drilling robomach::machine robomach::io_cad robomach::report_fits)
set(forbidden_report_fits robomach::io robomach::identification robomach::stability robomach::polishing
    robomach::drilling robomach::machine robomach::io_cad)
set(forbidden_io_base robomach::io robomach::kinematics robomach::dynamics robomach::identification
    robomach::calibration robomach::audit robomach::stability robomach::polishing robomach::drilling
    robomach::machine robomach::io_cad robomach::report robomach::workflows)
file(STRINGS ${LINKS} lines)
set(violations "")
set(seen "")
foreach(line ${lines})
  string(REGEX MATCH "^([a-z_]+)=(.*)$" m "${line}")
  set(target ${CMAKE_MATCH_1})
  string(REPLACE "|" ";" links "${CMAKE_MATCH_2}")
  list(APPEND seen ${target})
  foreach(l ${links})
    if(l IN_LIST forbidden_${target})
      list(APPEND violations "${target} links ${l}")
    endif()
  endforeach()
endforeach()
if(NOT "report" IN_LIST seen OR NOT "report_fits" IN_LIST seen OR NOT "io_base" IN_LIST seen OR NOT "io" IN_LIST seen)
  message(FATAL_ERROR "link rules: ${LINKS} does not list report, report_fits, io_base and io")
endif()
if(violations)
  string(REPLACE ";" "\n" msg "${violations}")
  message(FATAL_ERROR "link rule violations:\n${msg}")
endif()
message(STATUS "link rules: ok")
