# CLI tests of lucent analyze / stats / simulate / bench stats (included from
# CMakeLists.txt). Expected numbers come from closed forms, not from lucent's output.
set(LUCENT_APP_TEST_DIR ${CMAKE_CURRENT_SOURCE_DIR})
function(lucent_expect_number name expect digits)
  add_test(NAME ${name}
           COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent> "-DARGS=${ARGN}"
                   -DEXPECT=${expect} -DDIGITS=${digits}
                   -P ${LUCENT_APP_TEST_DIR}/expect_number.cmake)
endfunction()

# k = 2, df = 2: P(Q > q) = 1 - q / sqrt(4 + q^2), so P(Q > 1.5) = 0.4 exactly.
lucent_expect_number(app.stats_ptukey_k2_df2 0.4 13 stats;ptukey;--q;1.5;--k;2;--df;2)
lucent_expect_number(app.stats_ptukey_lower 0.6 13 stats;ptukey;--q;1.5;--k;2;--df;2;--lower)
lucent_expect_number(app.stats_qtukey_k2_df2 1.5 11 stats;qtukey;--p;0.4;--k;2;--df;2)
# k = 2, df = inf: P(Q > q) = erfc(q / 2); erfc(1) and erfc(20) from tables.
lucent_expect_number(app.stats_ptukey_k2_inf 0.157299207050285130658 13
                     stats;ptukey;--q;2;--k;2;--df;inf)
lucent_expect_number(app.stats_ptukey_far_tail 5.3958656116079e-176 12
                     stats;ptukey;--q;40;--k;2;--df;inf)
# Tukey's table: q(.05; k = 3, df = 10) = 3.877.
lucent_expect_number(app.stats_qtukey_table 3.877 4 stats;qtukey;--p;0.05;--k;3;--df;10)

