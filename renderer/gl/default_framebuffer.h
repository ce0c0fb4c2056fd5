#pragma once
// The window's own framebuffer (name 0), for the interactive windows' frames.
#include <glm/glm.hpp>

namespace lucent::gl {

// Binds the default framebuffer, sets the viewport to width x height pixels and clears
// its colour to `colour` (opaque).
void clear_default_framebuffer(int width, int height, glm::vec3 colour);

}  // namespace lucent::gl
