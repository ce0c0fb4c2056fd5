#include "renderer/gl/default_framebuffer.h"

#include <epoxy/gl.h>

namespace lucent::gl {

void clear_default_framebuffer(int width, int height, glm::vec3 colour) {
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, width, height);
    glClearColor(colour.r, colour.g, colour.b, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
}

}  // namespace lucent::gl
