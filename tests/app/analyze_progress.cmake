# lucent analyze shows each mixed-model fit on stderr: before it "clmm I/N: question Q,
# factor F (R ratings) ...", after it the fit's time, the time so far and the time left;
# one line per fit, numbered over the run's fits, and nothing of it on stdout.
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
execute_process(COMMAND ${COMMAND} simulate --out "${WORK_DIR}/study.csv" --participants 12
                        --stimuli-per-level 2 --effects 0,0.8,1.6
                        --questions translucent,realistic,glossy --seed 5
                RESULT_VARIABLE code ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "lucent simulate exited ${code}: ${err}")
endif()
set(seconds "[0-9]+(\\.[0-9])? s|[0-9]+ min [0-9][0-9] s")
# MODELS: --model; EXPECTED: the fits' "model question" in order.
function(check_progress models expected)
  execute_process(COMMAND ${COMMAND} analyze "${WORK_DIR}/study.csv"
                          --out "${WORK_DIR}/report_${models}" --model ${models}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "lucent analyze --model ${models} exited ${code}: ${err}")
  endif()
  if(out MATCHES "left|clmm |lmm ")
    message(FATAL_ERROR "--model ${models}: progress on stdout:\n${out}")
  endif()
  # The lines as a CMake list: their own semicolons written <semicolon>.
  string(REPLACE ";" "<semicolon>" lines "${err}")
  string(REPLACE "\n" ";" lines "${lines}")
  set(fits "")
  foreach(line IN LISTS lines)
    if(line MATCHES "^lucent analyze: (c?lmm) ")
      list(APPEND fits "${line}")
    endif()
  endforeach()
  list(LENGTH fits n)
  list(LENGTH expected total)
  if(NOT n EQUAL total)
    message(FATAL_ERROR "--model ${models}: ${n} progress lines, not ${total}:\n${err}")
  endif()
  set(i 0)
  foreach(want IN LISTS expected)
    list(GET fits ${i} line)
    math(EXPR i "${i} + 1")
    string(REPLACE " " ";" want "${want}")
    list(GET want 0 model)
    list(GET want 1 question)
    if(NOT line MATCHES "^lucent analyze: ${model} ${i}/${total}: question ${question}, factor thickness \\(72 ratings\\) \\.\\.\\. (${seconds})<semicolon> (${seconds}) elapsed, ~(${seconds}) left$")
      message(FATAL_ERROR "--model ${models}: progress line ${i}: '${line}'")
    endif()
  endforeach()
  if(total GREATER 0 AND NOT line MATCHES "~0\\.0 s left$")
    message(FATAL_ERROR "--model ${models}: time left after the last fit: '${line}'")
  endif()
endfunction()
# The default (anova,clmm): one clmm fit per question.
check_progress("anova,clmm" "clmm translucent;clmm realistic;clmm glossy")
check_progress("anova,lmm,clmm"
               "clmm translucent;lmm translucent;clmm realistic;lmm realistic;clmm glossy;lmm glossy")
# No mixed model, no progress line.
check_progress("anova" "")
