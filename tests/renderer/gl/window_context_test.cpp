// Window contexts need an X server: the test command runs under xvfb-run when DISPLAY is
// unset, so a missing DISPLAY skips only by hand and fails under scripts/test
// (display.h).
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <cstdlib>

#include "renderer/gl/context.h"
#include "renderer/gl/readback.h"
#include "tests/support/display.h"

namespace lucent {
namespace {

TEST(WindowContext, ClearsAndReadsBackColour) {
    LUCENT_REQUIRE_DISPLAY();
    gl::WindowOptions options;
    options.width = 64;
    options.height = 48;
    options.title = "lucent window test";
    auto window = gl::create_window_context(options);
    EXPECT_EQ(window->provider(), "glfw");
    int width = 0, height = 0;
    window->framebuffer_size(width, height);
    ASSERT_EQ(width, 64);
    ASSERT_EQ(height, 48);

    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, width, height);
    glClearColor(51.0f / 255.0f, 102.0f / 255.0f, 153.0f / 255.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    glReadBuffer(GL_BACK);
    const auto pixels = gl::read_framebuffer_rgba8(width, height);
    for (int i : {0, width * height / 2 + width / 2, width * height - 1}) {
        EXPECT_EQ(pixels[i * 4 + 0], 51);
        EXPECT_EQ(pixels[i * 4 + 1], 102);
        EXPECT_EQ(pixels[i * 4 + 2], 153);
    }
    window->swap_buffers();
    EXPECT_FALSE(window->should_close());
}

TEST(WindowContext, MissingMonitorIsReportedNotCrashed) {
    LUCENT_REQUIRE_DISPLAY();
    gl::WindowOptions options;
    options.fullscreen = true;
    options.monitor = 99;
    EXPECT_THROW(gl::create_window_context(options), gl::ContextError);
}

}  // namespace
}  // namespace lucent
