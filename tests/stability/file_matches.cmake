# Fails unless FILE's text matches every regex of REGEX (a |-separated list).
#   cmake -DFILE=report.md "-DREGEX=a|b" -P file_matches.cmake
file(READ ${FILE} text)
string(REPLACE "|" ";" regexes "${REGEX}")
foreach(r ${regexes})
  if(NOT text MATCHES "${r}")
    message(FATAL_ERROR "${FILE} does not match '${r}'")
  endif()
endforeach()
message(STATUS "${FILE} matches")
