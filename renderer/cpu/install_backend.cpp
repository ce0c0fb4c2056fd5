// Compiled into every target that links lucent_renderer_cpu (an INTERFACE source), so the
// backend is installed before main() in each program that renders, with no call to
// forget. Idempotent: each copy installs the same functions.
#include "renderer/core/cpu_backend.h"
#include "renderer/cpu/embree_backend.h"
#include "renderer/io/image_files.h"

namespace {

const bool installed = [] {
    lucent::install_cpu_backend({lucent::make_embree_ray_queries,
                                 lucent::embree_bake_ambient_occlusion,
                                 lucent::read_image_file});
    return true;
}();

}  // namespace
