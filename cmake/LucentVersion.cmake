# Version and build hash, baked into a small library every target may link.
find_package(Git QUIET)
set(LUCENT_BUILD_HASH "unknown")
if(GIT_FOUND AND EXISTS "${CMAKE_SOURCE_DIR}/.git")
  execute_process(COMMAND ${GIT_EXECUTABLE} describe --always --dirty --abbrev=12
                  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR}
                  OUTPUT_VARIABLE LUCENT_BUILD_HASH OUTPUT_STRIP_TRAILING_WHITESPACE
                  ERROR_QUIET)
  if(NOT LUCENT_BUILD_HASH)
    set(LUCENT_BUILD_HASH "unknown")
  endif()
endif()
configure_file(${CMAKE_SOURCE_DIR}/cmake/version.cpp.in
               ${CMAKE_BINARY_DIR}/generated/lucent_version.cpp @ONLY)
add_library(lucent_version STATIC ${CMAKE_BINARY_DIR}/generated/lucent_version.cpp)
target_include_directories(lucent_version PUBLIC ${CMAKE_SOURCE_DIR}/cmake/include)
target_link_libraries(lucent_version PRIVATE lucent_compile_options)
