#pragma once
// lucent_renderer_cpu's implementations of the core's CPU backend (core/cpu_backend.h),
// installed by cpu/install_backend.cpp in every program that links the library.
#include <memory>
#include <vector>

#include "renderer/core/ambient_occlusion.h"
#include "renderer/core/cpu_backend.h"
#include "renderer/core/mesh.h"

namespace lucent {

// Embree 3 ray queries over `mesh` (robust mode).
std::unique_ptr<RayQueries> make_embree_ray_queries(const Mesh& mesh);
// The bake behind core's bake_ambient_occlusion() (core/ambient_occlusion.h documents
// it).
std::vector<float> embree_bake_ambient_occlusion(const Mesh& mesh,
                                                 const AoBakeOptions& options);

}  // namespace lucent
