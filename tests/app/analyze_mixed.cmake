# `lucent analyze --model clmm,lmm --primary-model clmm` on R's wine data as a rating study
# (tests/app/data/wine_long.csv: judges as participants, bottles as stimuli): the ordinal
# model leads the summary, and its likelihood-ratio test is R's
# anova(clmm(rating ~ 1 + (1|judge) + (1|bottle)), clmm(rating ~ temp + ...)): 9.4277.
file(REMOVE_RECURSE "${WORK_DIR}")
execute_process(COMMAND ${COMMAND} analyze "${DATA}" --out "${WORK_DIR}" --scale 1..5
                        --model clmm,lmm --primary-model clmm
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "lucent analyze exited ${code}: ${err}")
endif()
file(READ "${WORK_DIR}/report.md" md)
string(FIND "${md}" "| bitterness ~ temp | clmm (primary) | likelihood ratio (chi-square) | 0.002137 | 9.428 |" at)
if(at EQUAL -1)
  message(FATAL_ERROR "the clmm row does not lead the summary:\n${md}")
endif()
string(FIND "${md}" "One-way ANOVA" anova_at)
if(NOT anova_at EQUAL -1)
  message(FATAL_ERROR "--model clmm,lmm ran the one-way ANOVA too")
endif()
file(STRINGS "${WORK_DIR}/mixed_tests.csv" rows)
list(GET rows 1 clmm)
if(NOT clmm MATCHES "^bitterness,temp,clmm,rating ~ level \\+ \\(1 \\| participant\\) \\+ \\(1 \\| stimulus\\),9\\.42770")
  message(FATAL_ERROR "mixed_tests.csv: ${clmm}")
endif()
if(NOT EXISTS "${WORK_DIR}/ordinal_bitterness_temp.svg")
  message(FATAL_ERROR "no ordinal figure")
endif()
if(EXISTS "${WORK_DIR}/anova.csv" OR NOT EXISTS "${WORK_DIR}/descriptives.csv")
  message(FATAL_ERROR "--model clmm,lmm: the one-way tables are written, or the descriptives are not")
endif()
