# Simulates a study, analyzes it, and checks the report files and the exact CSV headers.
file(MAKE_DIRECTORY "${WORK_DIR}")
execute_process(COMMAND ${COMMAND} simulate --out "${WORK_DIR}/study.csv" --participants 12
                        --effects 0,0.8,1.6 --questions translucent,realistic --seed 5
                RESULT_VARIABLE code ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "lucent simulate exited ${code}: ${err}")
endif()
file(REMOVE_RECURSE "${WORK_DIR}/report")
execute_process(COMMAND ${COMMAND} analyze "${WORK_DIR}/study.csv" --out "${WORK_DIR}/report"
                        --alpha 0.10
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "lucent analyze exited ${code}: ${err}")
endif()
set(expected_headers
    "anova.csv|question,factor,ss_between,ss_within,df_between,df_within,ms_between,ms_within,f,p,eta_sq,omega_sq"
    "tukey.csv|question,factor,level_a,level_b,diff,se,q,p_adj,lower,upper"
    "kruskal.csv|question,factor,h,df,p"
    "welch.csv|question,factor,f,df1,df2,p")
foreach(entry IN LISTS expected_headers)
  string(REPLACE "|" ";" entry "${entry}")
  list(GET entry 0 name)
  list(GET entry 1 header)
  file(STRINGS "${WORK_DIR}/report/${name}" lines)
  list(GET lines 0 first)
  if(NOT first STREQUAL header)
    message(FATAL_ERROR "${name}: header '${first}'")
  endif()
endforeach()
file(STRINGS "${WORK_DIR}/report/tukey.csv" tukey)
list(LENGTH tukey n)
if(NOT n EQUAL 7)  # header + 3 pairs x 2 questions
  message(FATAL_ERROR "tukey.csv has ${n} lines")
endif()
foreach(name report.md report.html plot_translucent__thickness.svg plot_realistic__thickness.svg)
  if(NOT EXISTS "${WORK_DIR}/report/${name}")
    message(FATAL_ERROR "missing ${name}")
  endif()
endforeach()
file(READ "${WORK_DIR}/report/report.html" html)
if(NOT html MATCHES "<svg" OR html MATCHES "[Nn]a[Nn]")
  message(FATAL_ERROR "report.html lacks an embedded SVG or contains NaN")
endif()
