#pragma once
// The built-in meshes (sphere, torus, torus_knot, hand, ...), made in code: no file, no
// importer. load_mesh() (renderer/io) dispatches built-in names here.
#include <string>

#include "renderer/core/mesh.h"

namespace lucent {

// True when the text before any ':' is a built-in mesh name.
bool is_builtin_mesh_spec(const std::string& spec);
// "name" or "name:budget" (budget: digits with an optional k or m suffix). Throws
// MeshError.
Mesh build_builtin_mesh(const std::string& spec);

}  // namespace lucent
