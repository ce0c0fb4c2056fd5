#pragma once
// Independent geometry checks for meshes: volume by the divergence theorem and
// edge-based closedness, written here rather than reused from the code under test.
#include <gtest/gtest.h>

#include <map>
#include <utility>

#include "renderer/core/mesh.h"

namespace lucent::test {

// Signed volume enclosed by the triangles (positive when wound outward).
inline double signed_volume(const Mesh& mesh) {
    double sum = 0.0;
    for (const glm::uvec3& t : mesh.triangles)
        sum += glm::dot(
            glm::dvec3(mesh.positions[t.x]),
            glm::cross(glm::dvec3(mesh.positions[t.y]), glm::dvec3(mesh.positions[t.z])));
    return sum / 6.0;
}

// Every directed edge must occur once and its reverse once: closed, 2-manifold along
// edges, and every pair of neighbours wound the same way.
inline ::testing::AssertionResult closed_and_consistently_wound(const Mesh& mesh) {
    std::map<std::pair<unsigned, unsigned>, int> directed;
    for (const glm::uvec3& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
    for (const auto& [edge, count] : directed) {
        if (count != 1)
            return ::testing::AssertionFailure()
                   << "edge " << edge.first << "->" << edge.second << " used " << count
                   << " times";
        if (directed.find({edge.second, edge.first}) == directed.end())
            return ::testing::AssertionFailure() << "edge " << edge.first << "->"
                                                 << edge.second << " has no twin (open)";
    }
    return ::testing::AssertionSuccess();
}

}  // namespace lucent::test
