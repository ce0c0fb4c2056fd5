# `lucent render CONFIG.toml | --preset NAME --out DIR`: stimulus sets from the command line.
set(LUCENT_STIMULI_CLI_DIR ${CMAKE_BINARY_DIR}/test-scratch/app_stimuli)
set(LUCENT_RENDER_SET_CHECK ${CMAKE_CURRENT_SOURCE_DIR}/render_set_check.cmake)

# The built-in thesis set renders headless: 20 images (18 rated, 2 practice) and a
# manifest row for each, and its report without warnings; a second run re-renders
# nothing; --force re-renders every image byte for byte.
add_test(NAME app.render_preset_thesis
         COMMAND ${CMAKE_COMMAND} -DLUCENT=$<TARGET_FILE:lucent> -DMODE=preset
                 -DOUT=${LUCENT_STIMULI_CLI_DIR}/thesis -DEXPECT_IMAGES=20
                 -P ${LUCENT_RENDER_SET_CHECK})
# The committed example file is the same set.
add_test(NAME app.render_config_example
         COMMAND ${CMAKE_COMMAND} -DLUCENT=$<TARGET_FILE:lucent> -DMODE=config
                 -DCONFIG=${CMAKE_SOURCE_DIR}/renderer/core/presets/thesis.toml
                 -DOUT=${LUCENT_STIMULI_CLI_DIR}/example -DEXPECT_IMAGES=20
                 -P ${LUCENT_RENDER_SET_CHECK})
set_tests_properties(app.render_preset_thesis app.render_config_example PROPERTIES
                     ENVIRONMENT "LUCENT_CACHE_DIR=${CMAKE_BINARY_DIR}/test-cache"
                     RESOURCE_LOCK lucent_ao_cache)

# Config errors: one line naming file:line:column and key, exit 2, nothing written.
file(MAKE_DIRECTORY ${LUCENT_STIMULI_CLI_DIR})
file(WRITE ${LUCENT_STIMULI_CLI_DIR}/unknown_technique.toml
     "[meshes]\nm = \"sphere\"\n[[stimuli]]\nid = \"a\"\ntechnique = \"phong\"\n")
file(WRITE ${LUCENT_STIMULI_CLI_DIR}/wrong_type.toml
     "[meshes]\nm = \"sphere\"\n[[stimuli]]\nid = \"a\"\ntechnique = \"ward\"\nroughness = \"smooth\"\n")
file(WRITE ${LUCENT_STIMULI_CLI_DIR}/unknown_key.toml
     "colour = 1\n[meshes]\nm = \"sphere\"\n[[stimuli]]\nid = \"a\"\ntechnique = \"ward\"\n")
foreach(case unknown_technique wrong_type unknown_key)
  set(expected_unknown_technique "unknown_technique.toml:5:13: stimuli\\[0\\].technique: unknown technique 'phong'")
  set(expected_wrong_type "wrong_type.toml:6:13: stimuli\\[0\\].roughness: wrong type")
  set(expected_unknown_key "unknown_key.toml:1:1: colour: unknown key")
  add_test(NAME app.render_config_${case}_exits_2
           COMMAND ${CMAKE_COMMAND} -DLUCENT=$<TARGET_FILE:lucent> -DMODE=error
                   -DCONFIG=${LUCENT_STIMULI_CLI_DIR}/${case}.toml
                   -DOUT=${LUCENT_STIMULI_CLI_DIR}/out_${case} "-DEXPECT_STDERR=${expected_${case}}"
                   -P ${LUCENT_RENDER_SET_CHECK})
endforeach()
add_test(NAME app.render_unknown_preset_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=render;--preset;nope;--out;${LUCENT_STIMULI_CLI_DIR}/nope"
                 -DEXPECT_CODE=2 "-DEXPECT_STDERR=unknown preset 'nope' \\(valid: thesis, heterogeneous, fabrics, physical, scaling, matching, jnd\\)"
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_exit.cmake)
add_test(NAME app.render_mesh_and_config_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=render;x.toml;--mesh;sphere;--out;${LUCENT_STIMULI_CLI_DIR}/both"
                 -DEXPECT_CODE=2 "-DEXPECT_STDERR=one of --mesh, CONFIG, --preset or --study$"
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_exit.cmake)
# lucent render --study: an unknown built-in study (--study-preset, the old name of
# --preset for a study), and a ladder too long to pre-render, are refused in one line
# (exit 2).
add_test(NAME app.render_study_unknown_preset_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=render;--study-preset;nope;--out;${LUCENT_STIMULI_CLI_DIR}/nope_study"
                 -DEXPECT_CODE=2 "-DEXPECT_STDERR=unknown preset 'nope' \\(valid: thesis, fabrics, scaling, matching, jnd\\)"
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_exit.cmake)
add_test(NAME app.render_study_ladder_too_long_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=render;--study;${CMAKE_CURRENT_SOURCE_DIR}/data/long_ladder.toml;--out;${LUCENT_STIMULI_CLI_DIR}/long_ladder"
                 -DEXPECT_CODE=2 "-DEXPECT_STDERR=long_ladder.toml: block 'j': the browser's ladder of deltas \\[0, 9997\\] in steps of 0.001 would be 9997001 pictures per standard \\(at most 2000\\): set ladder_step or max_delta"
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_exit.cmake)

# lucent stimuli report: a folder that is not a rendered set is refused in one line
# naming the file, and nothing is written.
add_test(NAME app.stimuli_report_without_manifest_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=stimuli;report;${LUCENT_STIMULI_CLI_DIR}"
                 -DEXPECT_CODE=2
                 "-DEXPECT_STDERR=lucent stimuli report: ${LUCENT_STIMULI_CLI_DIR}/manifest.csv: missing"
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_exit.cmake)
add_test(NAME app.stimuli_report_bad_threshold_exits_2
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=stimuli;report;${LUCENT_STIMULI_CLI_DIR};--min-delta-e;-1"
                 -DEXPECT_CODE=2 "-DEXPECT_STDERR=--min-delta-e"
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_exit.cmake)

# lucent bench render runs end to end (small images; the figures come from a full run).
add_test(NAME app.bench_render_smoke COMMAND lucent bench render --size 64x64)
set_tests_properties(app.bench_render_smoke PROPERTIES
    PASS_REGULAR_EXPRESSION "20 stimuli at 64x64.*empty +[0-9.]+ .*filled, before +[0-9.]+ .*filled +[0-9.]+ .*throughput.*now / before: [0-9.]+x")
add_test(NAME app.bench_render_csv
         COMMAND ${CMAKE_COMMAND} -DCOMMAND=$<TARGET_FILE:lucent>
                 "-DARGS=bench;render;--size;32x32"
                 -DCSV=${CMAKE_CURRENT_BINARY_DIR}/bench-render.csv
                 "-DEXPECT_CSV=\"AO cache filled\",\"stimuli per CPU-second\",[0-9.e+]+,1/CPUs;\"AO cache filled, before\",\"encode\",;\"summary\",\"filled now / before, stimuli per second\",[0-9.e+]+,ratio"
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/bench_csv_check.cmake)
