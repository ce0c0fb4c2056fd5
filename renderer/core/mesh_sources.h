#pragma once
// Internal to lucent_renderer: the two sources load_mesh() dispatches to.
#include <string>

#include "core/mesh.h"

namespace lucent {

// True when the text before any ':' is a built-in mesh name.
bool is_builtin_mesh_spec(const std::string& spec);
// "name" or "name:budget" (budget: digits with an optional k or m suffix). Throws MeshError.
Mesh build_builtin_mesh(const std::string& spec);
// Reads a file through Assimp and cleans it. Throws MeshError "PATH: reason".
Mesh load_mesh_file(const std::string& path);

}  // namespace lucent
