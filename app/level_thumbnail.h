#pragma once
// `lucent analyze --images` in lucent-full: a level's picture as a small PNG thumbnail.
#include <filesystem>
#include <string>

namespace lucent::app {

// Decodes `picture` (PNG as written by `lucent render`), box-filters it to at most 128
// pixels a side and returns the PNG bytes. Throws std::runtime_error naming the file.
std::string level_thumbnail_png(const std::filesystem::path& picture);

}  // namespace lucent::app
