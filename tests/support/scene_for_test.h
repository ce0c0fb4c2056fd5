#pragma once
// Builds a Scene exactly as `lucent render --mesh MESH --technique T --set ...` would,
// so technique tests exercise the same request path as the command line.
#include <string>
#include <utility>
#include <vector>

#include "render.h"

namespace lucent::test {

inline Scene scene_for(const std::string& technique, std::vector<KnobAssignment> settings,
                       const std::string& mesh, int size) {
    RenderRequest request;
    request.mesh = mesh;
    request.technique = technique;
    request.settings = std::move(settings);
    request.width = request.height = size;
    return build_scene(request);
}

}  // namespace lucent::test
