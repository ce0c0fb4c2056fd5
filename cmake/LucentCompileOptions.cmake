# Warnings and sanitizers applied to every Lucent target through one interface library,
# so third-party code found by find_package keeps its own flags.
add_library(lucent_compile_options INTERFACE)
# Includes name their layer from the repository root: "renderer/core/scene.h", "study/...".
target_include_directories(lucent_compile_options INTERFACE ${PROJECT_SOURCE_DIR})
target_compile_options(lucent_compile_options INTERFACE -Wall -Wextra -Wpedantic
                       -Wno-missing-field-initializers)

if(LUCENT_SANITIZE)
  message(STATUS "Lucent: sanitizers enabled: ${LUCENT_SANITIZE}")
  target_compile_options(lucent_compile_options INTERFACE
                         -fsanitize=${LUCENT_SANITIZE} -fno-omit-frame-pointer
                         -fno-sanitize-recover=undefined)
  target_link_options(lucent_compile_options INTERFACE -fsanitize=${LUCENT_SANITIZE})
endif()
