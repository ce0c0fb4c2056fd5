#include "renderer/core/cpu_backend.h"

#include <stdexcept>

#include "renderer/core/ambient_occlusion.h"
#include "renderer/core/image.h"

namespace lucent {
namespace {

CpuBackend& installed() {
    static CpuBackend backend;
    return backend;
}

}  // namespace

void install_cpu_backend(CpuBackend backend) { installed() = std::move(backend); }

const CpuBackend& cpu_backend() {
    const CpuBackend& backend = installed();
    if (!backend.ray_queries || !backend.bake_ambient_occlusion || !backend.read_image)
        throw std::logic_error(
            "this program does not link lucent_renderer_cpu (Embree ray casting, image "
            "files): CPU references, AO bakes and file textures are not available");
    return backend;
}

// The core's entry points that the backend serves.

std::vector<float> bake_ambient_occlusion(const Mesh& mesh,
                                          const AoBakeOptions& options) {
    return cpu_backend().bake_ambient_occlusion(mesh, options);
}

Image read_image(const std::filesystem::path& path) {
    return cpu_backend().read_image(path);
}

}  // namespace lucent
