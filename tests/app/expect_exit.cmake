# Runs COMMAND with ARGS and fails unless it exits with EXPECT_CODE and its stderr
# contains EXPECT_STDERR (a regular expression) on its first line.
execute_process(COMMAND ${COMMAND} ${ARGS} RESULT_VARIABLE code
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL EXPECT_CODE)
  message(FATAL_ERROR "expected exit ${EXPECT_CODE}, got ${code}\nstdout: ${out}\nstderr: ${err}")
endif()
string(REGEX MATCH "^[^\n]*" first_line "${err}")
if(DEFINED EXPECT_STDERR AND NOT first_line MATCHES "${EXPECT_STDERR}")
  message(FATAL_ERROR "first stderr line does not match '${EXPECT_STDERR}': ${first_line}")
endif()
