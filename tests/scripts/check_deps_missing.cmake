# Runs scripts/check-deps with scripts/install-deps's list less DROP and fails unless it
# exits 1 with one line naming DROP and a file of DROP's.
execute_process(COMMAND ${SOURCE_DIR}/scripts/install-deps --list
                OUTPUT_VARIABLE packages OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE code)
if(NOT code EQUAL 0 OR NOT packages MATCHES "(^| )${DROP}( |$)")
  message(FATAL_ERROR "install-deps --list failed or lacks ${DROP}: '${packages}'")
endif()
string(REGEX REPLACE "(^| )${DROP}( |$)" " " reduced "${packages}")
execute_process(COMMAND ${CMAKE_COMMAND} -E env "LUCENT_DEPS_PACKAGES=${reduced}"
                        ${SOURCE_DIR}/scripts/check-deps ${BUILD_DIR}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 1)
  message(FATAL_ERROR "expected exit 1 without ${DROP}, got ${code}\nstdout: ${out}\nstderr: ${err}")
endif()
string(STRIP "${err}" err)
if(err MATCHES "\n")
  message(FATAL_ERROR "expected one line, got:\n${err}")
endif()
if(NOT err MATCHES "misses packages the build used: (.*, )?${DROP} \\(/usr/[^)]+\\)")
  message(FATAL_ERROR "the line does not name ${DROP} and a file: ${err}")
endif()
message(STATUS "${err}")
