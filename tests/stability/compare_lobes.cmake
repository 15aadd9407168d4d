# Compares the rows of one method of two stability-lobes CSVs, without the
# pose_id column: spindle speed, lobe index, status and steps exactly, the
# depth and the chatter frequency to 4 decimals (1e-4 mm, 1e-4 Hz: the SD's
# depth search stops at a relative 1e-9 or so, so two runs on models that
# agree to rounding give the same 4 decimals unless a value sits on a
# rounding edge, which the chosen fixtures do not).
#   cmake -DA=a.csv -DB=b.csv -DMETHOD=zoa|sd -P compare_lobes.cmake
foreach(v A B METHOD)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "compare_lobes.cmake: -D${v}=... is required")
  endif()
endforeach()
foreach(f A B)
  file(STRINGS ${${f}} lines)
  set(rows_${f} "")
  foreach(l ${lines})
    if(l MATCHES ",${METHOD},")
      # (not REGEX REPLACE "^[^,]*,": CMake applies a "^" pattern again
      # to what remains, which would strip every field)
      string(FIND "${l}" "," comma)
      math(EXPR comma "${comma} + 1")
      string(SUBSTRING "${l}" ${comma} -1 l)
      string(REGEX REPLACE "([0-9]+\\.[0-9][0-9][0-9][0-9])[0-9]*" "\\1" l "${l}")
      list(APPEND rows_${f} "${l}")
    endif()
  endforeach()
endforeach()
list(LENGTH rows_A na)
list(LENGTH rows_B nb)
if(na EQUAL 0 OR NOT na EQUAL nb)
  message(FATAL_ERROR "${METHOD} rows: ${na} in ${A}, ${nb} in ${B}")
endif()
math(EXPR last "${na} - 1")
foreach(i RANGE ${last})
  list(GET rows_A ${i} a)
  list(GET rows_B ${i} b)
  if(NOT a STREQUAL b)
    message(FATAL_ERROR "${METHOD} row ${i} differs:\n  ${A}: ${a}\n  ${B}: ${b}")
  endif()
endforeach()
message(STATUS "${na} ${METHOD} rows agree")
