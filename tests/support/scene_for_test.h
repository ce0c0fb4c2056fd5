#pragma once
// Builds a Scene exactly as `lucent render --mesh MESH --technique T --set ...` would,
// so technique tests exercise the same request path as the command line; and looks
// passes up in the plan it makes.
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "renderer/render.h"

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

// The pass of `plan` named `name`, or nullptr when the plan has none (culled).
inline const Pass* find_pass(const FramePlan& plan, const std::string& name) {
    for (const auto& pass : plan.passes)
        if (pass.name == name) return &pass;
    return nullptr;
}

// Whether `pass` exists and its shader variant is compiled with `define`.
inline bool has_define(const Pass* pass, const std::string& define) {
    return pass && std::find(pass->shader.defines.begin(), pass->shader.defines.end(),
                             define) != pass->shader.defines.end();
}

}  // namespace lucent::test
