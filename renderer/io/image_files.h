#pragma once
// The OpenImageIO reader behind core's read_image() (core/cpu_backend.h installs it);
// write_image() and the rest of core/image.h's file functions are defined beside it.
#include <filesystem>

#include "renderer/core/image.h"

namespace lucent {

// Reads any image OpenImageIO can (read_image()'s contract, core/image.h).
Image read_image_file(const std::filesystem::path& path);

}  // namespace lucent
