// lucent info: creates a headless GL context and prints what it runs on, plus the
// versions of the libraries this build links.
#include <GLFW/glfw3.h>
#include <OpenImageIO/oiioversion.h>
#include <assimp/version.h>
#include <embree3/rtcore_config.h>
#include <sqlite3.h>
#include <toml++/toml.h>

#include <CLI/Version.hpp>
#include <boost/version.hpp>
#include <glm/detail/setup.hpp>
#include <iostream>

#include "app/commands.h"
#include "lucent/version.h"
#include "renderer/gl/context.h"

namespace lucent::app {
namespace {

int run_info() {
    std::cout << "lucent " << version_string() << " (" << build_hash() << ")\n";
    try {
        auto context = gl::create_headless_context();
        const gl::GlInfo info = context->info();
        std::cout << "context:          " << context->platform() << "\n"
                  << "GL vendor:        " << info.vendor << "\n"
                  << "GL renderer:      " << info.renderer << "\n"
                  << "GL version:       " << info.version << "\n"
                  << "GLSL version:     " << info.glsl_version << "\n"
                  << "max texture size: " << info.max_texture_size << "\n"
                  << "timer queries:    " << (info.has_timer_query ? "yes" : "no")
                  << "\n";
    } catch (const gl::ContextError& e) {
        std::cerr << "lucent info: cannot create a headless GL context: " << e.what()
                  << "\n";
        return kExitFailure;
    }
    std::cout << "libraries:\n"
              << "  GLFW          " << glfwGetVersionString() << "\n"
              << "  OpenImageIO   " << OIIO_VERSION_STRING << "\n"
              << "  SQLite        " << sqlite3_libversion() << "\n"
              << "  Assimp        " << aiGetVersionMajor() << "." << aiGetVersionMinor()
              << "." << aiGetVersionPatch() << "\n"
              << "  Embree        " << RTC_VERSION_STRING << "\n"
              << "  Boost         " << BOOST_VERSION / 100000 << "."
              << BOOST_VERSION / 100 % 1000 << "." << BOOST_VERSION % 100 << "\n"
              << "  GLM           " << GLM_VERSION_MAJOR << "." << GLM_VERSION_MINOR
              << "." << GLM_VERSION_PATCH << "\n"
              << "  toml++        " << TOML_LIB_MAJOR << "." << TOML_LIB_MINOR << "."
              << TOML_LIB_PATCH << "\n"
              << "  CLI11         " << CLI11_VERSION << "\n";
    return kExitOk;
}

}  // namespace

void register_info(CLI::App& app, int& exit_code) {
    auto* cmd = app.add_subcommand(
        "info",
        "Create a headless OpenGL context and print the GL implementation and the "
        "versions of linked libraries");
    cmd->callback([&exit_code] { exit_code = run_info(); });
}

}  // namespace lucent::app
