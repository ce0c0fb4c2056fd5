#pragma once
// Analytic meshes for the dipole tests, with split (per-face) normals: a box, a flat
// square plate and a puck (a cylinder lit along its axis). Units are whatever the test
// scales them by.
#include <cmath>

#include "renderer/core/mesh.h"

namespace lucent::dipole::test {

struct MeshBuilder {
    Mesh mesh;
    unsigned vertex(glm::vec3 p, glm::vec3 n) {
        mesh.positions.push_back(p);
        mesh.normals.push_back(n);
        return unsigned(mesh.positions.size() - 1);
    }
    // Counter-clockwise as seen from the side `n` points to.
    void quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::vec3 n) {
        const unsigned i = vertex(a, n), j = vertex(b, n), k = vertex(c, n),
                       l = vertex(d, n);
        mesh.triangles.push_back({i, j, k});
        mesh.triangles.push_back({i, k, l});
    }
    Mesh done(const std::string& name) {
        mesh.name = name;
        finalize_mesh(mesh);
        return mesh;
    }
};

// An axis-aligned box [0, size]; 2 triangles per face.
inline Mesh box(glm::vec3 size) {
    MeshBuilder b;
    const float x = size.x, y = size.y, z = size.z;
    b.quad({0, 0, z}, {x, 0, z}, {x, y, z}, {0, y, z}, {0, 0, 1});
    b.quad({0, 0, 0}, {0, y, 0}, {x, y, 0}, {x, 0, 0}, {0, 0, -1});
    b.quad({0, 0, 0}, {x, 0, 0}, {x, 0, z}, {0, 0, z}, {0, -1, 0});
    b.quad({0, y, 0}, {0, y, z}, {x, y, z}, {x, y, 0}, {0, 1, 0});
    b.quad({0, 0, 0}, {0, 0, z}, {0, y, z}, {0, y, 0}, {-1, 0, 0});
    b.quad({x, 0, 0}, {x, y, 0}, {x, y, z}, {x, 0, z}, {1, 0, 0});
    return b.done("box");
}

// A square plate of side `side` in z = 0 facing +z, split into n x n quads.
inline Mesh plate(float side, int n) {
    MeshBuilder b;
    const float h = side / n, o = -side / 2;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            b.quad({o + i * h, o + j * h, 0}, {o + (i + 1) * h, o + j * h, 0},
                   {o + (i + 1) * h, o + (j + 1) * h, 0}, {o + i * h, o + (j + 1) * h, 0},
                   {0, 0, 1});
    return b.done("plate");
}

// A cylinder of `radius` from z = 0 (bottom, facing -z) to z = thickness (top, facing
// +z) with `segments` around and `rings` radial rings on each face; the rim has normals
// perpendicular to the axis.
inline Mesh puck(float radius, float thickness, int segments, int rings) {
    MeshBuilder b;
    const auto at = [&](int s, int ring, float z) {
        const double phi = 2 * M_PI * s / segments, r = radius * double(ring) / rings;
        return glm::vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), z);
    };
    for (int face = 0; face < 2; ++face) {
        const float z = face == 0 ? thickness : 0.0f;
        const glm::vec3 n(0, 0, face == 0 ? 1.0f : -1.0f);
        for (int s = 0; s < segments; ++s)
            for (int ring = 0; ring < rings; ++ring) {
                // Counter-clockwise seen from +z; reversed for the bottom.
                const glm::vec3 q0 = at(s, ring, z), q1 = at(s, ring + 1, z),
                                q2 = at(s + 1, ring + 1, z), q3 = at(s + 1, ring, z);
                if (ring == 0) {  // a triangle at the centre
                    const unsigned c = b.vertex(q0, n), i = b.vertex(face ? q2 : q1, n),
                                   j = b.vertex(face ? q1 : q2, n);
                    b.mesh.triangles.push_back({c, i, j});
                } else if (face == 0) {
                    b.quad(q0, q1, q2, q3, n);
                } else {
                    b.quad(q0, q3, q2, q1, n);
                }
            }
    }
    for (int s = 0; s < segments; ++s) {
        const glm::vec3 a = at(s, rings, 0), c = at(s + 1, rings, 0);
        const glm::vec3 n0 = glm::normalize(glm::vec3(a.x, a.y, 0)),
                        n1 = glm::normalize(glm::vec3(c.x, c.y, 0));
        const unsigned i = b.vertex(a, n0), j = b.vertex(c, n1),
                       k = b.vertex(c + glm::vec3(0, 0, thickness), n1),
                       l = b.vertex(a + glm::vec3(0, 0, thickness), n0);
        b.mesh.triangles.push_back({i, j, k});
        b.mesh.triangles.push_back({i, k, l});
    }
    return b.done("puck");
}

// The same cylinder as puck(), its vertices shared and without normals, as an OBJ of
// `v` and `f` lines loads: finalize_mesh() gives each vertex the angle-weighted mean of
// its faces' normals, so the rim's vertices point 45 degrees out of both caps. rings = 1
// makes each cap a fan of `segments` long thin triangles from its centre.
inline Mesh puck_with_shared_vertices(float radius, float thickness, int segments,
                                      int rings) {
    Mesh mesh;
    const unsigned per_cap = 1 + unsigned(rings * segments);
    const auto index = [&](int s, int ring, int cap) {  // cap 0: top; ring 0: centre
        return cap * per_cap +
               (ring == 0 ? 0u : 1 + unsigned((ring - 1) * segments + s % segments));
    };
    for (int cap = 0; cap < 2; ++cap) {
        const float z = cap == 0 ? thickness : 0.0f;
        mesh.positions.push_back({0, 0, z});
        for (int ring = 1; ring <= rings; ++ring)
            for (int s = 0; s < segments; ++s) {
                const double phi = 2 * M_PI * s / segments,
                             r = radius * double(ring) / rings;
                mesh.positions.push_back(
                    {float(r * std::cos(phi)), float(r * std::sin(phi)), z});
            }
    }
    for (int cap = 0; cap < 2; ++cap)
        for (int s = 0; s < segments; ++s)
            for (int ring = 0; ring < rings; ++ring) {
                // Counter-clockwise seen from +z; reversed for the bottom.
                const unsigned q0 = index(s, ring, cap), q1 = index(s, ring + 1, cap),
                               q2 = index(s + 1, ring + 1, cap),
                               q3 = index(s + 1, ring, cap);
                if (ring == 0)
                    mesh.triangles.push_back(cap == 0 ? glm::uvec3{q0, q1, q2}
                                                      : glm::uvec3{q0, q2, q1});
                else if (cap == 0)
                    mesh.triangles.push_back({q0, q1, q2}),
                        mesh.triangles.push_back({q0, q2, q3});
                else
                    mesh.triangles.push_back({q0, q3, q2}),
                        mesh.triangles.push_back({q0, q2, q1});
            }
    for (int s = 0; s < segments; ++s) {
        const unsigned i = index(s, rings, 1), j = index(s + 1, rings, 1),
                       k = index(s + 1, rings, 0), l = index(s, rings, 0);
        mesh.triangles.push_back({i, j, k});
        mesh.triangles.push_back({i, k, l});
    }
    mesh.name = "puck";
    finalize_mesh(mesh);
    return mesh;
}

}  // namespace lucent::dipole::test
