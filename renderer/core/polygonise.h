#pragma once
// Marching tetrahedra: the zero set of a scalar field as a closed, outward-wound mesh.
#include <functional>

#include "renderer/core/mesh.h"

namespace lucent {

// `field` is negative inside and a distance bound (|field| <= distance to the surface
// times a small factor), so blocks of the grid far from the surface can be skipped.
// Samples on a cubic grid of spacing `cell` covering [lo, hi]; the surface must stay
// inside that box to be closed. Returns positions and triangles only (no normals, no
// hash): callers finish the mesh.
Mesh polygonise(const std::function<float(glm::vec3)>& field, glm::vec3 lo, glm::vec3 hi,
                float cell);

}  // namespace lucent
