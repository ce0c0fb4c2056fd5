# Runs COMMAND with ARGS plus `--csv CSV` and fails unless it exits 0 and the CSV file
# starts with the section,name,value,unit header and matches every regular expression in
# EXPECT_CSV (a list).
file(REMOVE "${CSV}")
execute_process(COMMAND ${COMMAND} ${ARGS} --csv ${CSV} RESULT_VARIABLE code
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "exit ${code}\nstdout: ${out}\nstderr: ${err}")
endif()
file(READ "${CSV}" csv)
if(NOT csv MATCHES "^section,name,value,unit\n")
  message(FATAL_ERROR "${CSV}: no CSV header:\n${csv}")
endif()
foreach(pattern IN LISTS EXPECT_CSV)
  if(NOT csv MATCHES "${pattern}")
    message(FATAL_ERROR "${CSV} does not match '${pattern}':\n${csv}")
  endif()
endforeach()
