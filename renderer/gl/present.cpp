#include "renderer/gl/present.h"

#include <epoxy/gl.h>

namespace lucent::gl {

void clear_frame(int width, int height, const float rgb[3]) {
    glViewport(0, 0, width, height);
    glClearColor(rgb[0], rgb[1], rgb[2], 1.f);
    glClear(GL_COLOR_BUFFER_BIT);
}

void wait_for_gpu() { glFinish(); }

}  // namespace lucent::gl
