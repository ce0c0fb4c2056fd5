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
    "welch.csv|question,factor,f,df1,df2,p"
    "rm_anova.csv|question,factor,n_participants,f,df_effect,df_error,p,mauchly_w,mauchly_p,gg_epsilon,p_gg,hf_epsilon,p_hf,partial_eta_sq,generalized_eta_sq"
    "friedman.csv|question,factor,n_participants,chi_sq,df,p,kendall_w"
    "posthoc_paired.csv|question,factor,level_a,level_b,diff,t,df,p,p_holm"
    "mixed_tests.csv|question,factor,model,formula,statistic,df,den_df,p,lr_chi_square,lr_df,lr_p,log_likelihood,participants,stimuli,ratings,notes"
    "mixed_effects.csv|question,factor,model,level,reference,estimate,se,ci_low,ci_high,estimable"
    "ordinal_probabilities.csv|question,factor,level,rating,predicted,observed")
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
# The simulator has every participant rate every level: a within-subject study, so the
# repeated-measures tables have a row per (question, factor) with all 12 participants.
file(STRINGS "${WORK_DIR}/report/rm_anova.csv" rm)
list(LENGTH rm n)
if(NOT n EQUAL 3)
  message(FATAL_ERROR "rm_anova.csv has ${n} lines")
endif()
list(GET rm 1 row)
if(NOT row MATCHES "^[a-z]+,thickness,12,")
  message(FATAL_ERROR "rm_anova.csv row: ${row}")
endif()
file(READ "${WORK_DIR}/report/report.md" md)
string(FIND "${md}" "| within (primary) |" within_at)
string(FIND "${md}" "| between |" between_at)
if(within_at LESS 0 OR between_at LESS within_at)
  message(FATAL_ERROR "the summary does not lead with the within-subject design")
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
