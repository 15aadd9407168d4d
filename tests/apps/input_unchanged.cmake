# Runs one app whose output names one of its inputs and checks that the input
# is unchanged (a typo must not destroy data), the exit code and stderr.
#   cmake -DCMD="exe;arg;..." -DEXPECT_RC=64 -DSTDERR_REGEX=... -DSOURCE=orig
#         -DINPUT=copy -P input_unchanged.cmake
# SOURCE is copied to INPUT first, so a failing run never damages the repo's
# file; CMD names INPUT.
configure_file(${SOURCE} ${INPUT} COPYONLY)
file(SHA256 ${INPUT} before)
execute_process(COMMAND ${CMD} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
file(SHA256 ${INPUT} after)
if(NOT before STREQUAL after)
  message(FATAL_ERROR "${INPUT} was changed by the run (exit ${rc})\nstderr:\n${err}")
endif()
if(NOT rc STREQUAL EXPECT_RC)
  message(FATAL_ERROR "exit code ${rc}, expected ${EXPECT_RC}\nstderr:\n${err}")
endif()
if(DEFINED STDERR_REGEX AND NOT err MATCHES "${STDERR_REGEX}")
  message(FATAL_ERROR "stderr does not match '${STDERR_REGEX}':\n${err}")
endif()
if(NOT out STREQUAL "")
  message(FATAL_ERROR "a failed run wrote to stdout:\n${out}")
endif()
