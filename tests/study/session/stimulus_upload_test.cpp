// The session window's own texture upload (issue 26 item 10): a picture the GPU cannot
// hold is refused in one line naming the file, never shown as a black texture. Every
// session path (pre-rendered files, live renders) goes through upload_texture.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "renderer/gl/errors.h"
#include "study/session/stimulus_source.h"
#include "tests/support/gl_test_fixture.h"
#include "tests/support/test_paths.h"

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

namespace lucent::study {
namespace {

// lucent serve's in-memory PNG (issue 44, item 4): what is decoded is what was encoded,
// translucent pixels included (straight alpha), and another reader sees the same.
TEST(ServedPng, EncodesAndDecodesEveryPixelExactlyAndRefusesOtherBytesInOneLine) {
    CpuImage image;
    image.width = 37;
    image.height = 11;
    image.rgba.resize(size_t(image.width) * image.height * 4);
    for (size_t i = 0; i < image.rgba.size(); ++i)
        image.rgba[i] = static_cast<uint8_t>((i * 37 + i / 4) % 256);
    const std::string png = encode_png_rgba8(image);
    ASSERT_EQ(png.substr(1, 3), "PNG");
    const CpuImage back = decode_png_rgba8(png, "picture");
    EXPECT_EQ(back.width, image.width);
    EXPECT_EQ(back.height, image.height);
    EXPECT_EQ(back.rgba, image.rgba);
    // Opaque, through the file reader the lab uses.
    for (size_t i = 3; i < image.rgba.size(); i += 4) image.rgba[i] = 255;
    const std::string path = (test::scratch_dir("served_png") / "opaque.png").string();
    std::ofstream(path, std::ios::binary) << encode_png_rgba8(image);
    EXPECT_EQ(load_image_rgba8(path).rgba, image.rgba);
    try {
        decode_png_rgba8("not a png", "stimulus 'a'");
        ADD_FAILURE() << "not refused";
    } catch (const StimulusError& e) {
        const std::string why = e.what();
        EXPECT_EQ(why.rfind("stimulus 'a': ", 0), 0u) << why;
        EXPECT_EQ(why.find('\n'), std::string::npos) << why;
    }
}

}  // namespace
}  // namespace lucent::study
