# The light `lucent` (analyze, export, merge, ...) links the renderer's core to validate
# protocols against the one technique list, but none of the libraries that render:
# no GL, windows, Embree, OpenImageIO or Assimp (issue 27: the core is separate from
# them). Run with -DBINARY=path.
execute_process(COMMAND ldd ${BINARY} OUTPUT_VARIABLE libraries RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "ldd ${BINARY} failed (${code})")
endif()
foreach(heavy embree OpenImageIO assimp epoxy libGL libEGL glfw)
  string(FIND "${libraries}" "${heavy}" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "${BINARY} links ${heavy}, a renderer library:\n${libraries}")
  endif()
endforeach()
