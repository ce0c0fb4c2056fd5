# Runs COMMAND with ARGS; fails unless it exits 0 and prints one number agreeing with
# EXPECT to DIGITS significant digits.
include(${CMAKE_CURRENT_LIST_DIR}/number_compare.cmake)
execute_process(COMMAND ${COMMAND} ${ARGS} RESULT_VARIABLE code OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "exit ${code}\nstdout: ${out}\nstderr: ${err}")
endif()
string(STRIP "${out}" out)
lucent_numbers_agree("${out}" "${EXPECT}" ${DIGITS} ok)
if(NOT ok)
  message(FATAL_ERROR "printed ${out}, expected ${EXPECT} to ${DIGITS} digits")
endif()
message(STATUS "printed ${out}, expected ${EXPECT}")
