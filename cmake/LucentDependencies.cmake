# Every dependency comes from a Debian 12 package (scripts/install-deps installs them).
find_package(PkgConfig REQUIRED)

find_package(glfw3 3.3 REQUIRED)
find_package(glm REQUIRED)
find_package(assimp REQUIRED)
find_package(embree 3 REQUIRED)
find_package(tomlplusplus REQUIRED)
find_package(CLI11 REQUIRED)
find_package(Boost 1.74 REQUIRED)              # Math and Multiprecision are header-only
find_package(Threads REQUIRED)
# Eigen (libeigen3-dev): the dense and sparse Cholesky factors of the mixed models.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)

pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)
pkg_check_modules(EGL REQUIRED IMPORTED_TARGET egl)
# OpenImageIO's CMake package names a missing /usr/include/opencv4 on Debian 12.
pkg_check_modules(OIIO REQUIRED IMPORTED_TARGET OpenImageIO)
pkg_check_modules(SQLITE3 REQUIRED IMPORTED_TARGET sqlite3)
pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui)
# littleCMS: sRGB -> Lab and CIEDE2000 for the stimulus-set report.
pkg_check_modules(LCMS2 REQUIRED IMPORTED_TARGET lcms2)
# NLopt's C++ API (libnlopt-cxx-dev): the bounded derivative-free optimiser (BOBYQA) of
# `lucent bench fidelity`'s fits and the mixed models' variance parameters.
pkg_check_modules(NLOPT_CXX REQUIRED IMPORTED_TARGET nlopt_cxx)

if(LUCENT_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(LUCENT_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()

# Dear ImGui's GLFW and OpenGL3 backends ship as sources in the Debian package.
set(LUCENT_IMGUI_BACKENDS_DIR "/usr/share/doc/libimgui-dev/examples/backends"
    CACHE PATH "Directory holding imgui_impl_glfw.cpp and imgui_impl_opengl3.cpp")
add_library(lucent_imgui_backends STATIC
            ${LUCENT_IMGUI_BACKENDS_DIR}/imgui_impl_glfw.cpp
            ${LUCENT_IMGUI_BACKENDS_DIR}/imgui_impl_opengl3.cpp)
target_include_directories(lucent_imgui_backends SYSTEM PUBLIC /usr/include/imgui/backends)
target_link_libraries(lucent_imgui_backends PUBLIC PkgConfig::IMGUI glfw)
set_target_properties(lucent_imgui_backends PROPERTIES POSITION_INDEPENDENT_CODE ON)
