#pragma once
// Files embedded in the binary by lucent_embed_files (study/CMakeLists.txt): presets.
#include <optional>
#include <string_view>

namespace lucent::embedded {
std::optional<std::string_view> study_file(std::string_view relative_path);
}  // namespace lucent::embedded
