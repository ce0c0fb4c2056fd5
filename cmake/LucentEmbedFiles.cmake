# lucent_embed_files(OUTPUT file.cpp FUNCTION ns::name BASE_DIR dir FILES a b ...)
# Generates a C++ source defining
#   std::optional<std::string_view> ns::name(std::string_view relative_path)
# that returns the embedded text of each file (keyed by its path relative to BASE_DIR),
# so shaders ship inside the binary and need no install step.
set(LUCENT_EMBED_SCRIPT "${CMAKE_CURRENT_LIST_DIR}/embed_files_script.cmake")
function(lucent_embed_files)
  cmake_parse_arguments(ARG "" "OUTPUT;FUNCTION;BASE_DIR" "FILES" ${ARGN})
  set(abs_files)
  foreach(f IN LISTS ARG_FILES)
    get_filename_component(abs "${f}" ABSOLUTE BASE_DIR "${ARG_BASE_DIR}")
    list(APPEND abs_files "${abs}")
  endforeach()
  string(REPLACE ";" "|" files_arg "${abs_files}")
  add_custom_command(
    OUTPUT "${ARG_OUTPUT}"
    COMMAND ${CMAKE_COMMAND} "-DOUTPUT=${ARG_OUTPUT}" "-DFUNCTION=${ARG_FUNCTION}"
            "-DBASE_DIR=${ARG_BASE_DIR}" "-DFILES=${files_arg}" -P "${LUCENT_EMBED_SCRIPT}"
    DEPENDS ${abs_files} "${LUCENT_EMBED_SCRIPT}"
    COMMENT "Embedding ${ARG_FUNCTION} files"
    VERBATIM)
endfunction()