add_test(NAME app.stats_bad_k_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=stats;ptukey;--q;3;--k;1;--df;10" -DEXPECT_CODE=2 -DEXPECT_STDERR=k
                 -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
add_test(NAME app.stats_bad_df_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=stats;qtukey;--p;0.05;--k;3;--df;lots" -DEXPECT_CODE=2
                 -DEXPECT_STDERR=--df -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
add_test(NAME app.analyze_rejects_out_of_scale
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=analyze;${LUCENT_APP_TEST_DIR}/data/out_of_scale.csv;--out;${CMAKE_CURRENT_BINARY_DIR}/out_of_scale"
                 -DEXPECT_CODE=2 "-DEXPECT_STDERR=out_of_scale.csv:3: rating 9 is outside the scale 1..7"
                 -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
# Issue 26 item 10: ratings of +-1e308 (--scale any) ended with "lucent: stod"; they, and
# a rating beyond the double range, are refused in one line naming file, line and column.
add_test(NAME app.analyze_ratings_of_plus_minus_1e308_name_line_and_column
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=analyze;${LUCENT_APP_TEST_DIR}/data/ratings_plus_minus_1e308.csv;--out;${CMAKE_CURRENT_BINARY_DIR}/plus_minus_1e308;--scale;any"
                 -DEXPECT_CODE=2 "-DEXPECT_STDERR=^lucent analyze: [^ ]*ratings_plus_minus_1e308.csv:3: column 6 .rating.: rating '-1e308' lies further"
                 -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
add_test(NAME app.analyze_rating_overflowing_1e400_names_line_and_column
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=analyze;${LUCENT_APP_TEST_DIR}/data/ratings_overflowing_1e400.csv;--out;${CMAKE_CURRENT_BINARY_DIR}/overflowing_1e400;--scale;any"
                 -DEXPECT_CODE=2 "-DEXPECT_STDERR=^lucent analyze: [^ ]*ratings_overflowing_1e400.csv:3: column 6 .rating.: rating '1e400' is beyond the range of a double"
                 -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
add_test(NAME app.analyze_bad_format_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=analyze;${LUCENT_APP_TEST_DIR}/data/out_of_scale.csv;--out;${CMAKE_CURRENT_BINARY_DIR}/bad_format;--format;pdf"
                 -DEXPECT_CODE=2 -DEXPECT_STDERR=pdf -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
add_test(NAME app.analyze_bad_design_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=analyze;${LUCENT_APP_TEST_DIR}/data/out_of_scale.csv;--out;${CMAKE_CURRENT_BINARY_DIR}/bad_design;--design;mixed"
                 -DEXPECT_CODE=2 -DEXPECT_STDERR=--design -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
add_test(NAME app.analyze_missing_input_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=analyze;/nonexistent/ratings.csv;--out;${CMAKE_CURRENT_BINARY_DIR}/missing"
                 -DEXPECT_CODE=2 -DEXPECT_STDERR=nonexistent -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
add_test(NAME app.analyze_nist_sirstv_scale_any
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 -DNIST_FILE=${LUCENT_SHARED_DIR}/data/nist-strd-anova/SiRstv.dat
                 -DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/nist_sirstv
                 -P ${LUCENT_APP_TEST_DIR}/analyze_nist.cmake)
set_tests_properties(app.analyze_nist_sirstv_scale_any PROPERTIES SKIP_REGULAR_EXPRESSION "SKIP:")
add_test(NAME app.analyze_simulated_study
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 -DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/pipeline
                 -P ${LUCENT_APP_TEST_DIR}/analyze_pipeline.cmake)
add_test(NAME app.analyze_shows_mixed_model_progress
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 -DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/analyze_progress
                 -P ${LUCENT_APP_TEST_DIR}/analyze_progress.cmake)
add_test(NAME app.analyze_mixed_models_lead_when_asked
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 -DDATA=${LUCENT_APP_TEST_DIR}/data/wine_long.csv
                 -DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/mixed_report
                 -P ${LUCENT_APP_TEST_DIR}/analyze_mixed.cmake)
add_test(NAME app.readme_analyst_commands_run_as_written
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 -DREADME=${CMAKE_SOURCE_DIR}/README.md
                 -DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/readme_analyst
                 -P ${LUCENT_APP_TEST_DIR}/readme_analyst.cmake)
add_test(NAME app.analyze_bad_model_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=analyze;${LUCENT_APP_TEST_DIR}/data/wine_long.csv;--out;${CMAKE_CURRENT_BINARY_DIR}/bad_model;--model;anova,glmm"
                 -DEXPECT_CODE=2 "-DEXPECT_STDERR=^lucent analyze: --model: 'glmm' is not one of anova, clmm, lmm"
                 -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
add_test(NAME app.analyze_primary_model_must_run_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=analyze;${LUCENT_APP_TEST_DIR}/data/wine_long.csv;--out;${CMAKE_CURRENT_BINARY_DIR}/primary_not_run;--model;anova;--primary-model;lmm"
                 -DEXPECT_CODE=2 "-DEXPECT_STDERR=--primary-model lmm is not among --model anova"
                 -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
add_test(NAME app.simulate_bad_effects_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=simulate;--out;${CMAKE_CURRENT_BINARY_DIR}/x.csv;--participants;0"
                 -DEXPECT_CODE=2 -DEXPECT_STDERR=participants -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
# lucent power: a balanced between design's closed form (noncentral F) is printed next to
# the simulation; lambda = 10 * 0.5 / 1, df 2 and 27: R's
# 1 - pf(qf(0.95, 2, 27), 2, 27, ncp = 5) = 0.4579922755.
add_test(NAME app.power_between_prints_closed_form
         COMMAND lucent power --design between --participants 10 --means 0,0.5,1
                 --residual-sd 1 --alpha 0.05 --simulations 200)
set_tests_properties(app.power_between_prints_closed_form PROPERTIES
    PASS_REGULAR_EXPRESSION "closed form \\(noncentral F\\) of the one-way ANOVA: 0\\.4580")
add_test(NAME app.power_bad_means_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=power;--means;3"
                 -DEXPECT_CODE=2 -DEXPECT_STDERR=--means -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
# lucent power --model lmm: pictures per level in a table, each row with the closed form
# of the balanced mixed-model F; m = 4, lambda = 4 * 0.125 / (0.4^2 + 1.2^2 / 20), df 1
# and 6: R's 1 - pf(qf(0.95, 1, 6), 1, 6, ncp = 2.1551724137931) = 0.2367055639.
add_test(NAME app.power_crossed_prints_closed_form_per_stimuli
         COMMAND lucent power --model lmm --participants 20 --means 4,4.5
                 --participant-sd 0.7 --stimulus-sd 0.4 --residual-sd 1.2 --alpha 0.05
                 --simulations 40 --stimuli-list 2,4)
set_tests_properties(app.power_crossed_prints_closed_form_per_stimuli PROPERTIES
    PASS_REGULAR_EXPRESSION "\n4 +[0-9.]+ \\+/- [0-9.]+ +[0-9.]+ \\+/- [0-9.]+ +0\\.2367")
add_test(NAME app.power_crossed_one_stimulus_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=power;--model;clmm;--means;3,4;--stimuli;1"
                 -DEXPECT_CODE=2 "-DEXPECT_STDERR=--stimuli must lie in \\[2, 1000\\]"
                 -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
add_test(NAME app.bench_stats_small COMMAND lucent bench stats --ratings 20000 --cdf-seconds 0.02
                                           --mixed-ratings 1200)
set_tests_properties(app.bench_stats_small PROPERTIES PASS_REGULAR_EXPRESSION
                     "evals/s.*clmm, 1260 ratings.*lucent +[0-9.]+ +[0-9.]+ +[0-9]+")
add_test(NAME app.bench_stats_bad_mixed_size_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=bench;stats;--ratings;2000;--cdf-seconds;0.01;--no-process;--mixed-ratings;50"
                 -DEXPECT_CODE=2 "-DEXPECT_STDERR=--mixed-ratings: 50 is not in"
                 -P ${LUCENT_APP_TEST_DIR}/expect_exit.cmake)
