// Marching tetrahedra (see polygonise.h).
#include "renderer/core/polygonise.h"

#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace lucent {

// Marching tetrahedra over a cubic grid of spacing `cell` covering [lo, hi]: each cube
// is split into six tetrahedra around its main diagonal (a conforming split, so the
// surface is closed), vertices on grid edges are shared, triangles face outward.
// The grid is visited in blocks of 8^3 cells and a block whose centre is farther from
// the surface than twice its half-diagonal is skipped (the field is a distance bound),
// so the cost follows the surface area, not the bounding box volume.
Mesh polygonise(const std::function<float(glm::vec3)>& field, glm::vec3 lo, glm::vec3 hi,
                float cell) {
    constexpr int kBlock = 8;
    const glm::ivec3 cells = glm::ivec3(glm::ceil((hi - lo) / cell));
    const glm::ivec3 dims = cells + 1;  // grid vertices
    auto global_index = [&](glm::ivec3 g) {
        return (static_cast<std::uint64_t>(g.z) * dims.y + g.y) * dims.x + g.x;
    };
    auto value_at = [&](glm::ivec3 g) {
        // A value of exactly zero would put a vertex on a grid corner shared by several
        // edges and create zero-area triangles: count it as outside.
        const float v = field(lo + cell * glm::vec3(g));
        return v == 0.0f ? 1e-7f * cell : v;
    };
    Mesh mesh;
    std::unordered_map<std::uint64_t, unsigned> edge_vertex;
    auto vertex_on_edge = [&](std::uint64_t a, glm::vec3 pa, float fa, std::uint64_t b,
                              glm::vec3 pb, float fb) {
        if (a > b) std::swap(a, b), std::swap(pa, pb), std::swap(fa, fb);
        const auto [it, inserted] = edge_vertex.try_emplace(
            (a << 32) ^ b, static_cast<unsigned>(mesh.positions.size()));
        if (inserted) mesh.positions.push_back(pa + (fa / (fa - fb)) * (pb - pa));
        return it->second;
    };
    static constexpr int kTetrahedra[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                              {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
    const float block_reach = 2.0f * 0.5f * std::sqrt(3.0f) * kBlock * cell;
    std::vector<float> block_values;
    for (int bz = 0; bz < cells.z; bz += kBlock)
        for (int by = 0; by < cells.y; by += kBlock)
            for (int bx = 0; bx < cells.x; bx += kBlock) {
                const glm::ivec3 first(bx, by, bz);
                const glm::ivec3 last = glm::min(first + kBlock, cells);  // vertex bounds
                const glm::vec3 centre = lo + cell * 0.5f * glm::vec3(first + last);
                if (std::abs(field(centre)) > block_reach) continue;
                const glm::ivec3 size = last - first + 1;
                block_values.resize(static_cast<std::size_t>(size.x) * size.y * size.z);
                auto local = [&](glm::ivec3 g) {
                    const glm::ivec3 l = g - first;
                    return (static_cast<std::size_t>(l.z) * size.y + l.y) * size.x + l.x;
                };
                for (int z = first.z; z <= last.z; ++z)
                    for (int y = first.y; y <= last.y; ++y)
                        for (int x = first.x; x <= last.x; ++x)
                            block_values[local({x, y, z})] = value_at({x, y, z});
                for (int z = first.z; z < last.z; ++z)
                    for (int y = first.y; y < last.y; ++y)
                        for (int x = first.x; x < last.x; ++x) {
                            std::uint64_t corner_index[8];
                            glm::vec3 corner_position[8];
                            float corner_value[8];
                            bool any_inside = false, any_outside = false;
                            for (int c = 0; c < 8; ++c) {
                                const glm::ivec3 g(x + (c & 1), y + ((c >> 1) & 1),
                                                   z + ((c >> 2) & 1));
                                corner_index[c] = global_index(g);
                                corner_position[c] = lo + cell * glm::vec3(g);
                                corner_value[c] = block_values[local(g)];
                                (corner_value[c] < 0.0f ? any_inside : any_outside) =
                                    true;
                            }
                            if (!any_inside || !any_outside) continue;
                            for (const auto& tet : kTetrahedra) {
                                int inside[4], outside[4], n_in = 0, n_out = 0;
                                for (int k = 0; k < 4; ++k)
                                    (corner_value[tet[k]] < 0.0f ? inside[n_in++]
                                                                 : outside[n_out++]) =
                                        tet[k];
                                if (n_in == 0 || n_out == 0) continue;
                                auto on = [&](int a, int b) {
                                    return vertex_on_edge(
                                        corner_index[a], corner_position[a],
                                        corner_value[a], corner_index[b],
                                        corner_position[b], corner_value[b]);
                                };
                                glm::vec3 in_centre(0.0f), out_centre(0.0f);
                                for (int k = 0; k < n_in; ++k)
                                    in_centre += corner_position[inside[k]];
                                for (int k = 0; k < n_out; ++k)
                                    out_centre += corner_position[outside[k]];
                                const glm::vec3 outward =
                                    out_centre / float(n_out) - in_centre / float(n_in);
                                // Orientation is decided on the edge midpoints, which are
                                // exact and never degenerate: moving each vertex along
                                // its edge keeps the triangle's side, while the
                                // interpolated vertices can form slivers whose own normal
                                // is noise.
                                auto mid = [&](int a, int b) {
                                    return 0.5f *
                                           (corner_position[a] + corner_position[b]);
                                };
                                auto faces_out = [&](glm::vec3 a, glm::vec3 b,
                                                     glm::vec3 c) {
                                    return glm::dot(glm::cross(b - a, c - a), outward) >
                                           0.0f;
                                };
                                if (n_in == 1 || n_out == 1) {
                                    const int lone = n_in == 1 ? inside[0] : outside[0];
                                    const int* others = n_in == 1 ? outside : inside;
                                    const unsigned a = on(lone, others[0]);
                                    const unsigned b = on(lone, others[1]);
                                    const unsigned c = on(lone, others[2]);
                                    if (faces_out(mid(lone, others[0]),
                                                  mid(lone, others[1]),
                                                  mid(lone, others[2])))
                                        mesh.triangles.push_back({a, b, c});
                                    else
                                        mesh.triangles.push_back({a, c, b});
                                } else {  // two in, two out: a quad around the
                                          // tetrahedron
                                    const unsigned q0 = on(inside[0], outside[0]);
                                    const unsigned q1 = on(inside[1], outside[0]);
                                    const unsigned q2 = on(inside[1], outside[1]);
                                    const unsigned q3 = on(inside[0], outside[1]);
                                    if (faces_out(mid(inside[0], outside[0]),
                                                  mid(inside[1], outside[0]),
                                                  mid(inside[1], outside[1]))) {
                                        mesh.triangles.push_back({q0, q1, q2});
                                        mesh.triangles.push_back({q0, q2, q3});
                                    } else {
                                        mesh.triangles.push_back({q0, q2, q1});
                                        mesh.triangles.push_back({q0, q3, q2});
                                    }
                                }
                            }
                        }
            }
    return mesh;
}

}  // namespace lucent
