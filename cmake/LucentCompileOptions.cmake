# Warnings and sanitizers applied to every Lucent target through one interface library,
# so third-party code found by find_package keeps its own flags.
add_library(lucent_compile_options INTERFACE)
# Includes name their layer from the repository root: "renderer/core/scene.h", "study/...".
target_include_directories(lucent_compile_options INTERFACE ${PROJECT_SOURCE_DIR})
# -Werror=switch: a switch over a closed family (study::Task, a technique's variants)
# with no default must name every member, so adding one is a build error wherever it
# must be handled, not a silent fall-through.
target_compile_options(lucent_compile_options INTERFACE -Wall -Wextra -Wpedantic
                       -Wno-missing-field-initializers -Werror=switch)

if(LUCENT_SANITIZE)
  message(STATUS "Lucent: sanitizers enabled: ${LUCENT_SANITIZE}")
  target_compile_options(lucent_compile_options INTERFACE
                         -fsanitize=${LUCENT_SANITIZE} -fno-omit-frame-pointer
                         -fno-sanitize-recover=undefined)
  target_link_options(lucent_compile_options INTERFACE -fsanitize=${LUCENT_SANITIZE})
endif()
