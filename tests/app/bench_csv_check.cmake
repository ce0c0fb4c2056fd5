# Runs COMMAND with ARGS plus `--csv CSV` and fails unless it exits 0 and the CSV file
# starts with the HEADER line (default: section,name,value,unit) and matches every regular
# expression in EXPECT_CSV (a list).
if(NOT DEFINED HEADER)
  set(HEADER "section,name,value,unit")
endif()
file(REMOVE "${CSV}")
execute_process(COMMAND ${COMMAND} ${ARGS} --csv ${CSV} RESULT_VARIABLE code
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "exit ${code}\nstdout: ${out}\nstderr: ${err}")
endif()
file(READ "${CSV}" csv)
string(FIND "${csv}" "${HEADER}\n" header_at)
if(NOT header_at EQUAL 0)
  message(FATAL_ERROR "${CSV}: no CSV header:\n${csv}")
endif()
foreach(pattern IN LISTS EXPECT_CSV)
  if(NOT csv MATCHES "${pattern}")
    message(FATAL_ERROR "${CSV} does not match '${pattern}':\n${csv}")
  endif()
endforeach()
