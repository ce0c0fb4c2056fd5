#include "renderer/gl/present.h"

#include <epoxy/gl.h>

#include "renderer/core/display_transform.h"

namespace lucent::gl {

void clear_frame(int width, int height, const float rgb[3]) {
    glViewport(0, 0, width, height);
    // The default framebuffer takes display values: the codes a PNG of a stimulus on this
    // background stores (code / 255 converts back to exactly that code).
    glClearColor(display_code(rgb[0]) / 255.f, display_code(rgb[1]) / 255.f,
                 display_code(rgb[2]) / 255.f, 1.f);
    glClear(GL_COLOR_BUFFER_BIT);
}

void wait_for_gpu() { glFinish(); }

}  // namespace lucent::gl
