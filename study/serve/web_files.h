#pragma once
// lucent serve's page (serve/web/: index.html, lucent.js, lucent.css), embedded by
// lucent_embed_files (study/CMakeLists.txt); nullopt for any other name.
#include <optional>
#include <string_view>

namespace lucent::embedded {
std::optional<std::string_view> serve_file(std::string_view relative_path);
}  // namespace lucent::embedded
