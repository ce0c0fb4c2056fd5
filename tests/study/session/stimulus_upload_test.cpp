// The session window's own texture upload (issue 26 item 10): a picture the GPU cannot
// hold is refused in one line naming the file, never shown as a black texture. Every
// session path (pre-rendered files, live renders) goes through upload_texture.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "renderer/gl/errors.h"
#include "study/session/stimulus_source.h"
#include "tests/support/gl_test_fixture.h"

namespace lucent::study {
namespace {

class StimulusUpload : public test::HeadlessGlTest {};

std::string refusal(const CpuImage& image) {
    try {
        upload_texture(image, "pictures/wide.png");
    } catch (const StimulusError& e) {
        return e.what();
    }
    return "";
}

// The picture as the texture holds it, top row first.
std::vector<uint8_t> read_back(const StimulusTexture& t) {
    std::vector<uint8_t> pixels(size_t(t.width) * t.height * 4);
    glGetTextureImage(t.texture.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE,
                      static_cast<GLsizei>(pixels.size()), pixels.data());
    return pixels;
}

TEST_F(StimulusUpload, APictureWiderThanTheLargestTextureIsRefusedNamingTheFile) {
    gl::check_errors("test start");
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    ASSERT_GT(max_size, 0);
    // One row one pixel wider than the GPU takes: before the check, a texture without
    // storage (GL_INVALID_VALUE, unchecked) that samples black.
    const CpuImage wide{max_size + 1, 1,
                        std::vector<uint8_t>(size_t(max_size + 1) * 4, 200)};
    const std::string why = refusal(wide);
    EXPECT_NE(why.find("pictures/wide.png"), std::string::npos) << why;
    EXPECT_NE(why.find(std::to_string(max_size + 1) + "x1 picture cannot be shown"),
              std::string::npos)
        << why;
    EXPECT_NE(why.find("largest texture (" + std::to_string(max_size)), std::string::npos)
        << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
    EXPECT_NO_THROW(gl::check_errors("after the refusal"));
}

TEST_F(StimulusUpload, AGlErrorLeftBeforeTheUploadStopsItInsteadOfShowingBlack) {
    gl::check_errors("test start");
    glEnable(0xFFFF);  // not a capability: GL_INVALID_ENUM, left for the next check
    const CpuImage small{2, 2, std::vector<uint8_t>(16, 90)};
    const std::string why = refusal(small);
    EXPECT_NE(why.find("pictures/wide.png: the 2x2 picture cannot be shown: GL error"),
              std::string::npos)
        << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
    EXPECT_NO_THROW(gl::check_errors("after the refusal"));
}

TEST_F(StimulusUpload, PixelStoreStateLeftByOtherCodeDoesNotChangeThePicture) {
    gl::check_errors("test start");
    // A row length and skips as another part of the window may leave them: the picture
    // must still arrive pixel for pixel.
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 7);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, 1);
    glPixelStorei(GL_UNPACK_SKIP_ROWS, 1);
    CpuImage image{3, 2, std::vector<uint8_t>(3 * 2 * 4)};
    image.rgba.reserve(
        512);  // what a reader that honours those skips reaches is allocated
    for (size_t i = 0; i < image.rgba.size(); ++i)
        image.rgba[i] = static_cast<uint8_t>(i * 9 + 1);
    const StimulusTexture t = upload_texture(image, "pictures/small.png");
    EXPECT_EQ(t.width, 3);
    EXPECT_EQ(t.height, 2);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    EXPECT_EQ(read_back(t), image.rgba);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
    glPixelStorei(GL_UNPACK_SKIP_ROWS, 0);
    EXPECT_NO_THROW(gl::check_errors("after the upload"));
}

}  // namespace
}  // namespace lucent::study
