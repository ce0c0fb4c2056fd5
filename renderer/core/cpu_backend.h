#pragma once
// What the GL-free core asks of libraries it does not link: Embree ray casting (the CPU
// references and the ambient-occlusion bake) and OpenImageIO (file textures). The core
// declares the operations; lucent_renderer_cpu implements them and installs itself in
// every program that links it (every program that renders does, through
// lucent_renderer). A program that only reads protocols and knobs (the light `lucent`
// that runs analyze, export, merge) links neither library, and asking it to trace a ray
// fails in one line instead of at link time.
#include <filesystem>
#include <functional>
#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <vector>

#include "renderer/core/ambient_occlusion.h"
#include "renderer/core/image.h"
#include "renderer/core/mesh.h"

namespace lucent {

struct RayHit;

// One mesh's acceleration structure: the queries RayCaster (cpu/ray_caster.h) forwards.
// Directions arrive normalised and finite, t_min < t_max; all const and thread-safe.
class RayQueries {
public:
    virtual ~RayQueries() = default;
    virtual std::optional<RayHit> first_hit(glm::vec3 origin, glm::vec3 unit_direction,
                                            float t_min, float t_max) const = 0;
    virtual bool occluded(glm::vec3 origin, glm::vec3 unit_direction, float t_min,
                          float t_max) const = 0;
};

struct CpuBackend {
    std::function<std::unique_ptr<RayQueries>(const Mesh&)> ray_queries;
    std::function<std::vector<float>(const Mesh&, const AoBakeOptions&)>
        bake_ambient_occlusion;
    std::function<Image(const std::filesystem::path&)> read_image;
};

// Replaces the installed backend (lucent_renderer_cpu calls it before main; tests may
// install another and restore the one they found).
void install_cpu_backend(CpuBackend backend);
// The installed backend; std::logic_error naming the missing library when there is none.
const CpuBackend& cpu_backend();

}  // namespace lucent
